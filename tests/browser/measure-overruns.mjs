// Measurement (not a test): servo-loop overruns and latencies of work_cell with no page open, then
// with four Scene Viewer pages open, for the same time on the real clock.
// Run: node tests/browser/measure-overruns.mjs [seconds]   (RP_BIN_DIR: the build's bin folder)
import { startProgram, launchBrowser, openViewer } from './harness.mjs';

const seconds = Number(process.argv[2] || 20);

async function run(pages) {
  const program = startProgram('work_cell', ['-gui-port', '0', '--seconds', String(seconds)]);
  const url = await program.url;
  let browser;
  const opened = [];
  if (pages > 0) {
    browser = await launchBrowser();
    for (let i = 0; i < pages; ++i) opened.push(await openViewer(browser, url, { width: 800, height: 600 }));
  }
  const { code } = await program.exited;
  const frames = [];
  for (const p of opened) frames.push(await p.evaluate(() => window.rp.frames));
  if (browser) await browser.close();
  const line = program.output().match(/servo loop: .*/);
  return { pages, code, line: line ? line[0] : program.output(), frames };
}

const results = [];
for (const pages of [0, 4]) results.push(await run(pages));
for (const r of results)
  console.log(`${r.pages} pages: ${r.line}${r.frames.length ? `; frames received per page: ${r.frames.join(', ')}` : ''}`);
