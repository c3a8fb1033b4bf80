#!/usr/bin/env python3
"""File-level imports in every crate of the workspace and every first-party Python
package: no circle, and no import up a floor.

A Rust file imports another when its production code names a path that resolves into it:
`use crate::a::b::Item` (or `crate::a::b::f(..)` inline) is an import of `a/b.rs` (or
`a/b/mod.rs`); `super::`, `self::` and a file's own child modules resolve the same way,
and `use` groups (`use crate::{a::X, b::{self, Y}}`) are expanded. A name that a module
re-exports (`pub use inner::Item;` in a `mod.rs` or `lib.rs`) is followed to the file
that defines it (through `pub use inner::*` too), so a facade does not hide a circle.
`mod x;` declarations are not imports.

A Python file imports another when an `import` or `from ... import` statement names it,
at module level or inside a function (a deferred import only hides a circle until the
function runs): `import p.a`, `from p import a` (a submodule) and `from .a import X`
(relative imports resolved against the file's package) all import `p/a.py`, and
`from p import X` of a name imports `p/__init__.py`. A name is not followed to where it
is defined, unlike Rust's re-exports: importing from a facade runs the facade, and all
it imports. Not imports: the packages above the named module, which Python runs first
but only to define the package (a package's `__init__.py` importing its submodules
would otherwise make a circle with each of them), module names in strings (Gymnasium
entry points, `importlib`), and imports under `if TYPE_CHECKING:`, which never run: they
name types for the reader and the type checker, and are how a file annotates with a
type of a module that imports it. The packages are the directories with an
`__init__.py` (`python/gantry`); directories of scripts are not checked: tests/python
and tools/bench import each other's files through the `sys.path` entries each script
adds when it runs (both have a `public_robots.py`), so which file a name means is known
only then, and nothing imports a test or a benchmark but another script.

Two rules, checked for every crate (`crates/*/src`, `python/src`, `src`) and package:

1. No circle among files. A circle means neither file can be read, tested or moved
   without the other; it is printed file by file. The few circles other engineers are
   untangling right now are listed in KNOWN_CIRCLES, by name, and are allowed only as
   listed (the same set of files, no more).
2. Where a crate or package declares floors (FLOORS, lowest first), a file may import
   files of lower floors only; a floor marked `peers` lets its files import each other
   (still without a circle, by rule 1). Files in one directory module (`debugger/*`) are
   one unit for the floors.

Unit tests (`#[cfg(test)]` to the end of a file, and modules declared under
`#[cfg(test)]`) may drive the crate from the top, as the integration tests do, so
they are not read.

    python3 tools/layers.py              # exits 1 and names each circle and upward import
    python3 tools/layers.py --self-test  # checks the checker on small trees in a temp dir

Run by tools/test-all.sh beside the crate-level rule (protocol stays pure, sim-core
has no tokio or mlua). docs/architecture.md draws the same floors.
"""

from __future__ import annotations

import ast
import os
import re
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# Floors, lowest first: (top-level modules or files of the crate, peers allowed).
FLOORS = {
    # The simulation's floors span three crates (docs/architecture.md, "Floors of the
    # simulation"): cargo orders the crates, these lists the modules inside each.
    "crates/scene/src": [
        ({"handle", "math"}, False),
        ({"error"}, False),
        ({"scene"}, False),
    ],
    "crates/world/src": [
        ({"math", "mesh_cluster", "signals", "tubes"}, False),
        ({"paths"}, False),
        ({"world"}, False),
        ({"sensor", "vision", "ik", "drawing", "graph", "motion", "planning"}, False),
        ({"ik_groups"}, False),
        ({"sim"}, False),
    ],
    # simUI's model, below the world: the limits and plain data, then the XML parser,
    # then the owner of every UI.
    "crates/ui/src": [
        ({"limits", "messages", "views", "widget"}, False),
        ({"error", "window"}, False),
        ({"parse"}, False),
        ({"uis"}, False),
    ],
    # Motion planning, below the world: the random numbers, the spaces and their metric,
    # the planner over any problem, then the task.
    "crates/planning/src": [
        ({"rng"}, False),
        ({"space"}, False),
        ({"metric", "rrt_connect"}, False),
        ({"task"}, False),
    ],
    # Inverse kinematics without a scene, below the world: the error, an environment's
    # own objects, the environments, the chain snapshot, then the solver on it.
    "crates/ik/src": [
        ({"error"}, False),
        ({"objects"}, False),
        ({"environment"}, False),
        ({"chain"}, False),
        ({"solver"}, False),
    ],
    # docs/architecture.md, "Floors inside the Lua host", explains each floor.
    "crates/lua/src": [
        ({"limits", "convert", "listeners", "lua_error", "app_state", "waiting", "file_rules"}, False),
        ({"sandbox", "running", "directory", "sim_cell", "hooks"}, False),
        ({"threads", "control", "recording", "models", "luasocket", "ros", "launch", "modules", "script_io"}, False),
        ({"messages"}, False),
        ({"debugger"}, False),
        ({"budget", "host_api"}, False),
        ({"scripts"}, False),
        ({"host"}, False),
        ({"host_step", "remote", "remote_blocking", "ros_dispatch"}, False),
        ({"ros_action_dispatch"}, False),
    ],
    # The Python package: the Gymnasium tasks, the env that runs one, the vector env that
    # runs many, and gantry.gym gathering and registering them (issue 47). The package's
    # own __init__.py (Client) is below every floor, as a crate root is.
    "python/gantry": [
        ({"tasks", "batch"}, False),
        ({"env"}, False),
        ({"vector"}, False),
        ({"gym"}, False),
    ],
}

# Circles allowed by name while a change that breaks them is under way, exactly as
# listed (the same set of files, no more); an entry that no longer matches a circle is
# reported as stale. None today: the two found when this check went file-level (the
# URDF importer and its fix-ups, the registry and Target) were broken by moving the XML
# options to urdf_fixups.rs and the name look-up to api/resolve.rs.
KNOWN_CIRCLES: dict[str, set[str]] = {}

TOKENS = re.compile(
    r"""r(?P<hashes>\#*)".*?"(?P=hashes)   # raw string (Lua chunks)
      | "(?:\\.|[^"\\])*"                # string
      | '(?:\\.|[^'\\])'                 # char
      | //[^\n]*                         # line comment, doc comments included
      | /\*.*?\*/                        # block comment
    """,
    re.S | re.X,
)
USE = re.compile(r"\buse\s+([^;]+);")
INLINE = re.compile(r"(?<![\w:])((?:crate|super|self|[a-z_][a-z0-9_]*)(?:::[A-Za-z_][A-Za-z0-9_]*)+)")
ITEM = r"\b(?:struct|enum|union|trait|type|fn|const|static|mod|macro_rules!)\s+{}\b"
TEST_MOD = re.compile(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([a-z_][a-z0-9_]*)\s*;")
TEST_USE = re.compile(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?use\s+[^;]+;")


def strip(text: str) -> str:
    """Code without comments and literals (doc links and messages may name any file)."""
    return TOKENS.sub(lambda m: '""' if m.group(0)[0] in "r\"'" else " ", text)


def production(text: str) -> str:
    """The code outside unit tests: `#[cfg(test)] mod x;` and `#[cfg(test)] use ..;` go,
    and the rest of the file from the first other `#[cfg(test)]` (the tests module at
    the end)."""
    text = TEST_USE.sub(" ", TEST_MOD.sub(" ", strip(text)))
    cut = text.find("#[cfg(test)]")
    return text if cut < 0 else text[:cut]


def expand(tree: str, prefix=()) -> list[tuple[tuple[str, ...], str | None]]:
    """The paths of a `use` tree, each with the name it brings into scope (None for `*`)."""
    tree = tree.strip()
    out = []
    # Split at the top-level `{`.
    depth, brace = 0, -1
    for i, c in enumerate(tree):
        if c == "{" and depth == 0:
            brace = i
            break
    if brace < 0:
        alias = None
        m = re.fullmatch(r"(.*?)\s+as\s+(\w+)", tree, re.S)
        if m:
            tree, alias = m.group(1), m.group(2)
        segs = tuple(s.strip() for s in tree.split("::") if s.strip())
        if not segs:
            return out
        if segs[-1] == "*":
            return [(prefix + segs[:-1], None)]
        if segs[-1] == "self":
            path = prefix + segs[:-1]
            return [(path, alias or (path[-1] if path else None))]
        return [(prefix + segs, alias or segs[-1])]
    head = tuple(s.strip() for s in tree[:brace].split("::") if s.strip())
    inner = tree[brace + 1 : tree.rfind("}")]
    parts, depth, start = [], 0, 0
    for i, c in enumerate(inner):
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(inner[start:i])
            start = i + 1
    parts.append(inner[start:])
    for p in parts:
        if p.strip():
            out.extend(expand(p, prefix + head))
    return out


class Crate:
    """One crate's files, its module tree and what each file imports."""

    def __init__(self, src: Path, root: Path):
        self.src, self.root = src, root
        self.files: dict[tuple[str, ...], Path] = {}
        for path in sorted(src.rglob("*.rs")):
            rel = path.relative_to(src).with_suffix("").parts
            if rel in (("lib",), ("main",)):
                mod = ()
            elif rel[-1] == "mod":
                mod = rel[:-1]
            else:
                mod = rel
            if mod == () and () in self.files:
                continue  # a crate with both lib.rs and main.rs: lib.rs is the root
            self.files[mod] = path
        self.text = {m: production(p.read_text()) for m, p in self.files.items()}
        self.tests = set()
        for m, p in self.files.items():
            for child in TEST_MOD.findall(strip(p.read_text())):
                self.tests.add(m + (child,))
        # Drop test-only modules and everything under them.
        for m in list(self.files):
            if any(m[: len(t)] == t for t in self.tests):
                del self.files[m]
                del self.text[m]
        self.scope = {m: {} for m in self.files}
        self.globs = {m: [] for m in self.files}
        self.uses = {m: [] for m in self.files}
        for m, text in self.text.items():
            for tree in USE.findall(text):
                for path, name in expand(tree):
                    self.uses[m].append(path)
                    if name:
                        self.scope[m][name] = path
                    else:
                        self.globs[m].append(path)

    def rel(self, mod) -> str:
        return str(self.files[mod].relative_to(self.root))

    def start(self, mod, path):
        """Where a path starts (a module) and the segments after it, or None if external."""
        first, rest = path[0], path[1:]
        if first == "crate":
            return (), rest
        if first == "self":
            return mod, rest
        if first == "super":
            base = mod
            while path and path[0] == "super":
                base, path = base[:-1], path[1:]
            return base, path
        if mod + (first,) in self.files:
            return mod + (first,), rest
        return None

    def resolve(self, mod, path, depth=0) -> set[tuple[str, ...]]:
        """The files a path names, following re-exports to where an item is defined."""
        begun = self.start(mod, path)
        if begun is None or depth > 8:
            return set()
        cur, rest = begun
        if cur not in self.files:
            return set()
        for i, seg in enumerate(rest):
            if cur + (seg,) in self.files:
                cur = cur + (seg,)
                continue
            target = self.scope[cur].get(seg)
            if target is None:
                target = self.glob_source(cur, seg)
            if target is not None and target != path:
                if self.start(cur, target) is None:
                    return set()  # a re-exported external item (`pub use other_crate::Value`)
                found = self.resolve(cur, target + rest[i + 1 :], depth + 1)
                if found:
                    return found
            return {cur}
        return {cur}

    def glob_source(self, mod, name):
        """The path of `name` when module `mod` has it only through `pub use inner::*`."""
        for g in self.globs[mod]:
            begun = self.start(mod, g)
            if begun is None:
                continue
            base, rest = begun
            inner = base + tuple(rest)
            if inner in self.files and (
                name in self.scope[inner] or re.search(ITEM.format(re.escape(name)), self.text[inner])
            ):
                return g + (name,)
        return None

    def imports(self) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
        graph = {}
        for m, text in self.text.items():
            paths = list(self.uses[m])
            body = USE.sub(" ", text)
            for p in INLINE.findall(body):
                paths.append(tuple(p.split("::")))
            out = set()
            for p in paths:
                out |= self.resolve(m, p)
            out.discard(m)
            graph[m] = out
        return graph


# Directories never searched for Python packages: build output, virtual environments
# and installed dependencies.
SKIP_DIRS = {"target", "node_modules", "site-packages", "__pycache__"}


class PyPackage:
    """One first-party Python package's files and what each imports (the module
    docstring says what counts), shaped like `Crate` for `check`: modules are tuples of
    names under the package (`()` for its `__init__.py`)."""

    def __init__(self, top: Path, root: Path):
        self.top, self.root, self.name = top, root, top.name
        self.files: dict[tuple[str, ...], Path] = {}
        for path in sorted(top.rglob("*.py")):
            rel = path.relative_to(top).with_suffix("").parts
            if any(part in SKIP_DIRS for part in rel):
                continue
            if rel[-1] == "__init__":
                # Only a directory with an __init__.py is a subpackage.
                self.files[rel[:-1]] = path
            elif (path.parent / "__init__.py").is_file():
                self.files[rel] = path

    def rel(self, mod) -> str:
        return str(self.files[mod].relative_to(self.root))

    def is_package(self, mod) -> bool:
        return self.files[mod].name == "__init__.py"

    def module(self, dotted: str):
        """The module a dotted absolute name means, or None outside this package."""
        parts = tuple(dotted.split("."))
        if parts[0] != self.name:
            return None
        return parts[1:]

    def base(self, mod, level: int):
        """The package that a relative import of `level` dots in `mod` starts from."""
        package = mod if self.is_package(mod) else mod[:-1]
        if level - 1 > len(package):
            return None  # above the top package: Python refuses it too
        return package[: len(package) - (level - 1)]

    def named(self, mod) -> set[tuple[str, ...]]:
        """The file of `mod`, or of its nearest enclosing module that is a file (a name
        such as `p.a.X` written as a module path)."""
        while mod not in self.files and mod:
            mod = mod[:-1]
        return {mod} if mod in self.files else set()

    def imports(self) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
        graph = {}
        for m, path in self.files.items():
            tree = ast.parse(path.read_text(), str(path))
            out = set()
            for node in runtime_imports(tree):
                if isinstance(node, ast.Import):
                    for alias in node.names:
                        target = self.module(alias.name)
                        if target is not None:
                            out |= self.named(target)
                    continue
                if node.level:
                    start = self.base(m, node.level)
                    if start is None:
                        continue
                    target = start + (tuple(node.module.split(".")) if node.module else ())
                else:
                    target = self.module(node.module)
                    if target is None:
                        continue
                for alias in node.names:
                    sub = target + (alias.name,)
                    # `from p import a` of a submodule imports it; of a name, imports p.
                    out |= {sub} if sub in self.files else self.named(target)
            out.discard(m)
            graph[m] = out
        return graph


def runtime_imports(tree: ast.AST):
    """Every import statement of a module that can run: at any depth (functions,
    classes, `try`), but not under `if TYPE_CHECKING:` (nor its `else:` opposite, which
    runs)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
            continue
        if isinstance(node, ast.If) and type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


def type_checking(test: ast.expr) -> bool:
    """Whether an `if` tests `TYPE_CHECKING` (or `typing.TYPE_CHECKING`)."""
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def packages(root: Path) -> list[Path]:
    """The top directories of first-party Python packages: an `__init__.py` in a
    directory whose parent has none, outside hidden directories and SKIP_DIRS."""
    found = []
    for here, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d not in SKIP_DIRS)
        path = Path(here)
        if "__init__.py" in files and not (path.parent / "__init__.py").is_file():
            found.append(path)
            dirs[:] = []  # its subpackages are its own
    return found


def circles(graph) -> list[list]:
    """Each strongly connected set of more than one file, as one circle through it."""
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        # Iterative Tarjan: the module trees are shallow but need not stay so.
        work = [(v, iter(sorted(graph[v])))]
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        while work:
            node, it = work[-1]
            advanced = False
            for w in it:
                if w not in graph:
                    continue
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    advanced = True
                    break
                if w in on:
                    low[node] = min(low[node], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                scc = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    scc.append(w)
                    if w == node:
                        break
                if len(scc) > 1:
                    sccs.append(set(scc))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    out = []
    for scc in sccs:
        # A shortest circle through the set's first file, found breadth first.
        first = min(scc)
        prev, frontier, cycle = {first: None}, [first], None
        while frontier and cycle is None:
            nxt = []
            for v in frontier:
                for w in sorted(graph[v] & scc):
                    if w == first:
                        cycle = [v]
                        break
                    if w not in prev:
                        prev[w] = v
                        nxt.append(w)
                if cycle:
                    break
            frontier = nxt
        while prev[cycle[-1]] is not None:
            cycle.append(prev[cycle[-1]])
        cycle.reverse()
        out.append((scc, cycle + [first]))
    return out


def check(crate: Crate, floors, known) -> tuple[list[str], list[str]]:
    """Problems (fail) and notes (known circles) of one crate."""
    graph = crate.imports()
    problems, notes = [], []
    for scc, cycle in circles(graph):
        files = {crate.rel(m) for m in scc}
        allowed = [name for name, listed in known.items() if listed == files]
        text = " -> ".join(crate.rel(m) for m in cycle)
        if allowed:
            notes.append(f"known circle '{allowed[0]}' (allowed until merged): {text}")
        else:
            problems.append(f"circle: {text}" + (f" (and {len(scc)} files in all)" if len(scc) + 1 > len(cycle) else ""))
    if floors:
        floor_of = {name: i for i, (names, _) in enumerate(floors) for name in names}
        for m in sorted(graph):
            if m == ():
                continue
            top = m[0]
            if top not in floor_of:
                problems.append(f"{crate.rel(m)}: '{top}' is on no floor (add it to FLOORS in tools/layers.py)")
                continue
            mine = floor_of[top]
            for t in sorted(graph[m]):
                if t == () or t[0] == top or t[0] not in floor_of:
                    continue
                theirs = floor_of[t[0]]
                if theirs > mine or (theirs == mine and not floors[mine][1]):
                    problems.append(
                        f"{crate.rel(m)} (floor {mine + 1}) imports {crate.rel(t)} (floor {theirs + 1})"
                    )
    return problems, notes


def crates(root: Path) -> list[Path]:
    found = sorted(p for p in (root / "crates").glob("*/src") if p.is_dir())
    found += [p for p in (root / "python/src", root / "src") if p.is_dir()]
    return found


def run(root: Path, floors_by_src, known, out=sys.stderr) -> int:
    problems, notes = [], []
    units = [Crate(src, root) for src in crates(root)] + [PyPackage(top, root) for top in packages(root)]
    for unit in units:
        rel = str((unit.src if isinstance(unit, Crate) else unit.top).relative_to(root))
        p, n = check(unit, floors_by_src.get(rel), known)
        problems += p
        notes += n
    for name in sorted(set(known) - {n.split("'")[1] for n in notes}):
        problems.append(f"known circle '{name}' is gone: remove it from KNOWN_CIRCLES")
    # Problems go to stderr; notes and the verdict to stdout (the self-test reads both
    # from one buffer).
    info = sys.stdout if out is sys.stderr else out
    for line in notes:
        print(line, file=info)
    for line in problems:
        print(line, file=out)
    if problems:
        print(f"layers: {len(problems)} problem(s): circles or imports up a floor", file=out)
        return 1
    print("layers: no circle among files, every import points down", file=info)
    return 0


def self_test() -> int:
    """The checker on three small trees: a circle, an upward import, and a clean one."""
    import io

    def tree(files: dict[str, str]) -> Path:
        root = Path(tempfile.mkdtemp(prefix="layers-"))
        for rel, text in files.items():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            (root / rel).write_text(text)
        return root

    def outcome(files, floors=None, known=None):
        root = tree(files)
        buf = io.StringIO()
        code = run(root, floors or {}, known or {}, out=buf)
        return code, buf.getvalue()

    failures = []

    def expect(label, cond, output):
        if not cond:
            failures.append(f"{label}:\n{output}")

    lib = "mod a;\nmod b;\nmod c;\npub use a::A;\n"
    # A circle through a grouped use, a re-export in lib.rs and an inline path.
    code, out = outcome({
        "crates/x/src/lib.rs": lib,
        "crates/x/src/a.rs": "use crate::{b::{self, B}};\npub struct A;\n",
        "crates/x/src/b.rs": "pub struct B;\nfn f() { crate::c::g(); }\n",
        "crates/x/src/c.rs": "use crate::A; // a comment naming crate::b\npub fn g() {}\n",
    })
    expect("circle", code == 1 and "circle: crates/x/src/a.rs -> crates/x/src/b.rs -> crates/x/src/c.rs -> crates/x/src/a.rs" in out, out)
    # super:: from a directory module, and the same circle allowed as a known circle.
    files = {
        "crates/x/src/lib.rs": "mod d;\n",
        "crates/x/src/d/mod.rs": "mod e;\npub use e::E;\npub struct D;\n",
        "crates/x/src/d/e.rs": "use super::D;\npub struct E;\n",
    }
    code, out = outcome(files)
    expect("super", code == 1 and "crates/x/src/d/e.rs -> crates/x/src/d/mod.rs" in out, out)
    known = {"d facade": {"crates/x/src/d/mod.rs", "crates/x/src/d/e.rs"}}
    code, out = outcome(files, known=known)
    expect("known circle", code == 0 and "known circle 'd facade'" in out, out)
    # An import up a floor; test code and string literals are not read.
    floors = {"crates/x/src": [({"a"}, False), ({"b", "c"}, False)]}
    code, out = outcome({
        "crates/x/src/lib.rs": lib,
        "crates/x/src/a.rs": "pub struct A;\nfn f() { let _ = crate::b::B; }\n",
        "crates/x/src/b.rs": "pub struct B;\n",
        "crates/x/src/c.rs": "use crate::a::A;\nconst S: &str = \"crate::b\";\n#[cfg(test)]\nmod tests { use crate::b::B; }\n",
    }, floors)
    expect("upward", code == 1 and "crates/x/src/a.rs (floor 1) imports crates/x/src/b.rs (floor 2)" in out
           and "c.rs (floor 2) imports" not in out, out)
    # A clean tree, with a stale known circle reported.
    clean = {
        "crates/x/src/lib.rs": lib,
        "crates/x/src/a.rs": "pub struct A;\n",
        "crates/x/src/b.rs": "use crate::a::A;\npub struct B;\n",
        "crates/x/src/c.rs": "use crate::{a::A, b::B};\n#[cfg(test)]\nmod tests;\n",
        "crates/x/src/c/tests.rs": "use crate::c::*; use crate::A;\n",
    }
    code, out = outcome(clean, floors={"crates/x/src": [({"a"}, False), ({"b"}, False), ({"c"}, False)]})
    expect("clean", code == 0, out)
    # A facade re-exporting with a glob is followed to the file that defines the name.
    code, out = outcome({
        "crates/x/src/lib.rs": "mod d;\n",
        "crates/x/src/d/mod.rs": "mod model;\nmod user;\npub use model::*;\npub use user::f;\n",
        "crates/x/src/d/model.rs": "pub struct M;\n",
        "crates/x/src/d/user.rs": "use super::M;\npub fn f() {}\n",
    })
    expect("glob facade", code == 0, out)
    code, out = outcome(clean, known={"old": {"crates/x/src/a.rs", "crates/x/src/b.rs"}})
    expect("stale known circle", code == 1 and "known circle 'old' is gone" in out, out)
    # Python: a facade and a module importing each other, the facade deferring its
    # import to a function, as gantry.gym and gantry.vector did (issue 47). The
    # vector module names the facade absolutely, the facade names it relatively.
    py_circle = {
        "python/p/__init__.py": "from p._ext import Client\n",
        "python/p/tasks.py": "class T:\n    pass\n",
        "python/p/gym.py": "from .tasks import T\n\ndef __getattr__(name):\n    from .vector import V\n    return V\n",
        "python/p/vector.py": "import os\nimport p.gym as gg\n\nclass V:\n    task = gg.T\n",
    }
    code, out = outcome(py_circle)
    expect("python circle", code == 1 and "circle: python/p/gym.py -> python/p/vector.py -> python/p/gym.py" in out, out)
    # Importing a name through the facade runs the facade: still a circle.
    code, out = outcome({**py_circle, "python/p/vector.py": "from .gym import T\n\nclass V:\n    pass\n"})
    expect("python facade", code == 1 and "circle: python/p/gym.py -> python/p/vector.py -> python/p/gym.py" in out, out)
    # Broken as in gantry: vector builds on tasks, gym gathers both. Not imports: the
    # package above (p/__init__.py, whose Client every module may use), names in
    # strings and comments, and TYPE_CHECKING imports; a floor keeps tasks at the bottom.
    py_floors = {"python/p": [({"tasks"}, False), ({"vector"}, False), ({"gym"}, False)]}
    py_clean = {
        "python/p/__init__.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .gym import V\n",
        "python/p/tasks.py": "from . import Client\nfrom typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from p.vector import V\nclass T:\n    pass\n",
        "python/p/gym.py": "from .tasks import T\nfrom .vector import V\nENTRY = 'p.vector:V'\n",
        "python/p/vector.py": "# from .gym import T\nfrom p import tasks\n\nclass V:\n    task = tasks.T\n",
    }
    code, out = outcome(py_clean, floors=py_floors)
    expect("python clean", code == 0, out)
    code, out = outcome({**py_clean, "python/p/tasks.py": "def f():\n    from . import vector\n"}, floors=py_floors)
    expect("python upward", code == 1 and "python/p/tasks.py (floor 1) imports python/p/vector.py (floor 2)" in out, out)
    for f in failures:
        print(f"layers self-test failed: {f}", file=sys.stderr)
    if failures:
        return 1
    print(
        "layers self-test: circle, super, known circle, upward import, clean tree, glob facade;"
        " Python circle, facade, clean package, upward import: ok"
    )
    return 0


def main() -> int:
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    return run(ROOT, FLOORS, KNOWN_CIRCLES)


if __name__ == "__main__":
    sys.exit(main())
