-- The paper's arm server (Chakraborty's FK demo) for gantry's text channel.
-- gantry listens on TCP itself and hands every packet to sysCall_packet; the script
-- never blocks the simulation the way the original's socket accept() did.
--
-- Commands (docs/text-protocol.md has examples):
--   <FK#J1=..,J2=..,...,J6=..>  set the joints, radians (clamped to limits, cyclic joints
--                               wrapped, as CoppeliaSim does); missing joints keep their
--                               value. Reply: the packet echoed (the paper's ack).
--   <IK#TX=..,TY=..,TZ=..>      move the IK target to (TX, TY, TZ), metres, world frame,
--                               keeping its orientation, and solve with simIK (damped
--                               least squares, damping 0.3, 100 iterations, as the paper).
--                               Out of reach: the arm moves as close as it can and the
--                               reply is an error saying so.
--   <JOINTS#>                   reply <JOINTS#J1=..,...,J6=..> with the joint angles, rad.
--   <TIP#>                      reply <TIP#X=..,Y=..,Z=..,QX=..,QY=..,QZ=..,QW=..>, world frame.

function sysCall_init()
    joints = {}
    for i = 1, 6 do
        joints[i] = sim.getObject('./joint' .. i)
    end
    tip = sim.getObject('./tip')
    target = sim.getObject('/target', {noError = true})
    if target ~= -1 then
        -- Unlike the original, gantry's IK works on the scene's own joints, so it always
        -- starts from the arm's current pose (the paper's IK world drifted after FK).
        ikEnv = simIK.createEnvironment()
        ikGroup = simIK.createGroup(ikEnv)
        simIK.setGroupCalculation(ikEnv, ikGroup, simIK.method_damped_least_squares, 0.3, 100)
        simIK.addElementFromScene(ikEnv, ikGroup, sim.getObject('.'), tip, target, simIK.constraint_pose)
    end
end

function sysCall_cleanup()
    if ikEnv then simIK.eraseEnvironment(ikEnv) end
end

local function fmt(x)
    return string.format('%.17g', x) -- round-trips a double exactly
end

function sysCall_packet(packet)
    local code = packet.code
    if code == 'FK' then
        for i = 1, 6 do
            local q = packet.fields['J' .. i]
            if q then sim.setJointPosition(joints[i], q) end
        end
        return nil -- echo the packet
    elseif code == 'IK' then
        if target == -1 then
            return '<ERR#IK needs a dummy aliased "target" in the scene>'
        end
        local p = sim.getObjectPosition(target, sim.handle_world)
        p[1] = packet.fields.TX or p[1]
        p[2] = packet.fields.TY or p[2]
        p[3] = packet.fields.TZ or p[3]
        sim.setObjectPosition(target, p, sim.handle_world)
        local result = simIK.handleGroup(ikEnv, ikGroup, {syncWorlds = true, allowError = true})
        if result ~= simIK.result_success then
            return '<ERR#IK target out of reach; the arm moved as close as it can>'
        end
        return nil -- echo the packet
    elseif code == 'JOINTS' then
        local parts = {}
        for i = 1, 6 do
            parts[i] = 'J' .. i .. '=' .. fmt(sim.getJointPosition(joints[i]))
        end
        return '<JOINTS#' .. table.concat(parts, ',') .. '>'
    elseif code == 'TIP' then
        local pose = sim.getObjectPose(tip, sim.handle_world)
        return string.format('<TIP#X=%s,Y=%s,Z=%s,QX=%s,QY=%s,QZ=%s,QW=%s>',
            fmt(pose[1]), fmt(pose[2]), fmt(pose[3]), fmt(pose[4]), fmt(pose[5]), fmt(pose[6]), fmt(pose[7]))
    end
    return '<ERR#unknown command ' .. code .. '; use FK, IK, JOINTS or TIP>'
end
