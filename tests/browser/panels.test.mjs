// Browser test of a manipulator's control panel and pop-up menu as an operator uses them (paper
// Figures 17 and 18) on rp-jointmove's Puma: the joint readouts in degrees, the end-effector pose,
// the arm's commands as buttons whose result (or refusal, with the reason) is shown, and the
// program's arm following them.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { withProgram, openViewer, waitInPage } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;

describe('control panel of rp-jointmove\'s Puma', () => {
  const ctx = withProgram('rp-jointmove', ['-gui-port', '0']);
  let page;
  const powerOn = () => page.evaluate(() => {
    const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
    const f = window.rp.scene.objects.find((x) => x.name === 'puma').panel.fields.find((x) => x.name === 'power');
    return o.values[f.stateIndex] !== 0;
  });
  const click = async (command) => {
    await page.click(`.panel[data-panel="puma"] button[data-command="${command}"]`);
    return waitInPage(page, (c) => {
      const r = document.querySelector('.panel[data-panel="puma"] .panel-result');
      return r.textContent.startsWith(`${c}: `) ? { text: r.textContent, refused: r.classList.contains('error') } : false;
    }, command);
  };

  it('shows the joints in degrees and the end-effector pose', async () => {
    page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'), { width: 1200, height: 800 });
    await page.evaluate(() => window.rp.openPanel('puma'));
    await page.waitForSelector('.panel[data-panel="puma"] span[data-field="q"][data-index="1"]');
    const label = await page.locator('.panel[data-panel="puma"] .row label', { hasText: 'Joint positions' }).first().textContent();
    assert.match(label, /\[deg\]/);
    // qr: joint 2 at 90 deg, joint 3 at -90 deg.
    await waitInPage(page, () => {
      const v = (i) => Number(document.querySelector(`.panel[data-panel="puma"] span[data-field="q"][data-index="${i}"]`).textContent);
      return Math.abs(v(1) - 90) < 0.5 && Math.abs(v(2) + 90) < 0.5;
    });
    // The Robotics Toolbox's fkine(qr): 20.3, -150.05, 1535.43 mm, no rotation.
    const ee = await waitInPage(page, () => {
      const t = document.querySelector('.panel[data-panel="puma"] [data-field="endEffector"]').textContent;
      return t.startsWith('x ') ? t : false;
    });
    const n = (k) => Number(ee.match(new RegExp(`${k} (-?[0-9.]+)`))[1]);
    assert.ok(Math.abs(n('x') - 20.3) < 0.5 && Math.abs(n('y') + 150.05) < 0.5 && Math.abs(n('z') - 1535.43) < 0.5, ee);
  });

  it('offers the arm\'s commands as buttons and in the pop-up menu', async () => {
    const buttons = await page.locator('.panel[data-panel="puma"] button[data-command]').evaluateAll((b) => b.map((x) => x.dataset.command));
    for (const c of ['Power On', 'Power Off', 'Gravity Compensation On', 'Gravity Compensation Off', 'Zero Gravity On',
      'Zero Gravity Off', 'Hold Here']) assert.ok(buttons.includes(c), `no ${c} in ${buttons}`);
    await page.evaluate(() => window.rp.showMenu('puma', 300, 300));
    for (const c of ['Power Off', 'Hold Here', 'Control Panel...'])
      assert.equal(await page.locator(`#popup-menu .item[data-action="${c}"]`).count(), 1, c);
    await page.keyboard.press('Escape');
  });

  it('Power Off switches the program\'s arm off and says so; Power On while a generator drives it is refused with the reason', async () => {
    assert.equal(await powerOn(), true);
    const off = await click('Power Off');
    assert.deepEqual(off, { text: 'Power Off: arm power off: brakes on', refused: false });
    await waitInPage(page, () => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      const f = window.rp.scene.objects.find((x) => x.name === 'puma').panel.fields.find((x) => x.name === 'power');
      return o.values[f.stateIndex] === 0;
    });
    const on = await click('Power On');
    assert.equal(on.refused, true);
    assert.match(on.text, /Power On: .*a trajectory generator drives the arm/);
    assert.equal(await powerOn(), false, 'the refused command changed nothing');
    const hold = await click('Hold Here');
    assert.equal(hold.refused, true);
    assert.match(hold.text, /a trajectory generator drives the arm/);
    if (shots) await page.screenshot({ path: join(shots, 'control-panel-commands.png') });
  });

  it('gravity compensation and zero-gravity mode follow the buttons, each saying what it did', async () => {
    assert.deepEqual(await click('Gravity Compensation Off'), { text: 'Gravity Compensation Off: gravity compensation off', refused: false });
    assert.deepEqual(await click('Gravity Compensation On'), { text: 'Gravity Compensation On: gravity compensation on', refused: false });
    const zg = await click('Zero Gravity On');
    assert.equal(zg.refused, false);
    assert.match(zg.text, /zero-gravity mode on/);
    const zgOff = await click('Zero Gravity Off');
    assert.match(zgOff.text, /zero-gravity mode off: the arm holds where it is/);
    // A command from the pop-up menu shows its result in the page too.
    await page.evaluate(() => window.rp.showMenu('puma', 300, 300));
    await page.click('#popup-menu .item[data-action="Gravity Compensation Off"]');
    await waitInPage(page, () => document.getElementById('messages').textContent === 'puma: Gravity Compensation Off: gravity compensation off');
    assert.deepEqual(page.rpErrors, []);
    await page.close();
  });
});
