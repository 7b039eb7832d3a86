// Browser test of QMotor's program control and log (qmotor.html) on qmotor_cell -qmotor: Stop,
// Start and Restart visibly change the program's state and the arm holds where it is; a changed
// gain saved to a file and loaded back from the page returns; a bad file is refused naming
// FILE:LINE; the CSV download has the chosen columns at the chosen decimation; the trigger starts
// the log only after the crossing; bad requests are refused naming the field.
import { describe, it, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { withProgram, openViewer, waitInPage, sleep } from './harness.mjs';

const dir = mkdtempSync(join(tmpdir(), 'rp-qmotor-program-'));
writeFileSync(join(dir, 'rp.cfg'), '[puma]\nclass Puma560\nqmotorConfig puma.cfg\n\n[wave]\nclass Wave\nqmotorConfig wave.cfg\n');
writeFileSync(join(dir, 'puma.cfg'), 'rate 1000\n');
writeFileSync(join(dir, 'wave.cfg'), 'gain 2\n');
writeFileSync(join(dir, 'broken.cfg'), 'kp 100\nkq 3\n');

// The puma's joint positions in the last state frame the page received.
const jointsOf = (page) => page.evaluate(() => {
  const desc = window.rp.scene.objects.find((o) => o.name === 'puma');
  const field = desc.panel.fields.find((f) => f.name === 'q');
  const index = window.rp.scene.objects.indexOf(desc);
  const o = window.rp.lastFrame.objects.find((x) => x.index === index);
  return o.values.slice(field.stateIndex, field.stateIndex + field.size);
});
const maxDiff = (a, b) => Math.max(...a.map((x, i) => Math.abs(x - b[i])));

describe('QMotor program control on qmotor_cell -qmotor', () => {
  const ctx = withProgram('qmotor_cell', ['-gui-port', '0', '-qmotor', '-config', join(dir, 'rp.cfg')]);
  after(() => rmSync(dir, { recursive: true, force: true }));
  let page;
  const open = async (object) => {
    const url = ctx.program.output().match(/rp: QMotor at (\S+)/)[1];
    page = await openViewer(ctx.browser, `${url}?object=${object}`, { width: 1200, height: 1000 });
    await waitInPage(page, (o) => window.rp.program && window.rp.program.object === o, object);
    return page;
  };

  it('stops, starts and restarts the puma: the state changes and the arm holds', async () => {
    await open('puma');
    await waitInPage(page, () => window.rp.program.running && document.getElementById('prog-state').textContent.startsWith('running'));
    // The program's timing (docs/realtime.md, Timing): its computation time and its executor's
    // overruns in the line, the rest in the line's tooltip.
    assert.match(await page.evaluate(() => document.getElementById('prog-state').textContent),
      /^running, \d+ cycles · computation p99 \d+\.\d µs · \d+ overruns/);
    assert.match(await page.evaluate(() => document.getElementById('prog-state').title),
      /^computation p50 \d+\.\d µs, p99 \d+\.\d µs, max \d+\.\d µs; (executor of \d+|own thread): wake-up p99 \d+\.\d µs, \d+ overruns/);
    await sleep(500);
    const before = await jointsOf(page);
    await page.click('#prog-stop');
    await waitInPage(page, () => window.rp.result && /stopped/.test(window.rp.result.text), undefined, 20000);
    const stopResult = await page.evaluate(() => window.rp.result);
    assert.equal(stopResult.ok, true, stopResult.text);
    assert.match(stopResult.text, /puma: control program stopped after \d+ cycles; the arm came to rest, is braked and powered off/);
    await waitInPage(page, () => document.getElementById('prog-state').textContent.startsWith('stopped'));
    assert.equal(await page.evaluate(() => window.rp.program.running), false);
    await sleep(1000); // stopped, braked: the arm does not move
    const stopped = await jointsOf(page);
    assert.ok(maxDiff(stopped, before) < 1e-3, `the arm moved at the stop: ${before} -> ${stopped}`);
    // A second Stop is refused with its reason, shown in the page.
    await page.click('#prog-stop');
    await waitInPage(page, () => window.rp.result && !window.rp.result.ok);
    assert.equal(await page.evaluate(() => window.rp.result.text), 'stop: puma: the control program is not running');
    assert.equal(await page.evaluate(() => document.getElementById('prog-result').className), 'bad');
    // Start: running again, holding where it stopped (power on as before).
    await page.click('#prog-start');
    await waitInPage(page, () => window.rp.result && window.rp.result.ok && /started/.test(window.rp.result.text));
    assert.equal(await page.evaluate(() => window.rp.result.text),
      'puma: control program started at 1000 Hz; the arm holds where it is (power on)');
    await waitInPage(page, () => document.getElementById('prog-state').textContent.startsWith('running'));
    await sleep(1500);
    const started = await jointsOf(page);
    assert.ok(maxDiff(started, stopped) < 1e-3, `the start moved the arm: ${stopped} -> ${started}`);
    // Restart: stopped and started, still where it was.
    const cycles = await page.evaluate(() => window.rp.program.cycles);
    await page.click('#prog-restart');
    await waitInPage(page, () => window.rp.result && /stopped after .*started/.test(window.rp.result.text), undefined, 20000);
    await waitInPage(page, (c) => window.rp.program.running && window.rp.program.cycles < c, cycles);
    await sleep(1000);
    assert.ok(maxDiff(await jointsOf(page), stopped) < 1e-3, 'the restart moved the arm');
    assert.deepEqual(page.rpErrors, []);
  });

  it('saves a changed gain and loads it back; a bad file names FILE:LINE', async () => {
    // Change kp[0] through the page, save it as tuned.cfg, change it again, load tuned.cfg.
    const kp0 = () => page.evaluate(() => window.rp.scene.objects.find((o) => o.name === 'puma')
      .panel.fields.find((f) => f.name === 'kp').value[0]);
    await page.evaluate(() => window.rp.conn.request({ type: 'setParameter', object: 'puma', name: 'kp', index: 0, value: 1234.5 }));
    await waitInPage(page, () => window.rp.scene.objects.find((o) => o.name === 'puma').panel.fields.find((f) => f.name === 'kp').value[0] === 1234.5);
    await page.fill('#cfg-save-as', 'tuned.cfg');
    await page.click('#cfg-save');
    await waitInPage(page, () => window.rp.result && /saved/.test(window.rp.result.text));
    assert.equal(await page.evaluate(() => window.rp.result.text), `saved the parameters of puma to ${join(dir, 'tuned.cfg')}`);
    assert.match(readFileSync(join(dir, 'tuned.cfg'), 'utf8'), /^kp 1234\.5 /m);
    await page.evaluate(() => window.rp.conn.request({ type: 'setParameter', object: 'puma', name: 'kp', index: 0, value: 777 }));
    await waitInPage(page, () => window.rp.scene.objects.find((o) => o.name === 'puma').panel.fields.find((f) => f.name === 'kp').value[0] === 777);
    await waitInPage(page, () => [...document.querySelectorAll('#cfg-files option')].some((o) => o.value === 'tuned.cfg'));
    await page.selectOption('#cfg-files', 'tuned.cfg');
    await page.click('#cfg-load');
    await waitInPage(page, () => window.rp.result && /loaded/.test(window.rp.result.text));
    assert.equal(await page.evaluate(() => window.rp.result.ok), true);
    await waitInPage(page, () => window.rp.scene.objects.find((o) => o.name === 'puma').panel.fields.find((f) => f.name === 'kp').value[0] === 1234.5);
    assert.equal(await kp0(), 1234.5);
    // A bad file: refused, naming the file and the line; nothing changed.
    await page.selectOption('#cfg-files', 'broken.cfg');
    await page.click('#cfg-load');
    await waitInPage(page, () => window.rp.result && !window.rp.result.ok);
    assert.equal(await page.evaluate(() => document.getElementById('prog-result').textContent),
      `load: ${join(dir, 'broken.cfg')}:2: 'kq' is not a parameter of puma (known: rate, priority, logEvery, logBufferSize, log, kp, kd, ki)`);
    assert.equal(await kp0(), 1234.5, 'line 1 of the bad file was applied');
    // Save refuses a path (no traversal).
    await page.fill('#cfg-save-as', '../escape.cfg');
    await page.click('#cfg-save');
    await waitInPage(page, () => window.rp.result && !window.rp.result.ok && /'file' must be a file name/.test(window.rp.result.text));
  });

  it('downloads the chosen columns at the chosen decimation as CSV', async () => {
    await page.check('#cap-variables input[data-variable="q"]');
    await page.check('#cap-variables input[data-variable="tau"]');
    await page.fill('#cap-every', '5');
    await page.fill('#cap-samples', '200');
    await page.selectOption('#cap-trigger-column', '');
    await page.click('#cap-arm');
    await waitInPage(page, () => window.rp.result && /QMotor log set|^capture:/.test(window.rp.result.text));
    assert.equal(await page.evaluate(() => window.rp.result.text), 'QMotor log set: 12 columns, every 5 cycles, 200 rows, from now');
    await waitInPage(page, () => window.rp.program.capture.rows === 200, undefined, 20000);
    assert.match(await page.evaluate(() => document.getElementById('cap-state').textContent), /^200 of 200 rows \(full\), every 5 cycles/);
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#cap-download')]);
    assert.equal(download.suggestedFilename(), 'puma-qmotor-log.csv');
    const csv = readFileSync(await download.path(), 'utf8').trim().split('\n');
    const header = csv[0].split(',');
    assert.deepEqual(header, ['t', ...[0, 1, 2, 3, 4, 5].map((i) => `puma.q[${i}]`), ...[0, 1, 2, 3, 4, 5].map((i) => `puma.tau[${i}]`)]);
    assert.equal(csv.length, 201);
    // Every 5th cycle of 1 ms: 5 ms apart (more only where the loop skipped a missed deadline:
    // then a whole number of milliseconds).
    const t = csv.slice(1).map((l) => Number(l.split(',')[0]));
    let exact = 0;
    for (let i = 1; i < t.length; ++i) {
      const ms = (t[i] - t[i - 1]) * 1000;
      assert.ok(ms > 4.999 && Math.abs(ms - Math.round(ms)) < 1e-6, `rows ${i - 1}, ${i}: ${t[i - 1]} -> ${t[i]}`);
      if (Math.abs(ms - 5) < 1e-6) exact++;
    }
    assert.ok(exact >= 0.9 * (t.length - 1), `only ${exact} of ${t.length - 1} steps are 5 ms`);
    for (const l of csv.slice(1)) assert.equal(l.split(',').length, 13);
  });

  it('starts the log only after the trigger variable crosses its level', async () => {
    await page.selectOption('#object', 'wave');
    await waitInPage(page, () => window.rp.program && window.rp.program.object === 'wave' && document.querySelector('#cap-variables input[data-variable="ramp"]'));
    // ramp: seconds since the wave program started (long past 3 s now). Arm the trigger "ramp
    // rising through 3": it cannot fire until the program is started again (ramp from 0).
    const level = 3;
    await page.check('#cap-variables input[data-variable="ramp"]');
    await page.check('#cap-variables input[data-variable="wave"]');
    await page.fill('#cap-every', '1');
    await page.fill('#cap-samples', '100');
    await page.selectOption('#cap-trigger-column', 'ramp');
    await page.selectOption('#cap-trigger-edge', 'rising');
    await page.fill('#cap-trigger-level', String(level));
    await page.click('#cap-arm');
    await waitInPage(page, () => window.rp.result && /QMotor log set|^capture:/.test(window.rp.result.text));
    assert.match(await page.evaluate(() => window.rp.result.text), /from the trigger/);
    await sleep(500);
    const waiting = await page.evaluate(() => window.rp.program.capture);
    assert.equal(waiting.triggered, false, `triggered with ramp past ${level}: ${JSON.stringify(waiting)}`);
    assert.equal(waiting.rows, 0);
    assert.match(await page.evaluate(() => document.getElementById('cap-state').textContent), /^armed: waiting for ramp rising through 3/);
    // Restart: ramp runs from 0 and crosses 3 three seconds later; nothing is logged before.
    await page.click('#prog-restart');
    await waitInPage(page, () => window.rp.result && /wave: control program stopped after .*started at 500 Hz/.test(window.rp.result.text));
    const atRestart = await page.evaluate(() => window.rp.lastReply.status.capture);
    assert.equal(atRestart.triggered, false, JSON.stringify(atRestart));
    assert.equal(atRestart.rows, 0);
    await waitInPage(page, () => window.rp.program.capture.rows === 100, undefined, 20000);
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#cap-download')]);
    assert.equal(download.suggestedFilename(), 'wave-qmotor-log.csv');
    const csv = readFileSync(await download.path(), 'utf8').trim().split('\n');
    assert.equal(csv[0], 't,wave.ramp,wave.wave');
    assert.equal(csv.length, 101);
    const ramps = csv.slice(1).map((l) => Number(l.split(',')[1]));
    // The first row is the cycle of the crossing: at or above the level, a few cycles past it at most.
    assert.ok(ramps[0] >= level && ramps[0] < level + 0.1, `the first row (ramp ${ramps[0]}) is not the crossing of ${level}`);
    for (let i = 1; i < ramps.length; ++i) assert.ok(ramps[i] > ramps[i - 1], 'rows out of order');
  });

  it('refuses bad requests naming the field', async () => {
    const error = (msg) => page.evaluate((m) => window.rp.conn.request(m).then(() => 'accepted', (e) => e.message), msg);
    assert.equal(await error({ type: 'qmotor', object: 'wave', action: 'capture', every: 0 }), "'every' must be an integer in 1..1000000");
    assert.equal(await error({ type: 'qmotor', object: 'wave', action: 'capture', every: 1e12 }), "'every' must be an integer in 1..1000000");
    assert.equal(await error({ type: 'qmotor', object: 'wave', action: 'capture', variables: ['nope'] }),
      "'variables': 'nope' is not a log variable of wave (known: ramp, wave)");
    assert.equal(await error({ type: 'qmotor', object: 'wave', action: 'capture', trigger: { column: 'ramp', level: null, edge: 'rising' } }),
      "'trigger.level' must be a finite number");
    assert.equal(await error({ type: 'qmotor', object: 'wave', action: 'load', file: '../../etc/passwd' }).then((m) => m.startsWith("'file' must be a file name ending in .cfg")), true);
    assert.equal(await error({ type: 'qmotor', object: 'wave', action: 'explode' }).then((m) => m.startsWith("'action' must be one of")), true);
    assert.equal(await error({ type: 'qmotor', object: 'nobody', action: 'status' }), "no object 'nobody'");
    // The wave program's own qmotorConfig (gain 2) was applied at its start.
    assert.equal(await page.evaluate(() => window.rp.scene.objects.find((o) => o.name === 'wave').panel.fields.find((f) => f.name === 'gain').value[0]), 2);
    assert.deepEqual(page.rpErrors, []);
  });
});
