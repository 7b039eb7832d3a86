// Object List window, the object pop-up menu (Figure 17) and control panels (Figure 18),
// rendered from the scene description and the state frames.
import { jointLabels, parseNumberInput } from './ui.js';

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

function fmt(x) {
  if (typeof x !== 'number' || !isFinite(x)) return String(x);
  return Math.abs(x) >= 1000 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(3) : x.toFixed(4);
}

export class ObjectList {
  constructor(container, onMenu) {
    this.container = container;
    this.onMenu = onMenu;
  }
  setScene(scene) {
    const rows = scene.objects.map((o) =>
      el('tr', { 'data-object': o.name, oncontextmenu: (ev) => { ev.preventDefault(); this.onMenu(o.name, ev.clientX, ev.clientY); } },
        el('td', {}, o.name), el('td', {}, o.published === false ? '(not published)' : o.className)));
    const table = el('table', { id: 'object-table' },
      el('thead', {}, el('tr', {}, el('th', {}, 'Name'), el('th', {}, 'Class'))), el('tbody', {}, ...rows));
    this.container.replaceChildren(table);
  }
}

export class PopupMenu {
  constructor(conn, openPanel, notify, inform) {
    this.conn = conn;
    this.openPanel = openPanel;
    this.notify = notify;
    this.inform = inform;
    this.menu = el('div', { id: 'popup-menu', class: 'popup hidden' });
    document.body.append(this.menu);
    document.addEventListener('click', () => this.hide());
    document.addEventListener('keydown', (e) => e.key === 'Escape' && this.hide());
  }
  hide() {
    this.menu.classList.add('hidden');
  }
  show(desc, x, y) {
    const item = (label, action) =>
      el('div', { class: 'item', 'data-action': label, onclick: (ev) => { ev.stopPropagation(); this.hide(); action(); } }, label);
    // A command's result (or why it was refused) is shown in the page.
    const run = (p, what) => p.then((r) => {
      if (what) this.inform(`${desc.name}: ${what}: ${(r && r.reply) || 'done'}`);
    }, (e) => this.notify(`${desc.name}: ${what ? `${what}: ` : ''}${e.message}`));
    const items = [el('div', { class: 'title' }, `${desc.name} (${desc.published === false ? 'not published' : desc.className})`)];
    if (desc.physical) {
      const display = (mode) => run(this.conn.display(desc.name, mode), null);
      items.push(item(desc.display === 'off' ? 'Show' : 'Hide', () => display(desc.display === 'off' ? 'solid' : 'off')));
      items.push(item('Solid', () => display('solid')));
      items.push(item('Wireframe', () => display('wireframe')));
    }
    if (desc.commands.length) items.push(el('div', { class: 'sep' }));
    for (const c of desc.commands) {
      const i = item(c.name, () => run(this.conn.command(desc.name, c.name), c.name));
      i.title = c.description;
      items.push(i);
    }
    items.push(el('div', { class: 'sep' }));
    items.push(item('Control Panel...', () => this.openPanel(desc.name)));
    this.menu.replaceChildren(...items);
    this.menu.style.left = `${x}px`;
    this.menu.style.top = `${y}px`;
    this.menu.classList.remove('hidden');
  }
}

// The prefix of a manipulator's commands that switch its servo control (DefaultManipulator).
const SERVO_CONTROL_COMMAND = 'Servo Control: ';

// A control panel window for one object.
export class ControlPanel {
  constructor(conn, name, notify, onClose) {
    this.conn = conn;
    this.name = name;
    this.notify = notify;
    this.body = el('div', { class: 'panel-body' });
    this.status = el('div', { class: 'panel-status' });
    // The object's commands as buttons; the last one's result, or why it was refused.
    this.commands = el('div', { class: 'panel-commands' });
    this.result = el('div', { class: 'panel-result hidden' });
    this.endEffector = null;
    this.title = el('span', {}, name);
    this.win = el('div', { class: 'window panel', 'data-panel': name },
      el('div', { class: 'window-title' }, this.title, el('button', { class: 'close', onclick: () => onClose(this) }, '×')),
      this.status, this.commands, this.result, this.body);
    document.getElementById('panels').append(this.win);
    this.cells = [];
  }
  close() {
    this.win.remove();
  }
  setDesc(desc) {
    const key = JSON.stringify(desc.panel);
    this.desc = desc;
    this.title.textContent = desc.panel.title;
    this.showStatus();
    // Values change often (a tuned gain comes back in the next description): the panel is
    // rebuilt only when its fields change, and the inputs are updated in place otherwise, except
    // the one being edited, so that nothing typed is lost.
    const structure = JSON.stringify([desc.panel.title, desc.panel.fields.map((f) =>
      [f.name, f.kind, f.size, f.tunable, f.stateIndex, f.min, f.max, f.label, f.unit, f.choices])]);
    this.setCommands(desc);
    if (key === this.key) return;
    this.key = key;
    if (structure === this.structure) {
      this.updateInputs(desc);
      return;
    }
    this.structure = structure;
    this.inputs = [];
    this.cells = [];
    const rows = [];
    // A manipulator's per-joint vectors: a first row names the joints above their columns, and
    // each value's tooltip names its joint (the URDF's names, or joint1, joint2, ...).
    const names = jointLabels(desc);
    const perJoint = (f) => names && f.kind === 'vector' && f.size === names.length;
    // Joint values are shown as an operator reads them: revolute joints in degrees, prismatic
    // ones in millimetres (the program's values are in rad and m).
    const prismatic = desc.prismatic || [];
    const display = (f, i) => {
      if (!perJoint(f) || (f.unit !== 'rad' && f.unit !== 'rad/s')) return { scale: 1, unit: f.unit };
      const p = prismatic[i];
      return { scale: p ? 1000 : 180 / Math.PI, unit: (p ? 'mm' : 'deg') + (f.unit === 'rad/s' ? '/s' : '') };
    };
    const unitOf = (f) => {
      if (!perJoint(f)) return f.unit;
      const units = [...new Set(names.map((_, i) => display(f, i).unit))];
      return units.join(' or ');
    };
    if (names && desc.panel.fields.some(perJoint)) {
      rows.push(el('div', { class: 'row joint-names' }, el('label', {}, 'joint'),
        el('div', { class: 'values' }, ...names.map((name) => el('span', { class: 'joint-name', title: name }, name)))));
    }
    for (const f of desc.panel.fields) {
      if (f.name === 'errorCode') continue;
      const n = f.kind === 'vector' ? f.size : 1;
      const cell = el('div', { class: 'values' });
      let error = null;
      if (f.tunable) {
        // What is wrong with the value typed last, next to the field (the page's own check or
        // the server's reply); cleared when a value is taken.
        error = el('div', { class: 'field-error hidden', 'data-error': f.name });
        const showError = (text) => {
          error.textContent = text;
          error.classList.toggle('hidden', !text);
        };
        for (let i = 0; i < n; ++i) {
          const input = el('input', { type: 'text', inputmode: 'decimal', autocomplete: 'off', spellcheck: 'false',
            'data-field': f.name, 'data-index': String(i) });
          if (f.value) input.value = f.value[i];
          if (f.max > f.min) input.title = `${perJoint(f) ? `${names[i]}: ` : ''}${f.min} to ${f.max}`;
          else if (perJoint(f)) input.title = names[i];
          // kp[shoulder] for a named joint (a URDF arm), kp[3] for a built-in arm's third.
          const named = perJoint(f) && desc.jointNames && desc.jointNames[i] !== `joint${i + 1}`;
          const label = f.kind === 'vector' ? `${f.name}[${named ? names[i] : i + 1}]` : f.name;
          if (perJoint(f)) input.dataset.joint = names[i];
          input.addEventListener('change', () => {
            // Refused in the page: never send a value the user did not type (an empty or
            // malformed box used to go out as 0).
            const v = parseNumberInput(input.value, f.min, f.max);
            if (v instanceof Error) {
              input.classList.add('invalid');
              showError(`${label}: ${v.message}; not sent`);
              return;
            }
            input.classList.remove('invalid');
            showError('');
            this.conn.setParameter(this.name, f.name, v, f.kind === 'vector' ? i : undefined)
              .catch((e) => {
                showError(`${label}: ${e.message}`);
                this.notify(`${this.name}.${f.name}: ${e.message}`);
                const now = this.desc.panel.fields.find((x) => x.name === f.name);
                if (now && now.value) input.value = now.value[i];
              });
          });
          this.inputs.push({ input, name: f.name, index: i });
          cell.append(input);
        }
      } else if (f.stateIndex >= 0) {
        for (let i = 0; i < n; ++i) {
          const span = el('span', { class: 'value', 'data-field': f.name, 'data-index': String(i) }, '-');
          if (perJoint(f)) {
            span.title = names[i];
            span.dataset.joint = names[i];
          }
          cell.append(span);
          this.cells.push({ span, index: f.stateIndex + i, field: f, scale: display(f, i).scale });
        }
      }
      const unit = f.tunable ? f.unit : unitOf(f);
      const row = el('div', { class: 'row' }, el('label', {}, `${f.label}${unit ? ` [${unit}]` : ''}${f.tunable ? ' (tunable)' : ''}`), cell);
      if (error) row.append(error);
      rows.push(row);
    }
    if (desc.kind === 'manipulator') {
      // The end-effector's pose in the world (setEndEffector(), from the 3D view's frames).
      this.endEffector = el('div', { class: 'values', 'data-field': 'endEffector' }, '-');
      rows.push(el('div', { class: 'row' }, el('label', {}, 'End-effector [mm, deg]'), this.endEffector));
    } else {
      this.endEffector = null;
    }
    this.body.replaceChildren(...rows);
  }
  // The command buttons, rebuilt when the object's commands change.
  // A manipulator's servo controls (commands "Servo Control: NAME") are one switch, showing the
  // one in use, instead of a button each.
  setCommands(desc) {
    const servo = SERVO_CONTROL_COMMAND;
    const key = JSON.stringify([desc.commands || [], desc.servoControls || []]);
    if (key !== this.commandKey) {
      this.commandKey = key;
      const items = (desc.commands || []).filter((c) => !c.name.startsWith(servo)).map((c) =>
        el('button', { 'data-command': c.name, title: c.description || c.name, onclick: () => this.run(c.name) }, c.name));
      this.servoSwitch = null;
      if ((desc.servoControls || []).length) {
        this.servoSwitch = el('select', { 'data-field': 'servoControl', title: 'the servo control in use',
          onchange: () => this.run(servo + this.servoSwitch.value).then((ok) => {
            if (!ok && this.desc.servoControl) this.servoSwitch.value = this.desc.servoControl;  // refused
          }) },
        ...desc.servoControls.map((n) => el('option', { value: n }, n)));
        items.push(el('label', { class: 'servo-switch' }, 'Servo control ', this.servoSwitch));
      }
      this.commands.replaceChildren(...items);
      this.commands.classList.toggle('hidden', items.length === 0);
    }
    // The one in use, as the program says (a refused switch goes back to it).
    if (this.servoSwitch && desc.servoControl && document.activeElement !== this.servoSwitch)
      this.servoSwitch.value = desc.servoControl;
  }
  // Runs command `name`; shows what it did, or why it was refused.
  // Resolves to whether it was carried out.
  run(name) {
    return this.conn.command(this.name, name).then((r) => {
      this.showResult(`${name}: ${(r && r.reply) || 'done'}`, false);
      return true;
    }, (e) => {
      this.showResult(`${name}: ${e.message}`, true);
      this.notify(`${this.name}: ${name}: ${e.message}`);
      return false;
    });
  }
  showResult(text, refused) {
    this.result.textContent = text;
    this.result.className = `panel-result ${refused ? 'error' : ''}`;
  }
  // The end-effector pose: position [mm], roll, pitch, yaw [deg] (a manipulator's panel).
  setEndEffector(pose) {
    if (!this.endEffector || !pose) return;
    const f = (x) => x.toFixed(1);
    const text = `x ${f(pose.position[0])}  y ${f(pose.position[1])}  z ${f(pose.position[2])}  ` +
      `roll ${f(pose.rpy[0])}  pitch ${f(pose.rpy[1])}  yaw ${f(pose.rpy[2])}`;
    if (this.endEffector.textContent !== text) this.endEffector.textContent = text;
  }
  // The object's error status, or the system shutdown once the program reported one.
  showStatus() {
    const e = this.desc.error;
    const down = this.conn.shutdown;
    let text = 'No error';
    if (e.code) text = `Error ${e.code}: ${e.message}`;
    else if (down) text = `System shutdown: ${down.reason}`;
    this.status.textContent = text;
    this.status.className = `panel-status ${e.code || down ? 'error' : ''}`;
    this.shownShutdown = down;
  }
  updateInputs(desc) {
    for (const { input, name, index } of this.inputs) {
      if (input === document.activeElement || input.classList.contains('invalid')) continue;
      const f = desc.panel.fields.find((x) => x.name === name);
      if (f && f.value) input.value = f.value[index];
    }
  }
  setValues(values) {
    if (this.desc && this.conn.shutdown !== this.shownShutdown) this.showStatus();
    for (const c of this.cells) {
      const v = values[c.index];
      if (v === undefined) continue;
      let text = fmt(v * (c.scale || 1));
      if (c.field.kind === 'boolean') text = v ? 'on' : 'off';
      else if (c.field.kind === 'choice') text = c.field.choices[v] ?? String(v);
      c.span.textContent = text;
    }
  }
}
