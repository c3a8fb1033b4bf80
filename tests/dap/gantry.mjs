// Helpers for the DAP end-to-end tests: a real gantry process per test, a DebugClient
// (Microsoft's DAP test client) with an event queue and request timeouts, and small
// assertions shared by the test files.
//
// Why a subclass of DebugClient: connected to an adapter on a port (server mode),
// DebugClient disables every timeout of waitForEvent, its requests never time out, and
// waitForEvent only sees events that arrive after it is called (an `initialized` or
// `stopped` event sent in the same TCP segment as a response is lost). GantryClient
// records every event from the moment it connects and consumes them in order, with
// timeouts everywhere, and fails pending requests when the connection closes.

import { spawn } from 'node:child_process';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { DebugClient } from '@vscode/debugadapter-testsupport';

export const REPO = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
export const BUBBLE_ROB_SCENE = path.join(REPO, 'assets', 'scenes', 'bubble_rob.toml');
export const BUBBLE_ROB_SCRIPT = fs.realpathSync(path.join(REPO, 'scripts', 'bubble_rob.lua'));
/** BubbleRob's time step (assets/scenes/bubble_rob.toml), s. */
export const BUBBLE_ROB_DT = 0.05;

/** Per-test timeout of node:test, ms. */
export const TEST_TIMEOUT = 30_000;
/** How long a request may wait for its response, ms. */
export const REQUEST_TIMEOUT = 10_000;
/** How long an expected event may take, ms. */
export const EVENT_TIMEOUT = 10_000;
/** How long gantry may take to print `listening dap=ADDR`, ms. */
export const START_TIMEOUT = 30_000;

/** The binary under test: $GANTRY_BIN, else target/release/gantry in the repository. */
export function gantryBin() {
    const bin = process.env.GANTRY_BIN || path.join(REPO, 'target', 'release', 'gantry');
    return path.resolve(REPO, bin);
}

// Every gantry started by this process, killed on exit whatever happened to the tests.
const running = new Set();
process.on('exit', () => {
    for (const proc of running) {
        try { proc.kill('SIGKILL'); } catch { /* already gone */ }
    }
});

const ANSI = /\x1b\[[0-9;]*m/g;
const LISTENING_DAP = /listening dap=(\[[0-9a-fA-F:.]+\]|[^\s:]+):(\d+)/;

/**
 * A running gantry. `stderr` and `stdout` hold everything it wrote so far (ANSI colours
 * removed); `stop()` ends it (SIGTERM, then SIGKILL after 3 s) and is safe to call twice.
 */
export class Gantry {
    constructor(proc, cmd) {
        this.proc = proc;
        this.cmd = cmd;
        this.stderr = '';
        this.stdout = '';
        this.exited = new Promise((resolve) => {
            proc.once('exit', (code, signal) => {
                running.delete(proc);
                resolve({ code, signal });
            });
        });
    }

    get alive() {
        return this.proc.exitCode === null && this.proc.signalCode === null;
    }

    /** The last lines of stderr, for failure messages. */
    tail(lines = 60) {
        return this.stderr.split('\n').slice(-lines).join('\n');
    }

    async stop() {
        if (!this.alive) return this.exited;
        this.proc.kill('SIGTERM');
        const timer = setTimeout(() => {
            if (this.alive) this.proc.kill('SIGKILL');
        }, 3000);
        try {
            return await this.exited;
        } finally {
            clearTimeout(timer);
        }
    }
}

/**
 * Start gantry on `scene` with the DAP server on a free port and every other listener on a
 * free port too; resolve once it prints `listening dap=HOST:PORT` on stderr. Registers the
 * process's end with `t.after` (node:test context), so it is killed even when the test
 * fails or times out.
 *
 * Options: `args` replaces the default listener arguments, `extraArgs` are appended,
 * `ready` is the regular expression to wait for (its groups 1 and 2 are host and port),
 * `timeout` (ms).
 */
export async function startGantry(t, scene, options = {}) {
    const {
        args = ['--debug=0', '--text-port', '0', '--zmq-port', '0', '--http-port', '0'],
        extraArgs = [],
        ready = LISTENING_DAP,
        timeout = START_TIMEOUT,
    } = options;
    const bin = gantryBin();
    if (!fs.existsSync(bin)) {
        throw new Error(`gantry binary not found at ${bin}: build it (cargo build --release --bin gantry) or set GANTRY_BIN`);
    }
    const cmd = [bin, 'run', scene, ...args, ...extraArgs];
    const proc = spawn(cmd[0], cmd.slice(1), { stdio: ['ignore', 'pipe', 'pipe'] });
    running.add(proc);
    const g = new Gantry(proc, cmd);
    if (t) t.after(() => g.stop());

    proc.stdout.setEncoding('utf8');
    proc.stdout.on('data', (chunk) => { g.stdout += chunk.replace(ANSI, ''); });

    await new Promise((resolve, reject) => {
        let pending = '';
        let done = false;
        const finish = (err) => {
            if (done) return;
            done = true;
            clearTimeout(timer);
            if (err) {
                g.stop().finally(() => reject(err));
            } else {
                resolve();
            }
        };
        const timer = setTimeout(() => finish(new Error(
            `gantry did not print a line matching ${ready} within ${timeout} ms\n` +
            `command: ${cmd.join(' ')}\nstderr so far:\n${g.stderr}`)), timeout);
        proc.stderr.setEncoding('utf8');
        proc.stderr.on('data', (chunk) => {
            const text = chunk.replace(ANSI, '');
            g.stderr += text;
            if (done) return;
            pending += text;
            const lines = pending.split('\n');
            pending = lines.pop();
            for (const line of lines) {
                const m = ready.exec(line);
                if (m) {
                    g.host = m[1].replace(/^\[|\]$/g, '');
                    g.port = Number(m[2]);
                    finish();
                    return;
                }
            }
        });
        proc.once('error', (err) => finish(new Error(`cannot start ${cmd.join(' ')}: ${err.message}`)));
        proc.once('exit', (code, signal) => {
            // Let the last stderr bytes arrive before reporting.
            setImmediate(() => finish(new Error(
                `gantry exited (code ${code}, signal ${signal}) before printing a line matching ${ready}\n` +
                `command: ${cmd.join(' ')}\nstderr:\n${g.stderr}`)));
        });
    });
    return g;
}

/**
 * A temporary folder with the given files ({name: text}); removed after the test.
 */
export function tempScene(t, files) {
    const dir = fs.realpathSync(fs.mkdtempSync(path.join(os.tmpdir(), 'gantry-dap-')));
    for (const [name, text] of Object.entries(files)) {
        fs.writeFileSync(path.join(dir, name), text);
    }
    if (t) t.after(() => fs.rmSync(dir, { recursive: true, force: true }));
    return dir;
}

/** A scene with one dummy per script: {objectName: scriptFile}. */
export function sceneToml(objects, dt = 0.05) {
    let toml = `[simulation]\ndt = ${dt}\n`;
    for (const [name, script] of Object.entries(objects)) {
        toml += `\n[[object]]\nname = "${name}"\nkind = "dummy"\nscript = "${script}"\n`;
    }
    return toml;
}

/** The 1-based number of the only line of `file` that contains `needle`. */
export function lineOf(file, needle) {
    const lines = fs.readFileSync(file, 'utf8').split('\n');
    const hits = [];
    lines.forEach((line, i) => { if (line.includes(needle)) hits.push(i + 1); });
    assert.equal(hits.length, 1, `expected exactly one line containing ${JSON.stringify(needle)} in ${file}, found ${hits.length}`);
    return hits[0];
}

/** Whether two paths name the same file. */
export function samePath(a, b) {
    try {
        return fs.realpathSync(a) === fs.realpathSync(b);
    } catch {
        return path.resolve(a) === path.resolve(b);
    }
}

function withTimeout(promise, ms, what) {
    let timer;
    return Promise.race([
        promise,
        new Promise((_, reject) => {
            timer = setTimeout(() => reject(new Error(`${what}: nothing within ${ms} ms`)), ms);
        }),
    ]).finally(() => clearTimeout(timer));
}

/**
 * DebugClient connected to a running adapter, with an ordered event queue
 * (`nextEvent`, `noEvent`) and a timeout on every request.
 */
export class GantryClient extends DebugClient {
    constructor() {
        super('node', 'unused', 'gantry');
        this.queue = [];      // events received and not consumed yet
        this.waiters = [];    // {type, where, resolve}
        this.closed = false;
        this.socketError = null;
        this.whenClosed = new Promise((resolve) => { this._closedNow = resolve; });
    }

    // Every DAP event goes through EventEmitter.emit(eventName, event): record it first.
    emit(name, ...rest) {
        const ev = rest[0];
        if (ev && typeof ev === 'object' && ev.type === 'event') {
            const i = this.waiters.findIndex((w) => w.type === ev.event && w.where(ev));
            if (i >= 0) {
                const [w] = this.waiters.splice(i, 1);
                w.resolve(ev);
            } else {
                this.queue.push(ev);
            }
        }
        return super.emit(name, ...rest);
    }

    /** Connect to the adapter at host:port (instead of DebugClient.start, which has no error handling). */
    connectTo(port, host = '127.0.0.1') {
        return withTimeout(new Promise((resolve, reject) => {
            const sock = net.createConnection({ port, host });
            sock.once('connect', () => {
                this._socket = sock;
                this.connect(sock, sock);
                resolve(this);
            });
            sock.on('error', (err) => {
                this.socketError = err;
                reject(err);
            });
            sock.on('close', () => {
                this.closed = true;
                this._closedNow();
                // Fail what is still waiting for a response instead of hanging.
                for (const [seq, clb] of this.pendingRequests) {
                    this.pendingRequests.delete(seq);
                    clb({ success: false, message: `connection closed before the response to request ${seq}` });
                }
            });
        }), REQUEST_TIMEOUT, `connecting to the DAP server at ${host}:${port}`);
    }

    send(command, args) {
        if (this.closed) return Promise.reject(new Error(`'${command}': the connection is closed`));
        return withTimeout(super.send(command, args), REQUEST_TIMEOUT, `response to '${command}'`);
    }

    /**
     * The oldest unconsumed event of this type (matching `where`), waiting for it if needed.
     * `signal` (an AbortSignal) withdraws the wait.
     */
    nextEvent(type, { timeout = EVENT_TIMEOUT, where = () => true, signal } = {}) {
        const i = this.queue.findIndex((ev) => ev.event === type && where(ev));
        if (i >= 0) return Promise.resolve(this.queue.splice(i, 1)[0]);
        let waiter;
        const p = new Promise((resolve, reject) => {
            waiter = { type, where, resolve };
            this.waiters.push(waiter);
            signal?.addEventListener('abort', () => reject(new Error(`wait for '${type}' withdrawn`)), { once: true });
        });
        return withTimeout(p, timeout, `'${type}' event`).catch((err) => {
            this.waiters = this.waiters.filter((w) => w !== waiter);
            throw err;
        });
    }

    /**
     * Wait for `count` output events whose text matches `re`, failing at once if a
     * `stopped` event arrives meanwhile. Returns the matching outputs.
     */
    async outputsWithoutStop(re, count, { timeout = EVENT_TIMEOUT } = {}) {
        const abort = new AbortController();
        // Withdrawn (not timed out) when the outputs are in: only a real stop settles it.
        const stop = this.nextEvent('stopped', { timeout: 3_600_000, signal: abort.signal }).then(
            (ev) => assert.fail(`unexpected 'stopped' event: ${JSON.stringify(ev.body)}`),
            () => {},
        );
        try {
            const outputs = [];
            const collect = (async () => {
                while (outputs.length < count) {
                    const ev = await this.nextEvent('output', {
                        timeout, signal: abort.signal, where: (e) => re.test(e.body?.output ?? ''),
                    });
                    outputs.push(ev.body.output);
                }
            })();
            collect.catch(() => {}); // its failure is reported through the race below
            await Promise.race([collect, stop]);
            return outputs;
        } finally {
            abort.abort();
        }
    }

    /** Fail if an event of this type is queued or arrives within `ms`. */
    async noEvent(type, ms) {
        const early = this.queue.find((ev) => ev.event === type);
        assert.equal(early, undefined, `unexpected '${type}' event: ${JSON.stringify(early)}`);
        let got;
        try {
            got = await this.nextEvent(type, { timeout: ms });
        } catch {
            return;
        }
        assert.fail(`unexpected '${type}' event within ${ms} ms: ${JSON.stringify(got)}`);
    }

    /** Drop queued events of this type (e.g. output already checked). */
    drop(type) {
        this.queue = this.queue.filter((ev) => ev.event !== type);
    }

    /** Close the connection (no disconnect request). */
    close() {
        if (this._socket) {
            this._socket.destroy();
            this._socket = null;
        }
    }
}

/**
 * Connect a GantryClient to `g` and run the configuration sequence as VS Code does:
 * initialize; attach (not awaited: an adapter may answer it only after configurationDone);
 * wait for `initialized`; `configure(dc)` (setBreakpoints, setExceptionBreakpoints, ...);
 * configurationDone; then the attach response. Returns {dc, capabilities}.
 * The client is closed after the test. `request: 'launch'` sends launch instead of attach;
 * `args` replaces the attach arguments (default: what VS Code sends for launch.json.example).
 */
export async function attach(t, g, { configure = async () => {}, request = 'attach', args, busyRetryMs = 0 } = {}) {
    let dc;
    let init;
    // With busyRetryMs, a connection the server closes before answering `initialize` (it
    // may still be busy with the previous client) is retried until that much time passed.
    const deadline = Date.now() + busyRetryMs;
    for (;;) {
        dc = new GantryClient();
        const client = dc;
        if (t) t.after(() => client.close());
        await dc.connectTo(g.port, g.host);
        try {
            init = await initialize(dc);
            break;
        } catch (err) {
            if (Date.now() >= deadline) throw err;
            // A refused client gets an error response, then the server closes.
            const closed = await withTimeout(dc.whenClosed, 1000, 'close').then(() => true, () => false);
            if (!closed) throw err;
            await new Promise((resolve) => setTimeout(resolve, 100));
        }
    }
    // What VS Code sends for editors/vscode/launch.json.example.
    const attachArgs = args ?? { type: 'gantry', request, name: 'Attach to gantry', host: g.host, port: g.port };
    const attached = request === 'launch' ? dc.launchRequest(attachArgs) : dc.attachRequest(attachArgs);
    attached.catch(() => {}); // awaited below; avoid an unhandled rejection meanwhile
    await dc.nextEvent('initialized');
    await configure(dc);
    await dc.configurationDoneRequest();
    await attached;
    return { dc, capabilities: init.body ?? {} };
}

function initialize(dc) {
    return dc.initializeRequest({
        clientID: 'gantry-dap-tests',
        clientName: 'gantry DAP tests',
        adapterID: 'gantry',
        pathFormat: 'path',
        linesStartAt1: true,
        columnsStartAt1: true,
        supportsVariableType: true,
        supportsRunInTerminalRequest: false,
        locale: 'en',
    });
}

/** setBreakpoints for one file; `bps` are numbers (lines) or SourceBreakpoint objects. */
export async function setBreakpoints(dc, file, bps) {
    const breakpoints = bps.map((b) => (typeof b === 'number' ? { line: b } : b));
    const r = await dc.setBreakpointsRequest({
        source: { path: file, name: path.basename(file) },
        breakpoints,
        lines: breakpoints.map((b) => b.line),
    });
    assert.ok(Array.isArray(r.body?.breakpoints), 'setBreakpoints: body.breakpoints is an array');
    assert.equal(r.body.breakpoints.length, breakpoints.length, 'setBreakpoints: one answer per breakpoint');
    r.body.breakpoints.forEach((b, i) => {
        assert.equal(b.verified, true, `breakpoint on line ${breakpoints[i].line} is verified: ${JSON.stringify(b)}`);
    });
    return r.body.breakpoints;
}

/**
 * Wait for a `stopped` event, check its body against the contract and return
 * {event, frames, top} (top = the top stack frame).
 */
export async function expectStop(dc, reason, { timeout = EVENT_TIMEOUT } = {}) {
    const event = await dc.nextEvent('stopped', { timeout });
    const body = event.body ?? {};
    assert.equal(body.reason, reason, `stopped reason (event: ${JSON.stringify(body)})`);
    assert.equal(body.threadId, 1, 'stopped threadId');
    assert.equal(body.allThreadsStopped, true, 'stopped allThreadsStopped');
    assert.equal(typeof body.description, 'string', `stopped description (event: ${JSON.stringify(body)})`);
    const st = await dc.stackTraceRequest({ threadId: 1 });
    const frames = st.body?.stackFrames ?? [];
    assert.ok(frames.length > 0, 'stackTrace has at least one frame');
    return { event, frames, top: frames[0] };
}

/** Check that a stack frame is at `line` of `file`. */
export function assertAt(frame, file, line) {
    assert.ok(frame.source && typeof frame.source.path === 'string', `frame has a source path: ${JSON.stringify(frame)}`);
    assert.ok(path.isAbsolute(frame.source.path), `source path is absolute: ${frame.source.path}`);
    assert.ok(samePath(frame.source.path, file), `frame in ${file}, not ${frame.source.path}`);
    if (line !== undefined) assert.equal(frame.line, line, `frame line (frame: ${JSON.stringify(frame)})`);
}

/** evaluate → response body. */
export async function evaluate(dc, expression, frameId, context = 'repl') {
    const r = await dc.evaluateRequest({ expression, frameId, context });
    return r.body;
}

/** evaluate → the number it shows. */
export async function evalNumber(dc, expression, frameId) {
    const body = await evaluate(dc, expression, frameId);
    const n = Number(body.result);
    assert.ok(Number.isFinite(n), `${expression} evaluates to a number, not ${JSON.stringify(body.result)}`);
    return n;
}

/** The simulation time seen from a stopped frame. */
export function simTime(dc, frameId) {
    return evalNumber(dc, 'sim.getSimulationTime()', frameId);
}

/** scopes → {Locals: scope, Upvalues: scope, Globals: scope}; checks the three names. */
export async function scopes(dc, frameId) {
    const r = await dc.scopesRequest({ frameId });
    const list = r.body?.scopes ?? [];
    assert.deepEqual(list.map((s) => s.name), ['Locals', 'Upvalues', 'Globals'], 'scope names');
    return Object.fromEntries(list.map((s) => [s.name, s]));
}

/** variables → Map name → Variable. */
export async function variables(dc, variablesReference) {
    const r = await dc.variablesRequest({ variablesReference });
    const list = r.body?.variables ?? [];
    return new Map(list.map((v) => [v.name, v]));
}

/** Assert that `promise` (a request) fails, and return the error's message. */
export async function rejects(promise, what) {
    let message;
    await assert.rejects(promise, (err) => {
        message = err.message;
        return true;
    }, `${what} should fail`);
    assert.ok(typeof message === 'string' && message.length > 0, `${what}: the failed response has a message`);
    return message;
}
