-- V-REP 3's blocking motions of objects, for threaded scripts: sim.followPath (along a
-- path object) and sim.moveToPosition (straight to a position and/or orientation),
-- written on the path functions (Rust, api/paths.rs), the object pose functions and
-- sim.step.
--
-- How to load: as lua/motion.lua, run this chunk once with the shared `sim` table and
-- the helpers lua/motion.lua returns (errors, public entry points, the thread check);
-- it adds the two functions and returns nothing. The sim.* functions it
-- uses are looked up when called; the Lua builtins are captured when loaded.
--
-- Each motion step places the object and is followed by one sim.step(); the object is
-- placed at its target in the last step. Both return the part of that last step the
-- motion did not need, s (V-REP's deltaTimeLeft; gantry does not carry it over into the
-- next blocking call).
local sim, helpers = ...
local type, error, pcall, tostring, math = type, error, pcall, tostring, math

local fail, public, need_thread = helpers.fail, helpers.public, helpers.need_thread

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

-- The speed and acceleration limits (arguments 5 and 6 of both functions): `velocity`
-- must not be 0; `accel` nil or 0 means infinite (V-REP takes its absolute value).
local function limits(fname, velocity, accel)
    velocity = finite(fname, "argument 5 (velocity)", velocity)
    if velocity == 0 then
        fail(fname, "argument 5 (velocity): expected a non-zero number")
    end
    if accel ~= nil then accel = math.abs(finite(fname, "argument 6 (accel)", accel)) end
    if accel == 0 then accel = nil end
    return velocity, accel
end

-- A motion over `dist` (> 0) from rest at speed `v` (> 0) under acceleration `a` (nil:
-- infinite): returns its duration and the distance covered at time t. With `stop`, it
-- slows down at `a` to end at rest (a trapezoid, sim.moveToPosition); without, it
-- reaches the end at speed (sim.followPath, V-REP's path handling).
local function profile(dist, v, a, stop)
    if a == nil then
        return dist / v, function(t) return math.min(dist, v * t) end
    end
    local ta = v / a
    local da = 0.5 * a * ta * ta
    local ramps = stop and 2 or 1
    if ramps * da >= dist then
        -- Never at full speed.
        ta = math.sqrt(dist / ramps * 2 / a)
        da = dist / ramps
        v = a * ta
    end
    local total = ramps * ta + (dist - ramps * da) / v
    return total, function(t)
        if t <= 0 then return 0 end
        if t < ta then return 0.5 * a * t * t end
        if not stop or t < total - ta then return math.min(dist, da + v * (t - ta)) end
        if t < total then
            local r = total - t
            return dist - 0.5 * a * r * r
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
-- relativeDistanceOnPath (0 the start, 1 the end) to the end of the path at `velocity`
-- (m/s along the path; negative: back to the start), reached from rest at `accel` (nil
-- or 0: at once); the end is reached at speed, as V-REP's path handling does.
-- positionAndOrOrientation: bit 0 the position follows the path, bit 1 the orientation
-- (nil: both; 0: the position); world frame.

local function follow_path(objectHandle, pathHandle, positionAndOrOrientation, relativeDistanceOnPath, velocity, accel)
    local fname = 'followPath'
    need_thread(fname)
    local obj = integer(fname, "argument 1 (objectHandle)", objectHandle)
    local path = integer(fname, "argument 2 (pathHandle)", pathHandle)
    local what = 3
    if positionAndOrOrientation ~= nil then
        what = math.abs(integer(fname, "argument 3 (positionAndOrOrientation)", positionAndOrOrientation)) & 3
        if what == 0 then what = 1 end
    end
    local from = finite(fname, "argument 4 (relativeDistanceOnPath)", relativeDistanceOnPath or 0)
    from = math.max(0, math.min(1, from))
    local v, a = limits(fname, velocity, accel)
    local length = sim.getPathLength(path)
    local start = from * length
    local dist = v > 0 and length - start or start
    local dir = v > 0 and 1 or -1
    sim.getObjectPosition(obj, -1) -- the object exists before anything moves
    local function place(s)
        local rel = length > 0 and (start + dir * s) / length or 1
        if what & 1 ~= 0 then
            sim.setObjectPosition(obj, -1, sim.getPositionOnPath(path, rel))
        end
        if what & 2 ~= 0 then
            sim.setObjectOrientation(obj, -1, sim.getOrientationOnPath(path, rel))
        end
    end
    if not (dist > 0) then
        return sim.getSimulationTimeStep()
    end
    local total, covered = profile(dist, math.abs(v), a, false)
    return run(total, covered, place)
end

sim.followPath = public(follow_path)

---------------------------------------------------------------------------------------
-- sim.moveToPosition(objectHandle, relativeToObjectHandle, position, orientation, velocity,
-- accel, distCalcMethod) -> deltaTimeLeft: moves the object in a straight line (position
-- interpolated linearly, orientation about one axis) to `position` and `orientation`
-- (Euler angles), both in the frame of relativeToObjectHandle (-1 the world,
-- sim.handle_parent the parent's); either may be nil to keep it, not both. It starts
-- from rest, accelerates at `accel` (nil or 0: at once) to `velocity` and slows down to
-- stop at the target. The distance the velocity applies to comes from the linear
-- distance dl (m) and the angle times a coefficient dac, as V-REP's distCalcMethod
-- `{method, angleToLinearCoeff}` (or the method alone) says: 0 dl, 1 dac, 2 max(dl, dac),
-- 3 dl + dac, 4 sqrt(dl^2 + dac^2), 5 (default) dl unless it is below 0.05 mm then dac,
-- 6 dac unless below 0.01 degree then dl; the coefficient defaults to 0.1 per 90 degrees.

local function move_to_position(objectHandle, relativeToObjectHandle, position, orientation, velocity, accel, distCalcMethod)
    local fname = 'moveToPosition'
    need_thread(fname)
    local obj = integer(fname, "argument 1 (objectHandle)", objectHandle)
    local rel = integer(fname, "argument 2 (relativeToObjectHandle)", relativeToObjectHandle or -1)
    if rel == sim.handle_parent then
        rel = sim.getObjectParent(obj)
    end
    if position == nil and orientation == nil then
        fail(fname, "arguments 3 and 4: a position, an orientation or both are needed")
    end
    local method, coeff = 5, 0.1 / (math.pi / 2)
    if type(distCalcMethod) == 'table' then
        method = integer(fname, "argument 7 (distCalcMethod)", distCalcMethod[1])
        if distCalcMethod[2] ~= nil then coeff = finite(fname, "argument 7 (distCalcMethod)", distCalcMethod[2]) end
    elseif distCalcMethod ~= nil then
        method = integer(fname, "argument 7 (distCalcMethod)", distCalcMethod)
    end
    if method < 0 or method > 6 then
        fail(fname, "argument 7 (distCalcMethod): expected 0 to 6 (sim.distcalcmethod_*), got %d", method)
    end
    local v, a = limits(fname, velocity, accel)
    local p0 = sim.getObjectPosition(obj, rel)
    local e0 = sim.getObjectOrientation(obj, rel)
    local p1 = position ~= nil and vector3(fname, "argument 3 (position)", position) or p0
    local e1 = orientation ~= nil and vector3(fname, "argument 4 (orientation)", orientation) or e0
    local m0, m1 = sim.buildMatrix(p0, e0), sim.buildMatrix(p1, e1)
    local dl = math.sqrt((p1[1] - p0[1]) ^ 2 + (p1[2] - p0[2]) ^ 2 + (p1[3] - p0[3]) ^ 2)
    local _, angle = sim.getRotationAxis(m0, m1)
    local dac = math.abs(angle) * coeff
    local dist
    if method == 0 then dist = dl
    elseif method == 1 then dist = dac
    elseif method == 2 then dist = math.max(dl, dac)
    elseif method == 3 then dist = dl + dac
    elseif method == 4 then dist = math.sqrt(dl * dl + dac * dac)
    elseif method == 5 then dist = dl >= 0.00005 and dl or dac
    else dist = math.abs(angle) >= 0.01 * math.pi / 180 and dac or dl
    end
    local function place(s)
        sim.setObjectMatrix(obj, rel, sim.interpolateMatrices(m0, m1, dist > 0 and s / dist or 1))
    end
    if not (dist > 0) then
        -- Nothing to travel by this method: the object goes to the target at once.
        place(0)
        return sim.getSimulationTimeStep()
    end
    local total, covered = profile(dist, math.abs(v), a, true)
    return run(total, covered, place)
end

sim.moveToPosition = public(move_to_position)
