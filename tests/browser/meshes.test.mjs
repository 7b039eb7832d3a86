// Browser test of URDF mesh visuals: rp-jointmove drives a UrdfManipulator made from a copy of
// tests/browser/data/packages/rp_mesh_arm/urdf/mesh_arm.urdf moved to a temporary folder, its
// package://rp_mesh_arm/... meshes found only through rp.cfg's `packagePath`. In Chromium, the
// world-space bounding box of what is drawn for every visual (a Z-up Collada file in centimetres,
// an STL in millimetres scaled by the URDF, OBJ files) agrees with the link's pose from the URDF's
// kinematics written out here, for the joint positions of the same state frame: a mesh turned by
// its up axis, scaled wrongly or misplaced fails. A mesh file that does not exist is drawn as its
// link's collision box, one that cannot be parsed as a placeholder; both are reported on the page
// next to the arm and once each on stderr. The view frames the arm when the page opens.
import { describe, it, after } from 'node:test';
import assert from 'node:assert/strict';
import { copyFileSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { withProgram, openViewer, waitInPage } from './harness.mjs';

const shots = process.env.RP_SCREENSHOT_DIR;
const here = dirname(fileURLToPath(import.meta.url));
const packages = join(here, 'data', 'packages');
const dir = mkdtempSync(join(tmpdir(), 'rp-meshes-'));
copyFileSync(join(packages, 'rp_mesh_arm', 'urdf', 'mesh_arm.urdf'), join(dir, 'mesh_arm.urdf'));
writeFileSync(join(dir, 'rp.cfg'),
  `[arm]\nclass UrdfManipulator\nurdf mesh_arm.urdf\ntip hand_link\npackagePath /nonexistent:${packages}\n`);

// 4x4 matrices (row-major arrays of rows) for the URDF chain written out by hand.
const mul = (a, b) => a.map((r) => [0, 1, 2, 3].map((j) => r.reduce((s, x, k) => s + x * b[k][j], 0)));
const T = (x, y, z) => [[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]];
const Rx = (a) => [[1, 0, 0, 0], [0, Math.cos(a), -Math.sin(a), 0], [0, Math.sin(a), Math.cos(a), 0], [0, 0, 0, 1]];
const Ry = (a) => [[Math.cos(a), 0, Math.sin(a), 0], [0, 1, 0, 0], [-Math.sin(a), 0, Math.cos(a), 0], [0, 0, 0, 1]];
const Rz = (a) => [[Math.cos(a), -Math.sin(a), 0, 0], [Math.sin(a), Math.cos(a), 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]];

// The world-space bounding box of box [lo, hi] (in the visual's frame) for joints q, per link of
// mesh_arm.urdf: the link's pose, then the visual's origin; the mesh files' extents in metres.
function expectedBoxes([q1, q2, q3]) {
  const upper = mul(T(0, 0, 0.1), Rz(q1));
  const fore = mul(mul(upper, T(0, 0, 0.4)), Ry(q2));
  const hand = mul(mul(fore, T(0.3, 0, 0)), Ry(q3));
  const c = 0.02; // half the placeholder cube
  const want = {
    base_link: [T(0, 0, 0), [-0.12, -0.08, 0], [0.12, 0.08, 0.1]],            // base.obj
    upper_link: [upper, [-0.03, -0.02, 0], [0.03, 0.02, 0.4]],                // upper_arm.dae: 6 x 4 x 40 cm, Z up
    cam_link: [mul(upper, T(0.05, 0, 0.3)), [-c, -c, -c], [c, c, c]],         // broken.dae: the placeholder
    fore_link: [fore, [0, -0.025, -0.02], [0.3, 0.025, 0.02]],                // forearm.stl, mm scaled by 0.001
    hand_link: [mul(mul(hand, T(0.01, 0, 0)), Rx(0.5)), [0, -0.03, -0.01], [0.1, 0.03, 0.01]], // hand.obj
    sensor_link: [mul(hand, T(0.1 + 0.02, 0, 0)), [-0.02, -0.015, -0.01], [0.02, 0.015, 0.01]], // its collision box
    tag_link: [mul(fore, T(0.15, 0, 0.02)), [-0.03, -0.02, 0], [0.03, 0.02, 0.025]],       // its collision mesh: base.obj / 4
  };
  const boxes = {};
  for (const [link, [m, lo, hi]] of Object.entries(want)) {
    const min = [Infinity, Infinity, Infinity];
    const max = [-Infinity, -Infinity, -Infinity];
    for (const x of [lo[0], hi[0]]) for (const y of [lo[1], hi[1]]) for (const z of [lo[2], hi[2]])
      for (let i = 0; i < 3; ++i) {
        const w = m[i][0] * x + m[i][1] * y + m[i][2] * z + m[i][3];
        min[i] = Math.min(min[i], w);
        max[i] = Math.max(max[i], w);
      }
    boxes[link] = { min, max };
  }
  return boxes;
}

// What the page draws for the arm and the joint positions of the same state frame.
const sample = (page) => page.evaluate(() => {
  const f = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'arm');
  return { shapes: window.rp.view.drawnShapes('arm'), q: f.values.slice(0, 3) };
});

function checkBoxes({ shapes, q }) {
  const want = expectedBoxes(q);
  assert.deepEqual(shapes.map((s) => s.link).sort(), Object.keys(want).sort());
  for (const s of shapes) {
    assert.ok(s.box, `nothing drawn for ${s.link} (${s.state}: ${s.error})`);
    for (const end of ['min', 'max'])
      for (let i = 0; i < 3; ++i)
        assert.ok(Math.abs(s.box[end][i] - want[s.link][end][i]) < 2e-5,
          `${s.link} (${s.state}) at q ${q}: box ${JSON.stringify(s.box)}, the URDF says ${JSON.stringify(want[s.link])}`);
  }
}

const meshesDone = () => {
  const d = window.rp.view.drawnShapes('arm');
  return d && d.every((s) => s.state !== 'loading') && window.rp.view.meshes.failed >= 1 &&
    window.rp.view.meshes.loaded >= 5;
};

describe('URDF meshes of a UrdfManipulator', () => {
  const ctx = withProgram('rp-jointmove', ['-gui-port', '0', '-config', join(dir, 'rp.cfg'), 'arm']);
  after(() => rmSync(dir, { recursive: true, force: true }));

  it('draws every mesh where the URDF puts its link, at zero and after the joints moved', async () => {
    const page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'));
    await waitInPage(page, meshesDone, undefined, 30000);
    const desc = await page.evaluate(() => window.rp.scene.objects.find((o) => o.name === 'arm'));
    assert.equal(desc.urdfVisuals, true, JSON.stringify(desc.urdfError));
    const shapes = await sample(page);
    assert.deepEqual(Object.fromEntries(shapes.shapes.map((s) => [s.link, s.state])), {
      base_link: 'mesh', upper_link: 'mesh', cam_link: 'placeholder', fore_link: 'mesh', hand_link: 'mesh',
      sensor_link: 'fallback', tag_link: 'fallback',
    });
    checkBoxes(shapes);
    // Every mesh is lit: the DAE (no normals) and the STL (zero facet normals) get their faces' normals.
    assert.deepEqual(await page.evaluate(() => {
      const unlit = [];
      window.rp.view.objects.get('arm').root.traverse((c) => {
        const n = c.isMesh && c.geometry.getAttribute('normal');
        if (c.isMesh && (!n || n.array.every((x) => x === 0))) unlit.push(c.name || c.geometry.type);
      });
      return unlit;
    }), []);
    // The hand's texture (a 4 x 4 checker board) is on its material; the forearm's missing one is not.
    await waitInPage(page, () => window.rp.view.drawnShapes('arm').every((s) => s.texture !== 'loading'));
    assert.deepEqual(await page.evaluate(() => {
      const d = window.rp.view.drawnShapes('arm');
      const hand = window.rp.view.objects.get('arm').drawn[d.findIndex((s) => s.link === 'hand_link')].objects[0];
      let map = null;
      hand.traverse((c) => { if (c.isMesh && c.material.map) map = [c.material.map.image.width, c.material.map.image.height]; });
      return { textures: d.map((s) => s.texture), map };
    }), { textures: [null, null, null, 'failed', 'drawn', null, null], map: [4, 4] });

    for (const [joint, value] of [[0, 0.7], [1, -0.5], [2, 0.8]])
      await ctx.page.evaluate(([j, v]) => window.rp.conn.message('jointmove', 'setJoint', JSON.stringify({ joint: j, value: v })), [joint, value]);
    await waitInPage(page, () => {
      const f = window.rp.frame.objects.find((x) => window.rp.scene.objects[x.index].name === 'arm');
      return Math.abs(f.values[0] - 0.7) < 0.01 && Math.abs(f.values[1] + 0.5) < 0.01 && Math.abs(f.values[2] - 0.8) < 0.01;
    }, undefined, 30000);
    checkBoxes(await sample(page));
    if (shots) await page.screenshot({ path: join(shots, 'urdf-meshes.png') });
    assert.deepEqual(page.rpErrors, []);
    await page.close();
  });

  it('reports the meshes it cannot draw next to the arm and once each on stderr', async () => {
    const page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'));
    await waitInPage(page, meshesDone, undefined, 30000);
    const label = await waitInPage(page, () => {
      const l = document.querySelector('.mesh-problems[data-object="arm"]');
      return l && !l.hidden && /broken\.dae/.test(l.textContent) && /missing_sensor\.dae/.test(l.textContent) && l.textContent;
    });
    assert.match(label, /cam_link: package:\/\/rp_mesh_arm\/meshes\/broken\.dae: /);
    assert.match(label, /sensor_link: package:\/\/rp_mesh_arm\/meshes\/missing_sensor\.dae: no such file/);
    assert.match(label, /fore_link: texture package:\/\/rp_mesh_arm\/textures\/missing_paint\.png: no such file/);
    // The label stands next to the arm, wholly inside the view.
    const box = await page.evaluate(() => {
      const r = document.querySelector('.mesh-problems[data-object="arm"]').getBoundingClientRect();
      const v = document.getElementById('view').getBoundingClientRect();
      return { left: r.left - v.left, top: r.top - v.top, right: r.right - v.left, bottom: r.bottom - v.top,
        width: v.width, height: v.height };
    });
    assert.ok(box.left >= 0 && box.right <= box.width && box.top >= 0 && box.bottom <= box.height, JSON.stringify(box));
    // Two pages drew the arm (and the Joint Move page): each file is reported once on stderr.
    await waitInPage(page, () => true);
    const out = () => ctx.program.output();
    for (let i = 0; i < 100 && !/broken\.dae/.test(out()); ++i) await new Promise((r) => setTimeout(r, 100));
    assert.equal(out().match(/rp: Scene Viewer: mesh \S*missing_sensor\.dae/g)?.length, 1, out());
    assert.equal(out().match(/rp: Scene Viewer: mesh \S*broken\.dae/g)?.length, 1, out());
    assert.match(out(), /missing_sensor\.dae of link 'sensor_link' of 'arm' .*no such file .*drawn with its collision geometry/);
    assert.equal(out().match(/rp: Scene Viewer: texture \S*missing_paint\.png/g)?.length, 1, out());
    await page.close();
  });

  it('serves only the files the description names that exist', async () => {
    const token = new URL(ctx.url).searchParams.get('token');
    const status = await ctx.page.evaluate(async (t) => {
      const out = [];
      for (let i = 0; i < 12; ++i) {
        const r = await fetch(`mesh?object=arm&shape=${i}${t ? `&token=${t}` : ''}`);
        out.push([r.status, r.headers.get('content-type')]);
      }
      return out;
    }, token);
    const ok = [200, 'application/octet-stream'];
    assert.deepEqual(status, [
      ok, ok, ok, ok, ok,                // base.obj, upper_arm.dae, broken.dae (served; the page cannot parse it), forearm.stl, hand.obj
      [404, 'text/plain'], [404, 'text/plain'], // missing_sensor.dae, missing_tag.stl: no file
      [200, 'image/png'], ok,           // the hand's texture, the tag's collision mesh
      [404, 'text/plain'], [404, 'text/plain'], [404, 'text/plain'], // nothing more
    ]);
  });

  it('frames the arm when the page opens', async () => {
    const page = await openViewer(ctx.browser, ctx.url.replace('jointmove.html', 'index.html'));
    await waitInPage(page, meshesDone, undefined, 30000);
    await waitInPage(page, () => window.rp.view.fits > 0 && !window.rp.view.refit);
    // The arm's bounding box as the camera sees it, in normalized device coordinates (-1..1).
    const span = await page.evaluate(() => {
      const v = window.rp.view;
      const lo = [Infinity, Infinity];
      const hi = [-Infinity, -Infinity];
      for (const s of v.drawnShapes('arm')) {
        for (const x of [s.box.min[0], s.box.max[0]]) for (const y of [s.box.min[1], s.box.max[1]])
          for (const z of [s.box.min[2], s.box.max[2]]) {
            const p = new v.camera.position.constructor(x, y, z).project(v.camera);
            lo[0] = Math.min(lo[0], p.x); lo[1] = Math.min(lo[1], p.y);
            hi[0] = Math.max(hi[0], p.x); hi[1] = Math.max(hi[1], p.y);
          }
      }
      return { lo, hi };
    });
    for (let i = 0; i < 2; ++i) assert.ok(span.lo[i] > -1 && span.hi[i] < 1, `the arm is cut off: ${JSON.stringify(span)}`);
    const fill = Math.max((span.hi[0] - span.lo[0]) / 2, (span.hi[1] - span.lo[1]) / 2);
    assert.ok(fill > 0.5, `the arm fills only ${(100 * fill).toFixed(0)}% of the view: ${JSON.stringify(span)}`);
    await page.close();
  });
});
