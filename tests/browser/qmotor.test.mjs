// Browser test of the QMotor window (-qmotor): its URL is printed, a plot receives samples of the
// arm's joint positions, and the tunable parameters are there.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { withProgram, openViewer, waitInPage, sleep } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;

describe('QMotor window on work_cell -qmotor', () => {
  const ctx = withProgram('work_cell', ['-gui-port', '0', '-qmotor', '--arm-only']);

  it('prints the QMotor URL and plots the joint positions live', async () => {
    const m = ctx.program.output().match(/rp: QMotor at (\S+)/);
    assert.ok(m, ctx.program.output());
    assert.equal(m[1], ctx.url.replace('index.html', 'qmotor.html'));
    const page = await openViewer(ctx.browser, `${m[1]}?object=puma`, { width: 1100, height: 640 });
    await page.waitForSelector('.u-wrap canvas');
    assert.deepEqual(await page.evaluate(() => window.rp.series), ['q[0]', 'q[1]', 'q[2]', 'q[3]', 'q[4]', 'q[5]']);
    const n0 = await page.evaluate(() => window.rp.samples);
    await waitInPage(page, (n) => window.rp.samples > n + 30, n0);
    const got = await page.evaluate(() => ({ n: window.rp.samples, t: window.rp.data[0], q: window.rp.data[1] }));
    assert.ok(got.t[got.t.length - 1] > got.t[0], 'time does not advance');
    assert.ok(Math.max(...got.q) - Math.min(...got.q) > 1e-3, 'joint 1 does not move in the plot');
    // Add the torques: six more series.
    await page.check('#fields input[data-field="tau"]');
    await waitInPage(page, () => window.rp.series.length === 12);
    assert.ok(await page.locator('.panel input[data-field="kp"]').count() === 6, 'no tunable kp in the window');
    await sleep(500);
    if (shots) await page.screenshot({ path: join(shots, 'qmotor.png') });
    await page.close();
  });
});
