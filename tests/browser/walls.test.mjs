// Browser test: virtual_walls (Figure 22) draws its wall where its servo control puts it, the
// plane x = 0.4 m, as a thin box on the side the arm must stay out of; the arm's panel switches
// between the wall control the program set and the default position control.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { withProgram, waitInPage } from './harness.mjs';

describe('virtual_walls in the Scene Viewer', () => {
  const ctx = withProgram('virtual_walls', ['-gui-port', '0']);

  it('draws the wall on the plane x = 0.4 m, behind it', async () => {
    const shapes = await waitInPage(ctx.page, () => {
      const s = window.rp.view.drawnShapes('wall');
      return s && s.length && s[0].box ? s : false;
    });
    assert.equal(shapes.length, 1);
    assert.equal(shapes[0].kind, 'box');
    const { min, max } = shapes[0].box;
    assert.ok(Math.abs(min[0] - 0.4) < 1e-6, `the wall starts at x = ${min[0]}`);
    assert.ok(Math.abs(max[0] - 0.42) < 1e-6, `the wall ends at x = ${max[0]}`);
    assert.ok(min[2] < 0.5 && max[2] > 1.5 && max[1] - min[1] > 1.5, `the wall covers ${JSON.stringify(shapes[0].box)}`);
    const listed = await ctx.page.evaluate(() => window.rp.scene.objects.some((o) => o.name === 'wall' && o.physical));
    assert.ok(listed, 'the wall is not in the scene description');
  });

  it('switches the arm between the wall control and the default control from its panel', async () => {
    const page = ctx.page;
    const arm = await page.evaluate(() => window.rp.scene.objects.find((o) => o.kind === 'manipulator'));
    assert.equal(arm.servoControls.length, 2, JSON.stringify(arm.servoControls));
    const [standard, wall] = arm.servoControls;
    assert.equal(standard, `${arm.name}.control`);
    assert.equal(arm.servoControl, wall, 'the program set the wall control');
    await page.evaluate((n) => window.rp.openPanel(n), arm.name);
    const select = `.panel[data-panel="${arm.name}"] select[data-field="servoControl"]`;
    await page.waitForSelector(select);
    assert.deepEqual(await page.locator(`${select} option`).evaluateAll((o) => o.map((x) => x.value)), [standard, wall]);
    assert.equal(await page.locator(select).inputValue(), wall, 'the switch shows the control in use');
    const buttons = await page.locator(`.panel[data-panel="${arm.name}"] button[data-command]`).evaluateAll((b) => b.map((x) => x.dataset.command));
    assert.ok(!buttons.some((b) => b.startsWith('Servo Control: ')), `no button per control: ${buttons}`);
    for (const to of [standard, wall]) {
      await page.selectOption(select, to);
      const result = await waitInPage(page, ([n, c]) => {
        const r = document.querySelector(`.panel[data-panel="${n}"] .panel-result`).textContent;
        return r.startsWith(`Servo Control: ${c}: `) ? r : false;
      }, [arm.name, to]);
      assert.ok(result.includes(`servo control ${to} in use`), result);
      await waitInPage(page, ([n, c]) => window.rp.scene.objects.find((o) => o.name === n).servoControl === c, [arm.name, to]);
    }
  });
});
