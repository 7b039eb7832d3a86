// Browser test of rp-jointmove (Figure 19): a slider moves the simulated joint through the servo
// loop; gains tuned in the viewer's control panel reach the servo loop (with the gains of a joint
// at zero its servo torque at rest becomes zero).
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { withProgram, openViewer, waitInPage } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;
const DEG = Math.PI / 180;

describe('rp-jointmove', () => {
  const ctx = withProgram('rp-jointmove', ['-gui-port', '0']);

  const jointAngle = (i) => ctx.page.evaluate((j) => window.rp.frame.objects.find((o) => window.rp.scene.objects[o.index].name === 'puma').values[j], i);
  const slide = (i, degrees) => ctx.page.evaluate(([j, d]) => {
    const s = document.querySelector(`input[data-joint="${j}"]`);
    s.value = String(d);
    s.dispatchEvent(new Event('input'));
  }, [i, degrees]);

  it('opens the Joint Move page with a slider per joint of the Puma', async () => {
    assert.match(ctx.url, /\/jointmove\.html$/);
    assert.match(ctx.program.output(), /rp-jointmove: moving puma \(Puma560, 6 joints\)/);
    await ctx.page.waitForSelector('input[data-joint="5"]');
    assert.equal(await ctx.page.locator('input[type="range"]').count(), 6);
  });

  it('a slider moves the simulated joint, and the arm follows at once', async () => {
    const start = await jointAngle(0);
    const t0 = Date.now();
    await slide(0, 40);
    // (No time limit asserted: the machine may be loaded. The delay is printed.)
    await waitInPage(ctx.page, ([s0, tol]) => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      return Math.abs(o.values[0] - s0) > tol;
    }, [start, 0.5 * DEG]);
    console.log(`joint 1 moved by 0.5 deg ${Date.now() - t0} ms after the slider`);
    await waitInPage(ctx.page, (target) => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      return Math.abs(o.values[0] - target) < 0.005 && Math.abs(o.values[6]) < 0.01;
    }, 40 * DEG, 15000);
    if (shots) await ctx.page.screenshot({ path: join(shots, 'joint-move.png') });
  });

  it('refuses a target outside the joint limits, and the sliders end a margin inside them', async () => {
    const err = await ctx.page.evaluate(() => window.rp.conn.message('jointmove', 'setJoint', JSON.stringify({ joint: 0, value: 100 }))
      .then(() => 'accepted', (e) => e.message));
    assert.match(err, /outside/);
    // A joint index is checked whole: 4294967297 used to be cut to 32 bits and move joint 2.
    const target = async () => JSON.parse((await ctx.page.evaluate(() => window.rp.conn.message('jointmove', 'read', ''))).reply).target;
    const before = await target();
    for (const joint of [4294967297, -4294967295, 6, -1]) {
      const e = await ctx.page.evaluate((j) => window.rp.conn.message('jointmove', 'setJoint', JSON.stringify({ joint: j, value: 0.5 }))
        .then(() => 'accepted', (x) => x.message), joint);
      assert.match(e, /'joint' must be an integer in 0\.\.5/, `joint ${joint}`);
    }
    assert.deepEqual(await target(), before);
    const limits = await ctx.page.evaluate(() => {
      const puma = window.rp.scene.objects.find((o) => o.name === 'puma');
      return [...document.querySelectorAll('input[data-joint]')].map((s, i) => ({
        qmin: puma.qmin[i], qmax: puma.qmax[i], min: Number(s.min), max: Number(s.max) }));
    });
    assert.equal(limits.length, 6);
    for (const [i, l] of limits.entries()) {
      const margin = Math.min(0.05 * (l.qmax - l.qmin), 5 * DEG);
      assert.ok(Math.abs(l.min * DEG - (l.qmin + margin)) < 1e-9, `joint ${i + 1}: slider starts at ${l.min} deg`);
      assert.ok(Math.abs(l.max * DEG - (l.qmax - margin)) < 1e-9, `joint ${i + 1}: slider ends at ${l.max} deg`);
      // A target on the limit itself is refused by the program; one at the slider's end is taken.
      const onLimit = await ctx.page.evaluate(([j, v]) => window.rp.conn.message('jointmove', 'setJoint',
        JSON.stringify({ joint: j, value: v })).then(() => 'accepted', (e) => e.message), [i, l.qmax]);
      assert.match(onLimit, /limits less a margin/);
    }
    const atEnd = await ctx.page.evaluate((v) => window.rp.conn.message('jointmove', 'setJoint',
      JSON.stringify({ joint: 5, value: v })).then(() => 'accepted', (e) => e.message), limits[5].max * DEG - 1e-9);
    assert.equal(atEnd, 'accepted');
    await ctx.page.evaluate(() => window.rp.conn.message('jointmove', 'setJoint', JSON.stringify({ joint: 5, value: 0 })));
  });

  it('gains set to zero in the control panel reach the servo loop: joint 1\'s torque drops to zero', async () => {
    // At rest (setpoint velocity exactly 0) joint 1's servo torque is kp e - kd qd + ki integral
    // (the friction feed-forward and the gravity torque of the vertical axis are 0).
    const tau0 = () => ctx.page.evaluate(() => window.rp.frame.objects.find((o) => window.rp.scene.objects[o.index].name === 'puma').values[12]);
    const before = await tau0();
    assert.ok(Math.abs(before) > 1e-6, `joint 1's torque at rest is already ${before} N m`);
    const viewer = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'));
    await viewer.evaluate(() => window.rp.openPanel('puma'));
    const panel = viewer.locator('.panel[data-panel="puma"]');
    for (const gain of ['kp', 'kd', 'ki']) {
      const input = panel.locator(`input[data-field="${gain}"][data-index="0"]`);
      await input.fill('0');
      await input.dispatchEvent('change');
    }
    await waitInPage(viewer, () => ['kp', 'kd', 'ki'].every((g) => window.rp.scene.objects.find((o) => o.name === 'puma')
      .panel.fields.find((f) => f.name === g).value[0] === 0));
    try {
      await waitInPage(ctx.page, () => Math.abs(window.rp.frame.objects.find((o) => window.rp.scene.objects[o.index].name === 'puma').values[12]) < 1e-9);
    } catch (e) {
      const v = await ctx.page.evaluate(() => window.rp.frame.objects.find((o) => window.rp.scene.objects[o.index].name === 'puma').values);
      throw new Error(`joint 1's torque did not drop to 0: state ${JSON.stringify(v)}`);
    }
    const after = await tau0();
    console.log(`joint 1 torque at rest: ${before} N m with the default gains, ${after} N m with kp = kd = ki = 0`);
    await viewer.close();
  });
});
