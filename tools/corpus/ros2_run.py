#!/usr/bin/env python3
"""Run public simROS2 / simROS scripts in gantry against an independent ROS 2 peer.

For each Lua file of a corpus kept OUTSIDE the repository (default
``/work/ros2-corpus``, files named ``<owner>__<repo>__<path with / -> __>``), this tool

1. reads the script statically: which ``simROS2.*`` / ``simROS.*`` functions it calls,
   the topics and types of its ``createPublisher`` / ``advertise`` and
   ``createSubscription`` / ``subscribe`` calls (string literals, or literals joined
   with ``..``), and the scene objects it looks up with ``sim.getObject('...')`` /
   ``sim.getObjectHandle('...')`` (literals, a variable assigned a literal, or
   ``'prefix'..i`` inside ``for i=a,b``);
2. builds a minimal TOML scene in a temporary folder: one object per looked-up path,
   a ``joint`` where the script calls joint functions on the handle, a
   ``proximity_sensor`` / ``vision_sensor`` / ``force_sensor`` likewise, a ``dummy``
   otherwise; the script (copied next to the scene) is attached to a dummy. When the
   script resolves ``'..'`` (CoppeliaSim 4.8's script objects: ``'.'`` is the script,
   ``'..'`` the object it sits on), the script's dummy is placed under a dummy ``robot``;
3. runs ``gantry run SCENE --steps N --no-listen`` (``--fast`` on request) in a fresh
   random ``ROS_DOMAIN_ID`` (100..229) while a Cyclone DDS participant (the peer of
   ``tests/python/ros2_peer.py``, from the ``/tmp/cddtest`` venv) reads every topic the
   script publishes and writes default-valued messages on every topic it subscribes
   to. Topics whose names are built at run time are found through DDS discovery
   (the DCPSPublication / DCPSSubscription built-in topics), so they are covered too.
   For the tutorial types (``example_interfaces`` Fibonacci actions and AddTwoInts
   services) the peer also plays the other side: it sends a goal to a script's action
   server and asks for the result, serves a script's action client, and answers a
   script's service client;
4. prints a markdown table: whether the script runs (no Lua error from it in gantry's
   log, and at least one message of every topic it publishes reached the peer),
   messages seen per topic, and the first error line.

The message classes are generated from gantry's own catalog text
(``crates/protocol/src/ros/catalog.rs``), field for field, with ROS 2's DDS name
mangling (``pkg::msg::dds_::T_``); a type gantry does not know cannot be read by the
peer either, and is reported.

Discovery: ``ros2_peer.py``'s configuration, unicast on the well-known ports of
127.0.0.1 (``lo`` often has no multicast; multicast discovery there took about 8 s,
longer than a 100-step run; unicast takes under a second).
Runs are paced to wall-clock time by default: with ``--fast`` gantry finishes 100 steps
in well under a millisecond, before any DDS discovery can complete.

Diagnostics (not "unmodified" runs): ``--no-feed`` (the peer writes nothing, to tell
callback failures from others), ``--shim`` (defines ``sim.verbosity_msgs`` first, to see
what CoppeliaSim 4.6+ scripts do next), ``--extra DIR`` (``<stem>.paths`` files listing
objects whose paths the script builds at run time, and ``<stem>.companion.lua``: our own
stand-in for a script of the original scene that feeds this one, e.g. through a signal),
``--verbose`` (counts the script's
log lines, e.g. from subscription callbacks). ``--extract-ttt`` writes the scripts of a
CoppeliaSim ``.ttt`` scene (Huffman-compressed, script texts lightly encoded), which is
how the simROS2 plugin's example scenes were read.

``--write-manifest`` (re)writes the manifest TSV (repository, path, commit, sha256,
bytes, functions used, note) from ``CORPUS/_fetch_log.tsv`` (repo, path, commit per file) and
the files themselves: metadata only, no code.

Run with the venv's Python::

    /tmp/cddtest/bin/python tools/corpus/ros2_run.py --corpus /work/ros2-corpus \\
        --manifest tools/corpus/ros2-manifest.tsv --markdown /tmp/ros2-report.md
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import gc
import hashlib
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import types as pytypes
from collections import defaultdict, deque
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
CATALOG_RS = REPO / "crates" / "protocol" / "src" / "ros" / "catalog.rs"
ANSI = re.compile(r"\x1b\[[0-9;]*m")

# --------------------------------------------------------------------------------------
# gantry's message catalog, read from its source text
# --------------------------------------------------------------------------------------


def read_catalog(path: Path = CATALOG_RS) -> tuple[dict, dict]:
    """``({'pkg/msg/T': [(type, name, default)]}, {'pkg/srv/T': (req, resp)})``."""
    src = path.read_text(encoding="utf-8")
    consts = dict(re.findall(r'const ([A-Z_0-9]+): &str = "(.*?)";', src, re.S))
    pkgs = re.findall(r'\("([a-z_0-9]+)",\s*([A-Z_0-9]+)\)', src)
    msgs: dict[str, list] = {}
    srvs: dict[str, tuple] = {}
    for pkg, const in pkgs:
        text = consts.get(const, "")
        cur = None
        kind = None
        part = 0
        for raw in text.splitlines():
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            m = re.match(r"(MSG|SRV|ACTION):\s*(\w+)$", line)
            if m:
                kind, cur = m.group(1), m.group(2)
                part = 0
                if kind == "ACTION":
                    continue  # the peer's action types are ros2_peer.py's
                if kind == "MSG":
                    msgs[f"{pkg}/msg/{cur}"] = []
                else:
                    srvs[f"{pkg}/srv/{cur}"] = ([], [])
                continue
            if kind == "ACTION":
                continue
            if line == "---":
                part = 1
                continue
            toks = line.split()
            if len(toks) < 2 or "=" in toks[1] or (len(toks) > 2 and toks[2].startswith("=")):
                continue  # a constant
            ftype, fname = toks[0], toks[1]
            default = toks[2] if len(toks) > 2 else None
            # qualify nested types
            base = re.sub(r"\[.*\]$", "", ftype)
            suffix = ftype[len(base):]
            if base not in PRIMITIVES:
                if base == "Header":
                    base = "std_msgs/msg/Header"
                elif "/" in base:
                    p, t = base.split("/")
                    base = f"{p}/msg/{t}"
                else:
                    base = f"{pkg}/msg/{base}"
            field = (base + suffix, fname, default)
            if kind == "MSG":
                msgs[f"{pkg}/msg/{cur}"].append(field)
            else:
                srvs[f"{pkg}/srv/{cur}"][part].append(field)
    return msgs, srvs


PRIMITIVES = {
    "bool", "byte", "char", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32",
    "uint64", "float32", "float64", "string",
}


def ros2_type(t: str) -> str:
    """ROS 1 names (``std_msgs/Float32``) as ROS 2's (``std_msgs/msg/Float32``)."""
    parts = t.split("/")
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return t


def dds_type_name(t: str) -> str:
    p, k, n = t.split("/")
    return f"{p}::{k}::dds_::{n}_"


def ros_type_from_dds(name: str) -> str | None:
    m = re.match(r"(\w+)::(msg|srv)::dds_::(\w+)_$", name)
    return f"{m.group(1)}/{m.group(2)}/{m.group(3)}" if m else None


class Idl:
    """Cyclone DDS classes for catalog messages, made on demand."""

    def __init__(self, msgs: dict):
        from cyclonedds.idl import IdlStruct
        from cyclonedds.idl import types as T

        self.T = T
        self.IdlStruct = IdlStruct
        self.msgs = msgs
        self.classes: dict[str, type] = {}
        self.prim = {
            "bool": bool, "byte": T.byte, "char": T.uint8, "int8": T.int8, "int16": T.int16,
            "int32": T.int32, "int64": T.int64, "uint8": T.uint8, "uint16": T.uint16,
            "uint32": T.uint32, "uint64": T.uint64, "float32": T.float32,
            "float64": T.float64, "string": str,
        }

    def field_type(self, ftype: str):
        m = re.match(r"(.+?)\[(<=)?(\d*)\]$", ftype)
        if m:
            inner = self.field_type(m.group(1))
            if m.group(3) and not m.group(2):
                return self.T.array[inner, int(m.group(3))]
            if m.group(3):
                return self.T.sequence[inner, int(m.group(3))]
            return self.T.sequence[inner]
        if ftype in self.prim:
            return self.prim[ftype]
        return self.cls(ftype)

    def cls(self, t: str) -> type:
        if t in self.classes:
            return self.classes[t]
        if t not in self.msgs:
            raise KeyError(f"{t} is not in gantry's catalog")
        fields = self.msgs[t]
        ann = {}
        if not fields:
            ann["structure_needs_at_least_one_member"] = self.T.uint8
        for ftype, fname, _ in fields:
            ann[fname] = self.field_type(ftype)
        name = t.replace("/", "_")
        c = pytypes.new_class(name, (self.IdlStruct,), {"typename": dds_type_name(t)},
                              lambda ns: ns.update({"__annotations__": ann}))
        c = dataclasses.dataclass(c)
        self.classes[t] = c
        return c

    def default(self, t: str):
        """A message of type ``t`` with ROS's default values."""
        c = self.cls(t)
        kw = {}
        fields = self.msgs[t]
        if not fields:
            kw["structure_needs_at_least_one_member"] = 0
        for ftype, fname, dflt in fields:
            kw[fname] = self._default_value(ftype, dflt)
        return c(**kw)

    def _default_value(self, ftype: str, dflt):
        m = re.match(r"(.+?)\[(<=)?(\d*)\]$", ftype)
        if m:
            if m.group(3) and not m.group(2):
                return [self._default_value(m.group(1), None) for _ in range(int(m.group(3)))]
            return []
        if ftype == "string":
            return dflt.strip("'\"") if dflt else ""
        if ftype == "bool":
            return dflt == "true"
        if ftype in ("float32", "float64"):
            return float(dflt) if dflt else 0.0
        if ftype in self.prim:
            return int(dflt) if dflt else 0
        return self.default(ftype)


# --------------------------------------------------------------------------------------
# static reading of a Lua script
# --------------------------------------------------------------------------------------

STR = r"""(?:'(?:[^'\\\n]|\\.)*'|"(?:[^"\\\n]|\\.)*")"""
LIT_CAT = rf"{STR}(?:\s*\.\.\s*{STR})*"


def strip_comments(src: str) -> str:
    """Lua source with comments blanked out (strings kept)."""
    out = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("--", i):
            m = re.match(r"--\[(=*)\[", src[i:])
            if m:
                end = src.find("]" + m.group(1) + "]", i + len(m.group(0)))
                end = n if end < 0 else end + len(m.group(1)) + 2
            else:
                end = src.find("\n", i)
                end = n if end < 0 else end
            out.append(re.sub(r"[^\n]", " ", src[i:end]))
            i = end
            continue
        if c in "'\"":
            j = i + 1
            while j < n and src[j] != c and src[j] != "\n":
                j += 2 if src[j] == "\\" else 1
            out.append(src[i:j + 1])
            i = j + 1
            continue
        m = re.match(r"\[(=*)\[", src[i:])
        if m:
            end = src.find("]" + m.group(1) + "]", i + len(m.group(0)))
            end = n if end < 0 else end + len(m.group(1)) + 2
            out.append(src[i:end])
            i = end
            continue
        out.append(c)
        i += 1
    return "".join(out)


def lit_value(expr: str) -> str | None:
    """The value of a string literal or of literals joined with ``..``."""
    expr = expr.strip()
    if not re.fullmatch(LIT_CAT, expr):
        return None
    return "".join(s[1:-1] for s in re.findall(STR, expr))


def split_args(code: str, start: int) -> list[str]:
    """The top-level arguments of the call whose '(' is at ``start``."""
    depth, args, cur, i = 0, [], [], start + 1
    while i < len(code):
        c = code[i]
        if c in "'\"":
            m = re.match(STR, code[i:])
            if m:
                cur.append(m.group(0))
                i += len(m.group(0))
                continue
        if c in "({[":
            depth += 1
        elif c in ")}]":
            if depth == 0:
                args.append("".join(cur).strip())
                return args
            depth -= 1
        elif c == "," and depth == 0:
            args.append("".join(cur).strip())
            cur = []
            i += 1
            continue
        cur.append(c)
        i += 1
    return args


JOINT_FNS = {
    "setJointTargetVelocity", "setJointTargetPosition", "setJointPosition", "getJointPosition",
    "getJointVelocity", "getJointForce", "getJointTargetVelocity", "setJointMaxForce",
    "setJointTargetForce", "getJointTargetPosition", "setJointForce", "getJointType",
    "getJointInterval", "setJointInterval", "getJointMode", "setJointMode", "getJointMaxForce",
    "getJointTargetForce",
}
PROX_FNS = {"readProximitySensor", "handleProximitySensor", "checkProximitySensor",
            "checkProximitySensorEx"}
VISION_FNS = {
    "getVisionSensorImg", "getVisionSensorImage", "getVisionSensorCharImage", "readVisionSensor",
    "handleVisionSensor", "getVisionSensorDepth", "getVisionSensorDepthBuffer",
    "getVisionSensorResolution", "setVisionSensorImg", "setVisionSensorImage",
    "setVisionSensorCharImage", "getVisionSensorRes", "checkVisionSensor",
}
FORCE_FNS = {"readForceSensor"}


class Script:
    """What a Lua file asks of gantry and of the ROS graph."""

    def __init__(self, path: Path, extra: Path | None = None):
        self.path = path
        self.extra: list[tuple[str, str]] = []
        # A companion script standing in for another script of the original scene (one
        # that feeds this one through signals), ours, attached to a dummy of its own.
        self.companion = extra / f"{path.stem}.companion.lua" if extra else None
        if self.companion and not self.companion.exists():
            self.companion = None
        if extra and (extra / f"{path.stem}.paths").exists():
            for line in (extra / f"{path.stem}.paths").read_text(encoding="utf-8").splitlines():
                line = line.split("#", 1)[0].split()
                if line:
                    self.extra.append((line[0], line[1] if len(line) > 1 else "dummy"))
        self.src = path.read_text(encoding="utf-8", errors="replace")
        self.code = strip_comments(self.src)
        code = self.code
        self.functions = sorted(set(re.findall(r"\b(simROS2?\.\w+)", code)))
        self.called = sorted(set(m.group(1) for m in
                                 re.finditer(r"\b(simROS2?\.\w+)\s*\(", code)))
        self.publishers: list[tuple[str | None, str | None, str]] = []  # topic, type, raw
        self.subscriptions: list[tuple[str | None, str | None, str]] = []
        self.services: list[str] = []
        for m in re.finditer(r"\bsimROS2?\s*\.\s*(createPublisher|advertise|createSubscription|"
                             r"subscribe|createService|createClient)\s*\(", code):
            args = split_args(code, m.end() - 1)
            if len(args) < 2:
                continue
            topic, typ = lit_value(args[0]), lit_value(args[1])
            typ = ros2_type(typ) if typ else None
            entry = (topic, typ, args[0])
            if m.group(1) in ("createPublisher", "advertise"):
                self.publishers.append(entry)
            elif m.group(1) in ("createSubscription", "subscribe"):
                self.subscriptions.append(entry)
            else:
                self.services.append(f"{m.group(1)}({args[0]}, {args[1]})")
        # Actions and service clients of the tutorial types the peer can play the other
        # side of: (kind, name) with kind "action server", "action client", "client".
        self.counterparts: list[tuple[str, str]] = []
        for m in re.finditer(r"\bsimROS2\s*\.\s*(createActionServer|createActionClient|createClient)\s*\(", code):
            args = split_args(code, m.end() - 1)
            if len(args) < 2:
                continue
            name, typ = lit_value(args[0]), lit_value(args[1])
            if not name or typ not in PLAYABLE.get(m.group(1), ()):
                continue
            kind = {"createActionServer": "action server", "createActionClient": "action client",
                    "createClient": "client"}[m.group(1)]
            self.counterparts.append((kind, name))
        self.sends_tf = bool(re.search(r"\bsimROS2?\.sendTransforms?\s*\(", code))
        self.objects = self._object_lookups() + self.extra

    def _object_lookups(self) -> list[tuple[str, str]]:
        """``[(path, kind)]`` of the objects the script looks up."""
        code = self.code
        assigned = dict((m.group(1), m.group(2)[1:-1]) for m in
                        re.finditer(rf"\b(\w+)\s*=\s*({STR})", code))
        loops = {m.group(1): (int(m.group(2)), int(m.group(3))) for m in
                 re.finditer(r"\bfor\s+(\w+)\s*=\s*(-?\d+)\s*,\s*(-?\d+)", code)}
        usage: dict[str, set] = defaultdict(set)
        for m in re.finditer(r"\bsim\.(\w+)\s*\(\s*([A-Za-z_]\w*)", code):
            usage[m.group(2)].add(m.group(1))
        found: dict[str, set] = defaultdict(set)
        for m in re.finditer(r"\bsim\.(getObject|getObjectHandle)\s*\(", code):
            args = split_args(code, m.end() - 1)
            if not args:
                continue
            a = args[0]
            paths = []
            v = lit_value(a)
            if v is not None:
                paths = [v]
            elif re.fullmatch(r"[A-Za-z_]\w*", a) and a in assigned:
                paths = [assigned[a]]
            else:
                mm = re.fullmatch(rf"({LIT_CAT})\s*\.\.\s*([A-Za-z_]\w*)(?:\s*\.\.\s*({LIT_CAT}))?", a)
                if mm and mm.group(2) in loops:
                    lo, hi = loops[mm.group(2)]
                    pre, post = lit_value(mm.group(1)), lit_value(mm.group(3) or "''")
                    paths = [f"{pre}{k}{post}" for k in range(lo, min(hi, lo + 31) + 1)]
            if not paths:
                continue
            # the variable it is stored in: `x = sim.getObject(`, `x[i] = ...`, `self.x = ...`
            before = code[max(0, m.start() - 80):m.start()]
            vm = re.search(r"([A-Za-z_][\w.]*)(?:\[[^\]]*\])?\s*=\s*$", before)
            var = vm.group(1).split(".")[-1] if vm else None
            kinds = set()
            if var:
                kinds |= usage.get(var, set())
            # a handle used directly: sim.fn(sim.getObject('x'))
            after = code[max(0, m.start() - 40):m.start()]
            dm = re.search(r"sim\.(\w+)\s*\(\s*$", after)
            if dm:
                kinds.add(dm.group(1))
            for p in paths:
                found[p] |= kinds
        out = []
        for p, fns in found.items():
            out.append((p, kind_of(p, fns)))
        return out


def kind_of(path: str, fns: set) -> str:
    if fns & JOINT_FNS:
        return "joint"
    if fns & PROX_FNS:
        return "proximity_sensor"
    if fns & VISION_FNS:
        return "vision_sensor"
    if fns & FORCE_FNS:
        return "force_sensor"
    leaf = path.rstrip("/").split("/")[-1].lower()
    if re.search(r"joint|motor", leaf):
        return "joint"
    if re.search(r"camera|vision|kinect", leaf):
        return "vision_sensor"
    if re.search(r"proximity|sonar|ultrasonic|infrared|sensingnose", leaf):
        return "proximity_sensor"
    return "dummy"


# --------------------------------------------------------------------------------------
# the minimal scene
# --------------------------------------------------------------------------------------


def build_scene(script: Script, folder: Path, shim: bool = False) -> tuple[Path, list[str]]:
    """Writes ``scene.toml`` and the script into ``folder``; returns the scene and notes."""
    notes = []
    uses_parent = any(p == ".." or p.startswith("../") for p, _ in script.objects)
    nodes: dict[tuple, dict] = {}

    def node(key: tuple, alias: str, kind: str = "dummy", parent: tuple | None = None):
        if key not in nodes:
            nodes[key] = {"alias": alias, "kind": "dummy", "parent": parent}
        if kind != "dummy":
            nodes[key]["kind"] = kind
        return key

    if uses_parent:
        robot = node(("robot",), "robot")
        host = node(("robot", "script"), "script", parent=robot)
        notes.append("'..' paths: script on dummy 'script' under dummy 'robot' (CoppeliaSim 4.8 script object)")
    else:
        robot = None
        host = node(("scriptHost",), "scriptHost")
    for path, kind in script.objects:
        p = re.sub(r"\{[^}]*\}", "", path)
        p = re.sub(r"\[\d+\]", "", p)
        if p in (".", "") or p == "..":
            tgt = host if p in (".", "") else (robot or host)
            if kind != "dummy":
                nodes[tgt]["kind"] = kind
            continue
        if p.startswith("./"):
            parent, parts = host, p[2:].split("/")
        elif p.startswith("../"):
            parent, parts = robot, p[3:].split("/")
        elif p.startswith(":/"):
            parent, parts = robot or host, p[2:].split("/")
        elif p.startswith("/"):
            parent, parts = None, p[1:].split("/")
        else:  # a legacy name (sim.getObjectHandle('name#0'))
            parent, parts = None, [p.split("#")[0]]
        parts = [x for x in parts if x and x != "."]
        for i, part in enumerate(parts):
            key = (parent or ()) + (part,)
            last = i == len(parts) - 1
            node(key, part, kind if last else "dummy", parent)
            parent = key
    if script.companion:
        node(("companion",), "companion")
        notes.append(f"companion script {script.companion.name} on dummy 'companion'")
    names = {k: f"o{i}" for i, k in enumerate(nodes)}
    lines = ["# Generated by tools/corpus/ros2_run.py: a minimal scene for one public script.",
             "[simulation]", "dt = 0.05", ""]
    for key, n in nodes.items():
        lines += ["[[object]]", f'name = "{names[key]}"', f'alias = "{toml_str(n["alias"])}"',
                  f'kind = "{n["kind"]}"']
        if n["parent"] is not None:
            lines.append(f'parent = "{names[n["parent"]]}"')
        if n["kind"] == "joint":
            lines.append('joint = "revolute"')
        if n["kind"] == "vision_sensor":
            lines.append("resolution = [64, 48]")
        if key == host:
            lines.append(f'script = "{script.path.name}"')
        if key == ("companion",):
            lines.append('script = "companion.lua"')
        if key == (robot or host):
            lines.append("model_base = true")
        lines.append("")
    scene = folder / "scene.toml"
    scene.write_text("\n".join(lines), encoding="utf-8")
    if script.companion:
        shutil.copy(script.companion, folder / "companion.lua")
    if shim:
        # Diagnostic only (--shim): prepended on the script's first line, so that line
        # numbers in errors stay those of the file as published.
        text = script.path.read_text(encoding="utf-8", errors="replace")
        (folder / script.path.name).write_text(SHIM + text, encoding="utf-8")
        notes.append(f"--shim: prepended `{SHIM.strip()}`")
    else:
        shutil.copy(script.path, folder / script.path.name)
    return scene, notes


# What --shim adds in front of a script: constants of CoppeliaSim 4.6+ that gantry lacks,
# to see what a script would do next. Results with --shim are not "runs unmodified".
SHIM = "sim=require('sim') sim.verbosity_msgs=sim.verbosity_msgs or sim.verbosity_scriptinfos "


def toml_str(s: str) -> str:
    return s.replace("\\", "\\\\").replace('"', '\\"')


# --------------------------------------------------------------------------------------
# one run against the peer
# --------------------------------------------------------------------------------------

IGNORED_TOPICS = {"rt/rosout", "rt/parameter_events"}

# The types whose other side the peer plays (ros2_peer.py has their IDL).
PLAYABLE = {
    "createActionServer": ("example_interfaces/action/Fibonacci",),
    "createActionClient": ("example_interfaces/action/Fibonacci",),
    "createClient": ("example_interfaces/srv/AddTwoInts",),
}


class Counterpart:
    """The peer's side of one action or service a script uses: a client sending one
    Fibonacci goal (order 3) to a script's action server and asking for its result, a
    Fibonacci action server for a script's action client, or an AddTwoInts server for a
    script's service client. ``progress`` counts what happened, under pseudo-topics
    (``action /fibonacci: result``) the report lists with the topics."""

    def __init__(self, peer, kind: str, name: str):
        import ros2_peer as rp
        self.rp, self.kind, self.name = rp, kind, name
        self.progress: dict[str, int] = {}
        self.guid, self.goal_id, self.goals = 0x5EED, None, {}
        if kind == "client":
            base = name.strip("/")
            self.requests = peer.reader(f"rq/{base}Request", rp.AddTwoIntsRequest)
            self.replies = peer.writer(f"rr/{base}Reply", rp.AddTwoIntsResponse)
        else:
            self.act = rp.FibonacciEndpoints(peer, name, serving=(kind == "action client"))

    @staticmethod
    def expected_for(kind: str, name: str) -> list[str]:
        return [{"action server": f"action {name}: result",
                 "action client": f"action {name}: result request",
                 "client": f"service {name}: request"}[kind]]

    def count(self, what: str, n: int = 1) -> None:
        key = f"{'service' if self.kind == 'client' else 'action'} {self.name}: {what}"
        self.progress[key] = self.progress.get(key, 0) + n

    @staticmethod
    def valid(samples) -> list:
        """The data samples (Cyclone also returns InvalidSample for a writer's dispose
        or unregister, e.g. when gantry exits)."""
        return [x for x in samples if type(x).__name__ != "InvalidSample"]

    def poll(self) -> None:
        rp, valid = self.rp, self.valid
        if self.kind == "client":
            for r in valid(self.requests.take(N=10)):
                self.count("request")
                self.replies.write(rp.AddTwoIntsResponse(client_guid=r.client_guid,
                                                         sequence_number=r.sequence_number, sum=r.a + r.b))
        elif self.kind == "action client":
            a = self.act
            for r in valid(a.requests["send_goal"].take(N=10)):
                self.count("goal")
                seq = [0, 1]
                while len(seq) < r.goal.order:
                    seq.append(seq[-1] + seq[-2])
                self.goals[bytes(r.goal_id.uuid)] = seq
                a.replies["send_goal"].write(rp.FibonacciSendGoalResponse(
                    client_guid=r.client_guid, sequence_number=r.sequence_number, accepted=True,
                    stamp=rp.Time(sec=0, nanosec=0)))
                a.feedback.write(rp.FibonacciFeedbackMessage(
                    goal_id=r.goal_id, feedback=rp.FibonacciFeedback(sequence=seq[:2])))
            for r in valid(a.requests["get_result"].take(N=10)):
                self.count("result request")
                a.replies["get_result"].write(rp.FibonacciGetResultResponse(
                    client_guid=r.client_guid, sequence_number=r.sequence_number, status=4,
                    result=rp.FibonacciResult(sequence=self.goals.get(bytes(r.goal_id.uuid), []))))
        else:
            a = self.act
            if self.goal_id is None and all(w.get_matched_subscriptions() for w in a.requests.values()):
                self.goal_id = rp.UUID(uuid=list(os.urandom(16)))
                a.requests["send_goal"].write(rp.FibonacciSendGoalRequest(
                    client_guid=self.guid, sequence_number=1, goal_id=self.goal_id,
                    goal=rp.FibonacciGoal(order=3)))
                self.count("goal")
            for r in valid(a.replies["send_goal"].take(N=10)):
                if r.accepted:
                    self.count("accepted")
                    a.requests["get_result"].write(rp.FibonacciGetResultRequest(
                        client_guid=self.guid, sequence_number=2, goal_id=self.goal_id))
            self.count("feedback", len(valid(a.feedback.take(N=100))))
            for r in valid(a.replies["get_result"].take(N=10)):
                if r.status == 4:
                    self.count("result")


class Result:
    def __init__(self, script: Script):
        self.script = script
        self.rc: int | None = None
        self.seen: dict[str, int] = {}           # gantry -> peer, per topic
        self.written: dict[str, int] = {}        # peer -> gantry, per topic
        self.matched: dict[str, bool] = {}       # peer writer matched a gantry reader
        self.gantry_writers: dict[str, str] = {}  # topic -> type seen on the graph
        self.gantry_readers: dict[str, str] = {}
        self.problems: list[str] = []
        self.errors: list[str] = []
        self.warnings: list[str] = []
        self.log: list[str] = []
        self.notes: list[str] = []
        self.script_lines = 0                    # INFO lines from the script (--verbose)

    def expected_topics(self) -> list[str]:
        exp = {f"rt{t}" if t.startswith("/") else f"rt/{t}"
               for t, _, _ in self.script.publishers if t}
        if self.script.sends_tf:
            exp.add("rt/tf")
        # An action's own topics are checked through its counterpart's progress.
        exp |= {t for t in self.gantry_writers if "/_action/" not in t}
        exp |= {e for kind, name in self.script.counterparts
                for e in Counterpart.expected_for(kind, name)}
        return sorted(exp - IGNORED_TOPICS)

    def runs(self) -> bool:
        if self.errors or self.rc not in (0,):
            return False
        return all(self.seen.get(t, 0) > 0 for t in self.expected_topics())


def gantry_bin(arg: str | None) -> str:
    for p in (arg, os.environ.get("GANTRY_BIN"), REPO / "target/ci/gantry",
              REPO / "target/release/gantry", REPO / "target/debug/gantry"):
        if p and Path(p).exists():
            return str(p)
    sys.exit("no gantry binary: pass --gantry or set GANTRY_BIN")


def run_one(script: Script, idl: Idl, args) -> Result:
    sys.path.insert(0, str(REPO / "tests" / "python"))
    from cyclonedds.builtin import (BuiltinDataReader, BuiltinTopicDcpsPublication,
                                    BuiltinTopicDcpsSubscription)
    from cyclonedds.core import Policy, Qos
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration
    import ros2_peer

    res = Result(script)
    domain = random.Random(os.getpid() ^ time.time_ns()).randrange(100, 230)
    peer = ros2_peer.Peer(domain)
    topics: dict[str, object] = {}

    def topic_of(name: str, typ: str):
        if name not in topics:
            topics[name] = Topic(peer.dp, name, idl.cls(typ))
        return topics[name]
    # IgnoreLocal: the peer never reads its own samples on a topic the script both
    # publishes and subscribes to, and its writers match only gantry's readers.
    read_qos = Qos(Policy.Reliability.BestEffort, Policy.Durability.Volatile,
                   Policy.History.KeepLast(100), Policy.IgnoreLocal.Participant)
    write_qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=200)),
                    Policy.Durability.Volatile, Policy.History.KeepLast(10),
                    Policy.IgnoreLocal.Participant)
    readers: dict[str, object] = {}
    writers: dict[str, tuple] = {}

    def add_reader(topic: str, typ: str | None):
        # An action's topics are its counterpart's (rcl_action's QoS, its own types).
        if topic in readers or topic in IGNORED_TOPICS or "/_action/" in topic:
            return
        if not typ:
            return
        try:
            readers[topic] = DataReader(peer.dp, topic_of(topic, typ), qos=read_qos)
            res.seen.setdefault(topic, 0)
        except Exception as e:  # noqa: BLE001 - reported, not fatal
            readers[topic] = None
            res.problems.append(f"peer cannot read {topic} ({typ}): {e}")

    def add_writer(topic: str, typ: str | None):
        if topic in writers or not typ:
            return
        try:
            w = DataWriter(peer.dp, topic_of(topic, typ), qos=write_qos)
            writers[topic] = (w, idl.default(typ))
            res.written.setdefault(topic, 0)
        except Exception as e:  # noqa: BLE001
            writers[topic] = (None, None)
            res.problems.append(f"peer cannot write {topic} ({typ}): {e}")

    def dds(topic: str) -> str:
        return f"rt{topic}" if topic.startswith("/") else f"rt/{topic}"

    for topic, typ, _ in script.publishers:
        if topic:
            add_reader(dds(topic), typ)
    if script.sends_tf:
        add_reader("rt/tf", "tf2_msgs/msg/TFMessage")
    for topic, typ, _ in script.subscriptions:
        if topic:
            add_writer(dds(topic), typ)
    counterparts = [Counterpart(peer, kind, name) for kind, name in script.counterparts]
    pubs_seen = BuiltinDataReader(peer.dp, BuiltinTopicDcpsPublication)
    subs_seen = BuiltinDataReader(peer.dp, BuiltinTopicDcpsSubscription)
    own = peer.dp.guid

    with tempfile.TemporaryDirectory(prefix="ros2run-") as tmp:
        scene, notes = build_scene(script, Path(tmp), shim=args.shim)
        res.notes += notes
        if args.keep_scenes:
            keep = Path(args.keep_scenes) / script.path.stem
            keep.mkdir(parents=True, exist_ok=True)
            shutil.copy(scene, keep / "scene.toml")
        cmd = [gantry_bin(args.gantry), "run", str(scene), "--steps", str(args.steps), "--no-listen"]
        if args.fast:
            cmd.append("--fast")
        if args.verbose:
            cmd.append("-v")
        env = dict(os.environ, ROS_DOMAIN_ID=str(domain), NO_COLOR="1")
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True, errors="replace", env=env)
        log: deque[str] = deque(maxlen=5000)

        def drain():
            for line in proc.stderr:
                log.append(ANSI.sub("", line.rstrip("\n")))

        th = threading.Thread(target=drain, daemon=True)
        th.start()
        deadline = time.monotonic() + args.steps * 0.05 * (0.2 if args.fast else 1.0) + args.timeout
        last_write = 0.0
        ended_at = None
        while True:
            now = time.monotonic()
            for s in pubs_seen.take(N=100):
                if s.participant_key == own or not (s.topic_name or "").startswith("rt/"):
                    continue
                t = ros_type_from_dds(s.type_name)
                res.gantry_writers[s.topic_name] = t or s.type_name
                add_reader(s.topic_name, t)
            for s in subs_seen.take(N=100):
                if s.participant_key == own or not (s.topic_name or "").startswith("rt/"):
                    continue
                t = ros_type_from_dds(s.type_name)
                res.gantry_readers[s.topic_name] = t or s.type_name
                add_writer(s.topic_name, t)
            for topic, r in readers.items():
                if r is not None:
                    res.seen[topic] += len(r.take(N=1000))
            for c in counterparts:
                c.poll()
            if not args.no_feed and now - last_write > 0.05:
                last_write = now
                for topic, (w, msg) in writers.items():
                    if w is None:
                        continue
                    if w.get_matched_subscriptions():
                        res.matched[topic] = True
                        w.write(msg)
                        res.written[topic] += 1
            if proc.poll() is not None:
                ended_at = ended_at or now
                if now - ended_at > 0.5:  # late samples
                    break
            elif now > deadline:
                proc.kill()
                res.problems.append(f"gantry did not finish {args.steps} steps in time; killed")
            time.sleep(0.01)
        res.rc = proc.wait()
        th.join(2)
    for c in counterparts:
        for k, n in c.progress.items():
            res.seen[k] = res.seen.get(k, 0) + n
    res.log = list(log)
    analyse_log(res)
    # let the participant go before the next script
    del readers, writers, pubs_seen, subs_seen, topics, peer, counterparts
    gc.collect()
    return res


def analyse_log(res: Result) -> None:
    name = res.script.path.name
    lines = res.log
    for i, line in enumerate(lines):
        is_err = " ERROR " in line or line.startswith("ERROR") or "[string" in line
        mine = name in line or "[string" in line
        if is_err and (mine or "script" in line):
            msg = re.sub(r"^\S+\s+ERROR\s+", "", line)
            # the script's own line in the traceback, if any
            where = next((m.group(1) for x in lines[i + 1:i + 12]
                          for m in [re.search(re.escape(name[-25:]) + r":(\d+):", x)] if m), "")
            if where and not re.search(re.escape(name[-25:]) + r":\d+:", msg):
                msg += f" [at line {where}]"
            res.errors.append(msg)
        elif " INFO " in line and f"[{name}]" in line:
            res.script_lines += 1
        elif " WARN " in line and "ROS 1 is end-of-life" not in line and "rustdds" not in line:
            res.warnings.append(re.sub(r"^\S+\s+WARN\s+", "", line))


# --------------------------------------------------------------------------------------
# manifest and report
# --------------------------------------------------------------------------------------


def _huffman_uncompress(data: bytes, size: int) -> bytes:
    """The Basic Compression Library's Huffman_Uncompress (CoppeliaSim's scene files)."""
    bits = int.from_bytes(data, "big")
    nbits = len(data) * 8
    pos = 0

    def bit() -> int:
        nonlocal pos
        b = (bits >> (nbits - 1 - pos)) & 1
        pos += 1
        return b

    def tree():
        if bit():
            x = 0
            for _ in range(8):
                x = (x << 1) | bit()
            return x
        a = tree()
        return (a, tree())

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 5000))
    root = tree()
    out = bytearray()
    for _ in range(size):
        n = root
        while isinstance(n, tuple):
            n = n[bit()]
        out.append(n)
    return bytes(out)


def _light_decode(buf: bytes) -> bytes:
    """CoppeliaSim's tt::lightDecodeBuffer (script texts in scene files; signed chars)."""
    b = bytearray(buf)
    n = len(b)
    if n < 3:
        return bytes(b)

    def sc(v):
        return v - 256 if v > 127 else v

    start, end = int(sc(b[0]) / 2), sc(b[n - 1]) * 3
    for i in range(1, n - 1):
        v = b[i]
        if i & 1:
            v += i + start + end
        if i & 2:
            v -= 3 * i + start
        if i & 4:
            v += i // 2 + end
        b[i] = v % 256
    return bytes(b)


def ttt_scripts(data: bytes) -> list[bytes]:
    """The script texts ("Ste" records) of a CoppeliaSim binary scene or model."""
    import struct

    if data[:4] not in (b"VREP", b"CSIM"):
        raise ValueError("not a CoppeliaSim binary scene")
    comp = data[12]
    size = struct.unpack("<i", data[13:17])[0]
    body = data[1021:]  # header: 4+4+4+1+4+4+2+4+1+1 bytes and 992 reserved
    buf = _huffman_uncompress(body, size) if comp == 1 else body
    out = []
    i = buf.find(b"Ste")
    while i >= 0:
        n = struct.unpack("<i", buf[i + 3:i + 7])[0]
        if 0 < n < len(buf) - i:
            text = _light_decode(buf[i + 7:i + 7 + n])
            if text.startswith((b"--", b"#", b"function", b"require", b"sim")) or b"sysCall_" in text:
                out.append(text)
        i = buf.find(b"Ste", i + 1)
    return out


def corpus_name(repo: str, path: str) -> str:
    owner, name = repo.split("/", 1)
    return f"{owner}__{name}__{path.replace('/', '__').replace('#', '__')}" + \
        ("" if path.endswith(".lua") else ".lua")


def read_manifest(path: Path) -> dict[str, dict]:
    out = {}
    if path and path.exists():
        with open(path, encoding="utf-8", newline="") as f:
            for r in csv.DictReader(f, delimiter="\t"):
                out[corpus_name(r["repo"], r["path"])] = r
    return out


def write_manifest(corpus: Path, out: Path) -> int:
    log = corpus / "_fetch_log.tsv"
    rows = []
    with open(log, encoding="utf-8", newline="") as f:
        for r in csv.reader(f, delimiter="\t"):
            if not r or r[0] == "repo":
                continue
            repo, path, commit = r[0], r[1], r[2]
            p = corpus / corpus_name(repo, path)
            if not p.exists():
                print(f"missing: {p}", file=sys.stderr)
                continue
            data = p.read_bytes()
            s = Script(p)
            note = ("script text decoded from the .ttt scene (ros2_run.py --extract-ttt)" if "#script-" in path
                    else "Lua code block of the HTML page" if "#lua-block-" in path else "")
            rows.append((repo, path, commit, hashlib.sha256(data).hexdigest(), str(len(data)),
                         " ".join(s.called), note))
    rows.sort(key=lambda x: (x[0].lower(), x[1]))
    with open(out, "w", encoding="utf-8", newline="") as f:
        w = csv.writer(f, delimiter="\t", lineterminator="\n")
        w.writerow(["repo", "path", "commit", "sha256", "bytes", "functions", "note"])
        w.writerows(rows)
    print(f"{len(rows)} rows written to {out}", file=sys.stderr)
    return 0


def shown(topic: str) -> str:
    """A DDS topic as its ROS name (``rt/x`` -> ``/x``); pseudo-topics as they are."""
    return topic[2:] if topic.startswith("rt/") else topic


def md_escape(s: str) -> str:
    return s.replace("|", "\\|").replace("\n", " ")


def report(results: list[Result], manifest: dict, args) -> str:
    out = ["| script | repo / path @ commit | runs | messages gantry -> peer | peer -> gantry | first error |",
           "|---|---|---|---|---|---|"]
    for r in results:
        m = manifest.get(r.script.path.name, {})
        where = f"{m.get('repo', '?')} `{m.get('path', r.script.path.name)}` @ {m.get('commit', '?')[:10]}"
        seen = ", ".join(f"{shown(t)}: {r.seen.get(t, 0)}" for t in r.expected_topics()) or "-"
        wrote = ", ".join(
            f"{t[2:]}: {n}{'' if r.matched.get(t) else ' (no gantry reader matched)'}"
            for t, n in sorted(r.written.items())) or "-"
        err = r.errors[0] if r.errors else ""
        if not err and not r.runs():
            missing = [shown(t) for t in r.expected_topics() if not r.seen.get(t)]
            err = f"(no Lua error) nothing received on {', '.join(missing)}" if missing else f"exit code {r.rc}"
        out.append(f"| {r.script.path.stem[:60]} | {md_escape(where)} | {'yes' if r.runs() else 'no'} | "
                   f"{md_escape(seen)} | {md_escape(wrote)} | {md_escape(err[:300])} |")
    out.append("")
    for r in results:
        out.append(f"### {r.script.path.name}")
        out.append(f"- functions: {', '.join(r.script.called) or '-'}")
        pubs = ", ".join(f"{t or '<dynamic: ' + raw + '>'} ({ty or '?'})" for t, ty, raw in r.script.publishers)
        subs = ", ".join(f"{t or '<dynamic: ' + raw + '>'} ({ty or '?'})" for t, ty, raw in r.script.subscriptions)
        out.append(f"- publishes: {pubs or '-'}{'; /tf (sendTransform)' if r.script.sends_tf else ''}")
        out.append(f"- subscribes: {subs or '-'}")
        if r.script.services:
            out.append(f"- services/clients: {'; '.join(r.script.services)}")
        out.append(f"- scene objects: {', '.join(f'{p} ({k})' for p, k in r.script.objects) or '-'}")
        if r.script.extra:
            out.append(f"- of which added by hand (paths built at run time): {len(r.script.extra)}")
        if args.no_feed:
            out.append("- run with --no-feed: the peer wrote nothing to the script's subscriptions")
        if r.gantry_writers or r.gantry_readers:
            out.append("- on the graph: writers " + (", ".join(f"{t} [{ty}]" for t, ty in sorted(r.gantry_writers.items())) or "-")
                       + "; readers " + (", ".join(f"{t} [{ty}]" for t, ty in sorted(r.gantry_readers.items())) or "-"))
        for n in r.notes + r.problems:
            out.append(f"- note: {n}")
        for e in r.errors[:5]:
            out.append(f"- error: `{md_escape(e[:400])}`")
        for w in r.warnings[:3]:
            out.append(f"- warning: `{md_escape(w[:300])}`")
        if args.verbose:
            out.append(f"- log lines written by the script (sim.addLog/print, -v): {r.script_lines}")
        out.append(f"- gantry exit code: {r.rc}; runs: {'yes' if r.runs() else 'no'}")
        out.append("")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", type=Path, default=Path("/work/ros2-corpus"))
    ap.add_argument("--manifest", type=Path, default=Path(__file__).with_name("ros2-manifest.tsv"))
    ap.add_argument("--write-manifest", action="store_true",
                    help="rewrite --manifest from CORPUS/_fetch_log.tsv and the files, then exit")
    ap.add_argument("--gantry", help="gantry binary (default $GANTRY_BIN, target/ci, release, debug)")
    ap.add_argument("--steps", type=int, default=100, help="simulation steps per script (default 100)")
    ap.add_argument("--fast", action="store_true",
                    help="pass --fast (unpaced; short runs may end before DDS discovery completes)")
    ap.add_argument("--timeout", type=float, default=30.0, help="extra wall seconds per run")
    ap.add_argument("--no-feed", action="store_true",
                    help="the peer writes nothing to the script's subscriptions (isolates callback failures)")
    ap.add_argument("--extra", type=Path,
                    help="folder of <script stem>.paths files (extra scene objects, 'path kind' lines, "
                         "for paths the script builds at run time) and <script stem>.companion.lua "
                         "files (our stand-ins for other scripts of the original scene) "
                         "(default CORPUS/_extra)")
    ap.add_argument("--shim", action="store_true",
                    help="diagnostic: define sim.verbosity_msgs before the script (not an unmodified run)")
    ap.add_argument("--extract-ttt", nargs=2, metavar=("SCENE.ttt", "OUTDIR"),
                    help="write the Lua scripts stored in a CoppeliaSim .ttt/.ttm file to OUTDIR, then exit")
    ap.add_argument("--verbose", action="store_true",
                    help="run gantry with -v and report how many log lines the script wrote (sim.addLog, print)")
    ap.add_argument("--only", help="run only files whose name contains this")
    ap.add_argument("--markdown", type=Path, help="also write the report here")
    ap.add_argument("--keep-scenes", help="copy each generated scene.toml into this folder")
    ap.add_argument("--list", action="store_true", help="only print the static reading")
    a = ap.parse_args(argv)

    if a.extract_ttt:
        for i, text in enumerate(ttt_scripts(Path(a.extract_ttt[0]).read_bytes())):
            out = Path(a.extract_ttt[1]) / f"{Path(a.extract_ttt[0]).name}__script-{i}.lua"
            out.write_bytes(text)
            print(out)
        return 0
    if a.write_manifest:
        return write_manifest(a.corpus, a.manifest)
    files = sorted(p for p in a.corpus.glob("*.lua") if not a.only or a.only in p.name)
    extra = a.extra or a.corpus / "_extra"
    scripts = [Script(p, extra) for p in files]
    if a.list:
        for s in scripts:
            print(s.path.name, s.called, s.publishers, s.subscriptions, s.objects, sep="\n  ")
        return 0
    msgs, _ = read_catalog()
    idl = Idl(msgs)
    manifest = read_manifest(a.manifest)
    results = []
    for s in scripts:
        print(f"running {s.path.name} ...", file=sys.stderr, flush=True)
        r = run_one(s, idl, a)
        print(f"  runs={'yes' if r.runs() else 'no'} seen={r.seen} errors={r.errors[:1]}",
              file=sys.stderr, flush=True)
        results.append(r)
    text = report(results, manifest, a)
    print(text)
    if a.markdown:
        a.markdown.write_text(text + "\n", encoding="utf-8")
    return 0 if all(r.runs() for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
