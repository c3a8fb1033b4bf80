"""(5) Two clients at once, one of them stepping: the other is served while the
simulation is held, and a client parked in sim.step() does not block anybody."""

import threading
import time

import pytest

# Several clients of one simulation, over the network: what only the server has.
pytestmark = pytest.mark.zmq_only


def test_stepping_client_and_observer(gantry):
    g = gantry("assets/scenes/bubble_rob.toml")  # --fast: free-running at full speed
    stepper, observer = g.client(), g.client()
    sim_s, sim_o = stepper.require("sim"), observer.require("sim")

    assert stepper.setStepping(True) == 0
    t0 = sim_s.getSimulationTime()
    dt = sim_s.getSimulationTimeStep()
    # The simulation is held; the observer is served all the while.
    for _ in range(100):
        assert sim_o.getSimulationTime() == t0
    for k in range(1, 6):
        stepper.step()
        assert sim_o.getSimulationTime() == pytest.approx(t0 + k * dt, abs=1e-9)

    # The observer parks in sim.step() (it waits for the next step, which only the
    # stepper can release) while the stepper's calls are answered at once.
    done = threading.Event()

    def observer_steps():
        observer.step()
        done.set()

    th = threading.Thread(target=observer_steps, daemon=True)
    th.start()
    time.sleep(0.2)
    assert not done.is_set(), "the observer waits for the next step"
    t_before = sim_s.getSimulationTime()
    for _ in range(100):
        assert sim_s.getSimulationTime() == t_before
    rob = sim_s.getObject("/bubbleRob")
    assert len(sim_s.getObjectPosition(rob, -1)) == 3
    stepper.step()
    th.join(5)
    assert done.is_set(), "the step released the parked observer"
    assert sim_o.getSimulationTime() == pytest.approx(t_before + dt, abs=1e-9)

    # Stepping off: the simulation free-runs again.
    assert stepper.setStepping(False) == 1
    t1 = sim_o.getSimulationTime()
    time.sleep(0.1)
    assert sim_o.getSimulationTime() > t1


STEPPER = """
import sys
from coppeliasim_zmqremoteapi_client import RemoteAPIClient
client = RemoteAPIClient(host="127.0.0.1", port=int(sys.argv[1]))
sim = client.require("sim")
client.setStepping(True)
client.step()
print("stepping", flush=True)
# Holds the simulation until killed or interrupted. A loop of short sleeps, as a user's
# script waits: the kernel may hand SIGINT to one of pyzmq's threads, and Python raises
# KeyboardInterrupt only when the main thread next runs Python code; blocked in a
# `readline` it never would (the interrupted client then hung for 30 s in full runs).
import time
while True:
    time.sleep(0.05)
"""


@pytest.mark.parametrize("how", ["kill", "interrupt"])
def test_a_vanished_stepping_client_releases_the_simulation(gantry, how):
    """CoppeliaSim keeps a stepping client's hold until its session times out (600 s by
    default), so a script stopped with Ctrl-C freezes the simulation. gantry ends the
    session when the client's connection closes."""
    import signal
    import subprocess
    import sys

    g = gantry("assets/scenes/bubble_rob.toml", fast=False)
    proc = subprocess.Popen([sys.executable, "-c", STEPPER, str(g.port)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "stepping"
        sim = g.client().require("sim")
        t0 = sim.getSimulationTime()
        time.sleep(0.3)
        assert sim.getSimulationTime() == t0, "held by the stepping client"
        proc.send_signal(signal.SIGKILL if how == "kill" else signal.SIGINT)
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            # CoppeliaSim's client sometimes hangs in its own teardown after Ctrl-C
            # under a full test run's load (never when run alone). Its connection stays
            # open until the process is gone, and the connection closing is what gantry
            # acts on, so the process is ended the hard way and the check goes on.
            assert how == "interrupt"
            proc.kill()
            proc.wait()
        # Released within a moment: the simulation runs in real time again.
        deadline = time.monotonic() + 5
        while sim.getSimulationTime() == t0 and time.monotonic() < deadline:
            time.sleep(0.05)
        t1 = sim.getSimulationTime()
        assert t1 > t0, "the simulation runs again"
        time.sleep(0.3)
        assert sim.getSimulationTime() > t1
        assert "disconnected; its stepping level and locks are released" in g.stderr()
    finally:
        proc.kill()
        proc.wait()
