-- Benchmark controller (issue 8): BubbleRob's obstacle avoidance alone, without the lab
-- sheet's distance segment, trace, graph and slider. tools/bench/pybullet_bench.py runs
-- the same logic in PyBullet with one ray test per rover per step.

local speed = 175 * math.pi / 180   -- rad/s, the lab sheet's initial slider speed

function sysCall_init()
    leftMotor = sim.getObject('./leftMotor')
    rightMotor = sim.getObject('./rightMotor')
    noseSensor = sim.getObject('./sensingNose')
    backUntilTime = -1
end

function sysCall_actuation()
    local t = sim.getSimulationTime()
    if sim.readProximitySensor(noseSensor) > 0 then
        backUntilTime = t + 4
    end
    if backUntilTime < t then
        sim.setJointTargetVelocity(leftMotor, speed)
        sim.setJointTargetVelocity(rightMotor, speed)
    else
        -- Back away in a curve at reduced speed.
        sim.setJointTargetVelocity(leftMotor, -speed / 2)
        sim.setJointTargetVelocity(rightMotor, -speed / 8)
    end
end
