// Teachpendant (Figure 20): zero-gravity mode, pushing the simulated arm by dragging its
// end-effector (Shift + left drag), a list of stored positions, moving back to one, cycling.
import * as THREE from 'three';
import './style.css';
import { Connection } from './connection.js';
import { SceneView } from './scene.js';
import { notify, showStatus } from './ui.js';

const params = new URLSearchParams(location.search);
const controller = params.get('controller') || 'teachpendant';
let objectName = params.get('object');
const view = new SceneView(document.getElementById('view'));
const tbody = document.querySelector('#positions tbody');
const zeroG = document.getElementById('zero-g');
const tpStatus = document.getElementById('tp-status');
let scene = null;
let lastFrame = null;
let state = null;
const DEG = 180 / Math.PI;

async function send(type, payload) {
  try {
    const r = await conn.message(controller, type, payload === undefined ? '' : JSON.stringify(payload));
    if (r.reply) showState(JSON.parse(r.reply));
  } catch (e) {
    notify(e.message);
  }
}

function showState(s) {
  state = s;
  zeroG.textContent = `Zero gravity: ${s.zeroGravity ? 'on' : 'off'}`;
  zeroG.classList.toggle('active', s.zeroGravity);
  tpStatus.textContent = s.busy ? `moving to ${s.target}` : '';
  // The table is updated in place: a row's elements live as long as its position, so a click on
  // Go or Delete is not lost to a state update replacing the button under the pointer (the page
  // reads the state every 500 ms, and after each request).
  const selected = new Set([...tbody.querySelectorAll('input:checked')].map((b) => b.dataset.name));
  while (tbody.rows.length > s.positions.length) tbody.lastElementChild.remove();
  s.positions.forEach((p, i) => {
    const tr = tbody.rows[i] || tbody.appendChild(positionRow(i));
    const [boxCell, nameCell, qCell] = tr.cells;
    const box = boxCell.firstElementChild;
    if (box.dataset.name !== p.name) {
      box.dataset.name = p.name;
      box.checked = selected.has(p.name);
    }
    if (nameCell.textContent !== p.name) nameCell.textContent = p.name;
    const q = p.q.map((x) => (x * DEG).toFixed(1)).join(' ');
    if (qCell.textContent !== q) qCell.textContent = q;
  });
}

// The row of stored position i: selection box, name, joint angles [deg], Go and Delete.
function positionRow(i) {
  const tr = document.createElement('tr');
  tr.dataset.index = String(i);
  const box = document.createElement('input');
  box.type = 'checkbox';
  const go = document.createElement('button');
  go.textContent = 'Go';
  go.className = 'go';
  go.onclick = () => send('goto', { index: i });
  const del = document.createElement('button');
  del.textContent = 'Delete';
  del.onclick = () => send('delete', { index: i });
  tr.append(...[box, '', '', go, del].map((c) => {
    const td = document.createElement('td');
    td.append(c);
    return td;
  }));
  return tr;
}

zeroG.onclick = () => send('zeroGravity', !(state && state.zeroGravity));
document.getElementById('store').onclick = () => send('store');
document.getElementById('cycle-all').onclick = () => send('cycle', {});
document.getElementById('cycle-selected').onclick = () => {
  const indices = [...tbody.querySelectorAll('tr')].filter((tr) => tr.querySelector('input').checked).map((tr) => Number(tr.dataset.index));
  if (!indices.length) notify('select positions first');
  else send('cycle', { indices });
};
document.getElementById('stop').onclick = () => send('stop');

// Shift + left drag: a spring-damper force pulling the end-effector towards the pointer (in the
// plane through the end-effector facing the camera), sent every 50 ms while dragging; zero when
// released. The damping (on the end-effector's velocity from the state frames) lets the arm come
// to rest under the pointer instead of swinging past it.
const STIFFNESS = 300; // [N/m]
const DAMPING = 80; // [N s/m]
const MAX_FORCE = 60; // [N]: enough to move the arm by hand, not to drive it past its velocity limits
let eeVelocity = new THREE.Vector3();
let eeLast = null; // { p, t }
let dragging = false;
let pointer = null;
let pushTimer = null;
const canvas = view.renderer.domElement;

function endEffector() {
  if (!scene || !lastFrame) return null;
  const o = lastFrame.objects.find((x) => scene.objects[x.index] && scene.objects[x.index].name === objectName);
  if (!o) return null;
  const m = o.poses[o.poses.length - 1];
  return new THREE.Vector3(m[12], m[13], m[14]);
}

function pushForce() {
  const ee = endEffector();
  if (!ee || !pointer) return [0, 0, 0];
  const r = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((pointer.x - r.left) / r.width) * 2 - 1, -((pointer.y - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, view.camera);
  const normal = new THREE.Vector3();
  view.camera.getWorldDirection(normal);
  const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, ee);
  const p = new THREE.Vector3();
  if (!ray.ray.intersectPlane(plane, p)) return [0, 0, 0];
  const f = p.sub(ee).multiplyScalar(STIFFNESS).addScaledVector(eeVelocity, -DAMPING);
  if (f.length() > MAX_FORCE) f.setLength(MAX_FORCE);
  return [f.x, f.y, f.z];
}

canvas.addEventListener('pointerdown', (ev) => {
  if (!ev.shiftKey || ev.button !== 0) return;
  dragging = true;
  view.controls.enabled = false;
  pointer = { x: ev.clientX, y: ev.clientY };
  canvas.setPointerCapture(ev.pointerId);
  send('push', { force: pushForce() });
  pushTimer = setInterval(() => send('push', { force: pushForce() }), 50);
});
canvas.addEventListener('pointermove', (ev) => {
  if (dragging) pointer = { x: ev.clientX, y: ev.clientY };
});
const release = () => {
  if (!dragging) return;
  dragging = false;
  clearInterval(pushTimer);
  view.controls.enabled = true;
  send('push', { force: [0, 0, 0] });
};
canvas.addEventListener('pointerup', release);
canvas.addEventListener('pointercancel', release);

const conn = new Connection({
  onStatus: (text, ok) => {
    showStatus(text, ok);
    if (ok) setTimeout(() => send('read'), 100);
  },
  onScene: (s) => {
    scene = s;
    view.setScene(s);
    const manipulators = s.objects.filter((o) => o.kind === 'manipulator');
    if (!objectName && manipulators.length) objectName = manipulators[0].name;
    const desc = manipulators.find((o) => o.name === objectName);
    document.getElementById('tp-title').textContent = desc ? `Teachpendant: ${desc.name} (${desc.className})` : `no manipulator '${objectName ?? ''}'`;
  },
  onFrame: (f) => {
    lastFrame = f;
    view.setFrame(f, scene);
    const ee = endEffector();
    if (ee && eeLast && f.time > eeLast.t) eeVelocity = ee.clone().sub(eeLast.p).divideScalar(f.time - eeLast.t);
    if (ee) eeLast = { p: ee, t: f.time };
  },
  onError: notify,
});
view.onMeshFailed = (object, shape, message) => conn.meshFailed(object, shape, message).catch(() => {});
setInterval(() => conn.connected && send('read'), 500);

window.rp = {
  conn,
  view,
  get scene() { return scene; },
  get frame() { return lastFrame; },
  get frames() { return conn.frames; },
  get state() { return state; },
  endEffectorOnScreen() {
    const ee = endEffector();
    if (!ee) return null;
    const v = ee.clone().project(view.camera);
    const r = canvas.getBoundingClientRect();
    return { x: r.left + ((v.x + 1) / 2) * r.width, y: r.top + ((1 - v.y) / 2) * r.height };
  },
};
