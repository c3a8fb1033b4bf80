#!/usr/bin/env python3
"""Puts the benchmark's figures side by side (issue 8) and draws the rover plot.

Reads, from target/bench/: gantry.json (`cargo bench --bench sim`), pybullet.json
(tools/bench/pybullet_bench.py), zmq.json (tests/python/bench_zmq.py --json),
startup.json (tools/bench/startup.py) and, if present, public.json
(tools/bench/public_robots.py), python.json (tools/bench/python_inproc.py), ray.json
(tools/bench/ray_batch.py), vision.json (tools/bench/vision.py) and mujoco.json
(tools/bench/mujoco_bench.py); prints one Markdown
report with ratios and the targets, writes it to target/bench/report.md, and draws
steps/s against the number of rovers to docs/rovers.png. `bash tools/bench.sh` runs everything in order.

    python3 tools/bench/report.py                 # the whole report
    python3 tools/bench/report.py --public-only   # only the public robots' table
    python3 tools/bench/report.py --vision-only   # only the vision section
    python3 tools/bench/report.py --mujoco-only   # only the MuJoCo section
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "target/bench"


def load(name: str) -> dict:
    path = BENCH / name
    if not path.exists():
        sys.exit(f"{path} is missing: run `bash tools/bench.sh`")
    return json.loads(path.read_text())


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def verdict(ok: bool) -> str:
    return "met" if ok else "**missed**"


def report(g: dict, pb: dict, zmq: dict, start: dict) -> str:
    out = []
    w = out.append
    w(f"Machine: {cpu_model()}, {g['cores']} cores; {platform.system()} {platform.release()}; "
      f"PyBullet API {pb['pybullet']}.\n")

    arm, parm = g["arm"], pb["arm"]
    ratio = arm["steps_per_s"] / parm["steps_per_s"]
    w("### 1. Arm: arm6.urdf, dt 1/240 s, 1 substep, new position targets every step, 10,000 steps\n")
    w("| | steps/s | RMS joint error | largest joint error |")
    w("|---|---|---|---|")
    w(f"| gantry (targets from Lua) | {arm['steps_per_s']:,.0f} | {arm['rms_error_rad']:.4f} rad | {arm['max_error_rad']:.4f} rad |")
    w(f"| PyBullet (setJointMotorControlArray) | {parm['steps_per_s']:,.0f} | {parm['rms_error_rad']:.4f} rad | {parm['max_error_rad']:.4f} rad |")
    w(f"| bare rapier (same targets, no Lua) | {arm['rapier_steps_per_s']:,.0f} | | |")
    w(f"\ngantry / PyBullet: **{ratio:.2f}x** (target ≥ 2x: {verdict(ratio >= 2)}); "
      f"gantry / bare rapier: {arm['steps_per_s'] / arm['rapier_steps_per_s']:.2f}.\n")

    w("### 2. Rovers: BubbleRob, dt 0.05 s, 10 substeps, one script (or ray test) per rover\n")
    w("| rovers | gantry, controller script | rtf | gantry, lab-sheet script | rtf | bare rapier | PyBullet, ray test | rtf | gantry / PyBullet |")
    w("|---|---|---|---|---|---|---|---|---|")
    pyb = {r["rovers"]: r for r in pb["rovers"]}
    hundred = None
    for r in g["rovers"]:
        n, dt = r["rovers"], r["dt"]
        p = pyb[n]
        ctl, lab = r["controller_steps_per_s"], r["lab_sheet_steps_per_s"]
        if n == 100:
            hundred = ctl * dt
        w(f"| {n} | {ctl:,.1f} | {ctl * dt:,.1f} | {lab:,.1f} | {lab * dt:,.1f} | {r['rapier_steps_per_s']:,.1f} | "
          f"{p['steps_per_s']:,.1f} | {p['rtf']:,.1f} | **{ctl / p['steps_per_s']:.2f}x** |")
    w(f"\n100 rovers at {hundred:.1f}x real time (target ≥ 50x: {verdict(hundred >= 50)}).\n")

    w("### 3. Overhead over bare rapier (same scene, no scripts, API or server)\n")
    w("| scene | gantry steps/s | bare rapier steps/s | gantry / rapier |")
    w("|---|---|---|---|")
    for s in g["scenes"]:
        w(f"| {s['scene']} | {s['steps_per_s']:,.0f} | {s['rapier_steps_per_s']:,.0f} | {s['steps_per_s'] / s['rapier_steps_per_s']:.2f} |")
    w(f"| arm benchmark (Lua targets every step) | {arm['steps_per_s']:,.0f} | {arm['rapier_steps_per_s']:,.0f} | {arm['steps_per_s'] / arm['rapier_steps_per_s']:.2f} |")
    for r in g["rovers"]:
        w(f"| {r['rovers']} rovers, controller script per rover (bare: the same controller in Rust) | "
          f"{r['controller_steps_per_s']:,.1f} | {r['rapier_steps_per_s']:,.1f} | "
          f"{r['controller_steps_per_s'] / r['rapier_steps_per_s']:.2f} |")
    w("\nTarget: within 15 % of bare rapier (ratio ≥ 0.85). The bubble_rob and showroom rows run the lab "
      "sheet's vision sensor (a software render and edge filter at every step), which bare rapier does not do.\n")

    t = g["text"]
    w("### 4. Latency\n")
    w("| channel | median | p99 |")
    w("|---|---|---|")
    w(f"| ZMQ `sim.getObjectPosition`, real Python client, {zmq['scene']} at full speed | {zmq['median_us']:.0f} µs | {zmq['p99_us']:.0f} µs |")
    w(f"| same call, {zmq['scene']} in real time (simulator idle between steps) | {zmq['idle_median_us']:.0f} µs | {zmq['idle_p99_us']:.0f} µs |")
    w(f"| same client against a busy-polling pyzmq echo server (the client's floor) | {zmq['floor_median_us']:.0f} µs | {zmq['floor_p99_us']:.0f} µs |")
    w(f"| text packet round trip, persistent connection (fk_arm, real time) | {t['persistent_median_us']:.0f} µs | {t['persistent_p99_us']:.0f} µs |")
    w(f"| text packet round trip, new connection per command | {t['per_connection_median_us']:.0f} µs | {t['per_connection_p99_us']:.0f} µs |")
    w(f"\nRemote stepping (`client.step()`, {zmq['scene']}): {zmq['steps_per_s']:,.0f} steps/s "
      f"(an empty scene, the protocol's own ceiling: {zmq['empty_steps_per_s']:,.0f} steps/s); "
      f"text channel: {t['packets_per_s']:,.0f} packets/s on one connection.\n")

    w("### 5. Start-up and memory (showroom)\n")
    w(f"Process start to first step (and exit): {start['start_to_first_step_ms']:.0f} ms median "
      f"(max {start['start_to_first_step_max_ms']:.0f} ms); peak resident memory over 2,000 steps with every "
      f"listener open: {start['peak_rss_mib']:.1f} MiB.\n")
    return "\n".join(out)


def python_section(py: dict, ray: dict | None) -> str:
    out = []
    w = out.append
    w("### 7. Python: in-process package against the ZMQ client and PyBullet (bubble_rob)\n")
    w("| call | median | p99 |")
    w("|---|---|---|")
    w(f"| `sim.getObjectPosition`, `gantry.Client` in-process | {py['inproc_median_us']:.2f} µs | {py['inproc_p99_us']:.2f} µs |")
    w(f"| `sim.getObjectPosition`, CoppeliaSim's ZMQ client against `gantry run --fast` | {py['zmq_median_us']:.0f} µs | {py['zmq_p99_us']:.0f} µs |")
    w(f"| PyBullet `getBasePositionAndOrientation` (DIRECT) | {py['pybullet_median_us']:.2f} µs | {py['pybullet_p99_us']:.2f} µs |")
    w(f"\nTarget median < 2 µs: {verdict(py['inproc_median_us'] < 2.0)}. Stepping: the headless binary "
      f"{py['binary_steps_per_s']:,.0f} steps/s; in-process `client.advance(n)` {py['advance_steps_per_s']:,.0f} "
      f"({py['advance_ratio']:.1%}), a `sim.step()` loop {py['step_loop_steps_per_s']:,.0f} "
      f"({py['step_loop_ratio']:.1%}); target >= 95 %: "
      f"{verdict(min(py['advance_ratio'], py['step_loop_ratio']) >= 0.95)}.")
    if ray:
        w(f"\nRay batch (`gantry.batch.run`), {ray['runs']} BubbleRob runs of {ray['sim_seconds']:g} simulated s "
          f"({ray['run_wall_s']:.1f} s wall each) on a local Ray with {ray['cpus']} CPUs: {ray['serial_s']:.1f} s one "
          f"after another, {ray['ray_s']:.1f} s on Ray, speed-up {ray['speedup']:.2f}x (target {ray['min_speedup']}x: "
          f"{verdict(ray['speedup'] >= ray['min_speedup'])}); identical results both ways.")
    return "\n".join(out) + "\n"


def vision_table(f: dict) -> str:
    """The vision benchmark's Markdown table (tools/bench/vision.py prints it too)."""
    c, t = f["cases"], f["targets"]
    what = {
        "640x480": "1 camera 640 x 480, RGB + depth, UR5 in view",
        "5x128": f"5 cameras 128 x 128, RGB + depth{' + mask' if f['mask'] else ''}, Panda in view (one step)",
        "1x1": "1 camera 1 x 1, UR5 in view",
    }
    target = {
        "640x480": f"≥ {t['fps_640x480']['target']:.0f} frames/s on one core (CPU): {verdict(t['fps_640x480']['met'])}",
        "5x128": f"≤ {t['ms_5x128']['target']:.0f} ms (wall): {verdict(t['ms_5x128']['met'])}",
        "1x1": f"≤ {t['ms_1x1']['target']:.2f} ms on one core (CPU): {verdict(t['ms_1x1']['met'])}",
    }
    out = ["| case | gantry wall ms (frames/s) | gantry CPU ms | PyBullet wall ms (frames/s) | PyBullet CPU ms | "
           "PyBullet / gantry, wall | gantry target |", "|---|---|---|---|---|---|---|"]
    for case, label in what.items():
        g, p = c[case]["gantry"], c[case]["pybullet"]
        out.append(f"| {label} | {g['ms']:.2f} ({g['fps']:,.0f}) | {g['cpu_ms']:.2f} | {p['ms']:.2f} ({p['fps']:,.0f}) | "
                   f"{p['cpu_ms']:.2f} | **{p['ms'] / g['ms']:.1f}x** | {target[case]} |")
    return "\n".join(out)


def vision_section(v: dict) -> str:
    """Section 8: vision sensors, gantry in-process against PyBullet's TinyRenderer (issue 30)."""
    m = v["machine"]
    return (
        "### 8. Vision sensors: gantry in-process against PyBullet's TinyRenderer, same scenes\n\n"
        + vision_table(v)
        + f"\n\nMedian over {v['rounds']} interleaved rounds of the mean time per frame (for the five cameras: "
        "per step, all five), on " + f"{m['cpu']} ({m['cores']} cores). gantry: `sim.handleVisionSensor` "
        "(one handle, or `sim.handle_all` for the five, which renders on all cores) and a copy of each RGB, "
        "depth (m)" + (" and mask" if v["mask"] else "") + " array. CPU ms is the process's CPU time per frame, "
        "all threads: the one-core targets are judged on it (a busy machine inflates wall time, not CPU time). "
        "PyBullet: `getCameraImage(renderer=ER_TINY_RENDERER)` per camera. The 1 x 1 target is issue 30's "
        "5.4 ms before culling divided by 20. tests/python/test_vision_referee.py checks that the two "
        "renderers' depth and masks agree on these scenes.\n"
    )


def ros2_section(r: dict) -> str:
    """ROS 2 (issue 29): what --ros2 costs, a VGA camera on the graph, command latency."""
    g, c = r["graph"], r["camera_640x480"]
    lf, lr = r["latency_fast"], r["latency_realtime"]
    cost = 100 * (1 - g["ratio"])
    return (
        "## ROS 2 (tools/bench/ros2.py, Cyclone DDS from PyPI as the peer)\n\n"
        "| what | figure | target |\n|---|---|---|\n"
        f"| showroom, /clock + /tf + /joint_states every step, peer subscribed | "
        f"{g['without_steps_per_s']:.0f} -> {g['with_ros2_steps_per_s']:.0f} steps/s ({cost:.1f} % cost) | "
        f"<= 5 % {verdict(cost <= 5)} |\n"
        f"| 640 x 480 camera at 30 Hz, paced in real time | rtf {c['real_time_factor_paced']:.3f}, "
        f"{c['images_received_median']:.0f} of {c['images_published']} images received | rtf >= 1 "
        f"{verdict(c['real_time_factor_paced'] >= 0.99)} |\n"
        f"| the same, --fast | rtf {c['real_time_factor_fast']:.1f} | |\n"
        f"| /cmd_vel -> callback -> ack round trip, --fast | median {lf['round_trip_ms_median']:.2f} ms, "
        f"p99 {lf['round_trip_ms_p99']:.2f} ms | |\n"
        f"| the same, real time (dt 0.05 s) | median {lr['round_trip_ms_median']:.1f} ms, "
        f"p99 {lr['round_trip_ms_p99']:.1f} ms | |\n"
    )


def public_robots(pub: dict) -> str:
    """Section 6: gantry and PyBullet on public mesh-collision arms (issue 15)."""
    out = []
    w = out.append
    w(f"### 6. Public robots: mesh-collision arms, dt 1/240 s, 1 substep, new position targets every step, "
      f"{pub['steps']:,} steps\n")
    w("| arm (package: URDF) | DoF | collision meshes: parts per link | gantry steps/s | PyBullet steps/s | "
      "gantry / PyBullet | gantry RMS / max error | PyBullet RMS / max error | RMS gantry / PyBullet |")
    w("|---|---|---|---|---|---|---|---|---|")
    fast, accurate, failed = [], [], []
    for a in pub["arms"]:
        g, p, c = a["gantry"], a["pybullet"], a["collision"]
        parts = list(c["parts_per_link"].values())
        lo, hi = min(parts), max(parts)
        mesh = (f"{'/'.join(c['kinds'])}, {lo if lo == hi else f'{lo}–{hi}'} "
                f"({sum(parts)} parts, {c['triangles']:,} triangles)")
        name = f"{a['arm']} ({a['package']}: {a['path']})"
        pyb = f"{p['steps_per_s']:,.0f} | "
        perr = f"{p['rms_error']:.4f} / {p['max_error']:.4f}"
        if "error" in g:
            failed.append(a["arm"])
            why = g["error"] if len(g["error"]) <= 60 else g["error"][:57] + "..."
            w(f"| {name} | {a['dof']} | {mesh} | failed: {why} | {pyb} | | {perr} | |")
            continue
        ratio = a["ratio"]  # the median of the per-repeat ratios
        rms = g["rms_error"] / p["rms_error"]
        fast.append(ratio >= 1.5)
        accurate.append(rms <= 1.25)
        w(f"| {name} | {a['dof']} | {mesh} | {g['steps_per_s']:,.0f} | {pyb}**{ratio:.2f}x** | "
          f"{g['rms_error']:.4f} / {g['max_error']:.4f} | {perr} | {rms:.2f} |")
    n = len(pub["arms"])
    w(f"\ngantry ≥ 1.5x PyBullet's steps/s on every arm: {verdict(len(fast) == n and all(fast))} "
      f"({sum(fast)} of {n}); gantry's RMS error ≤ 1.25x PyBullet's on every arm: "
      f"{verdict(len(accurate) == n and all(accurate))} ({sum(accurate)} of {n})"
      + (f"; failed: {', '.join(failed)} (see target/bench/public.json)" if failed else "") + ".")
    w(f"Binary: `{pub['gantry_bin']}`. steps/s is the median of {pub['repeat']} run(s) each, the ratio the "
      "median of the ratios of back-to-back runs; both count the stepping loop only (gantry's own figure, from "
      "after loading and `sysCall_init`; PyBullet's from after loadURDF). Errors are in rad (m for prismatic "
      "joints) over every movable joint and step. Targets come from a Lua script in gantry "
      "(scripts/bench/arm_tracking_any.lua) and from setJointMotorControlArray in PyBullet.")
    loads = ", ".join(f"{a['arm']} {a['gantry']['load_s']:.2f} / {a['pybullet']['load_s']:.2f}"
                      for a in pub["arms"] if "error" not in a["gantry"])
    w(f"Load time, s (gantry: process start to exit minus the stepping loop; PyBullet: loadURDF): {loads}.")
    alone = ", ".join(f"{a['arm']} {a['pybullet']['step_only_steps_per_s']:,.0f}" for a in pub["arms"])
    w(f"PyBullet's stepSimulation alone, without the Python calls around it, steps/s: {alone}.")
    notes = "; ".join(
        f"{a['arm']}: {' '.join(a['pybullet']['warnings'])}" for a in pub["arms"] if a["pybullet"].get("warnings")
    )
    if notes:
        w(f"PyBullet's importer warned: {notes}.")
    w("")
    return "\n".join(out)


def mujoco_section(mj: dict) -> str:
    """Section 9: gantry against MuJoCo (and PyBullet) on the public arms (issue 33)."""
    out = []
    w = out.append

    def rate(r: dict) -> str:
        if "error" in r:
            return "failed"
        return f"{r['steps_per_s']:,.0f}" + (" (unstable)" if r.get("unstable") else "")

    def err(r: dict) -> str:
        return "" if "error" in r else f"{r['rms_error']:.4f} / {r['max_error']:.4f}"

    def ratio(x: float | None) -> str:
        return "" if x is None else f"**{x:.2f}x**"

    w(f"### 9. MuJoCo: public arms, dt 1/240 s, new position targets every step, {mj['steps']:,} steps\n")
    w("Per-step user loop (steps/s; RMS / largest joint error, rad):\n")
    w("| arm | gantry, Lua | gantry, Python | MuJoCo, Python | PyBullet | gantry Python / MuJoCo | "
      "gantry Lua / MuJoCo | gantry RMS / max | MuJoCo RMS / max | PyBullet RMS / max |")
    w("|---|---|---|---|---|---|---|---|---|---|")
    for a in mj["arms"]:
        gl, gp, mp, pb = a["gantry_lua"], a["gantry_python"], a["mujoco_python"], a["pybullet"]
        w(f"| {a['arm']} ({a['package']}) | {rate(gl)} | {rate(gp)} | {rate(mp)} | {rate(pb)} | "
          f"{ratio(a['ratio_python_loop'])} | {ratio(a['ratio_lua_vs_mujoco_python'])} | {err(gl)} | {err(mp)} | "
          f"{err(pb)} |")
    w("\nEngine only (steps/s):\n")
    w("| arm | gantry `advance(n)`, Lua targets | MuJoCo `rollout` | gantry / MuJoCo | MuJoCo `mj_step` alone "
      "(inside the Python loop) |")
    w("|---|---|---|---|---|")
    for a in mj["arms"]:
        ga, mr, mp = a["gantry_advance"], a["mujoco_rollout"], a["mujoco_python"]
        alone = "" if "error" in mp else f"{mp['step_only_steps_per_s']:,.0f}"
        w(f"| {a['arm']} | {rate(ga)} | {rate(mr)} | {ratio(a['ratio_engine'])} | {alone} |")
    for a in mj.get("mobile", []):
        wheels = mj["wheels"]
        speeds = " and ".join(f"{side} {v:g}" for side, v in wheels["speed_rad_s"].items())
        w(f"\nWheeled robot: {a['arm']} ({a['package']}: {a['path']}), free base on a floor, every wheel in "
          f"velocity mode tracking {speeds} rad/s × sin(2π {wheels['frequency_hz']:g} Hz t) (gantry's velocity "
          f"controller, kv {mj['mujoco_gains']['kv_velocity']:g} N·m·s/rad, in gantry and MuJoCo; PyBullet's "
          f"VELOCITY_CONTROL); RMS / largest wheel-velocity error in rad/s:\n")
        w("| mode | gantry steps/s | MuJoCo steps/s | gantry / MuJoCo | gantry RMS / max | MuJoCo RMS / max |")
        w("|---|---|---|---|---|---|")
        w(f"| Lua loop (gantry) | {rate(a['gantry_lua'])} | | | {err(a['gantry_lua'])} | |")
        w(f"| Python loop | {rate(a['gantry_python'])} | {rate(a['mujoco_python'])} | "
          f"{ratio(a['ratio_python_loop'])} | {err(a['gantry_python'])} | {err(a['mujoco_python'])} |")
        w(f"| engine only (`advance(n)` with Lua targets / `rollout`) | {rate(a['gantry_advance'])} | "
          f"{rate(a['mujoco_rollout'])} | {ratio(a['ratio_engine'])} | {err(a['gantry_advance'])} | "
          f"{err(a['mujoco_rollout'])} |")
        w(f"\nPyBullet, Python loop: {rate(a['pybullet'])} steps/s, error {err(a['pybullet'])} rad/s.")
        ends = [(who, a[mode].get("base_end_m")) for who, mode in (("gantry", "gantry_python"),
                                                                   ("MuJoCo", "mujoco_python"))]
        if all(end for _, end in ends):
            w("Where the base ended (x, y, z in m): " + "; ".join(
                f"{who} ({', '.join(f'{v:.3f}' for v in end)})" for who, end in ends) + ".")
    stable = [a for a in mj["arms"] if not a["mujoco_python"].get("unstable") and "error" not in a["mujoco_python"]]
    loop_ok = [a for a in stable if (a["ratio_python_loop"] or 0) >= 1.0
               and a["gantry_python"]["rms_error"] <= 1.25 * a["mujoco_python"]["rms_error"]]
    engine_ok = [a for a in stable if (a["ratio_engine"] or 0) >= 0.75]
    if stable:
        w(f"\nIssue 33's targets, over the {len(stable)} arms MuJoCo simulates stably: gantry's Python loop ≥ 1.0x "
          f"MuJoCo's with an RMS error ≤ 1.25x: {verdict(len(loop_ok) == len(stable))} ({len(loop_ok)} of "
          f"{len(stable)}); engine only ≥ 0.75x MuJoCo's rollout: {verdict(len(engine_ok) == len(stable))} "
          f"({len(engine_ok)} of {len(stable)}).")
    gains = mj["mujoco_gains"]
    w(f"MuJoCo {mj['mujoco']} (position actuators kp {gains['kp']:g}, kv {gains['kv']:g}, gantry's servo law, "
      f"force limited to the URDF effort, integrator {gains['integrator']}; self-collision "
      f"{'MuJoCo default' if mj['mujoco_self_collision'] else 'off, as in gantry and PyBullet'}); "
      f"PyBullet API {mj['pybullet']}; gantry binary `{mj['gantry_bin']}`, package `{mj['gantry_package']}`. "
      f"Medians of {mj['repeat']} interleaved round(s); ratios are medians of same-round ratios.")
    if mj["skipped"]:
        w("Skipped: " + "; ".join(f"{s['arm']}: {s['reason']}" for s in mj["skipped"]) + ".")
    contacts = ", ".join(f"{a['arm']} {a['mujoco_python']['contacts_per_step']:.2f}" for a in mj["arms"]
                         if "error" not in a["mujoco_python"])
    if contacts:
        w(f"MuJoCo contacts per step: {contacts}.")
    w("")
    return "\n".join(out)


def plot(g: dict, pb: dict) -> Path | None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot", file=sys.stderr)
        return None
    n = [r["rovers"] for r in g["rovers"]]
    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=120)
    ax.plot(n, [r["controller_steps_per_s"] for r in g["rovers"]], "o-", label="gantry, controller script per rover")
    ax.plot(n, [r["lab_sheet_steps_per_s"] for r in g["rovers"]], "s--", label="gantry, lab-sheet script per rover")
    ax.plot(n, [r["rapier_steps_per_s"] for r in g["rovers"]], "^:", label="bare rapier (floor)")
    ax.plot(n, [r["steps_per_s"] for r in pb["rovers"]], "d-", label="PyBullet, ray test per rover")
    ax.axhline(1 / 0.05, color="grey", lw=0.8)
    ax.text(n[0], 1 / 0.05 * 1.1, "real time", color="grey")
    ax.axhline(50 / 0.05, color="grey", lw=0.8, ls="--")
    ax.text(n[0], 50 / 0.05 * 1.1, "50x real time (target at 100 rovers)", color="grey")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("rovers")
    ax.set_ylabel("simulation steps per second (dt 0.05 s)")
    ax.set_title("BubbleRob fleet, 10 substeps per step")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    path = ROOT / "docs/rovers.png"
    fig.savefig(path)
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--public-only", action="store_true", help="print only the public robots' table")
    ap.add_argument("--vision-only", action="store_true", help="print only the vision section")
    ap.add_argument("--mujoco-only", action="store_true", help="print only the MuJoCo section")
    args = ap.parse_args()
    if args.mujoco_only:
        print(mujoco_section(load("mujoco.json")))
        return
    if args.public_only:
        print(public_robots(load("public.json")))
        return
    if args.vision_only:
        print(vision_section(load("vision.json")))
        return
    g, pb, zmq, start = load("gantry.json"), load("pybullet.json"), load("zmq.json"), load("startup.json")
    text = report(g, pb, zmq, start)
    if (BENCH / "python.json").exists():
        ray = load("ray.json") if (BENCH / "ray.json").exists() else None
        text += "\n" + python_section(load("python.json"), ray)
    if (BENCH / "public.json").exists():
        text += "\n" + public_robots(load("public.json"))
    if (BENCH / "vision.json").exists():
        text += "\n" + vision_section(load("vision.json"))
    if (BENCH / "mujoco.json").exists():
        text += "\n" + mujoco_section(load("mujoco.json"))
    if (BENCH / "ros2.json").exists():
        text += "\n" + ros2_section(load("ros2.json"))
    (BENCH / "report.md").write_text(text + "\n")
    print(text)
    path = plot(g, pb)
    if path:
        print(f"\nplot written to {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
