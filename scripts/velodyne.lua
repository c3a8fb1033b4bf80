-- A Velodyne-style 3-D laser scanner (assets/scenes/scanners.toml): four depth sensors
-- 90 degrees apart, whose filters (velodyne_sensor.lua) turn their depth maps into 16
-- beams per azimuth, 1,800 azimuths around. Once the sensors were handled in a step, the
-- points nearer than the range (the sensors' far clipping distance) are drawn and
-- published as the string signal 'velodyne_points': packed floats, x, y, z per point,
-- in this scanner's frame (m).

-- m * {x, y, z} for a CoppeliaSim matrix (12 numbers, 3 rows of 4), without a call:
-- a call per point would cost more than the scan.
local function transform(m, x, y, z)
    return m[1] * x + m[2] * y + m[3] * z + m[4],
        m[5] * x + m[6] * y + m[7] * z + m[8],
        m[9] * x + m[10] * y + m[11] * z + m[12]
end

function sysCall_init()
    scanner = sim.getObject('.')
    sensors = {}
    for i = 1, 4 do
        sensors[i] = sim.getObject('./sensor' .. i)
    end
    maxScanDistance = sim.getObjectFloatParam(sensors[1], sim.visionfloatparam_far_clipping)
    points = sim.addDrawingObject(sim.drawing_points, 2, 0, -1, 4 * 450 * 16, {0, 0.6, 1})
end

function sysCall_sensing()
    local toScanner = sim.getMatrixInverse(sim.getObjectMatrix(scanner, -1))
    local measured, drawn, n = {}, {}, 0
    for _, sensor in ipairs(sensors) do
        local _, _, data = sim.readVisionSensor(sensor)
        if data then
            local toWorld = sim.getObjectMatrix(sensor, -1)
            local m = sim.multiplyMatrices(toScanner, toWorld)
            for k = 0, data[1] * data[2] - 1 do
                local w = 2 + 4 * k
                if data[w + 4] < maxScanDistance * 0.9999 then
                    local x, y, z = data[w + 1], data[w + 2], data[w + 3]
                    drawn[n + 1], drawn[n + 2], drawn[n + 3] = transform(toWorld, x, y, z)
                    measured[n + 1], measured[n + 2], measured[n + 3] = transform(m, x, y, z)
                    n = n + 3
                end
            end
        end
    end
    sim.addDrawingObjectItem(points, nil)
    if n > 0 then
        sim.addDrawingObjectItem(points | sim.handleflag_addmultiple, drawn)
    end
    sim.setStringSignal('velodyne_points', sim.packFloatTable(measured))
end
