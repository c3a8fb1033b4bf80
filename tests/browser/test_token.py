"""The viewer behind an access token (issue 9, security), in a real browser: opening the
URL that ``gantry run --token`` prints loads the whole page, its assets and its WebSocket
through the HttpOnly, SameSite=Strict cookie it sets; without the token every route
answers 401. Run with ``bash tools/browser-test.sh``.
"""

from __future__ import annotations

import urllib.error
import urllib.request

import pytest
from playwright.sync_api import sync_playwright

from viewer_util import Gantry, launch_chromium, wait_for

TOKEN = "browser-token-7f3a9c"


@pytest.fixture(scope="module")
def gantry():
    g = Gantry(extra=["--token", TOKEN])
    yield g
    g.close()
    print(f"--- gantry stderr ---\n{g.stderr()}")


def test_printed_url_opens_the_viewer_and_the_cookie_carries_the_rest(gantry):
    printed = wait_for(lambda: [line for line in gantry.log if line.startswith("viewer url=")],
                       what="the viewer url line")
    assert printed == [f"viewer url={gantry.url}?token={TOKEN}"], printed
    with sync_playwright() as p:
        browser = launch_chromium(p)
        pg = browser.new_page()
        errors: list[str] = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.goto(gantry.url + f"?token={TOKEN}")
        # The scene arrives over the WebSocket, which carries only the cookie.
        pg.wait_for_function("window.gantry && gantry.objects.length > 0 && gantry.frameMessages > 2",
                             timeout=20_000)
        cookies = {c["name"]: c for c in pg.context.cookies()}
        cookie = cookies[f"gantry_token_{gantry.addr['http'][1]}"]
        assert cookie["httpOnly"] and cookie["sameSite"] == "Strict", cookie
        assert pg.evaluate("document.cookie") == "", "the page's scripts cannot read the token"
        # A reload without ?token= and the API from the page both pass on the cookie.
        pg.goto(gantry.url)
        pg.wait_for_function("window.gantry && gantry.objects.length > 0", timeout=20_000)
        assert pg.evaluate("fetch('/api/status').then(r => r.status)") == 200
        assert not errors, errors

        # A fresh browser profile has no cookie: 401 with an explanation.
        other = browser.new_context().new_page()
        response = other.goto(gantry.url)
        assert response.status == 401
        assert "requires an access token" in other.content()
        browser.close()


@pytest.mark.parametrize("path", ["", "js/main.js", "api/status", "ws"])
def test_routes_without_the_token_are_refused(gantry, path):
    with pytest.raises(urllib.error.HTTPError) as e:
        urllib.request.urlopen(gantry.url + path, timeout=10)
    assert e.value.code == 401
