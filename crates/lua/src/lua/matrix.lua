-- gantry's `matrix` module: CoppeliaSim's Matrix and Vector classes, the part of them
-- that scripts use. Loaded once into the shared globals (before the scripts' environments
-- are copied); `require 'matrix'` returns `Matrix`.
--
-- * `Matrix(rows, cols [, data])`: `data` row-major, flat or as rows; zeros without it.
--   `Matrix{{1, 2}, {3, 4}}` takes the rows. `Matrix:eye(n)`, `Matrix:zeros(r, c)`.
-- * `Vector(n [, data])`, `Vector{x, y, ...}`: a column (n x 1). `Vector3`, `Vector4`
--   and `Vector7` check the length; `Matrix3x3` and `Matrix4x4` the shape.
-- * `m[i]`: element i of a vector, row i (a 1 x cols matrix) of a matrix; `v[i] = x`.
-- * `+`, `-` (same shape), `*` (matrix product, or by a number on either side), `/` by a
--   number, unary `-`, `==`, `#` (elements of a vector, rows of a matrix), `tostring`.
-- * `:rows()`, `:cols()`, `:get(i, j)`, `:set(i, j, x)`, `:t()`, `:copy()`, `:data()`
--   (a flat row-major copy), `:row(i)`, `:col(j)`, `:dot(v)`, `:cross(v)` (3-vectors),
--   `:norm()`, `:normalized()`, `:sum()`, `:abs()`.
--
-- Errors name the operation and the shapes, raised from the caller's line.
local setmetatable, getmetatable, rawget, type, error, tostring, math, string, table =
    setmetatable, getmetatable, rawget, type, error, tostring, math, string, table

-- The instances' metatable and the classes' are shared by every script (each script's
-- copy of `Matrix` keeps the metatable): `__metatable` hides them, so that no script
-- can change how another's matrices behave.
local PROTECTED = 'Matrix'
local methods = {}
local mt = {__metatable = PROTECTED}

local function is_matrix(x)
    return type(x) == 'table' and getmetatable(x) == PROTECTED and rawget(x, '_data') ~= nil
end

local function new(rows, cols, data)
    return setmetatable({_rows = rows, _cols = cols, _data = data}, mt)
end

local function zeros(rows, cols)
    local d = {}
    for i = 1, rows * cols do d[i] = 0 end
    return new(rows, cols, d)
end

local function check_dim(n, what)
    if type(n) ~= 'number' or n < 1 or n % 1 ~= 0 then
        error(what .. ' must be a positive integer, got ' .. tostring(n), 3)
    end
end

-- Matrix(rows, cols [, data]) or Matrix(tableOfRows).
local function construct(rows, cols, data)
    if type(rows) == 'table' then
        local r, c, d = #rows, nil, {}
        for i = 1, r do
            local row = rows[i]
            if type(row) ~= 'table' then error('Matrix{...}: row ' .. i .. ' is not a table', 3) end
            c = c or #row
            if #row ~= c then error('Matrix{...}: rows of different lengths', 3) end
            for j = 1, c do d[#d + 1] = row[j] end
        end
        if r == 0 or not c or c == 0 then error('Matrix{...}: no elements', 3) end
        return new(r, c, d)
    end
    check_dim(rows, 'Matrix: rows')
    check_dim(cols, 'Matrix: cols')
    if data == nil then return zeros(rows, cols) end
    if type(data) ~= 'table' then error('Matrix: data must be a table, got ' .. type(data), 3) end
    local d = {}
    if type(data[1]) == 'table' then
        for i = 1, rows do
            for j = 1, cols do d[#d + 1] = data[i] and data[i][j] end
        end
    else
        for i = 1, rows * cols do d[i] = data[i] end
    end
    for i = 1, rows * cols do
        if type(d[i]) ~= 'number' then
            error(string.format('Matrix: %d x %d needs %d numbers', rows, cols, rows * cols), 3)
        end
    end
    return new(rows, cols, d)
end

local function vector(n, data)
    if type(n) == 'table' then return construct(#n, 1, n) end
    return construct(n, 1, data)
end

local function shape(m)
    return m._rows .. ' x ' .. m._cols
end

local function same_shape(a, b, op)
    if not (is_matrix(a) and is_matrix(b)) or a._rows ~= b._rows or a._cols ~= b._cols then
        error(op .. ': operands must be matrices of the same shape'
            .. (is_matrix(a) and is_matrix(b) and (' (' .. shape(a) .. ' and ' .. shape(b) .. ')') or ''), 3)
    end
end

local function map(m, f)
    local d = {}
    for i = 1, #m._data do d[i] = f(m._data[i], i) end
    return new(m._rows, m._cols, d)
end

mt.__index = function(m, k)
    if type(k) == 'number' then
        if m._cols == 1 or m._rows == 1 then return m._data[k] end
        return methods.row(m, k)
    end
    return methods[k]
end

mt.__newindex = function(m, k, v)
    if type(k) == 'number' and (m._cols == 1 or m._rows == 1) and k >= 1 and k <= #m._data then
        m._data[k] = v
    else
        error('only the elements of a vector can be assigned by index', 2)
    end
end

mt.__len = function(m)
    if m._cols == 1 or m._rows == 1 then return #m._data end
    return m._rows
end

mt.__add = function(a, b)
    same_shape(a, b, '+')
    return map(a, function(x, i) return x + b._data[i] end)
end

mt.__sub = function(a, b)
    same_shape(a, b, '-')
    return map(a, function(x, i) return x - b._data[i] end)
end

mt.__unm = function(a)
    return map(a, function(x) return -x end)
end

mt.__mul = function(a, b)
    if type(a) == 'number' then return map(b, function(x) return a * x end) end
    if type(b) == 'number' then return map(a, function(x) return x * b end) end
    if not (is_matrix(a) and is_matrix(b)) then error('*: operands must be matrices or numbers', 2) end
    if a._cols ~= b._rows then
        error('*: ' .. shape(a) .. ' times ' .. shape(b) .. ': the inner sizes differ', 2)
    end
    local r = zeros(a._rows, b._cols)
    for i = 1, a._rows do
        for j = 1, b._cols do
            local s = 0
            for k = 1, a._cols do
                s = s + a._data[(i - 1) * a._cols + k] * b._data[(k - 1) * b._cols + j]
            end
            r._data[(i - 1) * b._cols + j] = s
        end
    end
    return r
end

mt.__div = function(a, b)
    if not (is_matrix(a) and type(b) == 'number') then error('/: a matrix divides by a number only', 2) end
    return map(a, function(x) return x / b end)
end

mt.__eq = function(a, b)
    if a._rows ~= b._rows or a._cols ~= b._cols then return false end
    for i = 1, #a._data do
        if a._data[i] ~= b._data[i] then return false end
    end
    return true
end

mt.__tostring = function(m)
    local rows = {}
    for i = 1, m._rows do
        local r = {}
        for j = 1, m._cols do r[j] = tostring(m._data[(i - 1) * m._cols + j]) end
        rows[i] = '[' .. table.concat(r, ', ') .. ']'
    end
    return 'Matrix(' .. m._rows .. ', ' .. m._cols .. ', {' .. table.concat(rows, ', ') .. '})'
end

function methods.rows(m) return m._rows end
function methods.cols(m) return m._cols end

function methods.get(m, i, j)
    return m._data[(i - 1) * m._cols + j]
end

function methods.set(m, i, j, v)
    if i < 1 or i > m._rows or j < 1 or j > m._cols then
        error(string.format('set: (%s, %s) is outside %s', tostring(i), tostring(j), shape(m)), 2)
    end
    m._data[(i - 1) * m._cols + j] = v
end

function methods.t(m)
    local r = zeros(m._cols, m._rows)
    for i = 1, m._rows do
        for j = 1, m._cols do
            r._data[(j - 1) * m._rows + i] = m._data[(i - 1) * m._cols + j]
        end
    end
    return r
end

function methods.copy(m) return map(m, function(x) return x end) end

function methods.data(m)
    local d = {}
    for i = 1, #m._data do d[i] = m._data[i] end
    return d
end

function methods.row(m, i)
    if i < 1 or i > m._rows then error('row: ' .. tostring(i) .. ' is outside ' .. shape(m), 2) end
    local d = {}
    for j = 1, m._cols do d[j] = m._data[(i - 1) * m._cols + j] end
    return new(1, m._cols, d)
end

function methods.col(m, j)
    if j < 1 or j > m._cols then error('col: ' .. tostring(j) .. ' is outside ' .. shape(m), 2) end
    local d = {}
    for i = 1, m._rows do d[i] = m._data[(i - 1) * m._cols + j] end
    return new(m._rows, 1, d)
end

function methods.sum(m)
    local s = 0
    for i = 1, #m._data do s = s + m._data[i] end
    return s
end

function methods.abs(m) return map(m, function(x) return math.abs(x) end) end

function methods.dot(a, b)
    if not is_matrix(b) or #a._data ~= #b._data then error('dot: operands must have as many elements', 2) end
    local s = 0
    for i = 1, #a._data do s = s + a._data[i] * b._data[i] end
    return s
end

function methods.cross(a, b)
    if not is_matrix(b) or #a._data ~= 3 or #b._data ~= 3 then error('cross: operands must be 3-vectors', 2) end
    local x, y = a._data, b._data
    return new(3, 1, {x[2] * y[3] - x[3] * y[2], x[3] * y[1] - x[1] * y[3], x[1] * y[2] - x[2] * y[1]})
end

function methods.norm(m) return math.sqrt(methods.dot(m, m)) end

function methods.normalized(m)
    local n = methods.norm(m)
    if n == 0 then error('normalized: the zero vector has no direction', 2) end
    return m / n
end

local Matrix = setmetatable({}, {__metatable = PROTECTED, __call = function(_, ...) return construct(...) end})
-- `Matrix:eye(n)` (as CoppeliaSim writes it) or `Matrix.eye(n)`. The table a script
-- calls it on is its own copy of `Matrix`, so any table counts as the receiver.
function Matrix.eye(a, b)
    local n = (type(a) == 'table') and b or a
    check_dim(n, 'eye: n')
    local m = zeros(n, n)
    for i = 1, n do m._data[(i - 1) * n + i] = 1 end
    return m
end
function Matrix.zeros(a, b, c)
    if type(a) == 'table' then a, b = b, c end
    check_dim(a, 'zeros: rows')
    check_dim(b, 'zeros: cols')
    return zeros(a, b)
end

local function sized(rows, cols, name)
    return setmetatable({}, {__metatable = PROTECTED, __call = function(_, ...)
        local m
        if cols == 1 then m = vector(...) else m = construct(...) end
        if m._rows ~= rows or m._cols ~= cols then
            error(name .. ': expected ' .. rows .. ' x ' .. cols .. ', got ' .. shape(m), 2)
        end
        return m
    end})
end

Vector = setmetatable({}, {__metatable = PROTECTED, __call = function(_, ...) return vector(...) end})
Vector3 = sized(3, 1, 'Vector3')
Vector4 = sized(4, 1, 'Vector4')
Vector7 = sized(7, 1, 'Vector7')
Matrix3x3 = setmetatable({}, {__metatable = PROTECTED, __call = function(_, data)
    return construct(3, 3, data)
end})
Matrix4x4 = setmetatable({}, {__metatable = PROTECTED, __call = function(_, data)
    return construct(4, 4, data)
end})
_G.Matrix = Matrix
return Matrix
