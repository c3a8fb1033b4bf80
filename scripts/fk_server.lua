-- The paper's arm server, without its socket: gantry's text channel delivers each
-- packet to sysCall_packet (see docs/text-protocol.md once the channel lands).
-- FK sets the six joints in radians; CoppeliaSim clamps and wraps them the same way.

function sysCall_init()
    joints = {}
    for i = 1, 6 do
        joints[i] = sim.getObject('./joint' .. i)
    end
end

function sysCall_packet(packet)
    if packet.code == 'FK' then
        for i = 1, 6 do
            local q = packet.fields['J' .. i]
            if q then sim.setJointPosition(joints[i], q) end
        end
    end
end
