// Browser test: the Object List is live. object_churn creates and destroys a Puma and a gripper
// every 0.9 s; the list shows them while they live and drops them after, and the viewer keeps
// running (no access to destroyed objects: this test runs under AddressSanitizer in CI).
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { withProgram, waitInPage } from './harness.mjs';

describe('Object List of object_churn', () => {
  const ctx = withProgram('object_churn', ['-gui-port', '0']);
  const rows = () => ctx.page.$$eval('#object-table tbody tr', (trs) => trs.map((tr) => tr.dataset.object));

  it('follows objects being created and destroyed', async () => {
    const seen = new Set();
    const deadline = Date.now() + 6000;
    let last = [];
    while (Date.now() < deadline && seen.size < 4) {
      last = await rows();
      for (const name of last) if (/^arm_\d+$/.test(name)) seen.add(name);
      await new Promise((r) => setTimeout(r, 50));
    }
    assert.ok(seen.size >= 3, `saw only ${[...seen]} in 6 s`);
    const created = [...ctx.program.output().matchAll(/created (arm_\d+)/g)].map((m) => m[1]);
    for (const name of seen) assert.ok(created.includes(name), `${name} was listed but never created`);
    // Destroyed arms leave the list: at most the newest arm and its tool are listed.
    await waitInPage(ctx.page, () => [...document.querySelectorAll('#object-table tbody tr')]
      .filter((tr) => /^arm_\d+$/.test(tr.dataset.object)).length <= 1);
    const frames = await ctx.page.evaluate(() => window.rp.frames);
    assert.ok(frames > 100, `only ${frames} state frames`);
  });
});
