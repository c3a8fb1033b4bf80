-- V-REP 3's blocking motions of objects, for threaded scripts: sim.followPath (along a
-- path object) and sim.moveToPosition (straight to a position and/or orientation),
-- written on the path functions (Rust, api/paths.rs), the object pose functions and
-- sim.step.
--
-- How to load: as lua/motion.lua, run this chunk once with the shared `sim` table as its
-- only argument; it adds the two functions and returns nothing. The sim.* functions it
-- uses are looked up when called; the Lua builtins are captured when loaded.
--
-- Both move the object with a trapezoidal velocity profile: from rest, at `accel` up to
-- `velocity`, then down to rest at the end (`accel` nil or not positive: at `velocity`
-- from start to end). Each motion step places the object and is followed by one
-- sim.step(); the object is placed at its target in the last step. Both return the part
-- of that last step the motion did not need, s (V-REP's deltaTimeLeft; gantry does not
-- carry it over into the next blocking call).
local sim = ...
local type, error, pcall, setmetatable, getmetatable, tostring =
    type, error, pcall, setmetatable, getmetatable, tostring
local math, string, table, coroutine = math, string, table, coroutine

-- Errors of this file: raised as tables and turned into messages at the public entry
-- points, so the position reported is the calling script's line.
local PathMotionError = {}
local function fail(fname, fmt, ...)
    error(setmetatable({message = string.format(fmt, ...) .. " (in function 'sim." .. fname .. "')"}, PathMotionError), 0)
end

local function public(f)
    return function(...)
        local r = table.pack(pcall(f, ...))
        if r[1] then
            return table.unpack(r, 2, r.n)
        end
        local e = r[2]
        if getmetatable(e) == PathMotionError then
            error(e.message, 2)
        end
        error(e, 0)
    end
end

local function need_thread(fname)
    if not coroutine.isyieldable() then
        fail(fname, "sim.%s blocks, and blocking calls need a threaded script: call it from "
            .. "sysCall_thread or sysCall_threadmain (or a coroutine), not from a non-threaded hook "
            .. "such as sysCall_actuation", fname)
    end
end

local function integer(fname, what, x)
    local i = type(x) == 'number' and math.tointeger(x) or nil
    if i == nil then
        fail(fname, "%s: expected an integer, got %s", what, tostring(x))
    end
    return i
end

local function finite(fname, what, x)
    if type(x) ~= 'number' or x ~= x or x == math.huge or x == -math.huge then
        fail(fname, "%s: expected a finite number, got %s", what, tostring(x))
    end
    return x
end

local function vector3(fname, what, t)
    if type(t) ~= 'table' or #t < 3 then
        fail(fname, "%s: expected a table of 3 numbers, got %s", what, type(t) == 'table' and (#t .. ' values') or type(t))
    end
    return {finite(fname, what, t[1]), finite(fname, what, t[2]), finite(fname, what, t[3])}
end

-- A trapezoidal profile over `dist`: returns its duration and the distance covered at
-- time t. `accel` nil or not positive: constant velocity.
local function profile(fname, dist, velocity, accel)
    velocity = finite(fname, "argument 5 (velocity)", velocity)
    if not (velocity > 0) then
        fail(fname, "argument 5 (velocity): expected a positive number, got %s", tostring(velocity))
    end
    if accel ~= nil then accel = finite(fname, "argument 6 (accel)", accel) end
    if not (dist > 0) then
        return 0, function() return 0 end
    end
    if accel == nil or accel <= 0 then
        return dist / velocity, function(t) return math.min(dist, velocity * t) end
    end
    local ta = velocity / accel
    local da = 0.5 * accel * ta * ta
    if 2 * da >= dist then
        -- Never at full velocity: a triangle.
        ta = math.sqrt(dist / accel)
        da = 0.5 * dist
        velocity = accel * ta
    end
    local total = 2 * ta + (dist - 2 * da) / velocity
    return total, function(t)
        if t <= 0 then return 0 end
        if t < ta then return 0.5 * accel * t * t end
        if t < total - ta then return da + velocity * (t - ta) end
        if t < total then
            local r = total - t
            return dist - 0.5 * accel * r * r
        end
        return dist
    end
end

-- Runs a motion of duration `total`: place(s) at each step's end time, then sim.step(),
-- until the end; returns the time left in the last step.
local function run(total, covered, place)
    local dt = sim.getSimulationTimeStep()
    local t = 0
    local stepping = sim.setStepping ~= nil
    if stepping then sim.setStepping(true) end
    local ok, e = pcall(function()
        while true do
            t = t + dt
            local done = t >= total
            place(covered(done and total or t))
            sim.step()
            if done then break end
        end
    end)
    if stepping then sim.setStepping(false) end
    if not ok then error(e, 0) end
    return t - total
end

---------------------------------------------------------------------------------------
-- sim.followPath(objectHandle, pathHandle, positionAndOrOrientation, relativeDistanceOnPath,
-- velocity, accel) -> deltaTimeLeft: moves the object along the path from
-- relativeDistanceOnPath (0 the start, 1 the end) to the end of the path, at `velocity`
-- (m/s along the path). positionAndOrOrientation: 1 the position follows the path, 2 the
-- orientation, 3 (or nil) both; world frame.

local function follow_path(objectHandle, pathHandle, positionAndOrOrientation, relativeDistanceOnPath, velocity, accel)
    local fname = 'followPath'
    need_thread(fname)
    local obj = integer(fname, "argument 1 (objectHandle)", objectHandle)
    local path = integer(fname, "argument 2 (pathHandle)", pathHandle)
    local what = 3
    if positionAndOrOrientation ~= nil then
        what = integer(fname, "argument 3 (positionAndOrOrientation)", positionAndOrOrientation)
        if what < 1 or what > 3 then
            fail(fname, "argument 3 (positionAndOrOrientation): 1 (position), 2 (orientation) or 3 (both), got %d", what)
        end
    end
    local from = finite(fname, "argument 4 (relativeDistanceOnPath)", relativeDistanceOnPath or 0)
    from = math.max(0, math.min(1, from))
    local length = sim.getPathLength(path)
    local start = from * length
    local total, covered = profile(fname, length - start, velocity, accel)
    sim.getObjectPosition(obj, -1) -- the object exists before anything moves
    return run(total, covered, function(s)
        local rel = length > 0 and (start + s) / length or 1
        if what & 1 ~= 0 then
            sim.setObjectPosition(obj, -1, sim.getPositionOnPath(path, rel))
        end
        if what & 2 ~= 0 then
            sim.setObjectOrientation(obj, -1, sim.getOrientationOnPath(path, rel))
        end
    end)
end

sim.followPath = public(follow_path)

---------------------------------------------------------------------------------------
-- sim.moveToPosition(objectHandle, relativeToObjectHandle, position, orientation, velocity,
-- accel, distCalcMethod) -> deltaTimeLeft: moves the object in a straight line (position
-- interpolated linearly, orientation about one axis) to `position` and `orientation`
-- (Euler angles), both in the frame of relativeToObjectHandle; either may be nil to keep
-- it. The distance the velocity applies to is V-REP's distCalcMethod of the linear
-- distance dl (m) and the angle dac (rad): 0 dl, 1 dac, 2 max(dl, dac), 3 dl + dac,
-- 4 sqrt(dl^2 + dac^2), 5 (nil) dl unless it is 0 then dac, 6 dac unless it is 0 then dl.

local NEGLIGIBLE = 1e-9

local function move_to_position(objectHandle, relativeToObjectHandle, position, orientation, velocity, accel, distCalcMethod)
    local fname = 'moveToPosition'
    need_thread(fname)
    local obj = integer(fname, "argument 1 (objectHandle)", objectHandle)
    local rel = integer(fname, "argument 2 (relativeToObjectHandle)", relativeToObjectHandle or -1)
    local method = integer(fname, "argument 7 (distCalcMethod)", distCalcMethod or 5)
    if method < 0 or method > 6 then
        fail(fname, "argument 7 (distCalcMethod): expected 0 to 6 (sim.distcalcmethod_*), got %d", method)
    end
    local p0 = sim.getObjectPosition(obj, rel)
    local e0 = sim.getObjectOrientation(obj, rel)
    local p1 = position ~= nil and vector3(fname, "argument 3 (position)", position) or p0
    local e1 = orientation ~= nil and vector3(fname, "argument 4 (orientation)", orientation) or e0
    local m0, m1 = sim.buildMatrix(p0, e0), sim.buildMatrix(p1, e1)
    local dl = math.sqrt((p1[1] - p0[1]) ^ 2 + (p1[2] - p0[2]) ^ 2 + (p1[3] - p0[3]) ^ 2)
    local _, dac = sim.getRotationAxis(m0, m1)
    dac = math.abs(dac)
    local dist
    if method == 0 then dist = dl
    elseif method == 1 then dist = dac
    elseif method == 2 then dist = math.max(dl, dac)
    elseif method == 3 then dist = dl + dac
    elseif method == 4 then dist = math.sqrt(dl * dl + dac * dac)
    elseif method == 5 then dist = dl > NEGLIGIBLE and dl or dac
    else dist = dac > NEGLIGIBLE and dac or dl
    end
    local total, covered = profile(fname, dist, velocity, accel)
    return run(total, covered, function(s)
        local f = dist > NEGLIGIBLE and s / dist or 1
        sim.setObjectMatrix(obj, rel, sim.interpolateMatrices(m0, m1, f))
    end)
end

sim.moveToPosition = public(move_to_position)
