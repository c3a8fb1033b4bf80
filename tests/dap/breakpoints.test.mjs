// Conditional breakpoints, hit counts and logpoints on BubbleRob's script.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
    BUBBLE_ROB_DT, BUBBLE_ROB_SCENE, BUBBLE_ROB_SCRIPT, TEST_TIMEOUT,
    assertAt, attach, expectStop, lineOf, setBreakpoints, simTime, startGantry,
} from './gantry.mjs';

const SCRIPT = BUBBLE_ROB_SCRIPT;
const dt = BUBBLE_ROB_DT;
// Two lines of sysCall_actuation that run once per step, the first before the second.
const ACTUATION_FIRST = lineOf(SCRIPT, 'result=sim.readProximitySensor(noseSensor)');
const ACTUATION = lineOf(SCRIPT, 'if (result>0) then backUntilTime');
const SENSING = lineOf(SCRIPT, 'local p=sim.getObjectPosition(bubbleRobBase,-1)');
const opts = { timeout: TEST_TIMEOUT };
// A logpoint in sysCall_sensing that prints once per step: progress without sleeping.
const TICK = { line: SENSING, logMessage: 'tick t={sim.getSimulationTime()}' };
const TICK_RE = /tick t=\d/;

test('conditional breakpoint: stops only where the Lua condition holds', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, {
        configure: (dc) => setBreakpoints(dc, SCRIPT, [{ line: ACTUATION, condition: 'sim.getSimulationTime() > 0.5' }]),
    });
    const first = await expectStop(dc, 'breakpoint');
    assertAt(first.top, SCRIPT, ACTUATION);
    const t1 = await simTime(dc, first.top.id);
    assert.ok(t1 > 0.5, `stopped at simulation time ${t1} > 0.5`);

    // A condition false for the next four steps and true from the fifth.
    const threshold = t1 + 4.5 * dt;
    await setBreakpoints(dc, SCRIPT, [{ line: ACTUATION, condition: `sim.getSimulationTime() > ${threshold}` }]);
    await dc.continueRequest({ threadId: 1 });
    const second = await expectStop(dc, 'breakpoint');
    assertAt(second.top, SCRIPT, ACTUATION);
    const t2 = await simTime(dc, second.top.id);
    assert.ok(Math.abs(t2 - (t1 + 5 * dt)) < 1e-6, `stopped at ${t2}, expected the first step after ${threshold}: ${t1 + 5 * dt}`);
});

test('hit count "3" stops once, on the third hit', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    // Stop in sysCall_actuation before the line that gets the hit count, so that the
    // count starts at a known step whatever the simulation did before the client came.
    const { dc } = await attach(t, g, { configure: (dc) => setBreakpoints(dc, SCRIPT, [ACTUATION_FIRST]) });
    const start = await expectStop(dc, 'breakpoint');
    assertAt(start.top, SCRIPT, ACTUATION_FIRST);
    const t0 = await simTime(dc, start.top.id);

    await setBreakpoints(dc, SCRIPT, [{ line: ACTUATION, hitCondition: '3' }, TICK]);
    await dc.continueRequest({ threadId: 1 });
    // Hits: this step (t0), the next (t0 + dt), the third (t0 + 2 dt).
    const hit = await expectStop(dc, 'breakpoint');
    assertAt(hit.top, SCRIPT, ACTUATION);
    const t3 = await simTime(dc, hit.top.id);
    assert.ok(Math.abs(t3 - (t0 + 2 * dt)) < 1e-9, `third hit at ${t3}, expected ${t0 + 2 * dt} (first at ${t0})`);

    // Only once: five more steps (ticks from the logpoint) without a stop.
    dc.drop('output');
    await dc.continueRequest({ threadId: 1 });
    await dc.outputsWithoutStop(TICK_RE, 5);
});

test('logpoint prints to the debug console with {expr} interpolated and does not stop', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, {
        configure: (dc) => setBreakpoints(dc, SCRIPT, [{ line: ACTUATION, logMessage: 'speed={speed}' }]),
    });
    const out = await dc.nextEvent('output', { where: (ev) => /speed=/.test(ev.body?.output ?? '') });
    assert.match(out.body.output, /speed=\d/, `interpolated: ${JSON.stringify(out.body.output)}`);
    await dc.noEvent('stopped', 1000);
});
