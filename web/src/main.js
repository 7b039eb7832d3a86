// The Scene Viewer page: 3D view, Object List, pop-up menus and control panels.
import './style.css';
import { Connection } from './connection.js';
import { inform, notify, showStatus } from './ui.js';
import { SceneView } from './scene.js';
import { ObjectList, PopupMenu, ControlPanel } from './panels.js';

const view = new SceneView(document.getElementById('view'));
const panels = new Map();
let scene = null;
let lastFrame = null;

function openPanel(name) {
  if (panels.has(name)) return;
  const p = new ControlPanel(conn, name, notify, (panel) => { panel.close(); panels.delete(name); });
  panels.set(name, p);
  const desc = scene && scene.objects.find((o) => o.name === name);
  if (desc) p.setDesc(desc);
}

const conn = new Connection({
  onStatus: showStatus,
  onScene: (s) => {
    scene = s;
    view.setScene(s);
    list.setScene(s);
    for (const [name, p] of panels) {
      const desc = s.objects.find((o) => o.name === name);
      if (desc) p.setDesc(desc);
    }
  },
  onFrame: (f) => {
    lastFrame = f;
    view.setFrame(f, scene);
    for (const o of f.objects) {
      const desc = scene && scene.objects[o.index];
      const p = desc && panels.get(desc.name);
      if (p) p.setValues(o.values);
    }
  },
  onError: notify,
});
view.onMeshFailed = (object, shape, message) => conn.meshFailed(object, shape, message).catch(() => {});
const menu = new PopupMenu(conn, openPanel, notify, inform);
const showMenu = (name, x, y) => {
  const desc = scene && scene.objects.find((o) => o.name === name);
  if (desc) menu.show(desc, x, y);
};
const list = new ObjectList(document.getElementById('object-list'), showMenu);

// The pop-up menu opens when the right button is released where it was pressed: a right drag
// pans the view and opens nothing (the browser's contextmenu event comes at the press on Linux).
const canvas = view.renderer.domElement;
let rightPress = null;
canvas.addEventListener('contextmenu', (ev) => ev.preventDefault());
canvas.addEventListener('pointerdown', (ev) => {
  if (ev.button === 2) rightPress = { x: ev.clientX, y: ev.clientY };
});
canvas.addEventListener('pointerup', (ev) => {
  if (ev.button !== 2 || !rightPress) return;
  const moved = Math.hypot(ev.clientX - rightPress.x, ev.clientY - rightPress.y);
  rightPress = null;
  if (moved > 4) return;
  const name = view.pick(ev.clientX, ev.clientY);
  if (name) showMenu(name, ev.clientX, ev.clientY);
});
document.getElementById('new-view').href = location.href;
document.getElementById('qmotor-link').href = `qmotor.html${location.search}`;
document.getElementById('reset-view').addEventListener('click', () => view.resetView());
document.getElementById('show-frames').addEventListener('change', (ev) => view.showFrames(ev.target.checked));
// The end-effector pose of each manipulator, in millimetres and degrees (a few times a second).
const readout = document.getElementById('ee-readout');
setInterval(() => {
  const f = (x, w) => x.toFixed(1).padStart(w);
  const poses = view.endEffectorPoses();
  for (const e of poses) if (panels.has(e.name)) panels.get(e.name).setEndEffector(e);
  const text = poses.map((e) =>
    `${e.name}  x ${f(e.position[0], 7)}  y ${f(e.position[1], 7)}  z ${f(e.position[2], 7)} mm   ` +
    `roll ${f(e.rpy[0], 6)}  pitch ${f(e.rpy[1], 6)}  yaw ${f(e.rpy[2], 6)} deg`).join('\n');
  if (readout.textContent !== text) readout.textContent = text;
  readout.hidden = text === '';
}, 200);
document.getElementById('toggle-list').addEventListener('click', () =>
  document.getElementById('list-window').classList.toggle('hidden'));

// For tests and the console: the live state of this page.
window.rp = {
  conn,
  view,
  get scene() { return scene; },
  get frame() { return lastFrame; },
  get frames() { return conn.frames; },
  openPanel,
  showMenu,
};
