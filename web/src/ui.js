// Small page helpers shared by the viewer and the utility pages.

// Shows `text` (an error, a refusal) in the #messages bar for five seconds.
export function notify(text) {
  const messages = document.getElementById('messages');
  messages.textContent = text;
  messages.classList.remove('hidden', 'info');
  clearTimeout(notify.timer);
  notify.timer = setTimeout(() => messages.classList.add('hidden'), 5000);
}

// Shows `text` (what a command did) in the #messages bar for five seconds, as information.
export function inform(text) {
  notify(text);
  document.getElementById('messages').classList.add('info');
}

// Shows the connection state in #status.
export function showStatus(text, ok) {
  const status = document.getElementById('status');
  status.textContent = text;
  status.className = ok ? 'ok' : 'bad';
}

// Reads what the user typed into a number field: the number, or an Error saying why it is refused
// (empty, not a plain decimal number such as "NaN", "-" or "1e", too large such as "1e999", or
// outside [min, max] when the field has a range). Nothing else is ever sent for a typed value.
export function parseNumberInput(text, min, max) {
  const t = String(text).trim();
  if (t === '') return new Error('enter a number');
  if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(t)) return new Error(`'${t}' is not a number`);
  const v = Number(t);
  if (!Number.isFinite(v)) return new Error(`${t} is too large`);
  if (typeof min === 'number' && typeof max === 'number' && max > min && (v < min || v > max))
    return new Error(`${v} is outside [${min}, ${max}]`);
  return v;
}

// Shows a system shutdown (a safety shutdown, an emergency stop, Ctrl-C) in a bar at the top of
// the page: why, the objects that reported an error, and when. It stays after the connection
// closes (the program has ended) until the user closes it.
export function showShutdown(info) {
  let bar = document.getElementById('shutdown');
  if (!bar) {
    bar = document.createElement('div');
    bar.id = 'shutdown';
    const text = document.createElement('span');
    text.id = 'shutdown-text';
    const close = document.createElement('button');
    close.textContent = '×';
    close.title = 'Hide';
    close.addEventListener('click', () => bar.classList.add('hidden'));
    bar.append(text, close);
    document.body.append(bar);
  }
  const objects = (info.objects || []).map((o) => `${o.name}: error ${o.code}${o.message ? ` (${o.message})` : ''}`);
  const when = info.time ? new Date(info.time) : null;
  const time = when && !Number.isNaN(when.getTime()) ? when.toLocaleTimeString() : String(info.time || '');
  document.getElementById('shutdown-text').textContent =
    `System shutdown: ${info.reason}${objects.length ? `; ${objects.join('; ')}` : ''} at ${time}`;
  bar.dataset.reason = info.reason;
  bar.classList.remove('hidden');
}

// Adds the emergency stop button to the page's toolbar: it shuts the whole system down.
export function addEmergencyStop(conn) {
  const toolbar = document.getElementById('toolbar');
  if (!toolbar || document.getElementById('emergency-stop')) return;
  const button = document.createElement('button');
  button.id = 'emergency-stop';
  button.textContent = 'EMERGENCY STOP';
  button.title = 'Shut the whole system down now';
  button.addEventListener('click', () => {
    conn.request({ type: 'emergencyStop' }).catch((e) => notify(`Emergency stop: ${e.message}`));
  });
  toolbar.prepend(button);
}

// The labels of a manipulator's joints from its description: the model's joint names (a URDF
// arm's own), with the default names joint1, joint2, ... of the built-in arms shown as
// "Joint 1", "Joint 2", ...; null for an object that is no manipulator.
export function jointLabels(desc) {
  if (!desc || !(desc.joints > 0)) return null;
  const names = Array.isArray(desc.jointNames) && desc.jointNames.length === desc.joints ? desc.jointNames : [];
  return Array.from({ length: desc.joints }, (_, i) =>
    (names[i] && names[i] !== `joint${i + 1}` ? names[i] : `Joint ${i + 1}`));
}
