// Browser test of URDF visuals: rp-jointmove drives a UrdfManipulator made from
// tests/browser/data/visual_arm.urdf (rp.cfg `urdf`); the Scene Viewer draws the arm's own
// <visual> elements (box, cylinders, sphere, STL mesh) on the right links, and they move with the
// joints: the sphere at link l3's origin is where the URDF's kinematics puts it for the joint
// positions of the same state frame, before and after a joint moves.
import { describe, it, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { withProgram, openViewer, waitInPage, canvasStats, waitForPictureChange } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;
const here = dirname(fileURLToPath(import.meta.url));
const dir = mkdtempSync(join(tmpdir(), 'rp-urdf-'));
writeFileSync(join(dir, 'rp.cfg'), `[arm]\nclass UrdfManipulator\nurdf ${join(here, 'data', 'visual_arm.urdf')}\n`);

// Where the URDF puts link l3's origin for joints q (written out from the file: base -> j1 at
// z 0.1 about z, j2 0.3 higher about y, j3 0.4 along the rotated x about y).
function l3Origin([q1, q2]) {
  const r = 0.4 * Math.cos(q2);
  return [Math.cos(q1) * r, Math.sin(q1) * r, 0.1 + 0.3 - 0.4 * Math.sin(q2)];
}

describe('URDF visuals of a UrdfManipulator', () => {
  const ctx = withProgram('rp-jointmove', ['-gui-port', '0', '-config', join(dir, 'rp.cfg'), 'arm']);
  after(() => rmSync(dir, { recursive: true, force: true }));

  // The sphere's world position in the page's 3D scene and the joint positions of the same frame.
  const sample = (page) => page.evaluate(() => {
    const o = window.rp.view.objects.get('arm');
    const link3 = o.frames.find((g) => g.name === 'link3');
    const sphere = link3.children[0];
    const p = sphere.getWorldPosition(sphere.position.clone());
    const f = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'arm');
    return { p: [p.x, p.y, p.z], q: f.values.slice(0, 3) };
  });

  it('draws the arm\'s own visuals on its links, moving with the joints', async () => {
    assert.match(ctx.program.output(), /rp-jointmove: moving arm \(UrdfManipulator, 3 joints\)/);
    const page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'));
    const desc = await page.evaluate(() => window.rp.scene.objects.find((o) => o.name === 'arm'));
    assert.equal(desc.urdfVisuals, true, JSON.stringify(desc.urdfError));
    assert.deepEqual(desc.shapes.map((s) => [s.kind, s.frame]), [['cylinder', 'base'], ['box', 'link1'], ['cylinder', 'link2'],
      ['sphere', 'link3'], ['mesh', 'link3'], ['box', 'link3']]);
    // The STL mesh is served and drawn; no generic link cylinders ("bones") are drawn.
    await waitInPage(page, () => window.rp.view.meshes.loaded >= 1);
    assert.equal(await page.evaluate(() => window.rp.view.objects.get('arm').bones.length), 0);
    const before = await sample(page);
    const want0 = l3Origin(before.q);
    for (let i = 0; i < 3; ++i) assert.ok(Math.abs(before.p[i] - want0[i]) < 1e-6, `l3 at ${before.p}, URDF says ${want0}`);
    const still = await canvasStats(page);
    assert.ok(still.foreground > 0.01 * still.total, `only ${still.foreground} pixels drawn`);
    if (shots) await page.screenshot({ path: join(shots, 'urdf-visuals.png') });

    // Move joints 1 and 2 through Joint Move; the visuals follow.
    for (const [joint, value] of [[0, 0.9], [1, -0.6]])
      await ctx.page.evaluate(([j, v]) => window.rp.conn.message('jointmove', 'setJoint', JSON.stringify({ joint: j, value: v })), [joint, value]);
    // While the arm moves, every frame's picture is where the URDF puts the link for that same
    // frame's joint values (the poses and the values are of one servo cycle, not read apart).
    let inMotion = 0;
    for (const deadline = Date.now() + 30000; ;) {
      const s = await sample(page);
      const want = l3Origin(s.q);
      for (let i = 0; i < 3; ++i) assert.ok(Math.abs(s.p[i] - want[i]) < 1e-6, `l3 at ${s.p} for joints ${s.q}, URDF says ${want}`);
      if (Math.abs(s.q[0] - 0.9) < 0.01 && Math.abs(s.q[1] + 0.6) < 0.01) break;
      if (Math.abs(s.q[0] - before.q[0]) > 0.01 || Math.abs(s.q[1] - before.q[1]) > 0.01) ++inMotion;
      assert.ok(Date.now() < deadline, `the arm did not reach the joints typed in 30 s (at ${s.q})`);
      await new Promise((r) => setTimeout(r, 20));
    }
    assert.ok(inMotion >= 1, 'no frame seen while the arm moved');
    const moved = await sample(page);
    const want1 = l3Origin(moved.q);
    for (let i = 0; i < 3; ++i) assert.ok(Math.abs(moved.p[i] - want1[i]) < 1e-6, `l3 at ${moved.p}, URDF says ${want1}`);
    assert.ok(Math.hypot(...moved.p.map((x, i) => x - before.p[i])) > 0.1, 'the sphere did not move');
    const changed = await waitForPictureChange(page, still);
    assert.ok(changed > 50, `the picture did not change as the arm moved (${changed} pixels)`);
    assert.deepEqual(page.rpErrors, []);
    await page.close();
  });

  // Issue 20: the panels label the joints with the URDF's names (j1, j2, j3), not "Joint 1".
  it('labels the joints with their URDF names in Joint Move and the control panel', async () => {
    await waitInPage(ctx.page, () => document.querySelectorAll('#sliders .slider-row').length === 3);
    assert.deepEqual(await ctx.page.evaluate(() => [...document.querySelectorAll('#sliders .slider-row .joint-name')]
      .map((e) => e.textContent)), ['j1', 'j2', 'j3']);
    const page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'));
    assert.deepEqual(await page.evaluate(() => window.rp.scene.objects.find((o) => o.name === 'arm').jointNames),
      ['j1', 'j2', 'j3']);
    await page.evaluate(() => window.rp.openPanel('arm'));
    const panel = page.locator('.panel[data-panel="arm"]');
    await panel.locator('.joint-names .joint-name').first().waitFor({ timeout: 10000 });
    assert.deepEqual(await panel.locator('.joint-names .joint-name').allTextContents(), ['j1', 'j2', 'j3']);
    // Each per-joint value names its joint (the gains typed per joint, the positions read out).
    assert.deepEqual(await panel.locator('input[data-field="kp"]').evaluateAll((es) => es.map((e) => e.dataset.joint)),
      ['j1', 'j2', 'j3']);
    assert.deepEqual(page.rpErrors, []);
    await page.close();
  });
});
