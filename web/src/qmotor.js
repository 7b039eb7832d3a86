// QMotor window: live plots (uPlot) of an object's state values and its tunable parameters.
// The values come with the state frames (60 Hz); the last 10 s are shown. Pause freezes the plot
// (samples keep coming); a drag zooms in on a time span and the wheel pans it, both freezing the
// plot so that the next frame does not undo them; Live follows again; the values under the cursor
// are read out; Export PNG saves the plot.
import 'uplot/dist/uPlot.min.css';
import uPlot from 'uplot';
import './style.css';
import { Connection } from './connection.js';
import { ControlPanel } from './panels.js';
import { jointLabels, notify, showStatus } from './ui.js';

const params = new URLSearchParams(location.search);
const select = document.getElementById('object');
const fieldsEl = document.getElementById('fields');
const plotEl = document.getElementById('plot');
const HISTORY = 600; // samples kept (10 s at 60 Hz)
let scene = null;
let objectName = params.get('object');
let chosen = new Set((params.get('fields') || '').split(',').filter(Boolean));
let panel = null;
let plot = null;
let series = []; // [{label, index}]
let data = [[]];
let samples = 0;
let dirty = false;
let frozen = false; // paused, zoomed or panned: the plot shows what it showed
const modeEl = document.getElementById('plot-mode');
const cursorEl = document.getElementById('plot-cursor');
let cursor = null; // { t, values: { label: value } } under the mouse
let lastFrame = null; // the latest state frame (every object's values)

function freeze(why) {
  // The plot keeps a copy of the samples it shows: new ones go on arriving in `data`.
  if (!frozen && plot) plot.setData(data.map((a) => a.slice()), false);
  frozen = true;
  modeEl.textContent = why;
}
function live() {
  frozen = false;
  modeEl.textContent = 'live';
  if (plot) plot.setData(data); // the latest samples, scales fitted to them again
  dirty = false;
}

function makePlot() {
  if (plot) plot.destroy();
  data = [[], ...series.map(() => [])];
  const colors = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f'];
  plot = new uPlot({
    width: plotEl.clientWidth || 700,
    height: 320,
    scales: { x: { time: false } },
    axes: [{ label: 'time [s]' }, {}],
    series: [{ label: 't' }, ...series.map((s, i) => ({ label: s.label, stroke: colors[i % colors.length], width: 1.5 }))],
    cursor: { drag: { x: true, y: false } },
    hooks: {
      // A drag zooms in: keep it (the next frame would reset the scales).
      setSelect: [(u) => {
        if (u.select.width > 2) freeze('zoomed');
      }],
      setCursor: [(u) => {
        const i = u.cursor.idx;
        if (i == null || !u.data[0].length) {
          cursor = null;
          cursorEl.textContent = '';
          return;
        }
        cursor = { t: u.data[0][i], values: {} };
        series.forEach((s, k) => (cursor.values[s.label] = u.data[k + 1][i]));
        cursorEl.textContent = `t ${cursor.t.toFixed(3)} s: ` +
          series.map((s) => `${s.label} ${Number(cursor.values[s.label]).toPrecision(5)}`).join(', ');
      }],
    },
  }, data, plotEl);
  // The wheel pans the shown time span (and freezes the plot there).
  plot.over.addEventListener('wheel', (ev) => {
    ev.preventDefault();
    const { min, max } = plot.scales.x;
    if (min == null || max == null) return;
    const shift = (max - min) * 0.1 * Math.sign(ev.deltaY || ev.deltaX);
    freeze('panned');
    plot.setScale('x', { min: min + shift, max: max + shift });
  }, { passive: false });
  if (frozen) {
    frozen = false; // a new plot (other fields): frozen again with its own copy
    freeze(modeEl.textContent);
  }
}

document.getElementById('plot-pause').addEventListener('click', () => freeze('paused'));
document.getElementById('plot-live').addEventListener('click', live);
document.getElementById('plot-png').addEventListener('click', () => {
  if (!plot) return;
  const a = document.createElement('a');
  a.download = `qmotor-${objectName || 'plot'}-${new Date().toISOString().replace(/[:.]/g, '-')}.png`;
  a.href = plot.ctx.canvas.toDataURL('image/png');
  a.click();
});

function buildFields(desc) {
  const fields = desc.panel.fields.filter((f) => f.stateIndex >= 0 && (f.kind === 'vector' || f.kind === 'number'));
  if (!chosen.size && fields.length) chosen = new Set([fields[0].name]);
  const boxes = fields.map((f) => {
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.dataset.field = f.name;
    box.checked = chosen.has(f.name);
    box.addEventListener('change', () => {
      if (box.checked) chosen.add(f.name);
      else chosen.delete(f.name);
      buildSeries(desc);
    });
    label.append(box, ` ${f.label}${f.unit ? ` [${f.unit}]` : ''}`);
    return label;
  });
  fieldsEl.replaceChildren(...boxes);
  buildSeries(desc);
}

function buildSeries(desc) {
  series = [];
  // A per-joint vector of an arm with named joints (a URDF arm) plots as q[shoulder], ...
  const names = jointLabels(desc);
  const named = (f, i) => names && f.size === names.length && desc.jointNames && desc.jointNames[i] !== `joint${i + 1}`;
  for (const f of desc.panel.fields)
    if (chosen.has(f.name) && f.stateIndex >= 0)
      for (let i = 0; i < (f.kind === 'vector' ? f.size : 1); ++i)
        series.push({ label: f.kind === 'vector' ? `${f.name}[${named(f, i) ? names[i] : i}]` : f.name, index: f.stateIndex + i });
  makePlot();
}

function choose(name) {
  const desc = scene.objects.find((o) => o.name === name);
  if (!desc) return;
  objectName = name;
  select.value = name;
  document.getElementById('plot-info').textContent = `${desc.name} (${desc.className})`;
  if (panel) panel.close();
  panel = new ControlPanel(conn, name, notify, () => {});
  panel.setDesc(desc);
  buildFields(desc);
}

select.addEventListener('change', () => {
  chosen = new Set();
  choose(select.value);
});

const conn = new Connection({
  onStatus: showStatus,
  onScene: (s) => {
    const first = !scene;
    scene = s;
    // Objects with values to plot, and every object that runs a control program (to start,
    // stop, tune and log it).
    const candidates = s.objects.filter((o) => o.hasControlLoop || o.panel.fields.some((f) => f.stateIndex >= 0));
    select.replaceChildren(...candidates.map((o) => new Option(`${o.name} (${o.className})`, o.name)));
    if (first || !candidates.some((o) => o.name === objectName)) {
      choose(objectName && candidates.some((o) => o.name === objectName) ? objectName : candidates[0] && candidates[0].name);
    } else {
      select.value = objectName;
      const desc = s.objects.find((o) => o.name === objectName);
      if (desc && panel) panel.setDesc(desc);
    }
  },
  onFrame: (f) => {
    lastFrame = f;
    if (!scene || !plot) return;
    const o = f.objects.find((x) => scene.objects[x.index] && scene.objects[x.index].name === objectName);
    if (!o) return;
    if (panel) panel.setValues(o.values);
    data[0].push(f.time);
    series.forEach((s, i) => data[i + 1].push(o.values[s.index]));
    if (data[0].length > HISTORY) for (const d of data) d.shift();
    samples++;
    dirty = true;
  },
  onError: notify,
});

const redraw = () => {
  requestAnimationFrame(redraw);
  if (dirty && plot && !frozen) {
    plot.setData(data);
    dirty = false;
  }
};
redraw();
new ResizeObserver(() => plot && plot.setSize({ width: plotEl.clientWidth || 700, height: 320 })).observe(plotEl);

window.rp = {
  conn,
  get scene() { return scene; },
  get frames() { return conn.frames; },
  get samples() { return samples; },
  get series() { return series.map((s) => s.label); },
  get data() { return data; },
  get plot() { return plot; },
  get frozen() { return frozen; },
  get cursor() { return cursor; },
  get lastFrame() { return lastFrame; },
};

// ---- Log variables: plots of any column of the program's log file, and start/stop logging ----
const LOG_HISTORY = 10; // seconds shown
const logEl = {
  file: document.getElementById('log-file'),
  state: document.getElementById('log-state'),
  columns: document.getElementById('log-columns'),
  filter: document.getElementById('log-filter'),
  plot: document.getElementById('log-plot'),
  start: document.getElementById('log-start'),
  stop: document.getElementById('log-stop'),
};
const logChosen = new Set((params.get('log') || '').split(',').filter(Boolean));
let logInfo = null;
let logPlot = null;
let logSeries = []; // column names, as plotted
let logData = { t: [], v: [] }; // per column: times and values
let logSamples = 0;
let logDirty = false;

function showLogState(logging) {
  logEl.state.textContent = logging ? 'logging' : 'stopped';
  logEl.state.className = logging ? 'on' : 'off';
  if (logInfo) logInfo.logging = logging;
}

function makeLogPlot() {
  if (logPlot) logPlot.destroy();
  logPlot = null;
  if (!logSeries.length) return;
  const colors = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f'];
  logPlot = new uPlot({
    width: logEl.plot.clientWidth || 700,
    height: 260,
    scales: { x: { time: false } },
    axes: [{ label: 'time [s]' }, {}],
    series: [{ label: 't' }, ...logSeries.map((c, i) => ({ label: c, stroke: colors[i % colors.length], width: 1.5 }))],
  }, [[], ...logSeries.map(() => [])], logEl.plot);
}

// The plotted data: the union of the columns' times (programs may sample at different times).
function logPlotData() {
  const times = [...new Set(logSeries.flatMap((c) => logData[c].t))].sort((a, b) => a - b);
  const index = new Map(times.map((t, i) => [t, i]));
  return [times, ...logSeries.map((c) => {
    const out = new Array(times.length).fill(null);
    logData[c].t.forEach((t, i) => { out[index.get(t)] = logData[c].v[i]; });
    return out;
  })];
}

async function subscribeLog() {
  logSeries = [...logChosen];
  const old = logData;
  logData = {};
  for (const c of logSeries) logData[c] = old[c] || { t: [], v: [] }; // columns kept go on
  makeLogPlot();
  try {
    await conn.request({ type: 'logSubscribe', columns: logSeries });
  } catch (e) {
    notify(`log: ${e.message}`);
  }
}

function buildLogColumns() {
  const f = logEl.filter.value.trim();
  const boxes = logInfo.columns.filter((c) => !f || c.includes(f)).map((c) => {
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.dataset.column = c;
    box.checked = logChosen.has(c);
    box.addEventListener('change', () => {
      if (box.checked) logChosen.add(c);
      else logChosen.delete(c);
      subscribeLog();
    });
    label.append(box, ` ${c}`);
    return label;
  });
  logEl.columns.replaceChildren(...boxes);
}

async function loadLog() {
  try {
    const r = await conn.request({ type: 'logInfo' });
    logInfo = JSON.parse(r.reply);
    logEl.file.textContent = logInfo.file;
    showLogState(logInfo.logging);
    for (const c of [...logChosen]) if (!logInfo.columns.includes(c)) logChosen.delete(c);
    buildLogColumns();
    subscribeLog();
  } catch (e) {
    logInfo = null;
    logEl.file.textContent = '';
    logEl.state.textContent = e.message;
    logEl.state.className = 'off';
    logEl.columns.replaceChildren();
  }
}

async function setLogging(on) {
  try {
    const r = await conn.request({ type: 'logging', on });
    showLogState(JSON.parse(r.reply).logging);
  } catch (e) {
    notify(`log: ${e.message}`);
  }
}

logEl.start.addEventListener('click', () => setLogging(true));
logEl.stop.addEventListener('click', () => setLogging(false));
logEl.filter.addEventListener('input', () => logInfo && buildLogColumns());
conn.onOpen = () => loadLog();
if (conn.connected) loadLog();
conn.onMessage = (msg) => {
  if (msg.type === 'logState') showLogState(msg.logging);
  if (msg.type !== 'logSamples') return;
  for (const s of msg.series) {
    const d = logData[s.column];
    if (!d) continue;
    // A batch may overlap what is plotted (a new subscription replays the recent samples).
    const after = d.t.length ? d.t[d.t.length - 1] : -Infinity;
    for (let i = 0; i < s.t.length; ++i) {
      if (s.t[i] <= after) continue;
      d.t.push(s.t[i]);
      d.v.push(s.v[i]);
      logSamples++;
    }
    const last = d.t[d.t.length - 1];
    let drop = 0;
    while (drop < d.t.length && d.t[drop] < last - LOG_HISTORY) drop++;
    if (drop) {
      d.t.splice(0, drop);
      d.v.splice(0, drop);
    }
  }
  logDirty = true;
};
const redrawLog = () => {
  requestAnimationFrame(redrawLog);
  if (logDirty && logPlot) {
    logPlot.setData(logPlotData());
    logDirty = false;
  }
};
redrawLog();
new ResizeObserver(() => logPlot && logPlot.setSize({ width: logEl.plot.clientWidth || 700, height: 260 })).observe(logEl.plot);

Object.defineProperties(window.rp, Object.getOwnPropertyDescriptors({
  get logInfo() { return logInfo; },
  get logSamples() { return logSamples; },
  get logSeries() { return logSeries; },
  get logData() { return logData; },
}));

// ---- The control program: start, stop, restart; save and load its control-program files; ----
// ---- QMotor's log (variables, decimation, trigger) and its CSV download.                   ----
const progEl = {
  name: document.getElementById('prog-name'),
  state: document.getElementById('prog-state'),
  result: document.getElementById('prog-result'),
  saveAs: document.getElementById('cfg-save-as'),
  files: document.getElementById('cfg-files'),
  folder: document.getElementById('cfg-folder'),
  capVars: document.getElementById('cap-variables'),
  capState: document.getElementById('cap-state'),
  every: document.getElementById('cap-every'),
  samplesIn: document.getElementById('cap-samples'),
  trigColumn: document.getElementById('cap-trigger-column'),
  trigEdge: document.getElementById('cap-trigger-edge'),
  trigLevel: document.getElementById('cap-trigger-level'),
};
let progStatus = null; // the last status of the chosen object's program
let progResult = null; // { ok, text } of the last request
let lastReply = null; // the last reply to a button (with the program's status at that moment)
let capVariablesOf = ''; // the object whose variables the check boxes list

function showResult(ok, text) {
  progResult = { ok, text };
  progEl.result.textContent = text;
  progEl.result.className = ok ? 'ok' : 'bad';
}

function showProgramStatus(s) {
  progStatus = s;
  if (!s.hasProgram) {
    progEl.name.textContent = `${s.object}: no control program`;
    progEl.state.textContent = '';
    return;
  }
  progEl.name.textContent = `${s.program} (${s.rate} Hz)`;
  progEl.state.textContent = s.running ? `running, ${s.cycles} cycles` : `stopped after ${s.cycles} cycles`;
  if (s.timing && s.timing.executorPrograms > 0) {
    // Its own computation time, and its executor's wake-up latency and overruns (docs/realtime.md).
    const t = s.timing;
    const shared = t.ownThread ? 'own thread' : `executor of ${t.executorPrograms}`;
    const last = t.lastOverrunProgram ? `, last by ${t.lastOverrunProgram}` : '';
    progEl.state.title = `computation p50 ${t.computationP50.toFixed(1)} µs, p99 ${t.computationP99.toFixed(1)} µs, ` +
      `max ${t.computationMax.toFixed(1)} µs; ${shared}: wake-up p99 ${t.wakeupP99.toFixed(1)} µs, ` +
      `${t.overruns} overruns${last}`;
    progEl.state.textContent += ` · computation p99 ${t.computationP99.toFixed(1)} µs · ${t.overruns} overruns${last}`;
  }
  progEl.state.className = s.running ? 'on' : 'off';
  progEl.folder.textContent = s.folder ? `in ${s.folder}` : 'no rp.cfg section: no folder';
  progEl.folder.title = s.configFile ? `qmotorConfig ${s.configFile}` : '';
  const chosenFile = progEl.files.value;
  if (progEl.files.options.length !== s.files.length || s.files.some((f, i) => progEl.files.options[i].value !== f)) {
    progEl.files.replaceChildren(...s.files.map((f) => new Option(f, f)));
    if (s.files.includes(chosenFile)) progEl.files.value = chosenFile;
  }
  if (capVariablesOf !== s.object) {
    capVariablesOf = s.object;
    progEl.capVars.replaceChildren(...s.variables.map((v) => {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.dataset.variable = v.name;
      label.append(box, ` ${v.name}${v.unit ? ` [${v.unit}]` : ''}`);
      return label;
    }));
    const columns = s.variables.flatMap((v) => (v.vector ? [...Array(v.size).keys()].map((i) => `${v.name}[${i}]`) : [v.name]));
    progEl.trigColumn.replaceChildren(new Option('none (at once)', ''), ...columns.map((c) => new Option(c, c)));
  }
  const c = s.capture;
  if (!c.armed) progEl.capState.textContent = 'not armed';
  else if (!c.triggered && !c.trigger) progEl.capState.textContent = 'armed: from the next cycle';
  else if (!c.triggered) progEl.capState.textContent = `armed: waiting for ${c.trigger.column} ${c.trigger.edge} through ${c.trigger.level}`;
  else progEl.capState.textContent = `${c.rows} of ${c.capacity} rows${c.rows === c.capacity ? ' (full)' : ''}, every ${c.every} cycles, from t = ${c.triggerTime.toFixed(3)} s`;
  progEl.capState.className = c.armed && c.triggered && c.rows < c.capacity ? 'on' : 'off';
}

// Sends a QMotor request about the chosen object; shows the message or the refusal with its reason.
async function qmotor(action, fields = {}, quiet = false) {
  if (!objectName) return null;
  try {
    const r = await conn.request({ type: 'qmotor', object: objectName, action, ...fields });
    const reply = JSON.parse(r.reply);
    if (reply.status) showProgramStatus(reply.status);
    if (!quiet) lastReply = reply;
    if (!quiet && reply.message) showResult(true, reply.message);
    return reply;
  } catch (e) {
    if (!quiet) showResult(false, `${action}: ${e.message}`);
    return null;
  }
}

document.getElementById('prog-start').addEventListener('click', () => qmotor('start'));
document.getElementById('prog-stop').addEventListener('click', () => qmotor('stop'));
document.getElementById('prog-restart').addEventListener('click', () => qmotor('restart'));
document.getElementById('cfg-save').addEventListener('click', () => {
  const file = progEl.saveAs.value.trim();
  qmotor('save', file ? { file } : {});
});
document.getElementById('cfg-load').addEventListener('click', () => {
  if (!progEl.files.value) return showResult(false, 'load: no control-program file in the folder');
  qmotor('load', { file: progEl.files.value });
});
document.getElementById('cap-arm').addEventListener('click', () => {
  const variables = [...progEl.capVars.querySelectorAll('input:checked')].map((b) => b.dataset.variable);
  // Numbers as typed: the server checks them (and names a bad one).
  const fields = { variables, every: Number(progEl.every.value), samples: Number(progEl.samplesIn.value) };
  fields.trigger = progEl.trigColumn.value
    ? { column: progEl.trigColumn.value, edge: progEl.trigEdge.value, level: Number(progEl.trigLevel.value) }
    : null;
  qmotor('capture', fields);
});
document.getElementById('cap-download').addEventListener('click', async () => {
  const reply = await qmotor('csv');
  if (!reply) return;
  const a = document.createElement('a');
  a.download = reply.file;
  a.href = URL.createObjectURL(new Blob([reply.csv], { type: 'text/csv' }));
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 60000);
  showResult(true, `downloaded ${reply.rows} rows as ${reply.file}`);
});
select.addEventListener('change', () => qmotor('status', {}, true));
// The program's state, twice a second.
setInterval(() => conn.connected && qmotor('status', {}, true), 500);

Object.defineProperties(window.rp, Object.getOwnPropertyDescriptors({
  get program() { return progStatus; },
  get result() { return progResult; },
  get lastReply() { return lastReply; },
}));
