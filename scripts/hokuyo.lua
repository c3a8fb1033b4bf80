-- A Hokuyo-style 2-D laser scanner (assets/scenes/scanners.toml), written as CoppeliaSim's
-- fast Hokuyo model is: two depth sensors of 120 degrees each, whose filters
-- (hokuyo_sensor.lua) turn their depth maps into points. Here, once the sensors were
-- handled in a step, the points nearer than the scan range (the sensors' far clipping
-- distance) are drawn in red and published as the string signal 'hokuyo_points':
-- packed floats, x, y, z per point, in this scanner's frame (m).

-- m * {x, y, z} for a CoppeliaSim matrix (12 numbers, 3 rows of 4), without a call.
local function transform(m, x, y, z)
    return m[1] * x + m[2] * y + m[3] * z + m[4],
        m[5] * x + m[6] * y + m[7] * z + m[8],
        m[9] * x + m[10] * y + m[11] * z + m[12]
end

function sysCall_init()
    scanner = sim.getObject('.')
    sensors = {sim.getObject('./sensor1'), sim.getObject('./sensor2')}
    maxScanDistance = sim.getObjectFloatParam(sensors[1], sim.visionfloatparam_far_clipping)
    points = sim.addDrawingObject(sim.drawing_points, 4, 0, -1, 1000, {1, 0, 0})
end

function sysCall_sensing()
    local toScanner = sim.getMatrixInverse(sim.getObjectMatrix(scanner, -1))
    local measured, drawn, n = {}, {}, 0
    for _, sensor in ipairs(sensors) do
        -- Packet 1 is the image's statistics; packet 2 the filter's points: the counts
        -- along x and y, then x, y, z (sensor frame) and the distance per point.
        local _, _, data = sim.readVisionSensor(sensor)
        if data then
            local toWorld = sim.getObjectMatrix(sensor, -1)
            local m = sim.multiplyMatrices(toScanner, toWorld)
            for k = 0, data[1] * data[2] - 1 do
                local w = 2 + 4 * k
                -- A point at the far distance is a beam that returned nothing.
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
    sim.setStringSignal('hokuyo_points', sim.packFloatTable(measured))
end
