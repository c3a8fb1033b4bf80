-- table.tostring(value): a readable one-line rendering of a value, tables included, as
-- CoppeliaSim's Lua helpers provide it (its ROS 2 plugin examples log each message with
-- it). Keys are sorted so the text is the same every run; the array part comes first
-- without keys; a table met again inside itself shows as <cycle>; nesting beyond 16
-- levels shows as {...}.
local type, tostring, pairs, ipairs, sort, concat, format, floor = ...

local function before(a, b)
    local ta, tb = type(a), type(b)
    if ta ~= tb then return ta < tb end
    if ta == 'number' or ta == 'string' then return a < b end
    return tostring(a) < tostring(b)
end

local function render(v, depth, seen)
    local t = type(v)
    if t == 'string' then return format('%q', v) end
    if t ~= 'table' then return tostring(v) end
    if seen[v] then return '<cycle>' end
    if depth > 16 then return '{...}' end
    seen[v] = true
    local n = #v
    local parts = {}
    for i = 1, n do parts[i] = render(v[i], depth + 1, seen) end
    local keys = {}
    for k in pairs(v) do
        if not (type(k) == 'number' and k >= 1 and k <= n and floor(k) == k) then
            keys[#keys + 1] = k
        end
    end
    sort(keys, before)
    for _, k in ipairs(keys) do
        local key
        if type(k) == 'string' and k:match('^[%a_][%w_]*$') then
            key = k
        else
            key = '[' .. render(k, depth + 1, seen) .. ']'
        end
        parts[#parts + 1] = key .. '=' .. render(v[k], depth + 1, seen)
    end
    seen[v] = nil
    return '{' .. concat(parts, ', ') .. '}'
end

function table.tostring(value)
    return render(value, 1, {})
end
