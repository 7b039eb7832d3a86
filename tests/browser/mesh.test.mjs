// Browser test: an object's mesh file (STL) is served by the program, only for a shape that names
// it, and drawn in the Scene Viewer.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { withProgram, waitInPage } from './harness.mjs';

describe('mesh files', () => {
  const ctx = withProgram('mesh_cell', ['-gui-port', '0', '-gui-token', 'mesh-token']);

  it('draws the STL mesh of an object', async () => {
    const desc = await ctx.page.evaluate(() => window.rp.scene.objects.find((o) => o.name === 'part'));
    assert.equal(desc.shapes[0].kind, 'mesh');
    assert.match(desc.shapes[0].mesh, /part\.stl$/);
    await waitInPage(ctx.page, () => window.rp.view.meshes.loaded === 1);
    assert.equal(await ctx.page.evaluate(() => window.rp.view.meshes.failed), 0);
  });

  it('serves only files that a live object\'s model names, with the token', async () => {
    const status = await ctx.page.evaluate(async () => {
      const get = async (q) => {
        const r = await fetch(`mesh?${q}`);
        return [r.status, (await r.text()).slice(0, 10)];
      };
      return {
        ok: await get('object=part&shape=0&token=mesh-token'),
        box: await get('object=part&shape=1&token=mesh-token'),
        nobody: await get('object=nobody&shape=0&token=mesh-token'),
        bad: await get('object=part&shape=../x&token=mesh-token'),
        noToken: await get('object=part&shape=0'),
      };
    });
    assert.deepEqual(status.ok, [200, 'solid part']);
    assert.equal(status.box[0], 404);
    assert.equal(status.nobody[0], 404);
    assert.equal(status.bad[0], 400);
    assert.equal(status.noToken[0], 403);
  });
});
