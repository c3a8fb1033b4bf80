#!/usr/bin/env python3
"""RLBench's task models on gantry through the `pyrep` package (issue 50).

RLBench's tasks are `.ttm` models (`rlbench/task_ttms/*.ttm` in stepjam/RLBench, not
part of this repository: pass the folder you have). For every model this script
  * loads it with `PyRep.import_model` into PyRep's own Panda scene
    (`scene_panda_reach_target.ttt`, from ../shared/coppelia-files/),
  * finds its waypoints (`waypoint0`, `waypoint1`, ... below the model: dummies, or 4.1
    path objects) and reads their extension strings, the gripper commands and path
    options RLBench's demos obey (`open_gripper()`, `ignore_collisions`, `linear`...),
    checking each against RLBench's grammar;
  * places it where RLBench's `Scene.load` does, at the workspace centre in front of
    the Panda;
and, for the first `--plan N` models whose waypoints are all points (all by default),
plans with `arm.get_path` (or `get_linear_path` where the extension string says
`linear`) to each waypoint in turn, checking collisions except where the waypoint says
`ignore_collisions`, as RLBench's demos do; steps the path, and measures how far the
Panda's tip ends from the waypoint.

    .venv/bin/python tools/rlbench_tasks.py DIR [--plan 12] [--ignore-collisions] [--json out.json]
Exit status 1 when a model does not load; planning results are reported, not judged
(RLBench's task code moves objects before an episode, `init_episode`, which this script
does not run, so some waypoints are planned against a task's objects as saved).
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO.parent / "shared" / "coppelia-files" / "PyRep__scene_panda_reach_target.ttt"
WAYPOINT = re.compile(r"^waypoint(\d+)$")
# RLBench's waypoint commands. RLBench finds them by substring (`'ignore_collision' in
# ext`, `open_gripper(` with an optional amount), so separators vary between task files
# (`;`, `,`, stray parentheses); each part must hold one command.
# Where RLBench puts a task: `Scene.load` sets the task's base at the centre of the
# `workspace` shape of its `task_design.ttt` (not in RLBench's public snapshot). That
# scene's Panda stands at about (-0.30, 0, 0.82) m, facing +x: its tip starts at RLBench's
# well-known initial gripper position (0.2785, -0.0082, 1.4719) m, and the same Panda in
# PyRep's scene holds its tip (0.587, -0.008, 0.653) m from its base in the same start
# configuration. The task models' bases sit at (0.25, 0, 0.752) m, the workspace centre
# on the table top, so the workspace is this far from the Panda's base, in the world
# frame (both Pandas face +x, unrotated):
WORKSPACE_FROM_PANDA = np.array([0.55, 0.0, -0.068])
COMMAND = re.compile(r"(open_gripper\([\d.\s]*\)|close_gripper\([\d.\s]*\)|ignore_collision|linear)")


def waypoints(base):
    from pyrep.objects.object import Object

    found = []
    for obj in base.get_objects_in_tree(exclude_base=False):
        m = WAYPOINT.match(obj.get_name().split("#")[0])
        if m:
            found.append((int(m.group(1)), obj))
    return [o for _, o in sorted(found, key=lambda x: x[0])]


def check_commands(ext: str) -> list[str]:
    """The parts of an extension string (split at `;` and `,`) that hold no RLBench
    command."""
    return [part for part in re.split(r"[;,]", ext) if part.strip(" )") and not COMMAND.search(part)]


def run_model(path: Path, plan: bool, check_collisions: bool = True) -> dict:
    from pyrep import PyRep
    from pyrep.objects.dummy import Dummy
    from pyrep.robots.arms.panda import Panda

    pr = PyRep()
    pr.launch(str(SCENE), headless=True)
    out = {"model": path.name}
    try:
        t0 = time.perf_counter()
        base = pr.import_model(str(path))
        out["load_s"] = time.perf_counter() - t0
        # Placed as RLBench places it: at the workspace centre in front of the Panda.
        base.set_position(Panda().get_position() + WORKSPACE_FROM_PANDA)
        wps = waypoints(base)
        out["waypoints"] = [{"name": w.get_name(), "type": w.get_type().name, "ext": w.get_extension_string()}
                            for w in wps]
        out["bad_commands"] = {w["name"]: check_commands(w["ext"]) for w in out["waypoints"] if check_commands(w["ext"])}
        if plan and wps and all(w["type"] == "DUMMY" for w in out["waypoints"]):
            pr.start()
            arm = Panda()
            tip = Dummy("Panda_tip")
            reached = []
            for w, info in zip(wps, out["waypoints"]):
                # RLBench's demos ignore collisions where the waypoint says so;
                # `--ignore-collisions` ignores them throughout.
                ignore = "ignore_collision" in info["ext"] or not check_collisions
                try:
                    if "linear" in info["ext"]:
                        p = arm.get_linear_path(w.get_position(), euler=w.get_orientation(), ignore_collisions=ignore)
                    else:
                        p = arm.get_path(w.get_position(), euler=w.get_orientation(), ignore_collisions=ignore,
                                         trials=100, max_configs=10)
                    done, steps = False, 0
                    while not done and steps < 2000:
                        done = p.step()
                        pr.step()
                        steps += 1
                    reached.append(float(np.linalg.norm(tip.get_position() - w.get_position())))
                except Exception as e:  # a waypoint out of reach here: reported
                    reached.append(f"{type(e).__name__}: {e}")
            out["tip_error_m"] = reached
            pr.stop()
    except Exception as e:
        out["error"] = f"{type(e).__name__}: {e}"
    finally:
        pr.shutdown()
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", type=Path, help="RLBench's rlbench/task_ttms folder")
    p.add_argument("--plan", type=int, default=1000, help="plan to the waypoints of this many models (default: all)")
    p.add_argument("--ignore-collisions", action="store_true",
                   help="ignore collisions while planning to every waypoint (RLBench checks them except where a "
                        "waypoint says ignore_collisions)")
    p.add_argument("--json", type=Path)
    a = p.parse_args()
    models = sorted(a.folder.glob("*.ttm"))
    if not models:
        print(f"rlbench_tasks: no .ttm in {a.folder}", file=sys.stderr)
        return 1
    results, planned = [], 0
    for m in models:
        r = run_model(m, planned < a.plan, not a.ignore_collisions)
        if "tip_error_m" in r:
            planned += 1
        results.append(r)
        errs = r.get("tip_error_m", [])
        ok = sum(1 for e in errs if isinstance(e, float) and e < 0.01)
        print(f"{m.name}: {'ERROR ' + r['error'] if 'error' in r else 'loaded'}; "
              f"{len(r.get('waypoints', []))} waypoints, "
              f"{sum(1 for w in r.get('waypoints', []) if w['ext'])} with commands"
              + (f"; reached {ok}/{len(errs)} within 1 cm" if errs else ""))
    loaded = [r for r in results if "error" not in r]
    wp = [w for r in loaded for w in r["waypoints"]]
    with_ext = [w for w in wp if w["ext"]]
    bad = {r["model"]: r["bad_commands"] for r in loaded if r.get("bad_commands")}
    plans = [e for r in loaded for e in r.get("tip_error_m", [])]
    print(f"\n{len(loaded)} of {len(models)} task models load; {len(wp)} waypoints, {len(with_ext)} with "
          f"extension strings ({len({w['ext'] for w in with_ext})} distinct); "
          f"{len(bad)} models with parts RLBench would not understand")
    if plans:
        ok = sum(1 for e in plans if isinstance(e, float) and e < 0.01)
        whole = [r["model"] for r in loaded if r.get("tip_error_m")
                 and all(isinstance(e, float) and e < 0.01 for e in r["tip_error_m"])]
        print(f"planned {len(plans)} waypoints of {planned} models: {ok} reached within 1 cm; "
              f"{len(whole)} models with every waypoint reached: {', '.join(m.removesuffix('.ttm') for m in whole)}")
    if a.json:
        a.json.write_text(json.dumps(results, indent=1))
    return 0 if len(loaded) == len(models) else 1


if __name__ == "__main__":
    sys.exit(main())
