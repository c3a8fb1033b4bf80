-- Benchmark controller for a wheeled robot (issue 33): sends each listed joint of the
-- robot this script is attached to a new velocity target at every step and measures how
-- well the joint follows it. tools/bench/mujoco_bench.py prepends the global JOINTS, the
-- joints in its benchmark order with their trajectory,
--   JOINTS = { {name = "<URDF joint name>", c = <rad/s>, a = <rad/s>, f = <Hz>}, ... }
-- and drives MuJoCo and PyBullet with the same targets: joint i's target velocity before
-- step k (k = 1, 2, ...) is c_i + a_i sin(2 pi f_i k dt), the velocity at the step's end;
-- the error |qdot_i - target_i| is read after the step.
--
-- Output, through print, in arm_tracking_any.lua's format (public_robots.run_gantry
-- reads it): @track-joint per joint at init (q0 is the joint's position), then at
-- cleanup @track-error per joint and @track-result. benchErrors() returns the sums to an
-- in-process caller.

local sin, abs, sqrt = math.sin, math.abs, math.sqrt
local setTarget, getVelocity = sim.setJointTargetVelocity, sim.getJointVelocity

local n = 0
local handles, names, centre, amplitude, omega, targets = {}, {}, {}, {}, {}, {}
local sumSq, maxErr = {}, {}
local dt, k = 0, 0

function sysCall_init()
    local base = sim.getObject(':')
    dt = sim.getSimulationTimeStep()
    local byName = {}
    for _, h in ipairs(sim.getObjectsInTree(base, sim.object_joint_type)) do
        byName[sim.getObjectAlias(h, -1)] = h
    end
    for i, j in ipairs(JOINTS) do
        local h = byName[j.name]
        if not h then error('no joint named ' .. j.name) end
        n = i
        handles[i], names[i], centre[i], amplitude[i] = h, j.name, j.c, j.a
        omega[i] = 2 * math.pi * j.f
        targets[i], sumSq[i], maxErr[i] = j.c, 0, 0
        print(string.format('@track-joint i=%d name=%s c=%.17g a=%.17g q0=%.17g', i, j.name, j.c, j.a,
            sim.getJointPosition(h)))
    end
end

function sysCall_actuation()
    k = k + 1
    local t = k * dt
    for i = 1, n do
        local v = centre[i] + amplitude[i] * sin(omega[i] * t)
        targets[i] = v
        setTarget(handles[i], v)
    end
end

function sysCall_sensing()
    for i = 1, n do
        local e = abs(getVelocity(handles[i]) - targets[i])
        sumSq[i] = sumSq[i] + e * e
        if e > maxErr[i] then maxErr[i] = e end
    end
end

function sysCall_cleanup()
    local total, largest = 0, 0
    for i = 1, n do
        print(string.format('@track-error i=%d name=%s sumsq=%.17g max=%.17g', i, names[i], sumSq[i], maxErr[i]))
        total = total + sumSq[i]
        if maxErr[i] > largest then largest = maxErr[i] end
    end
    print(string.format('@track-result joints=%d samples=%d rms=%.17g max=%.17g',
        n, n * k, sqrt(total / math.max(n * k, 1)), largest))
end

function benchErrors()
    return {sumSq, maxErr, k}
end
