// The DAP server on BubbleRob (assets/scenes/bubble_rob.toml, scripts/bubble_rob.lua):
// the configuration sequence, stack, scopes and variables, evaluate, setVariable,
// stepping, continue, pause and detaching. Each test runs its own gantry.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { setTimeout as sleep } from 'node:timers/promises';
import {
    BUBBLE_ROB_SCENE, BUBBLE_ROB_SCRIPT, REPO, TEST_TIMEOUT,
    assertAt, attach, evaluate, expectStop, lineOf, rejects, samePath,
    scopes, setBreakpoints, simTime, startGantry, variables,
} from './gantry.mjs';

const SCRIPT = BUBBLE_ROB_SCRIPT;
// Line numbers are looked up in the script's text, never hard-coded.
const ACTUATION = lineOf(SCRIPT, 'if (result>0) then backUntilTime');
const SENSING = lineOf(SCRIPT, 'local p=sim.getObjectPosition(bubbleRobBase,-1)');
const opts = { timeout: TEST_TIMEOUT };

const withBreakpoints = (...bps) => ({ configure: (dc) => setBreakpoints(dc, SCRIPT, bps) });

test('initialize, threads, stack trace, scopes and variables at a breakpoint in sysCall_actuation', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc, capabilities } = await attach(t, g, withBreakpoints(ACTUATION));

    for (const cap of [
        'supportsConfigurationDoneRequest', 'supportsConditionalBreakpoints',
        'supportsHitConditionalBreakpoints', 'supportsLogPoints', 'supportsSetVariable',
        'supportsEvaluateForHovers',
    ]) {
        assert.equal(capabilities[cap], true, `capability ${cap}`);
    }
    const filters = capabilities.exceptionBreakpointFilters ?? [];
    assert.ok(filters.some((f) => f.filter === 'error'), `exception filter "error" in ${JSON.stringify(filters)}`);

    const { top } = await expectStop(dc, 'breakpoint');
    assertAt(top, SCRIPT, ACTUATION);
    assert.match(top.name, /sysCall_actuation/, 'the frame names the hook');
    assert.ok(top.name.includes('/bubbleRob'), `the frame names the object path: ${top.name}`);

    const threads = await dc.threadsRequest();
    assert.deepEqual(threads.body.threads.map(({ id, name }) => ({ id, name })), [{ id: 1, name: 'simulation' }]);

    const sc = await scopes(dc, top.id);
    for (const s of Object.values(sc)) {
        assert.ok(s.variablesReference > 0, `scope ${s.name} has a variablesReference`);
    }
    await variables(dc, sc.Locals.variablesReference);
    await variables(dc, sc.Upvalues.variablesReference);
    const globals = await variables(dc, sc.Globals.variablesReference);
    for (const v of globals.values()) {
        assert.equal(typeof v.value, 'string', `value of ${v.name} is a string`);
        assert.equal(typeof v.type, 'string', `type of ${v.name} is a string`);
        assert.equal(typeof v.variablesReference, 'number', `variablesReference of ${v.name}`);
    }
    for (const name of ['speed', 'result', 'minMaxSpeed', 'leftMotor', 'xml']) {
        assert.ok(globals.has(name), `global ${name} in ${[...globals.keys()].join(', ')}`);
    }
    for (const lib of ['sim', 'math', 'string', 'table', 'coroutine', 'simUI']) {
        assert.ok(!globals.has(lib), `library table ${lib} is left out of Globals`);
    }

    const speed = globals.get('speed');
    assert.equal(speed.type, 'number');
    assert.ok(Number.isFinite(Number(speed.value)), `speed shows a number: ${speed.value}`);
    assert.equal(speed.variablesReference, 0);
    assert.equal(globals.get('leftMotor').type, 'number');
    assert.ok(Number.isFinite(Number(globals.get('leftMotor').value)), `a handle shows as a number: ${globals.get('leftMotor').value}`);
    assert.equal(globals.get('result').type, 'number');
    const xml = globals.get('xml');
    assert.equal(xml.type, 'string');
    assert.ok(xml.value.startsWith('"') && xml.value.includes('<ui title='), `a string shows quoted: ${xml.value}`);

    const mms = globals.get('minMaxSpeed');
    assert.equal(mms.type, 'table');
    assert.ok(mms.variablesReference > 0, 'a table can be expanded');
    const items = await variables(dc, mms.variablesReference);
    assert.deepEqual([...items.keys()], ['[1]', '[2]']);
    assert.ok(Math.abs(Number(items.get('[1]').value) - 50 * Math.PI / 180) < 1e-3, `[1] = ${items.get('[1]').value}`);
    assert.ok(Math.abs(Number(items.get('[2]').value) - 300 * Math.PI / 180) < 1e-3, `[2] = ${items.get('[2]').value}`);
    assert.equal(items.get('[1]').type, 'number');
});

test('evaluate in the frame, in the sandbox, while the simulation stands still', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, withBreakpoints(ACTUATION));
    const { top } = await expectStop(dc, 'breakpoint');

    const speed = Number((await evaluate(dc, 'speed', top.id)).result);
    assert.ok(Number.isFinite(speed), 'speed is a number');
    for (const context of ['repl', 'watch', 'hover']) {
        const body = await evaluate(dc, 'speed*2', top.id, context);
        assert.ok(Math.abs(Number(body.result) - 2 * speed) < 1e-9, `${context}: speed*2 = ${body.result}, speed = ${speed}`);
        assert.equal(body.type, 'number', `${context}: type`);
        assert.equal(body.variablesReference, 0, `${context}: a number has no children`);
    }
    const table = await evaluate(dc, 'minMaxSpeed', top.id, 'watch');
    assert.equal(table.type, 'table');
    assert.ok(table.variablesReference > 0, 'an evaluated table can be expanded');
    const items = await variables(dc, table.variablesReference);
    assert.deepEqual([...items.keys()], ['[1]', '[2]']);

    await rejects(evaluate(dc, 'nosuchfunction()', top.id), 'calling an undefined function');
    await rejects(evaluate(dc, 'speed +', top.id), 'a syntax error');
    // The script's sandbox: no os.exit, io or debug.getinfo.
    await rejects(evaluate(dc, 'os.exit()', top.id), 'os.exit()');
    await rejects(evaluate(dc, 'io.write("x")', top.id), 'io.write');
    await rejects(evaluate(dc, 'debug.getinfo(1)', top.id), 'debug.getinfo');
    assert.ok(g.alive, 'gantry is still running');

    // While stopped, simulation time does not advance.
    const before = (await evaluate(dc, 'sim.getSimulationTime()', top.id)).result;
    await sleep(500); // deliberate: half a second of wall-clock time (10 steps of BubbleRob)
    const after = (await evaluate(dc, 'sim.getSimulationTime()', top.id)).result;
    assert.equal(after, before, 'simulation time while stopped');
});

test('setVariable changes a local at the breakpoint in sysCall_sensing', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, withBreakpoints(SENSING));
    const { top } = await expectStop(dc, 'breakpoint');
    assertAt(top, SCRIPT, SENSING);
    assert.match(top.name, /sysCall_sensing/);

    const sc = await scopes(dc, top.id);
    const ref = sc.Locals.variablesReference;
    const locals = await variables(dc, ref);
    assert.ok(locals.has('result') && locals.has('distData'), `locals: ${[...locals.keys()].join(', ')}`);
    assert.equal(locals.get('result').type, 'number');

    const r = await dc.setVariableRequest({ variablesReference: ref, name: 'result', value: '42' });
    assert.equal(r.body.value, '42');
    const again = await variables(dc, ref);
    assert.equal(again.get('result').value, '42');
    assert.equal((await evaluate(dc, 'result', top.id)).result, '42', 'the frame sees the new value');
});

test('next steps to a later line of sysCall_actuation', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, withBreakpoints(ACTUATION));
    await expectStop(dc, 'breakpoint');

    await dc.nextRequest({ threadId: 1 });
    const { top } = await expectStop(dc, 'step');
    assertAt(top, SCRIPT);
    assert.ok(top.line > ACTUATION, `stepped from line ${ACTUATION} to a later line, not ${top.line}`);
    assert.match(top.name, /sysCall_actuation/);
});

test('stepOut of sysCall_actuation stops in the next hook that runs', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, withBreakpoints(ACTUATION));
    await expectStop(dc, 'breakpoint');

    await dc.stepOutRequest({ threadId: 1 });
    const { top } = await expectStop(dc, 'step');
    assert.doesNotMatch(top.name, /sysCall_actuation/, `stepped out of the hook: ${top.name}`);
    // BubbleRob's sysCall_sensing in the same step, or the vision sensor script's
    // sysCall_vision (scripts/edge_detect.lua), which runs between them.
    assert.match(top.name, /sysCall_(sensing|vision)/, `stopped in a later hook of the step: ${top.name}`);
    assert.ok(top.source?.path && path.isAbsolute(top.source.path), 'the frame has an absolute source path');
});

test('continue runs to the breakpoint again, later in simulation time (launch behaves as attach)', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, { request: 'launch', ...withBreakpoints(ACTUATION) });
    const first = await expectStop(dc, 'breakpoint');
    const t1 = await simTime(dc, first.top.id);

    await dc.continueRequest({ threadId: 1 });
    const second = await expectStop(dc, 'breakpoint');
    assertAt(second.top, SCRIPT, ACTUATION);
    const t2 = await simTime(dc, second.top.id);
    assert.ok(t2 > t1, `simulation time ${t2} after continue > ${t1}`);
});

test('pause stops the running simulation in a script line', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g);

    await dc.pauseRequest({ threadId: 1 });
    const { top } = await expectStop(dc, 'pause');
    const scripts = [SCRIPT, path.join(REPO, 'scripts', 'edge_detect.lua')];
    assert.ok(top.source?.path && scripts.some((s) => samePath(top.source.path, s)),
        `paused in one of the scene's scripts: ${JSON.stringify(top.source)}`);
    assert.ok(top.line >= 1, 'at a line');
    await dc.continueRequest({ threadId: 1 });
});

test('disconnect while stopped resumes the simulation; a new client can attach', opts, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const { dc } = await attach(t, g, withBreakpoints(ACTUATION));
    const first = await expectStop(dc, 'breakpoint');
    const t1 = await simTime(dc, first.top.id);

    await dc.disconnectRequest({ restart: false, terminateDebuggee: false });
    dc.close();
    assert.ok(g.alive, 'gantry keeps running after the client disconnects');

    // The server may take a moment to notice the first connection's end.
    const { dc: dc2 } = await attach(t, g, { busyRetryMs: 3000, ...withBreakpoints(ACTUATION) });
    const second = await expectStop(dc2, 'breakpoint');
    assertAt(second.top, SCRIPT, ACTUATION);
    const t2 = await simTime(dc2, second.top.id);
    assert.ok(t2 > t1, `simulation time ${t2} with the second client > ${t1} with the first`);
});
