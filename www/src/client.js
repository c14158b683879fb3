// Main-thread side of the polyscene worker (src/worker.js): start it, send
// it commands, get its messages as DOM events. A page that embeds polyscene
// (a web map, a dashboard) needs only this class and, for display, SceneView.
//
//   const client = new PolysceneClient();
//   client.addEventListener('scan', (e) => view.showScan(e.detail));
//   client.configure({ preset: 'gpp2' }, { kind: 'sim', layout: 'street', seed: 1 }, { play: true });
//
// Events (detail = the worker's message, see the PROTOCOL in worker.js):
// 'ready', 'reset', 'scan', 'restored', 'state', 'error'. Messages of an earlier run (sent
// before the last configure) are dropped here, so listeners never see a scan
// of a run that was replaced. Each 'scan' is acknowledged after the
// listeners ran, which is the worker's back-pressure.

export class PolysceneClient extends EventTarget {
  constructor({ workerUrl = new URL('./worker.js', import.meta.url) } = {}) {
    super();
    this.workerUrl = workerUrl;
    this.run = 0;
    this.lastConfigure = null;
    this.requests = new Map();
    this.nextRequest = 1;
    this.restarts = 0;
    this.#start();
  }

  #start() {
    this.worker = new Worker(this.workerUrl, { type: 'module', name: 'polyscene' });
    this.worker.onmessage = (ev) => this.#onMessage(ev.data);
    this.worker.onerror = (ev) => {
      ev.preventDefault?.();
      this.#emit('error', { run: this.run, fatal: true, message: `worker failed: ${ev.message || 'could not start (is www/pkg built?)'}` });
      this.#restart();
    };
  }

  #restart() {
    if (this.restarts >= 3) return; // give up: keep showing the error
    this.restarts++;
    this.worker.terminate();
    this.#start();
    if (this.lastConfigure) this.#post({ ...this.lastConfigure, run: ++this.run, play: false });
  }

  #emit(type, detail) {
    this.dispatchEvent(new CustomEvent(type, { detail }));
  }

  #onMessage(m) {
    if (m.type === 'snapshot') {
      const r = this.requests.get(m.request);
      this.requests.delete(m.request);
      r?.(m.json);
      return;
    }
    if (m.run !== undefined && m.run !== this.run && m.type !== 'error') return;
    if (m.type === 'scan') {
      try {
        this.#emit('scan', m);
      } finally {
        this.worker.postMessage({ type: 'ack', run: m.run });
      }
      return;
    }
    if (m.type === 'error' && m.fatal && m.run === this.run) {
      this.#emit('error', m);
      this.#restart();
      return;
    }
    this.#emit(m.type, m);
  }

  #post(m) {
    this.worker.postMessage(m);
  }

  /**
   * Start a new run: a new Scenario(options) over `source` from its first
   * scan (`source` omitted: the previous one). `play`: start playing (default:
   * keep the current play state). Returns the run number.
   */
  configure(options, source, { play } = {}) {
    const run = ++this.run;
    const m = { type: 'configure', run, options: { ...options } };
    if (source) m.source = source;
    if (play !== undefined) m.play = play;
    // Kept (with the source) to replay after a worker restart.
    this.lastConfigure = { ...m, source: source || this.lastConfigure?.source };
    this.#post(m);
    return run;
  }

  /**
   * Replace the run by a scenario restored from a snapshot (`json`: the text
   * of `scenario.toJSONString()` / a saved snapshot file). Answered by 'reset',
   * 'restored' (polygons, mesh) and 'state', or by 'error' naming `label`.
   * Returns the run number.
   */
  restore(json, label = 'snapshot') {
    const run = ++this.run;
    const m = { type: 'restore', run, json: String(json), label };
    this.lastConfigure = m;
    this.#post(m);
    return run;
  }

  play() {
    this.#post({ type: 'play' });
  }

  pause() {
    this.#post({ type: 'pause' });
  }

  step() {
    this.#post({ type: 'step' });
  }

  /** Scans per second; 0 for as fast as possible. */
  setSpeed(scansPerSecond) {
    this.#post({ type: 'speed', scansPerSecond });
  }

  /** The scenario's snapshot (`Scenario.toJSON()`), or null before a run. */
  snapshot() {
    const request = this.nextRequest++;
    return new Promise((resolve) => {
      this.requests.set(request, resolve);
      this.#post({ type: 'snapshot', request });
    });
  }

  terminate() {
    this.worker.terminate();
  }
}
