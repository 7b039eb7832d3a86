// Small page helpers shared by the viewer and the utility pages.

// Shows `text` in the #messages bar for five seconds.
export function notify(text) {
  const messages = document.getElementById('messages');
  messages.textContent = text;
  messages.classList.remove('hidden');
  clearTimeout(notify.timer);
  notify.timer = setTimeout(() => messages.classList.add('hidden'), 5000);
}

// Shows the connection state in #status.
export function showStatus(text, ok) {
  const status = document.getElementById('status');
  status.textContent = text;
  status.className = ok ? 'ok' : 'bad';
}
