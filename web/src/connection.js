// The page side of the Scene Viewer protocol (version 1): a WebSocket that reconnects, JSON
// messages, and binary state frames decoded into plain arrays. See docs/gui.md.
import { addEmergencyStop, showShutdown } from './ui.js';

export const PROTOCOL = 1;
const MAGIC = 0x31535052; // "RPS1"

// Decodes a binary state frame: { protocol, sceneVersion, time, objects: [{index, poses, values, error}] }.
export function decodeFrame(buffer) {
  const v = new DataView(buffer);
  if (buffer.byteLength < 24 || v.getUint32(0, true) !== MAGIC) throw new Error('not a state frame');
  const frame = {
    protocol: v.getUint32(4, true),
    sceneVersion: v.getUint32(8, true),
    time: v.getFloat64(16, true),
    objects: [],
  };
  const count = v.getUint32(12, true);
  let at = 24;
  for (let k = 0; k < count; ++k) {
    const index = v.getUint32(at, true);
    const frames = v.getUint32(at + 4, true);
    const values = v.getUint32(at + 8, true);
    const error = v.getUint32(at + 12, true);
    at += 16;
    const poses = [];
    for (let f = 0; f < frames; ++f) {
      const m = new Array(16);
      for (let i = 0; i < 16; ++i, at += 8) m[i] = v.getFloat64(at, true);
      poses.push(m);
    }
    const vals = new Array(values);
    for (let i = 0; i < values; ++i, at += 8) vals[i] = v.getFloat64(at, true);
    frame.objects.push({ index, poses, values: vals, error });
  }
  return frame;
}

// Connection to the program: calls onScene(scene), onFrame(frame), onStatus(text, connected).
export class Connection {
  constructor({ onScene, onFrame, onStatus, onError, onMessage, onOpen } = {}) {
    this.onMessage = onMessage || (() => {}); // other server messages (logSamples, logState)
    this.onOpen = onOpen || (() => {});
    this.onScene = onScene || (() => {});
    this.onFrame = onFrame || (() => {});
    this.onStatus = onStatus || (() => {});
    this.onError = onError || (() => {});
    this.token = new URLSearchParams(location.search).get('token') || '';
    this.nextId = 1;
    this.pending = new Map();
    this.scene = null;
    this.frames = 0;
    this.connected = false;
    this.hello = null;
    this.shutdown = null; // the system shutdown the program reported, kept after it ended
    addEmergencyStop(this);
    this.open();
  }

  open() {
    const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
    const url = `${proto}//${location.host}/ws${this.token ? `?token=${encodeURIComponent(this.token)}` : ''}`;
    const ws = new WebSocket(url);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    this.onStatus('connecting', false);
    ws.onopen = () => {
      this.connected = true;
      this.onStatus('connected', true);
      this.send({ type: 'hello', protocol: PROTOCOL });
      this.onOpen();
    };
    ws.onclose = () => {
      this.connected = false;
      for (const { reject } of this.pending.values()) reject(new Error('connection closed'));
      this.pending.clear();
      this.onStatus(this.shutdown ? 'program shut down: reconnecting' : 'disconnected: reconnecting', false);
      setTimeout(() => this.open(), 1000);
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data !== 'string') {
        let frame;
        try {
          frame = decodeFrame(ev.data);
        } catch (e) {
          this.onError(String(e));
          return;
        }
        this.frames++;
        this.onFrame(frame);
        return;
      }
      const msg = JSON.parse(ev.data);
      if (msg.type === 'hello') this.hello = msg;
      else if (msg.type === 'shutdown') {
        this.shutdown = msg;
        showShutdown(msg);
      }
      else if (msg.type === 'scene') {
        this.scene = msg;
        this.onScene(msg);
      } else if (msg.type === 'result' || msg.type === 'error') {
        const p = this.pending.get(msg.id);
        if (p) {
          this.pending.delete(msg.id);
          if (msg.type === 'result') p.resolve(msg);
          else p.reject(new Error(msg.message));
        } else if (msg.type === 'error') this.onError(msg.message);
      } else {
        this.onMessage(msg);
      }
    };
  }

  send(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(obj));
  }

  // Sends a request and resolves with the server's result (rejects with its error).
  request(obj) {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      if (!this.ws || this.ws.readyState !== WebSocket.OPEN) {
        reject(new Error('not connected'));
        return;
      }
      this.pending.set(id, { resolve, reject });
      this.ws.send(JSON.stringify({ ...obj, id }));
    });
  }

  command(object, command) {
    return this.request({ type: 'command', object, command });
  }
  display(object, mode) {
    return this.request({ type: 'display', object, mode });
  }
  setParameter(object, name, value, index) {
    const msg = { type: 'setParameter', object, name, value };
    if (index !== undefined) msg.index = index;
    return this.request(msg);
  }
  message(object, messageType, payload) {
    return this.request({ type: 'message', object, messageType, payload });
  }
  // Tells the server that mesh `shape` of `object` cannot be drawn (it reports it on stderr).
  meshFailed(object, shape, message) {
    return this.request({ type: 'meshFailed', object, shape, message: message || 'cannot be drawn' });
  }
}
