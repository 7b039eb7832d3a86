// Browser test of the emergency stop and the shutdown notice: every page has an emergency stop
// button; pressing it shuts the program down, and every page shows why (reason and time) instead
// of an endless "reconnecting", also after the program has ended.
import { describe, it, after } from 'node:test';
import assert from 'node:assert/strict';
import { startProgram, launchBrowser, openViewer, waitInPage } from './harness.mjs';

describe('emergency stop and shutdown notice', () => {
  let program;
  let browser;
  after(async () => {
    if (browser) await browser.close();
    if (program) await program.stop();
  });

  it('the emergency stop of one page shuts the program down; every page shows it after it ended', async () => {
    program = startProgram('rp-jointmove', ['-gui-port', '0']);
    const url = await program.url;
    browser = await launchBrowser();
    const jointMove = await openViewer(browser, url);
    const viewer = await openViewer(browser, url.replace('/jointmove.html', '/index.html'));
    for (const page of [jointMove, viewer]) {
      assert.equal(await page.locator('#emergency-stop').count(), 1);
      assert.equal(await page.locator('#shutdown').count(), 0);
    }
    await jointMove.click('#emergency-stop');
    // The program ends (an orderly system shutdown: it exits, it is not killed).
    const r = await program.exited;
    assert.equal(typeof r.code, 'number', `rp-jointmove ended with ${JSON.stringify(r)}:\n${program.output()}`);
    assert.match(program.output(), /rp: system shutdown: emergency stop from the Scene Viewer/);
    for (const page of [jointMove, viewer]) {
      await page.locator('#shutdown').waitFor({ state: 'visible' });
      assert.match(await page.textContent('#shutdown-text'),
        /^System shutdown: emergency stop from the Scene Viewer.* at \d/);
      // The connection is gone and the notice stays; the status says why.
      await waitInPage(page, () => document.getElementById('status').textContent === 'program shut down: reconnecting');
      assert.equal(await page.locator('#shutdown').isVisible(), true);
      assert.deepEqual(page.rpErrors, []);
    }
  });
});
