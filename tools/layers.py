#!/usr/bin/env python3
"""The floors inside gantry's crates, and a check that no import runs back up.

Each crate's top-level modules are stacked in floors (lowest first). Production code of
a module may use modules on lower floors only; a floor marked `peers` lets its modules
use each other (they share one state and are read together). Unit-test modules
(`#[cfg(test)]` to the end of the file) may drive the crate from the top, as the
integration tests do, so they are not checked.

    python3 tools/layers.py          # exits 1 and names each upward import

Run by tools/test-all.sh beside the crate-level rule (protocol stays pure, sim-core
has no tokio or mlua). docs/architecture.md draws the same floors.
"""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# (crate source dir, floors lowest first; a floor is (modules, peers allowed)).
CRATES = {
    "crates/sim-core/src": [
        ({"handle", "math", "signals"}, False),
        ({"error"}, False),
        ({"scene"}, False),
        ({"world"}, False),
        ({"sensor", "vision", "ik", "drawing", "graph", "ui", "motion"}, False),
        ({"sim"}, False),
        ({"api"}, False),
    ],
    "crates/script/src": [
        ({"limits", "convert", "listeners"}, False),
        ({"sandbox"}, False),
        ({"threads", "simulation", "messages", "debugger"}, True),
    ],
}

USE = re.compile(r"\bcrate::([a-z_]+)\b")
GROUPED = re.compile(r"\buse crate::\{([^;]*)\};", re.S)


COMMENT = re.compile(r"//.*$", re.M)


def production_text(path: Path) -> str:
    """The file's code outside unit tests, without comments (doc links may name any floor)."""
    text = path.read_text()
    cut = text.find("#[cfg(test)]")
    text = text if cut < 0 else text[:cut]
    return COMMENT.sub("", text)


def referenced(text: str) -> set[str]:
    names = set(USE.findall(text))
    for group in GROUPED.findall(text):
        names.update(re.findall(r"(?:^|[,{\s])([a-z_]+)(?=::|\s*[,}]|$)", group))
    return names


def check(src: str, floors) -> list[str]:
    base = ROOT / src
    floor_of = {}
    for i, (mods, _) in enumerate(floors):
        for m in mods:
            floor_of[m] = i
    problems = []
    for path in sorted(base.rglob("*.rs")):
        rel = path.relative_to(base)
        top = rel.parts[0].removesuffix(".rs")
        if top in ("lib", "main"):
            continue
        if top not in floor_of:
            problems.append(f"{src}/{rel}: module '{top}' is on no floor (add it to tools/layers.py)")
            continue
        mine = floor_of[top]
        for name in sorted(referenced(production_text(path))):
            if name == top or name not in floor_of:
                continue
            theirs = floor_of[name]
            same_floor_ok = theirs == mine and floors[mine][1]
            if theirs > mine or (theirs == mine and not same_floor_ok):
                problems.append(
                    f"{src}/{rel}: '{top}' (floor {mine + 1}) uses crate::{name} (floor {theirs + 1})"
                )
    return problems


def main() -> int:
    problems = [p for src, floors in CRATES.items() for p in check(src, floors)]
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        print(f"{len(problems)} import(s) run up or across a floor", file=sys.stderr)
        return 1
    print("layers: every import points down")
    return 0


if __name__ == "__main__":
    sys.exit(main())
