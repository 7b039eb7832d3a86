// Browser test of rp-teachpendant (Figure 20): zero-gravity mode, pushing the simulated arm by
// dragging its end-effector, storing positions, moving back to one, cycling through them, and
// zero-gravity mode after a motion leaving the arm where it was pushed to.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { withProgram, waitInPage, sleep } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;

describe('rp-teachpendant', () => {
  const ctx = withProgram('rp-teachpendant', ['-gui-port', '0']);
  const joints = () => ctx.page.evaluate(() => {
    const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
    return o.values.slice(0, 6);
  });
  const distance = (a, b) => Math.sqrt(a.reduce((s, x, i) => s + (x - b[i]) ** 2, 0));
  const state = () => ctx.page.evaluate(() => window.rp.state);
  const nearStored = (index, tolerance) => waitInPage(ctx.page, ([i, tol]) => {
    const s = window.rp.state;
    const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
    const q = s.positions[i].q;
    return !s.busy && Math.sqrt(q.reduce((acc, x, k) => acc + (x - o.values[k]) ** 2, 0)) < tol;
  }, [index, tolerance], 20000);

  it('opens the Teachpendant page', async () => {
    assert.match(ctx.url, /\/teachpendant\.html$/);
    assert.match(ctx.program.output(), /rp-teachpendant: teaching puma \(Puma560, 6 joints\)/);
    await waitInPage(ctx.page, () => window.rp.state !== null);
    assert.deepEqual((await state()).positions, []);
  });

  it('stores a position, then in zero-gravity mode a Shift-drag pushes the arm away', async () => {
    await ctx.page.click('#store');
    await waitInPage(ctx.page, () => window.rp.state.positions.length === 1);
    const q0 = await joints();
    await ctx.page.click('#zero-g');
    await waitInPage(ctx.page, () => window.rp.state.zeroGravity === true);
    const ee = await ctx.page.evaluate(() => window.rp.endEffectorOnScreen());
    await ctx.page.keyboard.down('Shift');
    await ctx.page.mouse.move(ee.x, ee.y);
    await ctx.page.mouse.down();
    await ctx.page.mouse.move(ee.x + 25, ee.y + 12, { steps: 5 });
    await sleep(1500); // the spring-damper brings the end-effector under the pointer
    await ctx.page.mouse.up();
    await ctx.page.keyboard.up('Shift');
    await sleep(500);
    const q1 = await joints();
    assert.ok(distance(q0, q1) > 0.05, `the arm moved only ${distance(q0, q1)} rad`);
    if (shots) await ctx.page.screenshot({ path: join(shots, 'teachpendant.png') });
    await ctx.page.click('#store');
    await waitInPage(ctx.page, () => window.rp.state.positions.length === 2);
    const s = await state();
    assert.deepEqual(s.positions.map((p) => p.name), ['P1', 'P2']);
    assert.ok(distance(s.positions[0].q, s.positions[1].q) > 0.05);
  });

  it('moves back to a stored position with the trajectory generator', async () => {
    // The table's rows outlive state updates (the page reads the state every 500 ms). Before, each
    // update replaced every button: a click on Go could land on a button just taken out of the page.
    await ctx.page.evaluate(() => {
      window.goBefore = document.querySelector('#positions tr[data-index="0"] button.go');
      window.stateBefore = window.rp.state;
    });
    await waitInPage(ctx.page, () => window.rp.state !== window.stateBefore);
    assert.ok(await ctx.page.evaluate(() => window.goBefore.isConnected), 'a state update replaced the Go button');
    await ctx.page.click('#positions tr[data-index="0"] button.go');
    await waitInPage(ctx.page, () => window.rp.state.busy || window.rp.state.zeroGravity === false);
    await nearStored(0, 0.01);
    assert.equal((await state()).zeroGravity, false);
  });

  it('cycles through all positions and refuses bad requests', async () => {
    await ctx.page.click('#cycle-all');
    // The program's own state, read every 20 ms: the motion to P2 (0.1 rad) can end between two of
    // the page's reads, 500 ms apart (under ASan on a loaded machine the page never saw it).
    const sawP2 = await ctx.page.evaluate(async () => {
      for (const end = Date.now() + 15000; Date.now() < end;) {
        const s = JSON.parse((await window.rp.conn.message('teachpendant', 'read', '')).reply);
        if (s.busy && s.target === 'P2') return true;
        await new Promise((r) => setTimeout(r, 20));
      }
      return false;
    });
    assert.ok(sawP2, 'the cycle never moved to P2');
    await nearStored(1, 0.01);
    const bad = await ctx.page.evaluate(async () => {
      const out = [];
      for (const [t, p] of [['goto', { index: 7 }], ['push', { force: [1e6, 0, 0] }], ['cycle', { times: 0 }], ['zeroGravity', 'yes'],
        ['cycle', { times: 4294967297 }], ['cycle', { times: -4294967295 }], ['cycle', { indices: new Array(1001).fill(0) }],
        ['push', { force: [0, 61, 0] }]])
        out.push(await window.rp.conn.message('teachpendant', t, JSON.stringify(p)).then(() => 'accepted', (e) => e.message));
      return out;
    });
    assert.match(bad[0], /no stored position 7/);
    assert.match(bad[1], /within/);
    assert.match(bad[2], /'times' must be 1 to 100/);
    assert.match(bad[3], /true or false/);
    // 'times' is checked whole (4294967297 used to wrap to 1 and start cycling), and the list of
    // indices is bounded (30,000 indices 100 times took half a gigabyte).
    assert.match(bad[4], /'times' must be 1 to 100/);
    assert.match(bad[5], /'times' must be 1 to 100/);
    assert.match(bad[6], /at most 1000 positions/);
    assert.match(bad[7], /within \+-60 N/, 'no client pushes harder than the page (60 N)');
  });

  // Until the last motion has ended, as the program says it (the page's state frame may be half a
  // second old).
  async function idle() {
    for (const end = Date.now() + 20000; ;) {
      const now = JSON.parse((await ctx.page.evaluate(() => window.rp.conn.message('teachpendant', 'read', ''))).reply);
      if (!now.busy) return;
      assert.ok(Date.now() < end, 'the last motion did not end');
      await new Promise((r) => setTimeout(r, 50));
    }
  }

  // Go to the stored position farthest from the arm, and Stop as soon as the arm has started
  // to move; checks where the arm comes to rest. Returns that position's index.
  async function goAndStop(attempt = 0) {
    await idle();
    const q = await joints();
    const { positions } = await state();
    let far = 0;
    positions.forEach((p, i) => { if (distance(p.q, q) > distance(positions[far].q, q)) far = i; });
    const D = distance(positions[far].q, q);
    assert.ok(D > 0.05, `the stored positions are only ${D} rad from here`);
    // Go, and Stop as soon as the arm has started to move (the page watches the state frames).
    // Before, Stop only ended a cycle after the current motion: the arm went on to the target.
    // The reply to Stop says where and how fast the arm was when the brake took over, and each
    // joint's braking deceleration (the program's own state: the page's state frame can be 0.1 s
    // old on a loaded machine, which made a bound from it fail).
    const { stoppedAt, brake } = await ctx.page.evaluate(([i, start, d]) => new Promise((resolve, reject) => {
      const puma = () => window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma').values;
      const moved = () => Math.sqrt(start.reduce((acc, x, k) => acc + (x - puma()[k]) ** 2, 0));
      window.rp.conn.message('teachpendant', 'goto', JSON.stringify({ index: i })).catch(reject);
      const timer = setInterval(() => {
        if (moved() < 0.02 * d) return;
        clearInterval(timer);
        const m = moved();
        window.rp.conn.message('teachpendant', 'stop', '').then((r) => {
          resolve({ stoppedAt: m, brake: JSON.parse(r.reply).brake });
        }, reject);
      }, 5);
    }), [far, q, D]);
    console.log(`Stop sent ${stoppedAt} rad into a motion of ${D} rad`);
    // On a loaded machine (a sanitizer build) the frames the page watches can lag so far that the
    // motion has ended when the page sends Stop: no Stop to judge. The arm is then at the target,
    // and the go is tried again from there (at most three times: a Stop that is refused, as every
    // Stop after the first once was, fails all three).
    if (!brake && attempt < 2) {
      console.log('the motion had ended before Stop was sent: again');
      return goAndStop(attempt + 1);
    }
    assert.ok(brake, 'the Stop reply does not say where the brake took over (the motion had ended?)');
    await waitInPage(ctx.page, () => window.rp.state && !window.rp.state.busy, null, 20000);
    await waitInPage(ctx.page, () => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      return o.values.slice(6, 12).every((v) => Math.abs(v) < 1e-3);
    }, null, 20000);
    const rest = await joints();
    // Each joint comes to rest within its braking distance v^2 / (2 a) of where the brake took
    // over (plus the servo loop's tracking error), and the arm stops short of the target whenever
    // that much is left to go. Before, Stop only ended a cycle after the current motion and the
    // arm went on to within 0.0002 rad of the target.
    const braking = brake.qd.map((v, k) => (v * v) / (2 * brake.deceleration[k]));
    console.log(`brake from ${brake.qd.map((v) => v.toFixed(3))} rad/s: braking distances ${braking.map((b) => b.toFixed(4))} rad`);
    rest.forEach((x, k) => assert.ok(Math.abs(x - brake.q[k]) <= braking[k] + 0.01,
      `joint ${k + 1} went ${Math.abs(x - brake.q[k])} rad after the brake took over (braking distance ${braking[k]} rad)`));
    const remaining = distance(brake.q, positions[far].q);
    const reach = Math.sqrt(braking.reduce((a, b) => a + (b + 0.01) ** 2, 0));
    console.log(`when the brake took over ${remaining} rad remained; it can take the arm ${reach} rad further`);
    if (remaining > reach + 0.01) {
      assert.ok(distance(rest, positions[far].q) > 0.01,
        `the arm went on to ${distance(rest, positions[far].q)} rad from the target (${remaining} rad remained at Stop)`);
    }
    return far;
  }

  it('Stop stops a motion at once: the arm comes to rest short of the target', async () => {
    const far = await goAndStop();
    // Go still works after a Stop.
    await ctx.page.evaluate((i) => window.rp.conn.message('teachpendant', 'goto', JSON.stringify({ index: i })), far);
    await nearStored(far, 0.01);
  });

  it('Stop works every time, not only the first', async () => {
    // Each Stop builds a brake while the last one still exists: under one fixed name every Stop
    // after the first was refused ("an object named 'teachpendant.brake' already exists") and the
    // arm went on to the target. Each time from a stored position, so that the other is the
    // whole distance between them away (a Stop leaves the arm between them).
    for (const from of [0, 1]) {
      await idle();
      await ctx.page.evaluate((i) => window.rp.conn.message('teachpendant', 'goto', JSON.stringify({ index: i })), from);
      await nearStored(from, 0.01);
      await goAndStop();
    }
  });

  it('a push force lapses when the page stops repeating it', async () => {
    // One push, as from a page closed in the middle of a drag: the program zeroes the force
    // once it has not been repeated for 250 ms (the page repeats it every 50 ms).
    const reply = await ctx.page.evaluate(() =>
      window.rp.conn.message('teachpendant', 'push', JSON.stringify({ force: [40, 0, 0] })).then((r) => JSON.parse(r.reply)));
    assert.equal(reply.pushing, true);
    const read = () => ctx.page.evaluate(() =>
      window.rp.conn.message('teachpendant', 'read', '').then((r) => JSON.parse(r.reply)));
    const deadline = Date.now() + 20000;
    let now = await read();
    while (now.pushing && Date.now() < deadline) now = await read();
    assert.equal(now.pushing, false);
    assert.equal(now.pushesLapsed, reply.pushesLapsed + 1);
    // A push repeated holds, and a zero force ends it.
    for (let i = 0; i < 5; ++i) {
      const r = await ctx.page.evaluate(() => window.rp.conn.message('teachpendant', 'push', JSON.stringify({ force: [5, 0, 0] }))
        .then((x) => JSON.parse(x.reply)));
      assert.equal(r.pushing, true);
    }
    const end = await ctx.page.evaluate(() => window.rp.conn.message('teachpendant', 'push', JSON.stringify({ force: [0, 0, 0] }))
      .then((x) => JSON.parse(x.reply)));
    assert.equal(end.pushing, false);
  });

  it('zero-gravity mode after a motion: switched off, the arm stays where it was pushed to', async () => {
    // The last Go left its generator holding the stored position. In zero-gravity mode a push
    // moves the arm; when the mode ends the arm must be held there. (Before, the generator left
    // set took over again and pulled the arm straight back to the stored position.)
    const send = (type, payload) => ctx.page.evaluate(([t, p]) =>
      window.rp.conn.message('teachpendant', t, p).then((r) => JSON.parse(r.reply)), [type, payload]);
    const atRest = () => waitInPage(ctx.page, () => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      return o.values.slice(6, 12).every((v) => Math.abs(v) < 1e-3);
    }, null, 20000);
    await atRest();
    const before = await joints();
    assert.equal((await send('zeroGravity', 'true')).zeroGravity, true);
    // One push, not repeated: the program lets it lapse after 250 ms of its own time (a push
    // repeated from here would last as long as this page's messages take on a loaded machine).
    assert.equal((await send('push', JSON.stringify({ force: [20, 0, 0] }))).pushing, true);
    const deadline = Date.now() + 20000;
    while ((await send('read', '')).pushing && Date.now() < deadline) await sleep(20);
    // The page's frames may lag the program on a loaded machine, and a frame from before the
    // push shows the arm at rest too (CI's ASan run once found the arm at rest 0.00007 rad from
    // where it stood before the push; the Stop test above has seen such lag): the motion is
    // awaited in the page first, then the rest after it. A push that never moves the arm still
    // fails below, after the wait (checked with a push of 0.5 N: 'moved only 0 rad').
    await waitInPage(ctx.page, (b) => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      return Math.sqrt(b.reduce((acc, x, k) => acc + (x - o.values[k]) ** 2, 0)) > 0.01;
    }, before, 20000).catch(() => {});
    await atRest();
    const pushed = await joints();
    const moved = distance(before, pushed);
    assert.ok(moved > 0.01, `the push moved the arm only ${moved} rad`);
    assert.equal((await send('zeroGravity', 'false')).zeroGravity, false);
    await sleep(1000);
    await atRest();
    const after = await joints();
    assert.ok(distance(pushed, after) < 0.25 * moved,
      `zero-gravity mode off moved the arm ${distance(pushed, after)} rad (back toward the stored position, ${moved} rad away)`);
  });
});
