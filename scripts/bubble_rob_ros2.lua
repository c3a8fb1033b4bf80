-- BubbleRob on ROS 2, in the manner of CoppeliaSim's ROS 2 tutorial script: wheel speeds
-- from geometry_msgs/Twist on /cmd_vel (differential drive), the nose sensor on
-- /<rover>/sensorTrigger, simulation time on /<rover>/simTime, the rover's pose on /tf,
-- and a std_srvs/SetBool service /<rover>/set_enabled that stops or frees the wheels.
-- Run it with `gantry run assets/scenes/bubble_rob_ros2.toml` (add --ros2 for /clock,
-- /tf_static and /joint_states too), then e.g.
--   ros2 topic pub /cmd_vel geometry_msgs/msg/Twist "{linear: {x: 0.1}}"
local sim = require 'sim'
local simROS2 = require 'simROS2'

local wheelRadius = 0.04 -- m (the tutorial's wheels: 0.08 m across)
local wheelSeparation = 0.2 -- m between the wheels' mid-planes

function cmdVel_callback(msg)
    -- v = (wl + wr) r / 2, w = (wr - wl) r / d
    local v, w = msg.linear.x, msg.angular.z
    leftSpeed = (v - w * wheelSeparation / 2) / wheelRadius
    rightSpeed = (v + w * wheelSeparation / 2) / wheelRadius
    commands = commands + 1
end

function setEnabled_callback(req)
    enabled = req.data
    sim.setInt32Signal('bubbleRobEnabled', enabled and 1 or 0)
    return {success = true, message = enabled and 'wheels enabled' or 'wheels stopped'}
end

function sysCall_init()
    robot = sim.getObject('.')
    leftMotor = sim.getObject('./leftMotor')
    rightMotor = sim.getObject('./rightMotor')
    noseSensor = sim.getObject('./sensingNose')
    local name = sim.getObjectAlias(robot)
    leftSpeed, rightSpeed, commands, enabled = 0, 0, 0, true
    sim.setInt32Signal('bubbleRobEnabled', 1)
    cmdVelSub = simROS2.createSubscription('/cmd_vel', 'geometry_msgs/msg/Twist', 'cmdVel_callback')
    sensorPub = simROS2.createPublisher('/' .. name .. '/sensorTrigger', 'std_msgs/msg/Bool')
    simTimePub = simROS2.createPublisher('/' .. name .. '/simTime', 'std_msgs/msg/Float32')
    enableSrv = simROS2.createService('/' .. name .. '/set_enabled', 'std_srvs/srv/SetBool', setEnabled_callback)
end

function sysCall_actuation()
    local l, r = leftSpeed, rightSpeed
    if not enabled then l, r = 0, 0 end
    sim.setJointTargetVelocity(leftMotor, l)
    sim.setJointTargetVelocity(rightMotor, r)
    sim.setInt32Signal('bubbleRobCommands', commands)
end

function sysCall_sensing()
    local detected = sim.readProximitySensor(noseSensor)
    simROS2.publish(sensorPub, {data = detected > 0})
    simROS2.publish(simTimePub, {data = sim.getSimulationTime()})
    simROS2.sendTransform(getTransformStamped(robot, 'bubbleRob', -1, 'world'))
end

function getTransformStamped(objHandle, name, relTo, relToName)
    local p = sim.getObjectPosition(objHandle, relTo)
    local o = sim.getObjectQuaternion(objHandle, relTo)
    return {
        header = {stamp = simROS2.getTime(), frame_id = relToName},
        child_frame_id = name,
        transform = {
            translation = {x = p[1], y = p[2], z = p[3]},
            rotation = {x = o[1], y = o[2], z = o[3], w = o[4]},
        },
    }
end

function sysCall_cleanup()
    simROS2.shutdownSubscription(cmdVelSub)
    simROS2.shutdownPublisher(sensorPub)
    simROS2.shutdownPublisher(simTimePub)
    simROS2.shutdownService(enableSrv)
end
