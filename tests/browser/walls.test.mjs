// Browser test: virtual_walls (Figure 22) draws its wall where its servo control puts it, the
// plane x = 0.4 m, as a thin box on the side the arm must stay out of.
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
});
