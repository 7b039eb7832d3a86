// Shared helpers of the browser tests: start a Robotic Platform program, read the URL it prints,
// drive Debian's Chromium headless through playwright-core (from web/node_modules).
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import http from 'node:http';
import { before, after } from 'node:test';
import assert from 'node:assert/strict';

const here = new URL('.', import.meta.url).pathname;
const require = createRequire(join(here, '../../web/package.json'));
const { chromium } = require('playwright-core');

export const BIN = process.env.RP_BIN_DIR || join(here, '../../build/bin');
export const CHROMIUM = process.env.RP_CHROMIUM || '/usr/bin/chromium';

// Starts `program args...`; resolves when it has printed the Scene Viewer URL.
export function startProgram(program, args = [], { cwd } = {}) {
  const workDir = cwd ? null : mkdtempSync(join(tmpdir(), 'rp-browser-'));
  const proc = spawn(join(BIN, program), args, {
    cwd: cwd || workDir,
    stdio: ['ignore', 'pipe', 'pipe'],
    // No display: a -qmotor program prints its URL and opens no browser of the user's.
    env: { ...process.env, DISPLAY: '', WAYLAND_DISPLAY: '' },
  });
  let out = '';
  const onData = (d) => {
    out += d.toString();
  };
  proc.stdout.on('data', onData);
  proc.stderr.on('data', onData);
  const exited = new Promise((resolve) => proc.on('exit', (code, signal) => resolve({ code, signal })));
  const url = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`${program}: no Scene Viewer URL in 20 s; output:\n${out}`)), 20000);
    const check = () => {
      const m = out.match(/rp: Scene Viewer at (\S+)/);
      if (m) {
        clearTimeout(timer);
        resolve(m[1]);
      }
    };
    proc.stdout.on('data', check);
    proc.stderr.on('data', check);
    exited.then(({ code, signal }) => {
      clearTimeout(timer);
      reject(new Error(`${program} exited (${code ?? signal}) before printing the URL:\n${out}`));
    });
  });
  return {
    proc,
    url,
    exited,
    output: () => out,
    async stop() {
      if (proc.exitCode === null && proc.signalCode === null) proc.kill('SIGTERM');
      const timer = setTimeout(() => proc.kill('SIGKILL'), 10000);
      const r = await exited;
      clearTimeout(timer);
      if (workDir) rmSync(workDir, { recursive: true, force: true });
      return r;
    },
  };
}

export async function launchBrowser() {
  return chromium.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: [
      '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--use-gl=swiftshader', '--enable-unsafe-swiftshader',
    ],
  });
}

// Opens `url` in a new page and waits until the scene and a first state frame arrived.
export async function openViewer(browser, url, { width = 1000, height = 700 } = {}) {
  const page = await browser.newPage({ viewport: { width, height } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url);
  await page.waitForFunction(() => window.rp && window.rp.scene && window.rp.frames > 2, null, { timeout: 20000 });
  page.rpErrors = errors;
  return page;
}

// Waits until `predicate` (run in the page with `arg`) is true; returns its last value.
export async function waitInPage(page, predicate, arg, timeout = 15000) {
  try {
    const handle = await page.waitForFunction(predicate, arg, { timeout, polling: 50 });
    return await handle.jsonValue();
  } catch (e) {
    const state = await page.evaluate(() => JSON.stringify({ connected: window.rp && window.rp.conn.connected,
      frames: window.rp && window.rp.frames, state: window.rp && window.rp.state })).catch(() => 'page gone');
    throw new Error(`not true within ${timeout} ms: ${predicate} (arg ${JSON.stringify(arg)}); page: ${state}`);
  }
}

// Non-background pixels and a coarse signature of the 3D view (read back from the WebGL canvas).
export async function canvasStats(page) {
  return page.evaluate(() => {
    const src = window.rp.view.renderer.domElement;
    const c = document.createElement('canvas');
    c.width = 200;
    c.height = 140;
    const g = c.getContext('2d');
    g.drawImage(src, 0, 0, c.width, c.height);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const bg = [d[0], d[1], d[2]];
    let foreground = 0;
    const pixels = [];
    for (let i = 0; i < d.length; i += 4) {
      const diff = Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]);
      if (diff > 30) foreground++;
      pixels.push(d[i] + d[i + 1] + d[i + 2]);
    }
    return { foreground, total: d.length / 4, pixels };
  });
}

export function pixelsChanged(a, b) {
  let n = 0;
  for (let i = 0; i < a.pixels.length; ++i) if (Math.abs(a.pixels[i] - b.pixels[i]) > 30) n++;
  return n;
}

// Waits (up to timeoutMs) until more than minPixels of the canvas differ from `before`, and returns
// how many do: the page draws a change in its next animation frames, which a loaded machine (the
// ASan build) may delay, and a small motion (a wrist joint) changes few pixels at first.
export async function waitForPictureChange(page, before, minPixels = 50, timeoutMs = 10000) {
  let changed = 0;
  for (const end = Date.now() + timeoutMs; changed <= minPixels && Date.now() < end;) {
    await sleep(200);
    changed = pixelsChanged(before, await canvasStats(page));
  }
  return changed;
}

// A raw WebSocket upgrade request from Node (no browser: any Origin header we like).
export function upgradeStatus(url, { origin, token } = {}) {
  const u = new URL(url);
  return new Promise((resolve, reject) => {
    const req = http.request({
      host: u.hostname,
      port: u.port,
      path: `/ws${token !== undefined ? `?token=${token}` : ''}`,
      headers: {
        Connection: 'Upgrade',
        Upgrade: 'websocket',
        'Sec-WebSocket-Version': '13',
        'Sec-WebSocket-Key': 'dGhlIHNhbXBsZSBub25jZQ==',
        ...(origin ? { Origin: origin } : {}),
      },
    });
    req.on('upgrade', (res, socket) => {
      socket.destroy();
      resolve(res.statusCode);
    });
    req.on('response', (res) => {
      res.resume();
      resolve(res.statusCode);
    });
    req.on('error', reject);
    req.end();
  });
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Registers before/after hooks for the enclosing describe(): start `program args...`, launch the
// browser and open the printed URL; at the end close the browser and check that the program ends
// in order on SIGTERM (an orderly system shutdown, then status 0 or the conventional 128 + 15).
// Returns an object whose program, url, browser and page are set once the hooks ran.
export function withProgram(program, args) {
  const ctx = {};
  before(async () => {
    ctx.program = startProgram(program, args);
    ctx.url = await ctx.program.url;
    ctx.browser = await launchBrowser();
    ctx.page = await openViewer(ctx.browser, ctx.url);
  });
  after(async () => {
    if (ctx.browser) await ctx.browser.close();
    if (ctx.program) {
      const r = await ctx.program.stop();
      console.log(`--- ${program} output ---\n${ctx.program.output()}`);
      assert.ok(r.code === 0 || r.code === 143 || r.signal === 'SIGTERM',
        `${program} ended with ${JSON.stringify(r)}:\n${ctx.program.output()}`);
    }
  });
  return ctx;
}
