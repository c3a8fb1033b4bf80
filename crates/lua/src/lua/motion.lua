-- sim.moveToConfig and sim.moveToPose, with their _init/_step/_cleanup parts, written on
-- sim.ruckigPos / sim.ruckigStep / sim.ruckigRemove (Rust, api/ruckig.rs) and sim.step.
--
-- How to load: run this chunk once, with the shared `sim` table as its only argument,
-- where lua/threads.lua is loaded (before the scripts' environments are copied), e.g.
--
--     let helpers: Table = lua.load(include_str!("lua/motion.lua")).call(sim.clone())?
--
-- It adds functions to that table and returns its error and thread helpers, which
-- lua/path_motion.lua shares. The sim.* functions it uses are
-- looked up in that table when called, not when loaded, so the load order against
-- threads.lua does not matter, and a script replacing sim.ruckigStep in its own copy of
-- `sim` cannot change how sim.moveToConfig moves. The Lua builtins are captured when
-- loaded.
--
-- Both CoppeliaSim forms are accepted:
-- * 4.6+: sim.moveToConfig(params) and sim.moveToPose(params) take one table and return
--   it completed (pos/pose, vel, accel, timeLeft, ...). Without a callback, moveToConfig
--   drives params.joints and moveToPose params.object. Without maxVel/maxAccel/maxJerk,
--   the target is reached in one step (CoppeliaSim 4.7+).
-- * 4.0-4.5: sim.moveToConfig(flags, currentPos, currentVel, currentAccel, maxVel,
--   maxAccel, maxJerk, targetPos, targetVel, callback, auxData, cyclicJoints, timeStep)
--   returns endPos, endVel, endAccel, timeLeft; sim.moveToPose(flags, currentPose|Matrix,
--   maxVel, maxAccel, maxJerk, targetPose|Matrix, callback, auxData, metric, timeStep)
--   returns the end pose (or matrix, as given) and timeLeft.
-- A callback returning true aborts the motion. The blocking calls need a threaded script
-- (sysCall_thread) or a coroutine: each motion step is followed by one sim.step().
local sim = ...
local type, error, pcall, select, setmetatable, getmetatable, tostring, pairs, ipairs =
    type, error, pcall, select, setmetatable, getmetatable, tostring, pairs, ipairs
local math, string, table, coroutine = math, string, table, coroutine

-- CoppeliaSim's Ruckig flags (sim.ruckig_phasesync, _nosync, _minvel, _minaccel; the
-- registry defines them in api/ruckig.rs with these values).
local PHASESYNC, NOSYNC, MINVEL, MINACCEL = 0, 3, 256, 512

-- The base cycle CoppeliaSim's motion functions give Ruckig, s: any simulation step is a
-- whole number of them.
local BASE_CYCLE = 0.0001
-- Limits used when none are given: large enough that the target is reached at once
-- (CoppeliaSim 4.7+), with a 10 s step so that it happens in the first step.
local NO_LIMIT_VEL, NO_LIMIT_ACCEL, NO_LIMIT_JERK, NO_LIMIT_STEP = 9999.0, 99999.0, 9999999.0, 10.0
-- Below this rotation (rad) moveToPose does not interpolate the orientation.
local MIN_ANGLE = math.pi * 0.00001
-- Below this distance moveToPose with a metric has nothing to move.
local MIN_DIST = 0.000001

-- Errors of this file: raised as tables and turned into messages at the public entry
-- points, so the position reported is the calling script's line.
local MotionError = {}
local function fail(fname, fmt, ...)
    error(setmetatable({message = string.format(fmt, ...) .. " (in function 'sim." .. fname .. "')"}, MotionError), 0)
end

-- Wraps an implementation as a public function: its own errors point at the caller,
-- others (a callback's, the API's) pass through unchanged.
local function public(f)
    return function(...)
        local r = table.pack(pcall(f, ...))
        if r[1] then
            return table.unpack(r, 2, r.n)
        end
        local e = r[2]
        if getmetatable(e) == MotionError then
            error(e.message, 2)
        end
        error(e, 0)
    end
end

-- Callbacks, kept out of the data tables (CoppeliaSim does so that the tables can travel
-- to remote clients), by data table; weak so that abandoned motions free them.
local callbacks = setmetatable({}, {__mode = 'k'})

local function rep(x, n)
    local t = {}
    for i = 1, n do t[i] = x end
    return t
end

local function concat(...)
    local out = {}
    for k = 1, select('#', ...) do
        local t = select(k, ...)
        for i = 1, #t do out[#out + 1] = t[i] end
    end
    return out
end

local function negated(t)
    local out = {}
    for i = 1, #t do out[i] = -t[i] end
    return out
end

local function copy(t)
    local out = {}
    for k, v in pairs(t) do out[k] = v end
    return out
end

-- `t` as n numbers (NaN refused). `what` names it ("'maxVel' field", "argument 5
-- (maxVel)"). Tolerant callers (the 4.0-4.5 form) may pass longer tables, which are cut.
local function numbers(fname, what, t, n, tolerant, allow_infinite)
    if type(t) ~= 'table' then
        fail(fname, "%s: expected a table of %d numbers, got %s", what, n, type(t))
    end
    if #t ~= n and not (tolerant and #t > n) then
        fail(fname, "%s: expected %d numbers, got %d", what, n, #t)
    end
    local out = {}
    for i = 1, n do
        local x = t[i]
        if type(x) ~= 'number' or x ~= x or (not allow_infinite and (x == math.huge or x == -math.huge)) then
            fail(fname, "%s: element %d must be a number, got %s", what, i, tostring(x))
        end
        out[i] = x
    end
    return out
end

-- How many numbers a table argument should hold when only its own length says so (at
-- least one, so that an empty or missing table is reported as too short).
local function len(t)
    return type(t) == 'table' and math.max(#t, 1) or 1
end

local function integer(fname, what, x)
    local i = type(x) == 'number' and math.tointeger(x) or nil
    if i == nil then
        fail(fname, "%s: expected an integer, got %s", what, tostring(x))
    end
    return i
end

local function check_callback(fname, what, cb)
    if cb ~= nil and type(cb) ~= 'function' then
        fail(fname, "%s: expected a function, got %s (gantry does not look callbacks up by name)", what, type(cb))
    end
    return cb
end

local function need_thread(fname)
    if not coroutine.isyieldable() then
        fail(fname, "sim.%s blocks, and blocking calls need a threaded script: call it from "
            .. "sysCall_thread (or a coroutine), not from a non-threaded hook such as sysCall_actuation", fname)
    end
end

-- The limits of `params` for `dim` DoFs, with the flags they imply: all three maxima
-- (then minima default to their negation, and the motion is phase-synchronised unless
-- flags say otherwise) or none (the target is reached in one step).
local function limits(fname, params, dim)
    local tol = params.tolerantArgs
    if params.maxVel ~= nil or params.maxAccel ~= nil or params.maxJerk ~= nil then
        for _, k in ipairs({'maxVel', 'maxAccel', 'maxJerk'}) do
            if params[k] == nil then fail(fname, "missing '%s' field", k) end
        end
        params.maxVel = numbers(fname, "'maxVel' field", params.maxVel, dim, tol, true)
        params.maxAccel = numbers(fname, "'maxAccel' field", params.maxAccel, dim, tol, true)
        params.maxJerk = numbers(fname, "'maxJerk' field", params.maxJerk, dim, tol, true)
        local flags = integer(fname, "'flags' field", params.flags or -1)
        if flags == -1 then flags = PHASESYNC end
        params.flags = flags | MINVEL | MINACCEL
    else
        params.maxVel = rep(NO_LIMIT_VEL, dim)
        params.maxAccel = rep(NO_LIMIT_ACCEL, dim)
        params.maxJerk = rep(NO_LIMIT_JERK, dim)
        params.flags = NOSYNC | MINVEL | MINACCEL
        params.timeStep = NO_LIMIT_STEP
    end
    params.minVel = numbers(fname, "'minVel' field", params.minVel or negated(params.maxVel), dim, tol, true)
    params.minAccel = numbers(fname, "'minAccel' field", params.minAccel or negated(params.maxAccel), dim, tol, true)
    params.vel = numbers(fname, "'vel' field", params.vel or rep(0.0, dim), dim, tol)
    params.accel = numbers(fname, "'accel' field", params.accel or rep(0.0, dim), dim, tol)
    params.targetVel = numbers(fname, "'targetVel' field", params.targetVel or rep(0.0, dim), dim, tol)
    local ts = params.timeStep or 0
    if type(ts) ~= 'number' or not (ts >= 0) then
        fail(fname, "'timeStep' field: expected 0 (the simulation step) or a positive number of seconds")
    end
    params.timeStep = ts
end

-- The motion step's duration, s.
local function step_time(data)
    if data.timeStep == 0 then return sim.getSimulationTimeStep() end
    return data.timeStep
end

-- Steps the generator; returns the result code, the new state, and sets data.timeLeft
-- (the part of the step not needed to finish, s).
local function ruckig_step(data)
    local res, s, sync = sim.ruckigStep(data.ruckigObj, step_time(data))
    if res == 1 then
        data.timeLeft = math.max(0.0, -sync)
    elseif res == 0 then
        data.timeLeft = 0.0
    end
    return res, s
end

-- Runs a motion to its end: a motion step, then a simulation step, until it finishes
-- (or a callback aborts it); cleans up whatever happens.
local function run(fname, init, step, cleanup, params)
    need_thread(fname)
    local data = init(params)
    -- A script's thread steps for the motion; a remote client's call (run by the
    -- engine, no script running) is stepped by the engine.
    local stepping = sim.setStepping ~= nil and pcall(sim.setStepping, true)
    local ok, e = pcall(function()
        while true do
            local res = step(data)
            if res < 0 then
                fail(fname, "sim.%s_step returned error code %d", fname, res)
            end
            sim.step()
            if res ~= 0 then break end
        end
    end)
    cleanup(data)
    if stepping then sim.setStepping(false) end
    if not ok then error(e, 0) end
    return data
end

---------------------------------------------------------------------------------------
-- sim.moveToConfig

local function config_init(params)
    local fname = 'moveToConfig_init'
    if type(params) ~= 'table' then
        fail(fname, "argument 1: expected a table of parameters, got %s", type(params))
    end
    params = copy(params) -- the caller's table is left as it is
    if params.pos ~= nil then
        params.pos = numbers(fname, "'pos' field", params.pos, len(params.pos), false)
        if params.joints ~= nil and (type(params.joints) ~= 'table' or #params.joints ~= #params.pos) then
            fail(fname, "'joints' field: expected %d joint handles, as many as 'pos' values", #params.pos)
        end
    elseif params.joints ~= nil then
        if type(params.joints) ~= 'table' or #params.joints == 0 then
            fail(fname, "'joints' field: expected a table of joint handles")
        end
        params.pos = {}
        for i = 1, #params.joints do
            params.pos[i] = sim.getJointPosition(params.joints[i])
        end
    else
        fail(fname, "missing field: either 'pos' or 'joints' is required")
    end
    local dim = #params.pos
    params.targetPos = numbers(fname, "'targetPos' field", params.targetPos, dim, params.tolerantArgs)
    limits(fname, params, dim)
    if params.cyclicJoints ~= nil and type(params.cyclicJoints) ~= 'table' then
        fail(fname, "'cyclicJoints' field: expected a table of booleans")
    end
    for i = 1, dim do
        -- A cyclic joint takes the shorter way round: the target within pi of the start.
        if params.cyclicJoints and params.cyclicJoints[i] then
            local v, w = params.pos[i], params.targetPos[i]
            w = v + math.fmod(w - v, 2 * math.pi)
            if w - v > math.pi then w = w - 2 * math.pi end
            if w - v <= -math.pi then w = w + 2 * math.pi end
            params.targetPos[i] = w
        end
    end
    local cb = check_callback(fname, "'callback' field", params.callback)
    params.callback = nil
    params.ruckigObj = sim.ruckigPos(dim, BASE_CYCLE, params.flags,
        concat(params.pos, params.vel, params.accel),
        concat(params.maxVel, params.maxAccel, params.maxJerk, params.minVel, params.minAccel),
        rep(1, dim), concat(params.targetPos, params.targetVel))
    params.timeLeft = 0.0
    callbacks[params] = cb
    return params
end

local function config_step(data)
    local fname = 'moveToConfig_step'
    if type(data) ~= 'table' or data.ruckigObj == nil then
        fail(fname, "argument 1: expected the table returned by sim.moveToConfig_init")
    end
    local res, s = ruckig_step(data)
    if res < 0 then return res, data end
    local n = #data.pos
    for i = 1, n do
        data.pos[i] = s[i]
        data.vel[i] = s[n + i]
        data.accel[i] = s[2 * n + i]
    end
    local cb = callbacks[data]
    if cb then
        local abort
        if data.legacyFunc then
            abort = cb(data.pos, data.vel, data.accel, data.auxData)
        else
            abort = cb(data)
        end
        if abort then res = 2 end
    elseif data.joints then
        -- CoppeliaSim's default: dynamic joints get a target, kinematic ones are placed
        -- (a target would start a kinematic joint's own, slower, motion profile).
        for i = 1, n do
            local j = data.joints[i]
            if sim.isDynamicallyEnabled == nil or sim.isDynamicallyEnabled(j) then
                sim.setJointTargetPosition(j, data.pos[i])
            else
                sim.setJointPosition(j, data.pos[i])
            end
        end
    end
    return res, data
end

local function config_cleanup(data)
    if type(data) == 'table' and data.ruckigObj ~= nil then
        sim.ruckigRemove(data.ruckigObj)
        data.ruckigObj = nil
        callbacks[data] = nil
    end
end

local function move_to_config(...)
    local params = ...
    local legacy = type(params) == 'number'
    if legacy then
        local fname = 'moveToConfig'
        local flags, pos, vel, accel, maxVel, maxAccel, maxJerk, targetPos, targetVel, callback, auxData, cyclic, timeStep = ...
        flags = integer(fname, "argument 1 (flags)", flags)
        pos = numbers(fname, "argument 2 (currentPos)", pos, len(pos), false)
        local n = #pos
        params = {
            tolerantArgs = true,
            legacyFunc = true,
            pos = pos,
            vel = vel,
            accel = accel,
            maxVel = numbers(fname, "argument 5 (maxVel)", maxVel, n, true, true),
            maxAccel = numbers(fname, "argument 6 (maxAccel)", maxAccel, n, true, true),
            maxJerk = numbers(fname, "argument 7 (maxJerk)", maxJerk, n, true, true),
            targetPos = numbers(fname, "argument 8 (targetPos)", targetPos, n, true),
            targetVel = targetVel,
            callback = check_callback(fname, "argument 10 (callback)", callback),
            auxData = auxData,
            cyclicJoints = cyclic,
            timeStep = timeStep or 0,
        }
        -- The minimum limits follow the maximum ones in the same table.
        if flags >= 0 and flags & MINVEL ~= 0 then
            params.minVel = numbers(fname, "argument 5 (maxVel, with minimum velocities)", {table.unpack(maxVel, n + 1)}, n)
            flags = flags - MINVEL
        end
        if flags >= 0 and flags & MINACCEL ~= 0 then
            params.minAccel = numbers(fname, "argument 6 (maxAccel, with minimum accelerations)", {table.unpack(maxAccel, n + 1)}, n)
            flags = flags - MINACCEL
        end
        params.flags = flags
    elseif type(params) ~= 'table' then
        fail('moveToConfig', "argument 1: expected a table of parameters (or the flags of the 4.0-4.5 form), got %s", type(params))
    end
    local data = run('moveToConfig', config_init, config_step, config_cleanup, params)
    if legacy then
        return data.pos, data.vel, data.accel, data.timeLeft
    end
    return data
end

sim.moveToConfig_init = public(config_init)
sim.moveToConfig_step = public(config_step)
sim.moveToConfig_cleanup = public(config_cleanup)
sim.moveToConfig = public(move_to_config)

---------------------------------------------------------------------------------------
-- sim.rmlMoveToJointPositions (CoppeliaSim 3.x-4.2, threaded scripts): the joints move
-- to targetPos under velocity, acceleration and jerk limits, blocking until they are
-- there, as sim.moveToConfig (which replaced it) moves them: dynamic joints get targets,
-- kinematic ones are placed. Returns result (1: reached), newPos, newVel, newAccel and
-- timeLeft. `direction` (cyclic joints: which way round) takes the shorter way.

local function rml_move_to_joint_positions(jointHandles, flags, currentVel, currentAccel, maxVel, maxAccel, maxJerk, targetPos, targetVel, direction)
    local fname = 'rmlMoveToJointPositions'
    if type(jointHandles) ~= 'table' or #jointHandles == 0 then
        fail(fname, "argument 1: expected a table of joint handles")
    end
    local n = #jointHandles
    -- `direction`: per cyclic joint, 0 for the shorter way round, +-x for x-1 extra full
    -- turns, which gantry does not do.
    local cyclic = nil
    if direction ~= nil then
        if type(direction) ~= 'table' then
            fail(fname, "argument 10 (direction): expected a table of integers")
        end
        cyclic = {}
        for i = 1, n do
            local d = direction[i] or 0
            if d ~= 0 then
                fail(fname, "argument 10 (direction): only 0 (the shorter way round) is supported, got %s", tostring(d))
            end
            cyclic[i] = sim.getJointInterval(jointHandles[i])
        end
    end
    local data = run(fname, config_init, config_step, config_cleanup, {
        tolerantArgs = true,
        joints = jointHandles,
        flags = integer(fname, "argument 2 (flags)", flags),
        vel = currentVel,
        accel = currentAccel,
        maxVel = numbers(fname, "argument 5 (maxVel)", maxVel, n, true, true),
        maxAccel = numbers(fname, "argument 6 (maxAccel)", maxAccel, n, true, true),
        maxJerk = numbers(fname, "argument 7 (maxJerk)", maxJerk, n, true, true),
        targetPos = numbers(fname, "argument 8 (targetPos)", targetPos, n, true),
        targetVel = targetVel,
        cyclicJoints = cyclic,
    })
    return 1, data.pos, data.vel, data.accel, data.timeLeft
end

sim.rmlMoveToJointPositions = public(rml_move_to_joint_positions)

---------------------------------------------------------------------------------------
-- sim.moveToPose

local function pose_init(params)
    local fname = 'moveToPose_init'
    if type(params) ~= 'table' then
        fail(fname, "argument 1: expected a table of parameters, got %s", type(params))
    end
    params = copy(params)
    if params.ik ~= nil then
        fail(fname, "'ik' field: not supported by gantry; move the IK target with 'object' and solve with simIK")
    end
    params.relObject = params.relObject or -1
    if params.pose ~= nil then
        params.pose = numbers(fname, "'pose' field", params.pose, 7, false)
        params.object = nil
        params.relObject = -1
    elseif params.object ~= nil then
        params.object = integer(fname, "'object' field", params.object)
        params.pose = sim.getObjectPose(params.object, params.relObject)
    else
        fail(fname, "missing field: either 'pose' or 'object' is required")
    end
    params.targetPose = numbers(fname, "'targetPose' field", params.targetPose, 7, false)
    local dim = 4
    if params.metric ~= nil then
        params.metric = numbers(fname, "'metric' field", params.metric, 4, false)
        dim = 1
    end
    limits(fname, params, dim)
    local cb = check_callback(fname, "'callback' field", params.callback)
    params.callback = nil

    params.startMatrix = sim.poseToMatrix(params.pose)
    params.targetMatrix = sim.poseToMatrix(params.targetPose)
    params.matrix = {table.unpack(params.startMatrix)}
    local _, angle = sim.getRotationAxis(params.startMatrix, params.targetMatrix)
    params.angle = angle
    local s, g = params.startMatrix, params.targetMatrix
    local dx = {g[4] - s[4], g[8] - s[8], g[12] - s[12], angle}
    local sel = rep(1, dim)
    local lim = concat(params.maxVel, params.maxAccel, params.maxJerk, params.minVel, params.minAccel)
    if params.metric then
        -- One DoF: the distance along the straight interpolation from start to goal, in
        -- the metric's units; the path is always the straight one.
        local d2 = 0
        for i = 1, 4 do d2 = d2 + (dx[i] * params.metric[i]) ^ 2 end
        params.dist = math.sqrt(d2)
        if params.dist > MIN_DIST then
            params.ruckigObj = sim.ruckigPos(1, BASE_CYCLE, params.flags,
                {0.0, params.vel[1], params.accel[1]}, lim, sel, {params.dist, params.targetVel[1]})
        end
    else
        -- Four DoFs: x, y, z and the rotation angle, each within its own limits (with
        -- phase synchronisation the path is straight too).
        params.dist = 1.0
        params.ruckigObj = sim.ruckigPos(4, BASE_CYCLE, params.flags,
            concat(rep(0.0, 4), params.vel, params.accel), lim, sel, concat(dx, params.targetVel))
    end
    params.timeLeft = 0.0
    callbacks[params] = cb
    return params
end

local function pose_step(data)
    local fname = 'moveToPose_step'
    if type(data) ~= 'table' or data.startMatrix == nil then
        fail(fname, "argument 1: expected the table returned by sim.moveToPose_init")
    end
    if data.ruckigObj == nil then
        return 1, data -- a metric move of (almost) no distance: nothing to do
    end
    local res, s = ruckig_step(data)
    if res < 0 then return res, data end
    if data.metric then
        data.matrix = sim.interpolateMatrices(data.startMatrix, data.targetMatrix, s[1] / data.dist)
        data.vel, data.accel = {s[2]}, {s[3]}
    else
        local t = 0
        if math.abs(data.angle) > MIN_ANGLE then
            t = s[4] / data.angle
        elseif res == 1 then
            t = 1 -- a rotation too small to interpolate is applied at the end
        end
        data.matrix = sim.interpolateMatrices(data.startMatrix, data.targetMatrix, t)
        data.matrix[4] = data.startMatrix[4] + s[1]
        data.matrix[8] = data.startMatrix[8] + s[2]
        data.matrix[12] = data.startMatrix[12] + s[3]
        data.vel = {s[5], s[6], s[7], s[8]}
        data.accel = {s[9], s[10], s[11], s[12]}
    end
    data.pose = sim.matrixToPose(data.matrix)
    local cb = callbacks[data]
    if cb then
        local abort
        if data.legacyFunc then
            abort = cb(data.useMatrices and data.matrix or data.pose, data.vel, data.accel, data.auxData)
        else
            abort = cb(data)
        end
        if abort then res = 2 end
    elseif data.object then
        sim.setObjectPose(data.object, data.pose, data.relObject)
    end
    return res, data
end

local function pose_cleanup(data)
    if type(data) == 'table' and data.ruckigObj ~= nil then
        sim.ruckigRemove(data.ruckigObj)
        data.ruckigObj = nil
    end
    if type(data) == 'table' then callbacks[data] = nil end
end

-- A 4.0-4.5 pose argument: 7 numbers (a pose) or 12 (a matrix, turned into a pose).
local function legacy_pose(fname, what, t)
    if type(t) == 'table' and #t == 12 then
        return sim.matrixToPose(numbers(fname, what, t, 12, false)), true
    end
    return numbers(fname, what, t, 7, false), false
end

local function move_to_pose(...)
    local params = ...
    local legacy = type(params) == 'number'
    if legacy then
        local fname = 'moveToPose'
        local flags, current, maxVel, maxAccel, maxJerk, target, callback, auxData, metric, timeStep = ...
        flags = integer(fname, "argument 1 (flags)", flags)
        local pose, as_matrix = legacy_pose(fname, "argument 2 (currentPose)", current)
        local dim = metric ~= nil and 1 or 4
        params = {
            tolerantArgs = true,
            legacyFunc = true,
            pose = pose,
            useMatrices = as_matrix,
            maxVel = numbers(fname, "argument 3 (maxVel)", maxVel, dim, true, true),
            maxAccel = numbers(fname, "argument 4 (maxAccel)", maxAccel, dim, true, true),
            maxJerk = numbers(fname, "argument 5 (maxJerk)", maxJerk, dim, true, true),
            targetPose = (legacy_pose(fname, "argument 6 (targetPose)", target)),
            callback = check_callback(fname, "argument 7 (callback)", callback),
            auxData = auxData,
            metric = metric,
            timeStep = timeStep or 0,
        }
        if flags >= 0 and flags & MINVEL ~= 0 then
            params.minVel = numbers(fname, "argument 3 (maxVel, with minimum velocities)", {table.unpack(maxVel, dim + 1)}, dim)
            flags = flags - MINVEL
        end
        if flags >= 0 and flags & MINACCEL ~= 0 then
            params.minAccel = numbers(fname, "argument 4 (maxAccel, with minimum accelerations)", {table.unpack(maxAccel, dim + 1)}, dim)
            flags = flags - MINACCEL
        end
        params.flags = flags
    elseif type(params) ~= 'table' then
        fail('moveToPose', "argument 1: expected a table of parameters (or the flags of the 4.0-4.5 form), got %s", type(params))
    end
    local data = run('moveToPose', pose_init, pose_step, pose_cleanup, params)
    if legacy then
        return data.useMatrices and data.matrix or data.pose, data.timeLeft
    end
    return data
end

sim.moveToPose_init = public(pose_init)
sim.moveToPose_step = public(pose_step)
sim.moveToPose_cleanup = public(pose_cleanup)
sim.moveToPose = public(move_to_pose)

-- The error and thread helpers, for the other motion file (lua/path_motion.lua).
return {fail = fail, public = public, need_thread = need_thread}
