#!/usr/bin/env python3
"""PyRep's own unit tests, unchanged, against gantry's `pyrep` package (issue 50).

The suite is third-party acceptance material kept outside the repository
(`../shared/pyrep/tests`, or `--suite DIR`). It is run as PyRep runs it (its tests
import `tests.core`, so from the folder above `tests/`), in-process with pytest, with
three additions of this runner, none of which edits the suite:
  * tests whose file opens a scene absent from the suite's assets (PyRep's
    `test_scene_robots.ttt` and the mobile scenes are over the size the snapshot kept)
    are reported as skipped, each naming the missing scene;
  * nothing is written into the suite's folder (no bytecode, no cache);
  * the outcome is checked against the issue's bar: at least `--min-passed` of the tests
    that can run pass, and every test of the modules PyRep users rely on most passes.
Every failure is printed with its first line of error. Exit status 0 when the bar is
met, 1 otherwise.

    .venv/bin/python tests/pyrep/run_suite.py [--suite ../shared/pyrep/tests] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

# Every test of these modules must pass (the list).
REQUIRED_MODULES = [
    "test_objects", "test_joints", "test_joint_groups", "test_dummies", "test_force_sensors",
    "test_proximity_sensors", "test_cameras", "test_misc", "test_vision_sensors",
]
SCENE_RE = re.compile(r"""['"]([\w.-]+\.tt[tm])['"]""")


class SuitePlugin:
    """Skips, by name, the tests whose scene is absent, and records every outcome."""

    def __init__(self, assets: Path):
        self.assets = assets
        self.outcomes: dict[str, tuple[str, str]] = {}

    def _missing_scene(self, path: Path) -> str | None:
        for name in SCENE_RE.findall(path.read_text(encoding="utf-8")):
            if not (self.assets / name).is_file():
                return name
        return None

    def pytest_collection_modifyitems(self, session, config, items):
        import pytest

        missing: dict[Path, str | None] = {}
        for item in items:
            path = Path(str(item.fspath))
            if path not in missing:
                missing[path] = self._missing_scene(path)
            if missing[path]:
                item.add_marker(pytest.mark.skip(
                    reason=f"needs PyRep's {missing[path]}, which is not in {self.assets}"))

    def pytest_runtest_logreport(self, report):
        if report.when == "call" or (report.when == "setup" and report.outcome != "passed"):
            message = ""
            if report.outcome == "skipped" and isinstance(report.longrepr, tuple):
                message = report.longrepr[2]
            elif report.outcome == "failed":
                message = report.longreprtext.strip().splitlines()[-1] if report.longreprtext else ""
            self.outcomes[report.nodeid] = (report.outcome, message)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--suite", type=Path, default=REPO.parent / "shared" / "pyrep" / "tests",
                        help="PyRep's tests folder (default ../shared/pyrep/tests)")
    # The bar is 135; the default holds what passes today (146 of the 147 that
    # can run: only `test_export_scene` fails, by design), so a regression fails the run.
    parser.add_argument("--min-passed", type=int, default=146)
    parser.add_argument("--json", type=Path, help="write every outcome here")
    parser.add_argument("pytest_args", nargs="*", help="extra pytest arguments (e.g. -k name)")
    args = parser.parse_args()

    suite = args.suite.resolve()
    if not (suite / "core.py").is_file():
        print(f"pyrep suite: PyRep's tests are not at {suite}", file=sys.stderr)
        return 1
    import pytest

    sys.dont_write_bytecode = True
    os.chdir(suite.parent)
    sys.path.insert(0, str(suite.parent))
    plugin = SuitePlugin(suite / "assets")
    pytest.main(["-q", "-p", "no:cacheprovider", "-o", "python_files=test_*.py",
                 "--rootdir", str(suite.parent), str(suite), *args.pytest_args], plugins=[plugin])

    out = plugin.outcomes
    passed = sorted(k for k, (o, _) in out.items() if o == "passed")
    failed = sorted(k for k, (o, _) in out.items() if o == "failed")
    skipped = sorted(k for k, (o, _) in out.items() if o == "skipped")
    runnable = len(passed) + len(failed)
    print(f"\npyrep suite: {len(passed)} of {runnable} runnable tests pass; {len(skipped)} skipped")
    for k in skipped:
        print(f"  skipped {k}: {out[k][1]}")
    for k in failed:
        print(f"  FAILED {k}: {out[k][1]}")
    required_failures = [k for k in failed if any(f"/{m}.py::" in k or k.startswith(f"{m}.py::") or
                                                  f"tests/{m}.py::" in k for m in REQUIRED_MODULES)]
    if args.json:
        args.json.write_text(json.dumps({"passed": passed, "failed": {k: out[k][1] for k in failed},
                                         "skipped": {k: out[k][1] for k in skipped}}, indent=1))
    ok = len(passed) >= args.min_passed and not required_failures
    if required_failures:
        print(f"pyrep suite: {len(required_failures)} failures in modules that must pass entirely:")
        for k in required_failures:
            print(f"  {k}")
    if len(passed) < args.min_passed:
        print(f"pyrep suite: {len(passed)} passed, fewer than the bar of {args.min_passed}")
    print("pyrep suite:", "bar met" if ok else "bar NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
