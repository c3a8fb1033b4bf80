-- Blocking calls for threaded scripts (see threads.rs).
--
-- A threaded script runs as a coroutine that the simulation thread resumes once per
-- step, at the start of actuation. Every blocking call is a yield: `sim.step` yields
-- once, `sim.wait` and `sim.waitForSignal` yield until their condition holds. The same
-- calls inside a coroutine of the script's own (the CoppeliaSim 4.0-4.5 pattern: a
-- coroutine created in sysCall_init and resumed from sysCall_actuation) yield to that
-- script's `coroutine.resume`, which is what CoppeliaSim does too.
--
-- Loaded once into the shared globals before the scripts' environments are copied,
-- with the functions it needs passed in, so that a script replacing `sim.getSimulationTime`
-- in its own copy cannot change how `sim.wait` measures time.
local sim, host, coroutine, error, type, string, ipairs = ...
local yield, isyieldable = coroutine.yield, coroutine.isyieldable
local getTime, getSystemTime = sim.getSimulationTime, sim.getSystemTime
local getInt, getFloat, getString = sim.getInt32Signal, sim.getFloatSignal, sim.getStringSignal
local tubeRead = sim.tubeRead

-- Raises the error CoppeliaSim users need when a blocking call is made where nothing
-- can be suspended: the non-threaded hooks must return for the simulation to advance.
-- `level` 3 points at the script line that called the API function.
local function need_thread(name)
    if not isyieldable() then
        error(string.format("sim.%s blocks, and blocking calls need a threaded script: call it "
            .. "from sysCall_thread (or a coroutine), not from a non-threaded hook such as "
            .. "sysCall_actuation, which must return for the simulation to advance "
            .. "(in function 'sim.%s')", name, name), 3)
    end
end

local function number_arg(value, index, name)
    if type(value) ~= 'number' then
        error(string.format("argument %d: expected number, got %s (in function 'sim.%s')",
            index, value == nil and 'no value' or type(value), name), 3)
    end
end

function sim.step()
    need_thread('step')
    yield()
end

-- CoppeliaSim 4.0-4.5 name of sim.step.
function sim.switchThread()
    need_thread('switchThread')
    yield()
end

-- Scripts see the step's start time for the whole step, so a wait of dt in simulation
-- time ends at the first step that starts at least dt after the call: after
-- n = ceil(dt / step) steps, fixed when the call starts. It returns what CoppeliaSim
-- documents, the time left, which is minus the overshoot: dt - n * step (<= 0).
--
-- Both are computed from step counts, never from differences of simulation times: the
-- time of step k is k * step in floating point, so (t0 + dt) - t1 rounds differently at
-- each start time (0.5 s at 0.05 s steps returned 0, -1.1e-16 or +4.4e-16 depending on
-- the step it began at, and +8.9e-16 in a test asserting <= 0). The step index is read
-- back from the time by rounding, which is exact: times are k * step, far from the
-- half-way points. WAIT_SLACK, in steps, absorbs the rounding in dt / step (0.07 / 0.01
-- is 7.000000000000001): a wait within a millionth of a step of n steps takes n steps,
-- and is on time.
local WAIT_SLACK = 1e-6
local floor, ceil = math.floor, math.ceil
local getStep = sim.getSimulationTimeStep

function sim.wait(dt, simTime)
    number_arg(dt, 1, 'wait')
    need_thread('wait')
    if simTime == false then
        -- Wall-clock time has no steps to count; it is not reproducible anyway.
        local t0 = getSystemTime()
        while getSystemTime() - t0 < dt do
            yield()
        end
        return (t0 + dt) - getSystemTime()
    end
    local step = getStep()
    local function index() return floor(getTime() / step + 0.5) end
    local n = ceil(dt / step - WAIT_SLACK)
    if not (n > 0) then n = 0 end -- dt <= 0 (or NaN): nothing to wait for
    local last = index() + n
    while index() < last do
        yield()
    end
    local left = dt - n * step
    -- The rounding residue of a wait of a whole number of steps is no overshoot.
    if left > -WAIT_SLACK * step then left = 0.0 end
    return left
end

-- Waits until a signal of any type exists and returns its value. Accepts the signal
-- name alone (4.0-4.5) or after a target handle (4.6+, the target is the scene here).
function sim.waitForSignal(a, b)
    local name = b
    if type(a) == 'string' then name = a end
    if type(name) ~= 'string' then
        error("argument 1: expected string (the signal name) (in function 'sim.waitForSignal')", 2)
    end
    need_thread('waitForSignal')
    while true do
        local v = getInt(name)
        if v == nil then v = getFloat(name) end
        if v == nil then v = getString(name) end
        if v ~= nil then return v end
        yield()
    end
end

-- V-REP's blocking tube read: a packet, waiting for one a step at a time; the
-- non-blocking form (the default) is the core's.
function sim.tubeRead(handle, blocking)
    local data = tubeRead(handle)
    if data ~= nil or not blocking then return data end
    need_thread('tubeRead')
    while data == nil do
        yield()
        data = tubeRead(handle)
    end
    return data
end

-- The mode setters (Rust, threads.rs) return ok, value; a failure is raised here, from
-- the script's line, as a string like every API error.
local function raising(f)
    return function(...)
        local ok, value = f(...)
        if not ok then error(value, 2) end
        return value
    end
end

for _, name in ipairs({'setStepping', 'getStepping', 'setThreadAutomaticSwitch',
        'getThreadAutomaticSwitch', 'setAutoYieldDelay', 'getAutoYieldDelay',
        'setThreadSwitchTiming', 'setThreadIsFree', 'acquireLock', 'releaseLock'}) do
    sim[name] = raising(host[name])
end
sim.isScriptRunningInThread = host.isScriptRunningInThread
