-- BubbleRob's controller in the style of CoppeliaSim's tutorial: drive forward until the
-- nose sensor sees an obstacle, then back up along a curve for 4 simulated seconds.
-- (The full tutorial controller, with its drawing, graph and UI calls, needs the
-- sensors-and-tools API; this one uses joints and the proximity sensor only.)

function sysCall_init()
    bubbleRobBase = sim.getObject('.')
    leftMotor = sim.getObject('./leftMotor')
    rightMotor = sim.getObject('./rightMotor')
    noseSensor = sim.getObject('./sensingNose')
    minMaxSpeed = {50 * math.pi / 180, 300 * math.pi / 180}   -- rad/s
    backUntilTime = -1
    speed = (minMaxSpeed[1] + minMaxSpeed[2]) * 0.5
    backups = 0
end

function sysCall_actuation()
    local result = sim.readProximitySensor(noseSensor)
    if result > 0 then
        if backUntilTime < sim.getSimulationTime() then backups = backups + 1 end
        backUntilTime = sim.getSimulationTime() + 4
    end
    if backUntilTime < sim.getSimulationTime() then
        sim.setJointTargetVelocity(leftMotor, speed)
        sim.setJointTargetVelocity(rightMotor, speed)
    else
        sim.setJointTargetVelocity(leftMotor, -speed / 2)
        sim.setJointTargetVelocity(rightMotor, -speed / 8)
    end
end
