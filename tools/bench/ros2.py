"""What joining a ROS 2 graph costs (issue 29), with Cyclone DDS from PyPI as the peer
that subscribes and publishes (tests/python/ros2_peer.py):

1. the showroom's headless step rate without --ros2 and with it (/clock, /tf,
   /tf_static and /joint_states every step, camera topics off), a peer subscribed to
   all of them (taking /clock); target: at most 5 % slower;
2. BubbleRob with its vision sensor at 640 x 480, published as image_raw, depth and
   camera_info at 30 Hz of simulated time (every 0.05 s step): paced in real time,
   whether the rate holds and how many images the peer received; with --fast, the
   real-time factor (target: at least 1);
3. latency from the peer writing a /cmd_vel Twist to the script's callback having set
   the wheel speeds, measured as the round trip to an acknowledgement the callback
   publishes (an upper bound of the one-way figure), in real time (dt 0.05 s: a command
   waits for the next step) and with --fast; median and p99.

Configurations run interleaved, `--repeat` times; figures are medians.

    .venv/bin/python tools/bench/ros2.py [--steps 4000] [--repeat 5] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "python"))
from gantry_proc import gantry_bin  # noqa: E402
from ros2_peer import (  # noqa: E402
    CameraInfo,
    Clock,
    Float64,
    Image,
    JointState,
    Peer,
    TFMessage,
    Twist,
    Vector3,
    free_domain,
)

RATE = re.compile(r"steps_per_s=([0-9.]+) ")
RTF = re.compile(r"rtf=([0-9.]+)")
TARGET_COST = 0.95

ACK_SCRIPT = """
local tutorial_init, tutorial_callback = sysCall_init, cmdVel_callback
function sysCall_init()
    tutorial_init()
    ackPub = simROS2.createPublisher('/ack', 'std_msgs/msg/Float64')
end
function cmdVel_callback(msg)
    tutorial_callback(msg)
    sim.setJointTargetVelocity(leftMotor, leftSpeed)
    sim.setJointTargetVelocity(rightMotor, rightSpeed)
    simROS2.publish(ackPub, {data = msg.linear.x})
end
"""


def run(cmd: list[str], env: dict) -> str:
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    if out.returncode != 0 or not RATE.search(out.stdout):
        raise RuntimeError(f"{' '.join(cmd)} failed ({out.returncode}):\n{out.stdout}\n{out.stderr}")
    return out.stdout


def counting(readers: list) -> tuple[threading.Event, list[int]]:
    """Takes samples from `readers` on a thread until the event is set; counts per reader."""
    stop = threading.Event()
    counts = [0] * len(readers)

    def loop():
        while not stop.is_set():
            for i, r in enumerate(readers):
                counts[i] += len(r.take(N=1000))
            time.sleep(0.005)

    threading.Thread(target=loop, daemon=True).start()
    return stop, counts


def graph_cost(steps: int, repeat: int) -> dict:
    domain = free_domain()
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    peer = Peer(domain)
    # Subscribed to all three (gantry sends every message to the peer, reliably, and
    # handles its acknowledgements), but only /clock is taken and decoded: decoding 45
    # transforms per message in Python would take the CPU this 2-core machine shares
    # with gantry, and measure the peer rather than gantry.
    readers = [peer.reader("rt/clock", Clock)]
    subscribed = [peer.reader("rt/tf", TFMessage), peer.reader("rt/joint_states", JointState)]
    assert subscribed
    base = [str(gantry_bin()), "run", "assets/scenes/showroom.toml", "--fast", "--steps", str(steps), "--no-listen"]
    without, with_ros, received = [], [], []
    for _ in range(repeat):
        without.append(float(RATE.search(run(base, env)).group(1)))
        stop, counts = counting(readers)
        with_ros.append(float(RATE.search(run(base + ["--ros2", "--ros2-camera-rate", "0"], env)).group(1)))
        time.sleep(0.3)
        stop.set()
        received.append(counts[0])
    a, b = statistics.median(without), statistics.median(with_ros)
    return {
        "steps": steps,
        "without_steps_per_s": a,
        "with_ros2_steps_per_s": b,
        "ratio": b / a,
        "clock_messages_received_median": statistics.median(received),
        "target_ratio": TARGET_COST,
    }


def camera(steps: int, repeat: int, tmp: Path) -> dict:
    """In real time for `steps` steps (the rate must hold, every image arrive), and with
    --fast (how far above real time the step rate stays while publishing)."""
    text = (REPO / "assets/scenes/bubble_rob_ros2.toml").read_text()
    text = text.replace("resolution = [256, 256]", "resolution = [640, 480]")
    text = text.replace('script = "../../scripts/', f'script = "{REPO}/scripts/')
    scene = tmp / "camera640.toml"
    scene.write_text(text)
    domain = free_domain()
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    peer = Peer(domain)
    readers = [
        peer.reader("rt/bubbleRob/sensingNose/visionSensor/image_raw", Image),
        peer.reader("rt/bubbleRob/sensingNose/visionSensor/camera_info", CameraInfo),
    ]
    base = [str(gantry_bin()), "run", str(scene), "--steps", str(steps), "--no-listen",
            "--ros2", "--ros2-camera-rate", "30"]
    rtf, images, fast_rtf = [], [], []
    for _ in range(repeat):
        # What the previous (fast) run left in the readers is not this run's.
        for r in readers:
            while r.take(N=1000):
                pass
        stop, counts = counting(readers)
        out = run(base, env)
        time.sleep(0.3)
        stop.set()
        rtf.append(float(RTF.search(out).group(1)))
        images.append(counts[0])
        fast_rtf.append(float(RTF.search(run(base + ["--fast"], env)).group(1)))
    return {
        "resolution": [640, 480],
        "camera_rate_hz": 30,
        "steps": steps,
        "real_time_factor_paced": statistics.median(rtf),
        "images_published": steps,
        "images_received_median": statistics.median(images),
        "real_time_factor_fast": statistics.median(fast_rtf),
        "target_real_time_factor": 1.0,
    }


def latency(samples: int, fast: bool, tmp: Path) -> dict:
    script = tmp / "bubble_rob_ros2_ack.lua"
    script.write_text((REPO / "scripts/bubble_rob_ros2.lua").read_text() + ACK_SCRIPT)
    text = (REPO / "assets/scenes/bubble_rob_ros2.toml").read_text()
    text = text.replace('script = "../../scripts/bubble_rob_ros2.lua"', f'script = "{script}"')
    scene = tmp / "ack.toml"
    scene.write_text(text)
    domain = free_domain()
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    peer = Peer(domain)
    cmd_vel = peer.writer("rt/cmd_vel", Twist)
    acks = peer.reader("rt/ack", Float64)
    args = [str(gantry_bin()), "run", str(scene), "--no-listen"] + (["--fast"] if fast else [])
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, text=True)
    try:
        deadline = time.monotonic() + 30
        while not cmd_vel.get_matched_subscriptions():
            if time.monotonic() > deadline:
                raise RuntimeError("gantry's /cmd_vel subscription never matched")
            time.sleep(0.01)
        rtts = []
        rng = random.Random(1)
        for i in range(samples):
            v = 0.001 * (i + 1) + rng.random() * 1e-6
            t0 = time.perf_counter()
            cmd_vel.write(Twist(linear=Vector3(v, 0, 0), angular=Vector3(0, 0, 0)))
            got = None
            while got is None and time.perf_counter() - t0 < 2.0:
                for s in acks.take(N=100):
                    if abs(s.data - v) < 1e-12:
                        got = time.perf_counter()
                # Not a busy loop: on two cores it would take the one the DDS threads need.
                time.sleep(0.0002)
            if got is None:
                raise RuntimeError(f"no acknowledgement of command {i}")
            rtts.append((got - t0) * 1e3)
            # A random phase against the simulation's steps, or every command would
            # arrive at the same point of a step and the figure would be that point's.
            time.sleep(rng.uniform(0.0, 0.05))
    finally:
        proc.terminate()
        proc.wait(10)
    rtts.sort()
    return {
        "mode": "fast" if fast else "real time (dt 0.05 s)",
        "samples": samples,
        "round_trip_ms_median": statistics.median(rtts),
        "round_trip_ms_p99": rtts[min(len(rtts) - 1, int(0.99 * len(rtts)))],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--latency-samples", type=int, default=300)
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    os.chdir(REPO)
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        report = {
            "graph": graph_cost(a.steps, a.repeat),
            "camera_640x480": camera(200, a.repeat, tmp),
            "latency_fast": latency(a.latency_samples, True, tmp),
            "latency_realtime": latency(max(a.latency_samples // 3, 50), False, tmp),
        }
    g, c = report["graph"], report["camera_640x480"]
    print(f"graph: {g['without_steps_per_s']:.0f} -> {g['with_ros2_steps_per_s']:.0f} steps/s "
          f"({100 * (1 - g['ratio']):.1f} % cost; target <= {100 * (1 - TARGET_COST):.0f} %)")
    print(f"camera 640x480 @30 Hz (dt 0.05 s: every step): paced rtf {c['real_time_factor_paced']:.3f}, "
          f"{c['images_received_median']:.0f} of {c['images_published']} images received; "
          f"--fast rtf {c['real_time_factor_fast']:.2f} (target >= 1)")
    for k in ("latency_fast", "latency_realtime"):
        lat = report[k]
        print(f"cmd_vel -> callback -> ack, {lat['mode']}: median {lat['round_trip_ms_median']:.2f} ms, "
              f"p99 {lat['round_trip_ms_p99']:.2f} ms")
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
