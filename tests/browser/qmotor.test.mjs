// Browser test of the QMotor window (-qmotor): its URL is printed, a plot receives samples of the
// arm's joint positions, and the tunable parameters are there; the plot pauses, zooms and pans
// without the next frames undoing it, reads the values under the cursor and exports a PNG; with
// -log FILE a log variable picked from the list of the program's log columns is plotted live, and
// Stop/Start logging leave a gap in the log file; bad log requests are refused.
import { describe, it, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
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
    // The arm's first motion may start a while after the page opens (a slow sanitizer build):
    // wait until the plot shows joint 1 moving.
    await waitInPage(page, () => Math.max(...window.rp.data[1]) - Math.min(...window.rp.data[1]) > 1e-3);
    const got = await page.evaluate(() => ({ n: window.rp.samples, t: window.rp.data[0], q: window.rp.data[1] }));
    assert.ok(got.t[got.t.length - 1] > got.t[0], 'time does not advance');
    assert.ok(Math.max(...got.q) - Math.min(...got.q) > 1e-3, 'joint 1 does not move in the plot');
    // Add the torques: six more series.
    await page.check('#fields input[data-field="tau"]');
    await waitInPage(page, () => window.rp.series.length === 12);
    assert.ok(await page.locator('.panel input[data-field="kp"]').count() === 6, 'no tunable kp in the window');
    // Without -log there is no log to plot or start: the window says so.
    await waitInPage(page, () => document.getElementById('log-state').textContent.includes('-log FILE'));
    await sleep(500);
    if (shots) await page.screenshot({ path: join(shots, 'qmotor.png') });
    await page.close();
  });
});

describe('QMotor log variables on work_cell -log FILE -qmotor', () => {
  const dir = mkdtempSync(join(tmpdir(), 'rp-qmotor-log-'));
  const logFile = join(dir, 'qmotor-log.csv');
  const ctx = withProgram('work_cell', ['-gui-port', '0', '-qmotor', '--arm-only', '-log', logFile]);
  after(() => rmSync(dir, { recursive: true, force: true }));

  it('plots a picked log variable and stops and starts logging to the file', async () => {
    const url = ctx.program.output().match(/rp: QMotor at (\S+)/)[1];
    const page = await openViewer(ctx.browser, `${url}?object=puma`, { width: 1100, height: 900 });
    // The list holds the program's log columns; pick one.
    await page.waitForSelector('#log-columns input[data-column="puma.q[1]"]');
    const info = await page.evaluate(() => window.rp.logInfo);
    assert.equal(info.file, logFile);
    assert.equal(info.logging, true);
    for (const c of ['puma.q[0]', 'puma.qd[5]', 'puma.tau[2]', 'puma.qdes[3]']) assert.ok(info.columns.includes(c), c);
    await page.check('#log-columns input[data-column="puma.q[1]"]');
    await page.fill('#log-filter', 'tau');
    await page.check('#log-columns input[data-column="puma.tau[1]"]');
    await waitInPage(page, () => window.rp.logSeries.length === 2 && window.rp.logData['puma.q[1]'].t.length > 300);
    const last = () => page.evaluate(() => { const t = window.rp.logData['puma.q[1]'].t; return t[t.length - 1]; });
    const q = await page.evaluate(() => window.rp.logData['puma.q[1]']);
    for (let i = 1; i < q.t.length; ++i) assert.ok(q.t[i] > q.t[i - 1], 'sample times do not increase');
    // Samples at the servo rate (1 kHz), not the 60 Hz display rate.
    assert.ok((q.t.length - 1) / (q.t[q.t.length - 1] - q.t[0]) > 500, 'fewer than 500 samples a second');
    // The arm pauses between moves: wait until the plotted joint has moved.
    await waitInPage(page, () => { const v = window.rp.logData['puma.q[1]'].v; return Math.max(...v) - Math.min(...v) > 1e-3; });
    await page.waitForSelector('#log-plot .u-wrap canvas');
    if (shots) await page.screenshot({ path: join(shots, 'qmotor-log.png'), fullPage: true });

    // Stop logging, let a second of samples pass (they still reach the plot), start again.
    await page.click('#log-stop');
    await waitInPage(page, () => document.getElementById('log-state').textContent === 'stopped');
    const tStop = await last();
    await waitInPage(page, (t) => { const a = window.rp.logData['puma.q[1]'].t; return a[a.length - 1] > t + 1.0; }, tStop);
    const tStart = await last();
    await page.click('#log-start');
    await waitInPage(page, () => document.getElementById('log-state').textContent === 'logging');
    await waitInPage(page, (t) => { const a = window.rp.logData['puma.q[1]'].t; return a[a.length - 1] > t + 1.0; }, tStart);

    // Bad log requests are refused with a message; the program goes on.
    const refused = await page.evaluate(async () => {
      const out = [];
      for (const m of [{ type: 'logging', on: 'yes' }, { type: 'logging' }, { type: 'logSubscribe', columns: 'puma.q[1]' },
        { type: 'logSubscribe', columns: ['no.such[0]'] }, { type: 'logSubscribe', columns: [7] },
        { type: 'logSubscribe', columns: Array.from({ length: 40 }, (_, i) => `puma.q[${i % 6}]`) }]) {
        try {
          await window.rp.conn.request(m);
          out.push('accepted');
        } catch (e) {
          out.push(e.message);
        }
      }
      return out;
    });
    assert.equal(refused.length, 6);
    for (const r of refused) assert.notEqual(r, 'accepted', JSON.stringify(refused));
    assert.match(refused[0], /'on' must be true or false/);
    assert.match(refused[3], /'no\.such\[0\]' is not a column/);
    await page.close();

    // The file: rows before the stop and after the start, none in between.
    await ctx.program.stop();
    const rows = readFileSync(logFile, 'utf8').trim().split('\n');
    const header = rows[0].split(',');
    assert.equal(header[0], 't');
    assert.ok(header.includes('puma.q[1]'));
    const times = rows.slice(1).map((r) => Number(r.split(',')[0]));
    const gap = times.filter((t) => t > tStop + 0.3 && t < tStart);
    assert.equal(gap.length, 0, `${gap.length} rows logged while logging was stopped (${tStop}..${tStart})`);
    assert.ok(times.some((t) => t < tStop), 'no rows before the stop');
    assert.ok(times.some((t) => t > tStart + 0.3), 'no rows after the start');
    assert.ok(times.filter((t) => t <= tStop).length > 300, 'too few rows before the stop');
  });
});

describe('QMotor plot controls on work_cell -qmotor', () => {
  const ctx = withProgram('work_cell', ['-gui-port', '0', '-qmotor', '--arm-only']);

  it('pause, zoom and pan that the next frames do not undo, a cursor readout, Live, and a PNG export', async () => {
    const url = ctx.program.output().match(/rp: QMotor at (\S+)/)[1];
    const page = await openViewer(ctx.browser, `${url}?object=puma`, { width: 1100, height: 700 });
    await page.waitForSelector('#plot .u-over');
    await waitInPage(page, () => window.rp.samples > 60);
    const shown = () => page.evaluate(() => {
      const p = window.rp.plot;
      return { last: p.data[0][p.data[0].length - 1], min: p.scales.x.min, max: p.scales.x.max };
    });
    // Pause: samples keep coming, the plot keeps what it showed.
    await page.click('#plot-pause');
    const paused = await shown();
    const n0 = await page.evaluate(() => window.rp.samples);
    await waitInPage(page, (n) => window.rp.samples > n + 30, n0);
    assert.deepEqual(await shown(), paused, 'the paused plot changed');
    assert.equal(await page.textContent('#plot-mode'), 'paused');
    // Live: the plot follows the samples again.
    await page.click('#plot-live');
    await waitInPage(page, (t) => {
      const d = window.rp.plot.data[0];
      return d[d.length - 1] > t + 0.2;
    }, paused.last);
    // A drag over the plot zooms in on that span and keeps it while frames arrive. (Once the plot
    // holds its 10 s its span no longer grows between the reading before and the drag: on a busy
    // machine the drag came 0.9 s later, and the span had grown from 2.7 to 3.6 s.)
    await waitInPage(page, () => window.rp.data[0].length >= 600, undefined, 20000);
    const over = await page.locator('#plot .u-over').boundingBox();
    const before = await shown();
    await page.mouse.move(over.x + over.width * 0.3, over.y + over.height / 2);
    await page.mouse.down();
    await page.mouse.move(over.x + over.width * 0.6, over.y + over.height / 2, { steps: 5 });
    await page.mouse.up();
    await waitInPage(page, () => window.rp.frozen);
    const zoomed = await shown();
    assert.equal(await page.textContent('#plot-mode'), 'zoomed');
    const n1 = await page.evaluate(() => window.rp.samples);
    await waitInPage(page, (n) => window.rp.samples > n + 30, n1);
    assert.deepEqual(await shown(), zoomed, 'the next frames undid the zoom');
    // The drag covered 30 % of the width: the span shown is about 30 % of the span before.
    const share = (zoomed.max - zoomed.min) / (before.max - before.min);
    assert.ok(share > 0.2 && share < 0.4, `zoom ${JSON.stringify(zoomed)}, before ${JSON.stringify(before)}`);
    // The wheel pans the span by a tenth of its width.
    await page.mouse.move(over.x + over.width / 2, over.y + over.height / 2);
    await page.mouse.wheel(0, -100);
    const panned = await waitInPage(page, (z) => {
      const x = window.rp.plot.scales.x;
      return x.min !== z.min ? { min: x.min, max: x.max } : false;
    }, zoomed);
    const width = zoomed.max - zoomed.min;
    assert.ok(Math.abs((panned.max - panned.min) - width) < 1e-9 * Math.max(1, width), 'panning changed the span');
    assert.ok(Math.abs(Math.abs(panned.min - zoomed.min) - 0.1 * width) < 1e-9 * Math.max(1, width), JSON.stringify(panned));
    // The cursor reads the plotted values at the sample under it.
    await page.mouse.move(over.x + over.width / 2, over.y + over.height / 2);
    const c = await waitInPage(page, () => window.rp.cursor);
    const at = await page.evaluate((t) => {
      const p = window.rp.plot;
      const i = p.data[0].indexOf(t);
      return { i, q0: p.data[1][i] };
    }, c.t);
    assert.ok(at.i >= 0, 'the cursor time is not a sample time');
    assert.equal(c.values['q[0]'], at.q0);
    assert.match(await page.textContent('#plot-cursor'), /^t [0-9.]+ s: q\[0\] /);
    // Export PNG: a PNG file of the plot.
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#plot-png')]);
    assert.match(download.suggestedFilename(), /^qmotor-puma-.*\.png$/);
    const path = await download.path();
    const png = readFileSync(path);
    assert.deepEqual([...png.subarray(0, 8)], [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a], 'not a PNG file');
    assert.ok(png.length > 2000, `${png.length} bytes`);
    assert.deepEqual(page.rpErrors, []);
    await page.close();
  });
});
