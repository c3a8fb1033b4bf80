// The DAP server on small scenes written for the test into a temporary folder: break on
// a script error, breakpoints kept across a hot reload, two scripts with breakpoints.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { setTimeout as sleep } from 'node:timers/promises';
import {
    TEST_TIMEOUT,
    assertAt, attach, evaluate, expectStop, lineOf, samePath, sceneToml, setBreakpoints,
    simTime, startGantry, tempScene,
} from './gantry.mjs';

const opts = { timeout: TEST_TIMEOUT };

test('break on script errors: stopped "exception" at the erroring line; the simulation goes on', opts, async (t) => {
    const dir = tempScene(t, {
        'scene.toml': sceneToml({ faulty: 'err.lua', ticker: 'tick.lua' }),
        'err.lua': [
            'function sysCall_actuation()',
            '  if sim.getSimulationTime() > 0.2 then',
            '    local t = nil',
            '    return t.x',
            '  end',
            'end',
            '',
        ].join('\n'),
        'tick.lua': [
            'function sysCall_actuation()',
            '  local now = sim.getSimulationTime()',
            'end',
            '',
        ].join('\n'),
    });
    const err = path.join(dir, 'err.lua');
    const tick = path.join(dir, 'tick.lua');
    const errLine = lineOf(err, 'return t.x');
    const tickLine = lineOf(tick, 'local now');

    const g = await startGantry(t, path.join(dir, 'scene.toml'));
    const { dc } = await attach(t, g, {
        configure: (dc) => dc.setExceptionBreakpointsRequest({ filters: ['error'] }),
    });
    const { event, top } = await expectStop(dc, 'exception');
    const text = event.body.text ?? '';
    assert.match(text, /attempt to index/, `the Lua error message: ${JSON.stringify(text)}`);
    assert.match(text, new RegExp(`err\\.lua:${errLine}:`), `file:line: message: ${JSON.stringify(text)}`);
    assertAt(top, err, errLine);
    assert.match(top.name, /sysCall_actuation/);
    assert.ok(top.name.includes('/faulty'), `the frame names the object path: ${top.name}`);
    const tErr = await simTime(dc, top.id);
    assert.ok(tErr > 0.2, `the error happens after 0.2 s, at ${tErr}`);

    // After continue the simulation goes on without the errored script: the next two stops
    // are the other script's breakpoint, not the error again.
    await setBreakpoints(dc, tick, [tickLine]);
    await dc.continueRequest({ threadId: 1 });
    let last = tErr;
    for (let i = 0; i < 2; i++) {
        const stop = await expectStop(dc, 'breakpoint');
        assertAt(stop.top, tick, tickLine);
        const now = await simTime(dc, stop.top.id);
        assert.ok(now >= last, `simulation time ${now} after ${last}`);
        last = now;
        await dc.continueRequest({ threadId: 1 });
    }
    assert.ok(last > tErr, `the simulation went on after the error: ${last} > ${tErr}`);
    assert.ok(g.alive, 'gantry keeps running');
});

test('breakpoints survive a hot reload of the script', opts, async (t) => {
    const v1 = 'function sysCall_actuation()\n  local a = 1\n  local b = 2\nend\n';
    const v2 = 'function sysCall_actuation()\n  local a = 10\n  local b = 3\nend\n';
    const dir = tempScene(t, { 'scene.toml': sceneToml({ reloaded: 'reload.lua' }), 'reload.lua': v1 });
    const file = path.join(dir, 'reload.lua');
    const line = lineOf(file, 'local b');

    const g = await startGantry(t, path.join(dir, 'scene.toml'));
    const { dc } = await attach(t, g, { configure: (dc) => setBreakpoints(dc, file, [line]) });
    const first = await expectStop(dc, 'breakpoint');
    assertAt(first.top, file, line);
    assert.equal((await evaluate(dc, 'a', first.top.id)).result, '1');

    await sleep(1100); // deliberate: the new version must get a different modification time
    fs.writeFileSync(file, v2);
    assert.equal(lineOf(file, 'local b'), line);

    // Run on; the old version may still stop a few times before gantry notices the change.
    const deadline = Date.now() + 20_000;
    let a;
    let stops = 0;
    while (a !== '10') {
        assert.ok(Date.now() < deadline, `no stop in the reloaded version within 20 s (${stops} stops in the old one)`);
        await dc.continueRequest({ threadId: 1 });
        const stop = await expectStop(dc, 'breakpoint');
        assertAt(stop.top, file, line);
        a = (await evaluate(dc, 'a', stop.top.id)).result;
        assert.ok(a === '1' || a === '10', `a = ${a}`);
        stops++;
    }
});

test('breakpoints in two scripts: both stop, each frame names its own file', opts, async (t) => {
    const body = 'function sysCall_actuation()\n  local x = 1\nend\n';
    const dir = tempScene(t, {
        'scene.toml': sceneToml({ alpha: 'a.lua', beta: 'b.lua' }),
        'a.lua': body,
        'b.lua': body,
    });
    const a = path.join(dir, 'a.lua');
    const b = path.join(dir, 'b.lua');
    const line = lineOf(a, 'local x');

    const g = await startGantry(t, path.join(dir, 'scene.toml'));
    const { dc } = await attach(t, g, {
        configure: async (dc) => {
            await setBreakpoints(dc, a, [line]);
            await setBreakpoints(dc, b, [line]);
        },
    });
    // Both hooks run every step, so two consecutive stops are in the two scripts.
    const first = await expectStop(dc, 'breakpoint');
    await dc.continueRequest({ threadId: 1 });
    const second = await expectStop(dc, 'breakpoint');
    const stops = [first.top, second.top];
    for (const top of stops) assert.equal(top.line, line);
    const inA = stops.filter((f) => samePath(f.source.path, a));
    const inB = stops.filter((f) => samePath(f.source.path, b));
    assert.equal(inA.length, 1, `one stop in a.lua: ${stops.map((f) => f.source.path).join(', ')}`);
    assert.equal(inB.length, 1, `one stop in b.lua: ${stops.map((f) => f.source.path).join(', ')}`);
    assert.ok(inA[0].name.includes('/alpha'), `a.lua's frame names /alpha: ${inA[0].name}`);
    assert.ok(inB[0].name.includes('/beta'), `b.lua's frame names /beta: ${inB[0].name}`);
});
