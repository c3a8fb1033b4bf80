"""The viewer while a script is stopped in the debugger (issue 17): a real gantry on
BubbleRob with ``--debug=0``, a small DAP client over TCP (the protocol's framing:
``Content-Length`` header, JSON body), and the page in headless chromium.

The page must show "paused in bubble_rob.lua:LINE" while the breakpoint holds, step
and continue the script from its banner, and the HTTP API must say the simulation is
paused in the debugger instead of hanging. The test saves test-artifacts/debugging.png
(copied to docs/debugging.png with GANTRY_UPDATE_SCREENSHOT=1).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import urllib.error
import urllib.request

import pytest
from playwright.sync_api import sync_playwright

from viewer_util import REPO, Gantry, launch_chromium

ARTIFACTS = REPO / "test-artifacts"
SCRIPT = REPO / "scripts" / "bubble_rob.lua"


class Dap:
    """The smallest DAP client: requests in order, events kept until asked for."""

    def __init__(self, addr: tuple[str, int]):
        self.sock = socket.create_connection(addr, timeout=20)
        self.buf = b""
        self.seq = 0
        self.events: list[dict] = []

    def _read(self) -> dict:
        while b"\r\n\r\n" not in self.buf:
            self._fill()
        header, rest = self.buf.split(b"\r\n\r\n", 1)
        length = int(header.split(b":")[1])
        while len(rest) < length:
            self.buf = header + b"\r\n\r\n" + rest
            self._fill()
            header, rest = self.buf.split(b"\r\n\r\n", 1)
        self.buf = rest[length:]
        return json.loads(rest[:length])

    def _fill(self):
        chunk = self.sock.recv(65536)
        if not chunk:
            raise ConnectionError("the debug adapter closed the connection")
        self.buf += chunk

    def request(self, command: str, arguments: dict | None = None) -> dict:
        self.seq += 1
        body = json.dumps({"seq": self.seq, "type": "request", "command": command, "arguments": arguments or {}})
        self.sock.sendall(f"Content-Length: {len(body)}\r\n\r\n{body}".encode())
        while True:
            msg = self._read()
            if msg["type"] == "event":
                self.events.append(msg)
            elif msg.get("request_seq") == self.seq:
                assert msg["success"], f"{command} failed: {msg.get('message')}"
                return msg.get("body") or {}

    def event(self, name: str) -> dict:
        while True:
            for i, e in enumerate(self.events):
                if e["event"] == name:
                    return self.events.pop(i)["body"]
            self.events.append(self._read())

    def close(self):
        self.sock.close()


def line_of(text: str) -> int:
    for n, line in enumerate(SCRIPT.read_text().splitlines(), start=1):
        if text in line:
            return n
    raise AssertionError(f"{text!r} is not in {SCRIPT}")


@pytest.fixture()
def gantry():
    g = Gantry(extra=[str(REPO / "assets" / "scenes" / "bubble_rob.toml"), "--debug=0"])
    yield g
    g.close()
    print(f"--- gantry stderr ---\n{g.stderr()}")


def test_the_page_shows_the_stop_and_steps_and_continues_the_script(gantry):
    line = line_of("if (result>0) then backUntilTime")
    with sync_playwright() as p:
        browser = launch_chromium(p)
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(gantry.url)
        page.wait_for_function("window.gantry && gantry.objects.length > 0 && gantry.framesRendered > 0",
                               timeout=20_000)
        assert page.is_hidden("#debug-banner")

        dap = Dap(gantry.addr["dap"])
        try:
            dap.request("initialize", {"clientID": "pytest", "adapterID": "gantry", "linesStartAt1": True})
            dap.request("attach")
            bps = dap.request("setBreakpoints", {"source": {"path": str(SCRIPT)}, "breakpoints": [{"line": line}]})
            assert bps["breakpoints"][0]["verified"]
            dap.request("configurationDone")
            stopped = dap.event("stopped")
            assert stopped["reason"] == "breakpoint"

            page.wait_for_selector("#debug-banner:not([hidden])", timeout=10_000)
            assert page.inner_text("#debug-where") == f"paused in bubble_rob.lua:{line} (breakpoint)"
            # The HTTP API answers at once that the simulation is held, not after it.
            with pytest.raises(urllib.error.HTTPError) as e:
                urllib.request.urlopen(gantry.url + "api/status", timeout=5)
            assert e.value.code == 503
            assert "paused in debugger at bubble_rob.lua" in e.value.read().decode()

            ARTIFACTS.mkdir(exist_ok=True)
            shot = ARTIFACTS / "debugging.png"
            page.screenshot(path=str(shot))
            if os.environ.get("GANTRY_UPDATE_SCREENSHOT") == "1":
                shutil.copyfile(shot, REPO / "docs" / "debugging.png")

            # Step over from the page: the script stops on a later line of the hook.
            page.click("#debug-banner button[data-debug=step_over]")
            stopped = dap.event("stopped")
            assert stopped["reason"] == "step"
            frames = dap.request("stackTrace", {"threadId": 1})["stackFrames"]
            assert frames[0]["line"] > line
            page.wait_for_function(f"document.getElementById('debug-where').textContent"
                                   f" === 'paused in bubble_rob.lua:{frames[0]['line']} (step)'", timeout=10_000)

            # Continue from the page, with the breakpoint gone: the simulation runs on.
            dap.events.clear()
            dap.request("setBreakpoints", {"source": {"path": str(SCRIPT)}, "breakpoints": []})
            page.click("#debug-banner button[data-debug=continue]")
            dap.event("continued")
            page.wait_for_selector("#debug-banner", state="hidden", timeout=10_000)
            t0 = gantry.status()["time"]
            page.wait_for_timeout(500)
            assert gantry.status()["time"] > t0
        finally:
            dap.close()
        assert not errors, f"JavaScript errors on the page: {errors}"
        browser.close()
