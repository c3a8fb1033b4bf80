-- A Velodyne-style 3-D laser scanner (assets/scenes/scanners.toml): four depth sensors
-- 90 degrees apart, whose filters (velodyne_sensor.lua) turn their depth maps into 16
-- beams per azimuth, 1,800 azimuths around. Once the sensors were handled in a step, the
-- points nearer than the range (the sensors' far clipping distance) are drawn and
-- published as the string signal 'velodyne_points': packed floats, x, y, z per point,
-- in this scanner's frame (m).
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
    local measured = {}
    sim.addDrawingObjectItem(points, nil)
    for _, sensor in ipairs(sensors) do
        local _, _, data = sim.readVisionSensor(sensor)
        if data then
            -- Sensor frame to the scanner's: one matrix per sensor, not per point.
            local m = sim.multiplyMatrices(toScanner, sim.getObjectMatrix(sensor, -1))
            local world = sim.getObjectMatrix(sensor, -1)
            for k = 0, data[1] * data[2] - 1 do
                local w = 2 + 4 * k
                if data[w + 4] < maxScanDistance * 0.9999 then
                    local p = {data[w + 1], data[w + 2], data[w + 3]}
                    sim.addDrawingObjectItem(points, sim.multiplyVector(world, p))
                    local q = sim.multiplyVector(m, p)
                    measured[#measured + 1] = q[1]
                    measured[#measured + 1] = q[2]
                    measured[#measured + 1] = q[3]
                end
            end
        end
    end
    sim.setStringSignal('velodyne_points', sim.packFloatTable(measured))
end
