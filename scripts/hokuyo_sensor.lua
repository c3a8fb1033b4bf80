-- The filter of each of the Hokuyo-style scanner's two depth sensors
-- (assets/scenes/scanners.toml), as CoppeliaSim's fast Hokuyo model has it: the depth
-- map becomes the work image, the work image one point per pixel (evenly across the
-- image, not in angle), and the points become the second packet that
-- sim.readVisionSensor returns (hokuyo.lua reads it).
function sysCall_vision(inData)
    simVision.sensorDepthMapToWorkImg(inData.handle)
    local trigger, packet = simVision.coordinatesFromWorkImg(inData.handle, inData.resolution, false)
    -- The depth map as the sensor's image, so that the viewer shows what was scanned.
    simVision.workImgToSensorImg(inData.handle)
    return {trigger = trigger, packedPackets = {packet}}
end
