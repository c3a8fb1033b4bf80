-- The debugger's view into paused scripts (gantry run --debug). Host-only: this chunk
-- receives Lua's real `debug` library, which no script ever sees, and returns the
-- functions the Rust side (debugger/inspect.rs) calls while a script is stopped.
--
-- Frames are counted over *script* frames only (functions whose chunk is a scene
-- script): the host's own Lua (the API wrappers, threads.lua) and C functions are
-- skipped, so frame 1 is always the script line the user stopped on. Levels are found
-- afresh on every call, because they depend on who is asking: on the paused thread
-- itself (a breakpoint) this code's own frames sit on top of the script's; from the
-- coroutine an expression is evaluated in, the paused thread is another thread.
--
-- It runs with the host's globals; `load` (gone from the globals, see sandbox.rs) and
-- the real `debug` come as arguments, with `scripts`, the set of script chunk names.
local debug, load, scripts = ...

-- Absolute levels of the script frames of `co`, as seen by the caller of `levels`.
local function levels(co)
    local start, adjust = 0, 0
    if co == coroutine.running() then
        -- 0 is getinfo, 1 this function, 2 its caller (seen there as 1).
        start, adjust = 2, -1
    end
    local out, level = {}, start
    while true do
        local info = debug.getinfo(co, level, 'S')
        if not info then break end
        if scripts[info.source] then out[#out + 1] = level + adjust end
        level = level + 1
    end
    return out
end

local M = {}

-- The script frames of `co`, top first: {source, line, name} each.
function M.frames(co)
    local out = {}
    for i, level in ipairs(levels(co)) do
        -- `levels` answered for this function; getinfo below is one call deeper than
        -- this function on the running thread, as `levels` assumed.
        local info = debug.getinfo(co, level, 'Sln')
        out[i] = { source = info.source, line = info.currentline, name = info.name }
    end
    return out
end

-- Name/value pairs of frame `k`'s locals (temporaries such as '(for state)' left out).
-- A name declared twice (shadowing) appears once, with the innermost value.
function M.locals(co, k)
    local level = levels(co)[k]
    if not level then return {} end
    local names, values, index = {}, {}, {}
    local i = 1
    while true do
        local name, value = debug.getlocal(co, level, i)
        if name == nil then break end
        if string.sub(name, 1, 1) ~= '(' then
            if index[name] then
                values[index[name]] = value
            else
                names[#names + 1] = name
                values[#names] = value
                index[name] = #names
            end
        end
        i = i + 1
    end
    return names, values
end

-- Name/value pairs of the upvalues of frame `k`'s function (`_ENV` left out: it is the
-- script's globals, shown as their own scope).
function M.upvalues(co, k)
    local level = levels(co)[k]
    if not level then return {} end
    local f = debug.getinfo(co, level, 'f').func
    local names, values, i = {}, {}, 1
    while true do
        local name, value = debug.getupvalue(f, i)
        if name == nil then break end
        if name ~= '_ENV' then
            names[#names + 1] = name
            values[#names] = value
        end
        i = i + 1
    end
    return names, values
end

-- Sets local `name` of frame `k` (the innermost of that name); false if there is none.
function M.setlocal(co, k, name, value)
    local level = levels(co)[k]
    if not level then return false end
    local found, i = nil, 1
    while true do
        local n = debug.getlocal(co, level, i)
        if n == nil then break end
        if n == name then found = i end
        i = i + 1
    end
    if not found then return false end
    debug.setlocal(co, level, found, value)
    return true
end

-- Sets upvalue `name` of frame `k`'s function; false if there is none.
function M.setupvalue(co, k, name, value)
    local level = levels(co)[k]
    if not level then return false end
    local f = debug.getinfo(co, level, 'f').func
    local i = 1
    while true do
        local n = debug.getupvalue(f, i)
        if n == nil then return false end
        if n == name then
            debug.setupvalue(f, i, value)
            return true
        end
        i = i + 1
    end
end

-- An environment that reads and writes frame `k`'s locals, then its upvalues, then the
-- script's globals `env`: what an expression typed in the editor sees. Everything else
-- (the sandbox's limits included) is the script's own environment.
local function frame_env(co, k, env)
    local function find(name)
        local level = levels(co)[k]
        if not level then return nil end
        local found, value, i = false, nil, 1
        while true do
            local n, v = debug.getlocal(co, level, i)
            if n == nil then break end
            if n == name then found, value = true, v end
            i = i + 1
        end
        if found then return true, value end
        local f = debug.getinfo(co, level, 'f').func
        i = 1
        while true do
            local n, v = debug.getupvalue(f, i)
            if n == nil then break end
            if n == name and n ~= '_ENV' then return true, v end
            i = i + 1
        end
        return false
    end
    return setmetatable({}, {
        __index = function(_, name)
            local found, value = find(name)
            if found then return value end
            return env[name]
        end,
        __newindex = function(_, name, value)
            if not (M.setlocal(co, k, name, value) or M.setupvalue(co, k, name, value)) then
                env[name] = value
            end
        end,
    })
end

-- Compiles `code` for frame `k` of `co` (no frame: the script's globals only): as an
-- expression first (`return code`), then as statements. Returns the function or nil
-- and the compile error.
function M.compile(co, k, env, code)
    local scope = env
    if co ~= nil and k ~= nil then scope = frame_env(co, k, env) end
    local f = load('return ' .. code, '=(evaluate)', 't', scope)
    if f then return f end
    local g, err = load(code, '=(evaluate)', 't', scope)
    if g then return g end
    return nil, err
end

-- Runs `f` in a fresh coroutine, so that the time-budget hook (which Lua does not call
-- inside the hook that stopped the script) applies to it. Returns true and the
-- results, or false and the error.
function M.run(f)
    local co = coroutine.create(f)
    local result = table.pack(coroutine.resume(co))
    if result[1] and coroutine.status(co) ~= 'dead' then
        return false, 'the expression tried to wait (sim.step, sim.wait ...), which it cannot do in the debugger'
    end
    return table.unpack(result, 1, result.n)
end

-- What the editor shows for a value: text and Lua type.
function M.describe(v)
    local t = type(v)
    if t == 'string' then return string.format('%q', v), t end
    if t == 'table' then
        local n = 0
        for _ in next, v do
            n = n + 1
            if n >= 1000 then break end
        end
        local len = rawlen(v)
        if len > 0 and len == n then return 'table [' .. len .. ']', t end
        return 'table {' .. (n >= 1000 and '1000+' or n) .. ' entries}', t
    end
    return tostring(v), t
end

-- The entries of table `t` for the editor, at most `limit`: array part in order, then
-- the other keys sorted by their text. Keys come back as display names.
function M.entries(t, limit)
    local names, values, keys = {}, {}, {}
    local len = #t
    for i = 1, math.min(len, limit) do
        names[#names + 1] = '[' .. i .. ']'
        values[#names] = rawget(t, i)
        keys[#names] = i
    end
    local rest = {}
    for key in next, t do
        if not (math.type(key) == 'integer' and key >= 1 and key <= len) then
            rest[#rest + 1] = key
            if #rest + #names >= limit then break end
        end
    end
    table.sort(rest, function(a, b) return tostring(a) < tostring(b) end)
    for _, key in ipairs(rest) do
        if type(key) == 'string' then names[#names + 1] = key
        else names[#names + 1] = '[' .. tostring(key) .. ']' end
        values[#names] = rawget(t, key)
        keys[#names] = key
    end
    return names, values, keys
end

return M
