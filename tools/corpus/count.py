#!/usr/bin/env python3
"""Count which CoppeliaSim API functions a corpus of public scripts calls.

The corpus (kept outside the repository, see README.md) has two folders:

    CORPUS/lua/<owner>__<repo>__<path with / replaced by __>
    CORPUS/python/<owner>__<repo>__<path with / replaced by __>

Lua files are CoppeliaSim 4.x scene scripts (child, customization, add-on,
threaded); Python files are clients of the ZMQ remote API
(``coppeliasim_zmqremoteapi_client``).

Call sites counted:

* Lua: ``sim.X(``, ``simIK.X(``, ``simUI.X(`` ... (any ``sim`` or
  ``simXxx`` module table), also the paren-less forms ``sim.X 'str'`` and
  ``sim.X {tbl}``, and ``pcall(sim.X, ...)`` / ``xpcall(sim.X, ...)``.
  ``sim.X`` used as a plain value is not a call and is not counted, nor are
  constants such as ``sim.handle_self``.
* Python: calls through names bound to ``client.require('sim')`` or
  ``client.getObject('sim')`` (``sim = ...``, ``self.sim = ...``,
  ``self._sim = ...``, ``await client.require(...)``), names copied from them
  (``sim = self.sim``), and, as a fallback, the conventional names ``sim``,
  ``simIK``, ... .  Client-level ``client.step()`` and
  ``client.setStepping(...)`` count as ``sim.step`` / ``sim.setStepping``.

Comments are ignored (Lua ``--`` and ``--[[ ]]``, Python ``#``) and so are
string contents.

Only the Python standard library is used.
"""

from __future__ import annotations

import argparse
import collections
import io
import os
import re
import sys
import tokenize
from dataclasses import dataclass, field

LANGS = ("lua", "python")

# A module table of the CoppeliaSim API: `sim` or `simXxx` (simIK, simUI, ...).
MODULE_RE = re.compile(r"^sim(?:[A-Z0-9]\w*)?$")
# Module names recognised without a visible binding (`require`) in the file.
# Other `simXxx` names (often user variables such as `simJoints`, `simTip`)
# count only when the file binds them with require/getObject.
KNOWN_MODULES = {
    "sim", "simIK", "simUI", "simVision", "simOMPL", "simROS", "simROS2",
    "simBubble", "simAssimp", "simGeom", "simIM", "simIGL", "simEigen",
    "simQHull", "simConvex", "simConvexDecompose", "simSurfRec", "simOctomap",
    "simPovRay", "simWS", "simZMQ", "simSubprocess", "simCmd", "simLuaCmd",
    "simMTB", "simRRS1", "simICP", "simOpenMesh", "simSkeleton", "simSkel",
    "simURDF", "simSDF", "simCollada", "simGLTF", "simRuckig", "simB0",
    "simRemoteApi", "simDyn", "simEvents", "simQML", "simMujoco", "simBWF",
    "simK3", "simJoystick", "simCam", "simLDraw", "simURLDrop", "simHaply",
    "simCHAI3D", "simMath", "simAprilTag", "simOpenGL3", "simExternalRenderer",
    "simDataflow", "simVideoRecorder", "simBlueZero", "simPlugin", "simCodeEditor",
}


# --------------------------------------------------------------------------
# Supported-function list
# --------------------------------------------------------------------------

API_ROW_RE = re.compile(r"^\s*\|\s*`([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)+)`")


def load_api_markdown(path: str) -> dict[str, set[str]]:
    """Qualified names in the first column of table rows (`| `sim.x` | ...`)."""
    names: dict[str, set[str]] = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            m = API_ROW_RE.match(line)
            if m:
                # Columns: name | Scripts | Remote clients | Notes. A name scripts
                # cannot call does not count for Lua; one the remote API does not
                # serve does not count for Python.
                cols = [c.strip() for c in line.strip().strip("|").split("|")]
                langs = set(LANGS)
                if len(cols) >= 3:
                    if cols[1] == "no":
                        langs.discard("lua")
                    if cols[2] == "no":
                        langs.discard("python")
                names[m.group(1)] = langs
    return names


def load_names_file(path: str) -> dict[str, set[str]]:
    """One qualified name per line; an optional second field (`lua` or
    `python`) restricts the name to that language.  `#` starts a comment."""
    names: dict[str, set[str]] = {}
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            parts = line.split()
            langs = {p for p in parts[1:] if p in LANGS} or set(LANGS)
            names.setdefault(parts[0], set()).update(langs)
    return names


# --------------------------------------------------------------------------
# Lua
# --------------------------------------------------------------------------

def _long_bracket_level(text: str, i: int) -> int | None:
    """If text[i] starts a long bracket `[==[`, its level, else None."""
    if text[i] != "[":
        return None
    j = i + 1
    while j < len(text) and text[j] == "=":
        j += 1
    if j < len(text) and text[j] == "[":
        return j - i - 1
    return None


def strip_lua(text: str) -> tuple[str, str, list[str]]:
    """Returns (code without comments, code without comments and with string
    contents removed, string literals in order).  Newlines are kept so line
    numbers stay valid.  Removed strings become `""`."""
    keep: list[str] = []     # comments removed, strings kept
    blank: list[str] = []    # comments removed, strings emptied
    strings: list[str] = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "-" and text.startswith("--", i):
            lvl = _long_bracket_level(text, i + 2) if i + 2 < n else None
            if lvl is not None:
                close = "]" + "=" * lvl + "]"
                end = text.find(close, i + 4 + lvl)
                end = n if end < 0 else end + len(close)
            else:
                end = text.find("\n", i)
                end = n if end < 0 else end
            nl = "\n" * text.count("\n", i, end)
            keep.append(nl)
            blank.append(nl)
            i = end
            continue
        if c in "'\"":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            end = min(j + 1, n)
            s = text[i:end]
            keep.append(s)
            strings.append(s[1:-1])
            blank.append('""' + "\n" * s.count("\n"))
            i = end
            continue
        if c == "[":
            lvl = _long_bracket_level(text, i)
            if lvl is not None:
                close = "]" + "=" * lvl + "]"
                end = text.find(close, i + 2 + lvl)
                end = n if end < 0 else end + len(close)
                s = text[i:end]
                keep.append(s)
                strings.append(s[2 + lvl:-(2 + lvl)])
                blank.append('""' + "\n" * s.count("\n"))
                i = end
                continue
        keep.append(c)
        blank.append(c)
        i += 1
    return "".join(keep), "".join(blank), strings


LUA_CALL_RE = re.compile(
    r"(?<![\w.:])(sim(?:[A-Z0-9]\w*)?)\s*\.\s*([A-Za-z_]\w*)\s*(?=[(\"'{])")
LUA_PCALL_RE = re.compile(
    r"\b(?:x?pcall)\s*\(\s*(sim(?:[A-Z0-9]\w*)?)\s*\.\s*([A-Za-z_]\w*)\s*[,)]")
LUA_HOOK_RE = re.compile(
    r"(?:\bfunction\s+(sysCall_\w+)\s*\(|\b(sysCall_\w+)\s*=\s*function\b)")
LUA_REQUIRE_RE = re.compile(
    r"\brequire\s*\(?\s*(?:'([^']*)'|\"([^\"]*)\"|\[\[(.*?)\]\])")
LUA_LEGACY_RE = re.compile(r"(?<![\w.:])(sim[A-Z]\w*)\s*\(")
LUA_CALLTYPE_RE = re.compile(r"\bsim_call_type\b")


@dataclass
class FileResult:
    path: str
    repo: str
    lang: str
    calls: collections.Counter = field(default_factory=collections.Counter)
    hooks: set = field(default_factory=set)
    requires: set = field(default_factory=set)
    idioms: collections.Counter = field(default_factory=collections.Counter)
    legacy_calls: int = 0
    parse_note: str = ""


IDIOMS_LUA = [
    ("sim.getObjectHandle(...) (4.0-4.2 style)", re.compile(r"\bsim\.getObjectHandle\b")),
    ("sim.getObjectHandle('name#...') (hash-suffix name)",
     re.compile(r"\bsim\.getObjectHandle\s*\(\s*['\"][^'\"]*#")),
    ("sim.getObject(path) (4.3+ style)", re.compile(r"\bsim\.getObject\s*[('\"]")),
    ("relative path './x' or '.' in sim.getObject",
     re.compile(r"\bsim\.getObject\s*\(?\s*['\"]\.")),
    ("sim.getObjectAssociatedWithScript(sim.handle_self)",
     re.compile(r"\bsim\.getObjectAssociatedWithScript\s*\(\s*sim\.handle_self")),
    ("sim.handle_self anywhere", re.compile(r"\bsim\.handle_self\b")),
    ("sim.getScriptSimulationParameter / set (old script params)",
     re.compile(r"\bsim\.(?:get|set)ScriptSimulationParameter\b")),
    ("sim.switchThread()", re.compile(r"\bsim\.switchThread\b")),
    ("sim.setThreadAutomaticSwitch", re.compile(r"\bsim\.setThreadAutomaticSwitch\b")),
    ("coroutine-based threading in a non-threaded script",
     re.compile(r"\bcoroutine\.(?:create|resume|wrap)\b")),
    ("sim.wait(...)", re.compile(r"\bsim\.wait\s*\(")),
    ("string/int signals (sim.set*/get*Signal)",
     re.compile(r"\bsim\.(?:set|get|clear)(?:String|Int32|Integer|Float)Signal\b")),
    ("sim.packTable / sim.unpackTable", re.compile(r"\bsim\.(?:un)?packTable\b")),
    ("simUI XML dialog (simUI.create)", re.compile(r"\bsimUI\.create\b")),
    ("sim_call_type dispatch (pre-sysCall style)", LUA_CALLTYPE_RE),
    ("require('sim') / require 'sim' (4.6+ style)",
     re.compile(r"\brequire\s*\(?\s*['\"]sim['\"]")),
]


def analyse_lua(path: str, repo: str, text: str) -> FileResult:
    r = FileResult(path=path, repo=repo, lang="lua")
    keep, blank, _strings = strip_lua(text)
    for m in LUA_REQUIRE_RE.finditer(keep):
        name = m.group(1) if m.group(1) is not None else (
            m.group(2) if m.group(2) is not None else m.group(3))
        r.requires.add(name)
    modules = KNOWN_MODULES | {q for q in r.requires if MODULE_RE.match(q)}
    for rx in (LUA_CALL_RE, LUA_PCALL_RE):
        for m in rx.finditer(blank):
            if m.group(1) in modules:
                r.calls[f"{m.group(1)}.{m.group(2)}"] += 1
    for m in LUA_HOOK_RE.finditer(blank):
        r.hooks.add(m.group(1) or m.group(2))
    r.legacy_calls = sum(1 for _ in LUA_LEGACY_RE.finditer(blank))
    for label, rx in IDIOMS_LUA:
        if rx.search(keep):
            r.idioms[label] += 1
    return r


# --------------------------------------------------------------------------
# Python
# --------------------------------------------------------------------------

SKIP_TOKENS = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT,
               tokenize.DEDENT, tokenize.ENCODING}
CLIENT_CTORS = {"RemoteAPIClient"}
CLIENT_METHODS = {"step": "sim.step", "setStepping": "sim.setStepping"}


def py_tokens(text: str) -> tuple[list[tuple[int, str]], str]:
    """Significant tokens as (type, string); strings keep their text so a
    module name can be read from `require('sim')`.  Falls back to a crude
    regex tokenizer if the file does not tokenize (e.g. Python 2 code)."""
    toks: list[tuple[int, str]] = []
    try:
        for t in tokenize.generate_tokens(io.StringIO(text).readline):
            if t.type in SKIP_TOKENS:
                continue
            toks.append((t.type, t.string))
        return toks, ""
    except (tokenize.TokenError, IndentationError, SyntaxError) as e:
        toks = []
        clean = re.sub(r"#[^\n]*", "", text)
        for m in re.finditer(
                r"('''[\s\S]*?'''|\"\"\"[\s\S]*?\"\"\"|'(?:\\.|[^'\\\n])*'"
                r"|\"(?:\\.|[^\"\\\n])*\"|[A-Za-z_]\w*|\d[\w.]*|\S)", clean):
            s = m.group(0)
            if s[0] in "'\"":
                toks.append((tokenize.STRING, s))
            elif s[0].isalpha() or s[0] == "_":
                toks.append((tokenize.NAME, s))
            else:
                toks.append((tokenize.OP, s))
        return toks, f"tokenize failed ({type(e).__name__}); regex fallback"


def _string_value(s: str) -> str | None:
    m = re.match(r"^[rRbBuUfF]*('''|\"\"\"|'|\")(.*)\1$", s, re.S)
    return m.group(2) if m else None


IDIOMS_PY = [
    ("client.require('sim') (current client)",
     re.compile(r"\.require\s*\(\s*['\"]sim['\"]")),
    ("client.getObject('sim') (older client)",
     re.compile(r"\.getObject\s*\(\s*['\"]sim['\"]")),
    ("from zmqRemoteApi import RemoteAPIClient (pre-pip package)",
     re.compile(r"\bfrom\s+zmqRemoteApi\b")),
    ("asyncio client", re.compile(r"coppeliasim_zmqremoteapi_client\.asyncio")),
    ("stepping mode (setStepping / step)",
     re.compile(r"\.(?:setStepping|step)\s*\(")),
    ("legacy simx* calls (legacy remote API)", re.compile(r"\bsimx[A-Z]\w*\s*\(")),
    ("sim.getObjectHandle (deprecated)", re.compile(r"\.getObjectHandle\s*\(")),
    ("sim.callScriptFunction", re.compile(r"\.callScriptFunction\s*\(")),
]


def analyse_python(path: str, repo: str, text: str) -> FileResult:
    r = FileResult(path=path, repo=repo, lang="python")
    toks, note = py_tokens(text)
    r.parse_note = note
    n = len(toks)

    def tok(i: int) -> tuple[int, str]:
        return toks[i] if 0 <= i < n else (-1, "")

    # 1. Bindings: NAME [. NAME]* = [await] <expr ending in .require|.getObject>( 'mod' )
    #    or  = [await] require('mod')   (Python scripts inside CoppeliaSim)
    #    or  = RemoteAPIClient(...)     (client objects)
    bound: dict[str, str] = {}     # name -> module ('sim', 'simIK', ...)
    clients: set[str] = {"client"}
    for i in range(n):
        if tok(i) != (tokenize.OP, "="):
            continue
        # target: last NAME before '=' (handles `self.sim = ...`)
        if tok(i - 1)[0] != tokenize.NAME:
            continue
        target = tok(i - 1)[1]
        j = i + 1
        if tok(j) == (tokenize.NAME, "await"):
            j += 1
        # scan the right-hand side up to the end of the simple expression
        k = j
        rhs: list[tuple[int, str]] = []
        depth = 0
        while k < n:
            t = tok(k)
            if t[0] == tokenize.OP and t[1] in "([{":
                depth += 1
            elif t[0] == tokenize.OP and t[1] in ")]}":
                if depth == 0:
                    break
                depth -= 1
            elif depth == 0 and t[0] == tokenize.OP and t[1] in (",", "=", ";", ":"):
                break
            elif depth == 0 and t[0] == tokenize.NAME and k > j and \
                    tok(k - 1)[0] in (tokenize.NAME, tokenize.STRING, tokenize.NUMBER) \
                    and tok(k - 1)[1] not in ("await", "not", "and", "or", "in", "is"):
                break  # next statement on a new line
            rhs.append(t)
            k += 1
            if depth == 0 and t == (tokenize.OP, ")"):
                break
        if not rhs:
            continue
        names = [s for ty, s in rhs if ty == tokenize.NAME]
        # X = <...>.require('mod') / .getObject('mod') / require('mod')
        for a in range(len(rhs) - 2):
            if rhs[a][0] == tokenize.NAME and rhs[a][1] in ("require", "getObject") \
                    and rhs[a + 1] == (tokenize.OP, "(") and rhs[a + 2][0] == tokenize.STRING:
                mod = _string_value(rhs[a + 2][1])
                if mod and MODULE_RE.match(mod):
                    bound[target] = mod
                break
        else:
            if any(s in CLIENT_CTORS for s in names):
                clients.add(target)
            elif len(rhs) in (1, 3) and rhs[-1][0] == tokenize.NAME:
                # alias: X = Y  or  X = self.Y
                src = rhs[-1][1]
                if src in bound:
                    bound[target] = bound[src]
                elif src in clients:
                    clients.add(target)

    def module_of(name: str) -> str | None:
        if name in bound:
            return bound[name]
        if name in KNOWN_MODULES:
            return name
        return None

    # 2. Calls: [<anything> .] NAME . NAME (
    for i in range(n - 3):
        t0, t1, t2, t3 = tok(i), tok(i + 1), tok(i + 2), tok(i + 3)
        if t0[0] != tokenize.NAME or t1 != (tokenize.OP, ".") or \
                t2[0] != tokenize.NAME or t3 != (tokenize.OP, "("):
            continue
        # the object must not itself be the attribute of a non-self object
        # chain we do not understand, except `self.sim` / `obj._sim` forms.
        mod = module_of(t0[1])
        if mod is not None:
            r.calls[f"{mod}.{t2[1]}"] += 1
        elif t0[1] in clients and t2[1] in CLIENT_METHODS:
            r.calls[CLIENT_METHODS[t2[1]]] += 1
    for a in range(n - 2):
        if tok(a)[0] == tokenize.NAME and tok(a)[1] in ("require", "getObject") \
                and tok(a + 1) == (tokenize.OP, "(") and tok(a + 2)[0] == tokenize.STRING:
            mod = _string_value(tok(a + 2)[1])
            if mod and MODULE_RE.match(mod):
                r.requires.add(mod)
    for label, rx in IDIOMS_PY:
        if rx.search(text):
            r.idioms[label] += 1
    r.legacy_calls = sum(v for k, v in r.calls.items() if k.split(".", 1)[1].startswith("simx"))
    return r


# --------------------------------------------------------------------------
# Corpus walk and report
# --------------------------------------------------------------------------

def repo_of(filename: str) -> str:
    parts = filename.split("__")
    return f"{parts[0]}/{parts[1]}" if len(parts) >= 3 else "?"


def walk(corpus: str) -> list[FileResult]:
    results: list[FileResult] = []
    for lang, ext in (("lua", ".lua"), ("python", ".py")):
        d = os.path.join(corpus, lang)
        if not os.path.isdir(d):
            continue
        for fn in sorted(os.listdir(d)):
            if not fn.endswith(ext) or fn.startswith("_"):
                continue
            with open(os.path.join(d, fn), encoding="utf-8", errors="replace") as f:
                text = f.read()
            repo = repo_of(fn)
            if lang == "lua":
                results.append(analyse_lua(fn, repo, text))
            else:
                results.append(analyse_python(fn, repo, text))
    return results


ROS_MODULES = {"simROS", "simROS2", "simExtRosInterface", "simExtROS2", "simExtROS"}


def uses_ros(r: FileResult) -> bool:
    """A file that calls simROS.* / simROS2.* or requires a ROS plugin module."""
    return (any(k.split(".", 1)[0] in ROS_MODULES for k in r.calls)
            or any(q in ROS_MODULES for q in r.requires))


def is_impl(name: str, lang: str, names: dict[str, set[str]]) -> bool:
    return lang in names.get(name, ())


def pct(a: int, b: int) -> str:
    return f"{100.0 * a / b:.1f}%" if b else "n/a"


def summarize(results: list[FileResult], names: dict[str, set[str]]) -> dict:
    s: dict = {}
    for scope in ("all",) + LANGS:
        rs = [r for r in results if scope == "all" or r.lang == scope]
        calls = collections.Counter()
        impl_sites = 0
        files_all_impl = 0
        files_with_calls = 0
        for r in rs:
            calls.update(r.calls)
            impl_sites += sum(v for k, v in r.calls.items() if is_impl(k, r.lang, names))
            if r.calls:
                files_with_calls += 1
                if all(is_impl(k, r.lang, names) for k in r.calls):
                    files_all_impl += 1
        total = sum(calls.values())
        distinct_impl = sum(
            1 for k in calls if any(is_impl(k, r.lang, names) for r in rs if k in r.calls))
        s[scope] = dict(
            files=len(rs), repos=len({r.repo for r in rs}), sites=total,
            distinct=len(calls), distinct_impl=distinct_impl,
            impl_sites=impl_sites, files_with_calls=files_with_calls,
            files_all_impl=files_all_impl)
    return s


def missing_ranking(results, names, top):
    sites = collections.Counter()
    files = collections.defaultdict(set)
    repos = collections.defaultdict(set)
    per_lang = collections.defaultdict(collections.Counter)
    for r in results:
        for k, v in r.calls.items():
            if is_impl(k, r.lang, names):
                continue
            sites[k] += v
            files[k].add(r.path)
            repos[k].add(r.repo)
            per_lang[k][r.lang] += v
    ranked = sorted(sites, key=lambda k: (-sites[k], -len(repos[k]), -len(files[k]), k))
    return [(k, sites[k], len(files[k]), len(repos[k]), per_lang[k]["lua"],
             per_lang[k]["python"]) for k in ranked[:top]], len(sites)


def top_used(results, names, top):
    sites = collections.Counter()
    files = collections.defaultdict(set)
    repos = collections.defaultdict(set)
    impl = {}
    for r in results:
        for k, v in r.calls.items():
            sites[k] += v
            files[k].add(r.path)
            repos[k].add(r.repo)
            impl.setdefault(k, set())
            if is_impl(k, r.lang, names):
                impl[k].add(r.lang)
    ranked = sorted(sites, key=lambda k: (-sites[k], -len(repos[k]), k))[:top]
    return [(k, sites[k], len(files[k]), len(repos[k]),
             "yes" if impl[k] == {x for x in LANGS if any(
                 k in r.calls for r in results if r.lang == x)} else
             ("partly (" + ",".join(sorted(impl[k])) + ")" if impl[k] else "no"))
            for k in ranked]


def render(results, names, top, api_label) -> str:
    out: list[str] = []
    w = out.append
    s = summarize(results, names)
    w("# CoppeliaSim API usage in a corpus of public scripts\n")
    w(f"Supported-function list: `{api_label}` ({len(names)} names).\n")
    w("| scope | files | repos | call sites | distinct functions | distinct implemented "
      "| call sites implemented | files with calls | files fully implemented |")
    w("|---|---|---|---|---|---|---|---|---|")
    for scope in ("all",) + LANGS:
        x = s[scope]
        w(f"| {scope} | {x['files']} | {x['repos']} | {x['sites']} | {x['distinct']} | "
          f"{x['distinct_impl']} | {x['impl_sites']} ({pct(x['impl_sites'], x['sites'])}) | "
          f"{x['files_with_calls']} | {x['files_all_impl']} "
          f"({pct(x['files_all_impl'], x['files_with_calls'])}) |")
    w("")
    w("\"Files fully implemented\": files with at least one call whose every call is to a "
      "supported function, over files with at least one call.\n")

    ranked, nmissing = missing_ranking(results, names, top)
    w(f"## Top {len(ranked)} unimplemented functions by call sites "
      f"({nmissing} unimplemented functions in all)\n")
    w("| # | function | call sites | files | repos | Lua sites | Python sites |")
    w("|---|---|---|---|---|---|---|")
    for i, (k, n, f, rp, lu, py) in enumerate(ranked, 1):
        w(f"| {i} | `{k}` | {n} | {f} | {rp} | {lu} | {py} |")
    w("")

    by_repo = sorted(missing_ranking(results, names, 10**6)[0],
                     key=lambda x: (-x[3], -x[2], -x[1], x[0]))[:top]
    w(f"### Same functions ranked by number of repositories (less sensitive to one "
      f"repository repeating a call)\n")
    w("| # | function | repos | files | call sites |")
    w("|---|---|---|---|---|")
    for i, (k, n, f, rp, _lu, _py) in enumerate(by_repo, 1):
        w(f"| {i} | `{k}` | {rp} | {f} | {n} |")
    w("")

    for lang in LANGS:
        rr = [r for r in results if r.lang == lang]
        ranked_l, nmiss_l = missing_ranking(rr, names, min(top, 30))
        w(f"### Top {len(ranked_l)} unimplemented, {lang} only ({nmiss_l} in all)\n")
        w("| # | function | call sites | files | repos |")
        w("|---|---|---|---|---|")
        for i, (k, n, f, rp, _lu, _py) in enumerate(ranked_l, 1):
            w(f"| {i} | `{k}` | {n} | {f} | {rp} |")
        w("")

    w("## Most used functions (all, with support status)\n")
    w("| # | function | call sites | files | repos | supported |")
    w("|---|---|---|---|---|---|")
    for i, (k, n, f, rp, ok) in enumerate(top_used(results, names, 40), 1):
        w(f"| {i} | `{k}` | {n} | {f} | {rp} | {ok} |")
    w("")

    lua = [r for r in results if r.lang == "lua"]
    hooks = collections.Counter(h for r in lua for h in r.hooks)
    w("## Lua hooks defined (files defining each)\n")
    w("| hook | files |")
    w("|---|---|")
    for h, c in hooks.most_common():
        w(f"| `{h}` | {c} |")
    nohook = sum(1 for r in lua if not r.hooks)
    w(f"| (no sysCall_ function: module/library file or pre-sysCall script) | {nohook} |")
    w("")

    req = collections.Counter(q for r in lua for q in r.requires)
    w("## Lua `require` targets (files requiring each)\n")
    w("| module | files |")
    w("|---|---|")
    for q, c in req.most_common():
        w(f"| `{q}` | {c} |")
    w("")

    py = [r for r in results if r.lang == "python"]
    preq = collections.Counter(q for r in py for q in r.requires)
    w("## Python `client.require(...)` / `getObject(...)` modules (files)\n")
    w("| module | files |")
    w("|---|---|")
    for q, c in preq.most_common():
        w(f"| `{q}` | {c} |")
    w("")

    for lang, label in (("lua", "Lua"), ("python", "Python")):
        rr = [r for r in results if r.lang == lang]
        idi = collections.Counter()
        for r in rr:
            idi.update(r.idioms)
        w(f"## {label} idioms (files showing each, of {len(rr)})\n")
        w("| idiom | files |")
        w("|---|---|")
        for k, v in idi.most_common():
            w(f"| {k} | {v} |")
        w("")

    notes = [r for r in results if r.parse_note]
    legacy = [r for r in results if r.legacy_calls and r.lang == "python"]
    if notes or legacy:
        w("## Parser notes\n")
        for r in notes:
            w(f"- `{r.path}`: {r.parse_note}")
        for r in legacy:
            w(f"- `{r.path}`: {r.legacy_calls} legacy `simx*` call sites (should not be in corpus)")
        w("")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", default="/work/corpus", help="corpus root (lua/, python/)")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--api", help="docs/api.md: backticked qualified names in table rows")
    g.add_argument("--names", help="file with one qualified name per line [lua|python]")
    ap.add_argument("--markdown", metavar="OUT", help="also write the report to OUT")
    ap.add_argument("--top", type=int, default=60, help="length of the missing list")
    ap.add_argument("--per-file", action="store_true",
                    help="print each file's unimplemented calls to stderr")
    ap.add_argument("--without-ros", action="store_true",
                    help="leave out files that call or require simROS / simROS2")
    a = ap.parse_args(argv)

    names = load_api_markdown(a.api) if a.api else load_names_file(a.names)
    if not names:
        print("no supported names found", file=sys.stderr)
        return 2
    results = walk(a.corpus)
    if not results:
        print(f"no corpus files under {a.corpus}", file=sys.stderr)
        return 2
    if a.without_ros:
        before = len(results)
        results = [r for r in results if not uses_ros(r)]
        print(f"--without-ros: left out {before - len(results)} files", file=sys.stderr)
    report = render(results, names, a.top, a.api or a.names)
    print(report)
    if a.markdown:
        with open(a.markdown, "w", encoding="utf-8") as f:
            f.write(report + "\n")
    if a.per_file:
        for r in results:
            miss = sorted(k for k in r.calls if not is_impl(k, r.lang, names))
            if miss:
                print(f"{r.lang}\t{r.path}\t{' '.join(miss)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
