// Browser test of the Scene Viewer's view controls on rp-jointmove's Puma 560 (drawn with its
// model's link shapes): the end-effector pose readout (against the Robotics Toolbox's fkine(qr), and after joint 1 turns), each frame's
// axes on demand, the camera kept above the floor while the user drags, and Reset view.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { withProgram, openViewer, waitInPage } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;
const DEG = Math.PI / 180;

// Keeps the 3D view's pixels at full resolution in the page (thin axis lines vanish in a
// scaled-down copy); with `compare`, returns how many differ from the kept ones.
const picture = (page, compare = false) => page.evaluate((cmp) => {
  const src = window.rp.view.renderer.domElement;
  const c = document.createElement('canvas');
  c.width = src.width;
  c.height = src.height;
  const g = c.getContext('2d');
  g.drawImage(src, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  let n = 0;
  const a = window.keptPicture;
  if (cmp) {
    for (let i = 0; i < d.length; i += 4)
      if (Math.abs(a[i] - d[i]) + Math.abs(a[i + 1] - d[i + 1]) + Math.abs(a[i + 2] - d[i + 2]) > 60) n++;
  }
  window.keptPicture = d;
  return n;
}, compare);

// The Puma's line of the readout as numbers: [x, y, z] mm and [roll, pitch, yaw] deg.
const readout = (page) => page.evaluate(() => {
  const line = document.getElementById('ee-readout').textContent.split('\n').find((l) => l.startsWith('puma '));
  if (!line) return null;
  const n = (k) => Number(line.match(new RegExp(`${k}\\s*(-?[0-9.]+)`))[1]);
  return { p: [n('x'), n('y'), n('z')], rpy: [n('roll'), n('pitch'), n('yaw')] };
});

describe('Scene Viewer view controls on rp-jointmove', () => {
  const ctx = withProgram('rp-jointmove', ['-gui-port', '0']);
  let page;

  it('shows the end-effector pose in millimetres and degrees', async () => {
    page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'), { width: 1000, height: 700 });
    await waitInPage(page, () => document.getElementById('ee-readout').textContent.includes('puma'));
    // The Puma holds qr = (0, 90, -90, 0, 0, 0) deg; the Robotics Toolbox (d1 = 0.67183 m) gives
    // fkine(qr) = [0.0203, -0.15005, 1.53543] m with R = I (shared/refdata, 02_puma560).
    const r = await readout(page);
    assert.ok(r, 'no readout line for the Puma');
    // The Puma's links are drawn by its model's shapes (DH offsets, motor housings), not as
    // generic cylinders between its frames.
    const look = await page.evaluate(() => {
      const o = window.rp.view.objects.get('puma');
      return { linksDrawn: o.desc.linksDrawn, bones: o.bones.length, shapes: o.drawn.length };
    });
    assert.deepEqual({ linksDrawn: look.linksDrawn, bones: look.bones }, { linksDrawn: true, bones: 0 });
    assert.ok(look.shapes >= 12, `${look.shapes} shapes`);
    const expected = [20.3, -150.05, 1535.43];
    for (let i = 0; i < 3; ++i) assert.ok(Math.abs(r.p[i] - expected[i]) < 0.2, `position ${JSON.stringify(r.p)}`);
    for (let i = 0; i < 3; ++i) assert.ok(Math.abs(r.rpy[i]) < 0.1, `orientation ${JSON.stringify(r.rpy)}`);
  });

  it('follows the arm: joint 1 at 40 deg turns the pose about z by joint 1\'s angle', async () => {
    await page.evaluate((v) => window.rp.conn.message('jointmove', 'setJoint', JSON.stringify({ joint: 0, value: v })),
      40 * DEG);
    // Wait until joint 1 has settled near 40 deg (the servo loop holds it within its accuracy).
    const q1 = await waitInPage(page, () => {
      const o = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'puma');
      return Math.abs(o.values[0] - 40 * Math.PI / 180) < 0.005 && Math.abs(o.values[6]) < 1e-3 ? o.values[0] : false;
    }, undefined, 20000);
    // qr's pose turned about z by the measured joint 1 angle (the readout rounds to 0.1).
    await page.waitForTimeout(500);
    const r = await readout(page);
    const c = Math.cos(q1);
    const s = Math.sin(q1);
    const x = 20.3 * c + 150.05 * s;
    const y = 20.3 * s - 150.05 * c;
    assert.ok(Math.abs(r.rpy[2] - q1 / DEG) < 0.1, `yaw ${r.rpy[2]}, joint 1 at ${q1 / DEG} deg`);
    assert.ok(Math.abs(r.rpy[0]) < 0.1 && Math.abs(r.rpy[1]) < 0.1, `roll and pitch ${r.rpy}`);
    assert.ok(Math.abs(r.p[0] - x) < 1 && Math.abs(r.p[1] - y) < 1, `position ${JSON.stringify(r.p)}, expected ${x}, ${y}`);
    assert.ok(Math.abs(r.p[2] - 1535.43) < 1, `height ${r.p[2]}`);
  });

  it('draws every frame\'s axes on demand', async () => {
    const count = () => page.evaluate(() => {
      let shown = 0;
      let all = 0;
      for (const o of window.rp.view.objects.values()) {
        all += o.frames.length;
        shown += o.axes.filter((a) => a.visible).length;
        if (o.axes.length !== o.frames.length) return { error: `${o.desc.name}: ${o.axes.length} axes, ${o.frames.length} frames` };
      }
      return { shown, all };
    });
    let c = await count();
    assert.equal(c.error, undefined, c.error);
    assert.equal(c.shown, 0, 'axes shown before asked for');
    assert.ok(c.all >= 8, `${c.all} frames`); // the Puma's base, 6 links, end-effector
    await picture(page);
    await page.check('#show-frames');
    c = await count();
    assert.equal(c.shown, c.all);
    await page.waitForTimeout(300);
    const changed = await picture(page, true);
    assert.ok(changed > 200, `${changed} pixels changed when the axes were shown`);
    if (shots) await page.screenshot({ path: join(shots, 'viewer-frames.png') });
    await page.uncheck('#show-frames');
    c = await count();
    assert.equal(c.shown, 0);
  });

  it('keeps the camera above the floor while the user drags, and Reset view brings the first view back', async () => {
    const camera = () => page.evaluate(() => {
      const v = window.rp.view;
      const d = v.camera.position.clone().sub(v.controls.target).normalize();
      return { z: v.camera.position.z, targetZ: v.controls.target.z, dir: d.toArray(), def: v.defaultDirection.toArray(),
        fits: v.fits };
    });
    const box = await page.locator('#view canvas').boundingBox();
    const cx = box.x + box.width / 2;
    const cy = box.y + box.height / 2;
    // Left drag upwards: orbits the camera down towards (and, unbounded, below) the floor.
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    for (let k = 1; k <= 20; ++k) await page.mouse.move(cx, cy - 30 * k);
    await page.mouse.up();
    // Right drags (pan) up and then down a long way: the target never goes below the floor.
    for (const sign of [-1, 1]) {
      await page.mouse.move(cx, cy);
      await page.mouse.down({ button: 'right' });
      for (let k = 1; k <= 20; ++k) await page.mouse.move(cx, cy + sign * 40 * k);
      await page.mouse.up({ button: 'right' });
      const c = await camera();
      assert.ok(c.targetZ >= 0 && c.z > c.targetZ, `after a pan: camera z ${c.z}, target z ${c.targetZ}`);
    }
    await page.waitForTimeout(300);
    const moved = await camera();
    assert.ok(moved.targetZ >= 0, `target below the floor: ${moved.targetZ}`);
    assert.ok(moved.z > moved.targetZ, `camera at z ${moved.z}, not above its target at ${moved.targetZ}`);
    const away = Math.acos(moved.dir.reduce((a, x, i) => a + x * moved.def[i], 0));
    assert.ok(away > 0.2, `the drag did not move the view (${away} rad)`);
    await page.click('#reset-view');
    const reset = await camera();
    const angle = Math.acos(Math.min(1, reset.dir.reduce((a, x, i) => a + x * reset.def[i], 0)));
    assert.ok(angle < 1e-6, `after Reset view the camera looks from ${JSON.stringify(reset.dir)}, not ${JSON.stringify(reset.def)}`);
    assert.ok(reset.fits > moved.fits, 'Reset view did not frame the scene');
    assert.ok(reset.z > 0);
    assert.deepEqual(page.rpErrors, []);
    await page.close();
  });
});
