-- Benchmark controller (issue 8): sends every joint of arm6 a new position target at
-- every step and measures how well the arm tracks it. tools/bench/pybullet_bench.py
-- drives PyBullet with the same trajectory, so both report comparable errors.
--
-- Joint i follows q_i(t) = A_i sin(2 pi f_i t) (radians). The target sent at the start
-- of a step is the trajectory at the step's end; the error is read after the step.

local A = {0.6, 0.5, 0.4, 0.8, 0.6, 1.0}   -- rad
local F = {0.25, 0.3, 0.35, 0.4, 0.45, 0.5} -- Hz

function sysCall_init()
    joints = {}
    for i = 1, 6 do
        joints[i] = sim.getObject(':/joint' .. i)
    end
    dt = sim.getSimulationTimeStep()
    targets = {0, 0, 0, 0, 0, 0}
    sumSq, count, maxErr = 0, 0, 0
end

function sysCall_actuation()
    local t = sim.getSimulationTime() + dt
    for i = 1, 6 do
        targets[i] = A[i] * math.sin(2 * math.pi * F[i] * t)
        sim.setJointTargetPosition(joints[i], targets[i])
    end
end

function sysCall_sensing()
    for i = 1, 6 do
        local e = math.abs(sim.getJointPosition(joints[i]) - targets[i])
        sumSq = sumSq + e * e
        count = count + 1
        if e > maxErr then maxErr = e end
    end
end

-- Called by the benchmark: RMS and largest joint error so far, rad.
function trackingError()
    return math.sqrt(sumSq / math.max(count, 1)), maxErr
end
