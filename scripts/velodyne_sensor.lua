-- The filter of each of the Velodyne-style scanner's four depth sensors
-- (assets/scenes/scanners.toml), as CoppeliaSim's VPL-16 model has it: the depth map
-- becomes the work image, and the work image 450 azimuths x 16 beams spread over 30
-- degrees of elevation, which become the second packet that sim.readVisionSensor
-- returns (velodyne.lua reads it).
function sysCall_vision(inData)
    simVision.sensorDepthMapToWorkImg(inData.handle)
    local trigger, packet = simVision.velodyneDataFromWorkImg(inData.handle, {450, 16}, 30 * math.pi / 180)
    return {trigger = trigger, packedPackets = {packet}}
end
