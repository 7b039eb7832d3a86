// Joint Move (Figure 19): a slider per joint of one manipulator; moving a slider sends the joint's
// new target to the rp-jointmove program, whose trajectory generator the arm follows at once.
import './style.css';
import { Connection } from './connection.js';
import { jointLabels, notify, showStatus } from './ui.js';
import { SceneView } from './scene.js';

const params = new URLSearchParams(location.search);
const controller = params.get('controller') || 'jointmove';
let objectName = params.get('object');
const view = new SceneView(document.getElementById('view'));
const sliders = document.getElementById('sliders');
const jmStatus = document.getElementById('jm-status');
let scene = null;
let built = null;
let rows = [];
let lastFrame = null;

function build(desc) {
  built = desc.name;
  document.getElementById('jm-title').textContent = `Joint Move: ${desc.name} (${desc.className})`;
  rows = [];
  const deg = 180 / Math.PI;
  const children = [];
  const names = jointLabels(desc);
  for (let i = 0; i < desc.joints; ++i) {
    const input = document.createElement('input');
    input.type = 'range';
    // The sliders end a margin inside the joint limits (5 % of the range, at most 5 degrees; the
    // program refuses targets beyond it): the arm lags its setpoint and would overshoot a limit.
    const margin = Math.min(0.05 * (desc.qmax[i] - desc.qmin[i]), 5 / deg);
    input.min = String((desc.qmin[i] + margin) * deg);
    input.max = String((desc.qmax[i] - margin) * deg);
    input.step = '0.1';
    input.dataset.joint = String(i);
    input.value = '0';
    const label = document.createElement('span');
    label.className = 'joint-name';
    label.textContent = names[i];
    input.title = names[i];
    const value = document.createElement('span');
    value.className = 'value';
    value.textContent = '-';
    input.addEventListener('input', () => {
      input.dataset.touched = '1';
      conn.message(controller, 'setJoint', JSON.stringify({ joint: i, value: Number(input.value) / deg }))
        .catch((e) => notify(e.message));
    });
    const row = document.createElement('div');
    row.className = 'slider-row';
    row.append(label, input, value);
    children.push(row);
    rows.push({ input, value });
  }
  sliders.replaceChildren(...children);
}

const conn = new Connection({
  onStatus: showStatus,
  onScene: (s) => {
    scene = s;
    view.setScene(s);
    const manipulators = s.objects.filter((o) => o.kind === 'manipulator');
    if (!objectName && manipulators.length) objectName = manipulators[0].name;
    const desc = manipulators.find((o) => o.name === objectName);
    if (!desc) {
      jmStatus.textContent = `no manipulator '${objectName ?? ''}'`;
      return;
    }
    jmStatus.textContent = desc.error.code ? `Error ${desc.error.code}: ${desc.error.message}` : '';
    if (built !== desc.name) build(desc);
  },
  onFrame: (f) => {
    lastFrame = f;
    view.setFrame(f, scene);
    if (!scene) return;
    const o = f.objects.find((x) => scene.objects[x.index] && scene.objects[x.index].name === built);
    if (!o) return;
    rows.forEach((r, i) => {
      const d = o.values[i] * (180 / Math.PI);
      r.value.textContent = `${d.toFixed(1)}°`;
      if (!r.input.dataset.touched) r.input.value = String(d); // start where the arm is
    });
  },
  onError: notify,
});
view.onMeshFailed = (object, shape, message) => conn.meshFailed(object, shape, message).catch(() => {});

window.rp = {
  conn,
  view,
  get scene() { return scene; },
  get frame() { return lastFrame; },
  get frames() { return conn.frames; },
};
