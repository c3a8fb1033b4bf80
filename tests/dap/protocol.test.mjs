// Bad DAP input on a raw TCP connection (not DebugClient): malformed JSON, an unknown
// command and an absurd Content-Length get failed responses, and none of it stops a
// well-behaved client from attaching afterwards.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import {
    BUBBLE_ROB_SCENE, BUBBLE_ROB_SCRIPT, EVENT_TIMEOUT, TEST_TIMEOUT,
    assertAt, attach, expectStop, lineOf, setBreakpoints, startGantry,
} from './gantry.mjs';

const SCRIPT = BUBBLE_ROB_SCRIPT;
const ACTUATION = lineOf(SCRIPT, 'if (result>0) then backUntilTime');

/** A raw DAP connection: writes bytes, parses `Content-Length` frames coming back. */
class RawDap {
    constructor(sock) {
        this.sock = sock;
        this.buf = Buffer.alloc(0);
        this.messages = [];
        this.waiters = [];
        this.errors = [];
        this.closed = new Promise((resolve) => sock.once('close', resolve));
        sock.on('data', (data) => this.feed(data));
        sock.on('error', (err) => this.errors.push(err));
    }

    static connect(port, host) {
        return new Promise((resolve, reject) => {
            const sock = net.createConnection({ port, host });
            sock.once('connect', () => resolve(new RawDap(sock)));
            sock.once('error', reject);
        });
    }

    feed(data) {
        this.buf = Buffer.concat([this.buf, data]);
        for (;;) {
            const end = this.buf.indexOf('\r\n\r\n');
            if (end < 0) return;
            const header = this.buf.subarray(0, end).toString('latin1');
            const m = /^Content-Length:\s*(\d+)\s*$/im.exec(header);
            if (!m) {
                this.deliver({ parseError: `frame without Content-Length: ${JSON.stringify(header)}` });
                this.buf = this.buf.subarray(end + 4);
                continue;
            }
            const length = Number(m[1]);
            if (this.buf.length < end + 4 + length) return;
            const body = this.buf.subarray(end + 4, end + 4 + length).toString('utf8');
            this.buf = this.buf.subarray(end + 4 + length);
            try {
                this.deliver(JSON.parse(body));
            } catch (err) {
                this.deliver({ parseError: `invalid JSON from the server (${err.message}): ${body}` });
            }
        }
    }

    deliver(msg) {
        const i = this.waiters.findIndex((w) => w.where(msg));
        if (i >= 0) this.waiters.splice(i, 1)[0].resolve(msg);
        else this.messages.push(msg);
    }

    write(bytes) {
        this.sock.write(bytes);
    }

    request(obj) {
        const json = JSON.stringify(obj);
        this.write(`Content-Length: ${Buffer.byteLength(json, 'utf8')}\r\n\r\n${json}`);
    }

    /** The next response from the server (events are skipped). */
    response(what, timeout = EVENT_TIMEOUT) {
        const where = (m) => m.parseError !== undefined || m.type === 'response';
        const i = this.messages.findIndex(where);
        let p;
        if (i >= 0) {
            p = Promise.resolve(this.messages.splice(i, 1)[0]);
        } else {
            p = new Promise((resolve, reject) => {
                const timer = setTimeout(() => {
                    this.waiters = this.waiters.filter((x) => x !== w);
                    reject(new Error(`no response to ${what} within ${timeout} ms`));
                }, timeout);
                const w = { where, resolve: (m) => { clearTimeout(timer); resolve(m); } };
                this.waiters.push(w);
            });
        }
        return p.then((m) => {
            assert.equal(m.parseError, undefined, m.parseError);
            return m;
        });
    }
}

test('bad DAP input gets failed responses; the server stays usable', { timeout: TEST_TIMEOUT }, async (t) => {
    const g = await startGantry(t, BUBBLE_ROB_SCENE);
    const raw = await RawDap.connect(g.port, g.host);
    t.after(() => raw.sock.destroy());

    // Malformed JSON in a well-formed frame.
    raw.write('Content-Length: 5\r\n\r\n{oops');
    const r0 = await raw.response('malformed JSON');
    assert.equal(r0.success, false, `malformed JSON: ${JSON.stringify(r0)}`);
    assert.equal(r0.request_seq, 0);

    // An unknown command.
    raw.request({ seq: 1, type: 'request', command: 'flyToTheMoon' });
    const r1 = await raw.response('an unknown command');
    assert.equal(r1.success, false, `unknown command: ${JSON.stringify(r1)}`);
    assert.equal(r1.request_seq, 1);
    assert.match(r1.message ?? '', /flyToTheMoon/, `the message names the command: ${JSON.stringify(r1)}`);

    // The connection is still usable.
    raw.request({ seq: 2, type: 'request', command: 'threads' });
    const r2 = await raw.response('threads');
    assert.equal(r2.request_seq, 2, `threads answered: ${JSON.stringify(r2)}`);
    assert.equal(r2.command, 'threads');
    if (r2.success) {
        assert.deepEqual(r2.body.threads.map(({ id, name }) => ({ id, name })), [{ id: 1, name: 'simulation' }]);
    }

    // A frame too large to accept: a failed response, then the server closes the connection.
    raw.write('Content-Length: 99999999999\r\n\r\n');
    const r3 = await raw.response('Content-Length: 99999999999');
    assert.equal(r3.success, false, `huge Content-Length: ${JSON.stringify(r3)}`);
    let timer;
    await Promise.race([
        raw.closed,
        new Promise((_, reject) => {
            timer = setTimeout(() => reject(new Error('the server did not close the connection within 5 s')), 5000);
        }),
    ]).finally(() => clearTimeout(timer));
    assert.ok(g.alive, 'gantry keeps running');

    // Nothing else changed: a fresh DebugClient attaches (arguments {}) and hits a breakpoint.
    const { dc } = await attach(t, g, { args: {}, busyRetryMs: 3000, configure: (dc) => setBreakpoints(dc, SCRIPT, [ACTUATION]) });
    const { top } = await expectStop(dc, 'breakpoint');
    assertAt(top, SCRIPT, ACTUATION);
});
