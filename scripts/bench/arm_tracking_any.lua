-- Benchmark controller for any arm (issue 15): sends every movable joint of the robot
-- this script is attached to a new position target at every step and measures how well
-- the arm tracks it. tools/bench/public_robots.py writes the scenes that use it and drives
-- PyBullet with the same trajectory, so both report comparable errors.
--
-- The movable joints (revolute, prismatic, continuous) are numbered i = 1, 2, ... by
-- depth (how many joints of any type lie between the robot's base and the joint), then
-- by name among joints of equal depth (for a serial arm: base to tip; the two fingers
-- of a gripper: alphabetically). The order does not depend on how the object tree
-- lists siblings. For joint i with limits [lo, hi]:
--   c_i = (lo + hi) / 2, A_i = min(0.5, (hi - lo) / 4), or c_i = 0, A_i = 0.5 if the
--   joint is unlimited or cyclic (continuous);
--   f_i = 0.25 + 0.05 (i - 1) Hz;  q_i(t) = c_i + A_i sin(2 pi f_i t)
-- (rad for revolute joints, m for prismatic ones). If the global VELOCITY_LIMIT maps a
-- joint's name to its URDF <limit velocity> (the benchmark prepends it), A_i is lowered
-- to VELOCITY_MARGIN * limit / (2 pi f_i) where that is smaller, so the target never
-- asks for more speed than the joint may give. The scene starts the arm at the
-- centres c_i. The target sent before step k (k = 1, 2, ...) is q(k dt), the trajectory
-- at the step's end; the error is read after the step, as in arm_tracking.lua.
--
-- Output, through print (shown on stderr with `gantry -v`), one line each:
--   sysCall_init:    @track-joint i=<i> name=<alias> c=<c> a=<A> q0=<position at start>
--   sysCall_cleanup: @track-error i=<i> name=<alias> sumsq=<sum of squared errors> max=<largest>
--                    (per joint), then
--                    @track-result joints=<n> samples=<count> rms=<all joints> max=<all joints>
-- The per-joint sums let the caller leave joints out (URDF <mimic> followers, which the
-- simulator moves from their leader whatever target they get).
--
-- The same controller drives a wheeled robot's wheels (issue 33): tools/bench/mujoco_bench.py
-- prepends TRACK = 'velocity' and the joints in its benchmark order with their trajectory,
--   JOINTS = { {name = "<URDF joint name>", c = <rad/s>, a = <rad/s>, f = <Hz>}, ... }
-- and the targets are then velocities, c_i + a_i sin(2 pi f_i t), the error
-- |qdot_i - target_i|.

local sin, abs, sqrt, min = math.sin, math.abs, math.sqrt, math.min
local velocity = TRACK == 'velocity'
local setTarget = velocity and sim.setJointTargetVelocity or sim.setJointTargetPosition
local getPosition = sim.getJointPosition
local getTracked = velocity and sim.getJointVelocity or getPosition

local n = 0
local handles, names, centre, amplitude, omega, targets = {}, {}, {}, {}, {}, {}
local sumSq, maxErr = {}, {}
local dt, k = 0, 0

-- The joints of JOINTS, by name, with their trajectories.
local function listedJoints(base)
    local byName = {}
    for _, h in ipairs(sim.getObjectsInTree(base, sim.object_joint_type)) do
        byName[sim.getObjectAlias(h, -1)] = h
    end
    local out = {}
    for i, j in ipairs(JOINTS) do
        local h = byName[j.name]
        if not h then error('no joint named ' .. j.name) end
        out[i] = {h = h, name = j.name, c = j.c, a = j.a, f = j.f}
    end
    return out
end

-- Every movable joint, in the order and with the trajectories described above.
local function movableJoints(base)
    local found = {}
    for _, h in ipairs(sim.getObjectsInTree(base, sim.object_joint_type)) do
        if sim.getJointType(h) ~= sim.joint_fixed_subtype then
            local depth, p = 0, sim.getObjectParent(h)
            while p ~= base and p ~= -1 do
                if sim.getObjectType(p) == sim.object_joint_type then depth = depth + 1 end
                p = sim.getObjectParent(p)
            end
            found[#found + 1] = {h = h, depth = depth, name = sim.getObjectAlias(h, -1)}
        end
    end
    table.sort(found, function(a, b)
        if a.depth ~= b.depth then return a.depth < b.depth end
        return a.name < b.name
    end)
    for i, f in ipairs(found) do
        local cyclic, interval = sim.getJointInterval(f.h)
        local lo, range = interval[1], interval[2]
        local c, a = 0, 0.5
        -- Unlimited non-cyclic joints report a huge interval (-1e5, range 2e5).
        if not cyclic and range < 1e5 then
            c = lo + range / 2
            a = min(0.5, range / 4)
        end
        f.f = 0.25 + 0.05 * (i - 1)
        local limit = VELOCITY_LIMIT and VELOCITY_LIMIT[f.name]
        if limit then a = min(a, VELOCITY_MARGIN * limit / (2 * math.pi * f.f)) end
        f.c, f.a = c, a
    end
    return found
end

function sysCall_init()
    local base = sim.getObject(':')
    dt = sim.getSimulationTimeStep()
    for i, j in ipairs(JOINTS and listedJoints(base) or movableJoints(base)) do
        n = i
        handles[i], names[i], centre[i], amplitude[i] = j.h, j.name, j.c, j.a
        omega[i] = 2 * math.pi * j.f
        targets[i], sumSq[i], maxErr[i] = j.c, 0, 0
        print(string.format('@track-joint i=%d name=%s c=%.17g a=%.17g q0=%.17g', i, j.name, j.c, j.a, getPosition(j.h)))
    end
end

function sysCall_actuation()
    k = k + 1
    local t = k * dt
    for i = 1, n do
        local q = centre[i] + amplitude[i] * sin(omega[i] * t)
        targets[i] = q
        setTarget(handles[i], q)
    end
end

function sysCall_sensing()
    for i = 1, n do
        local e = abs(getTracked(handles[i]) - targets[i])
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
