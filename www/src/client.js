// Main-thread side of the polyscene worker (src/worker.js): start it, send
// it commands, get its messages as DOM events. A page that embeds polyscene
// (a web map, a dashboard) needs only this class and, for display, SceneView.
// The npm package ships it as `polyscene/worker`.
//
//   const client = new PolysceneClient();
//   client.addEventListener('scan', (e) => view.showScan(e.detail));
//   client.configure({ preset: 'gpp2' }, { kind: 'sim', layout: 'street', seed: 1 }, { play: true });
//   const polygons = await client.detect(cloud, { stride: 3 }, { signal });
//
// Anything may be called at once: the worker keeps every message until its
// wasm is loaded (`client.ready` resolves then, with the option defaults).
// Events (detail = the worker's message, see the PROTOCOL in worker.js):
// 'ready', 'reset', 'scan', 'restored', 'state', 'error', 'progress'. Messages
// of an earlier run (sent before the last configure) are dropped here, so
// listeners never see a scan of a run that was replaced. Each 'scan' is
// acknowledged after the listeners ran, which is the worker's back-pressure.

export class PolysceneClient extends EventTarget {
  /**
   * `workerUrl`: where the worker module is (default: worker.js next to this
   * file; a bundler that follows `new Worker(new URL(...))`, such as Vite or
   * webpack, bundles it). With esbuild, bundle worker.js as an entry point of
   * its own and give its URL here.
   */
  constructor({ workerUrl } = {}) {
    super();
    this.workerUrl = workerUrl;
    this.run = 0;
    this.lastConfigure = null;
    this.requests = new Map(); // snapshot requests: id -> resolve
    this.calls = new Map(); // detect requests: id -> { message, resolve, reject, onProgress, signal, onAbort }
    this.nextRequest = 1;
    this.restarts = 0;
    this.#start();
  }

  #start() {
    // The literal `new Worker(new URL('./worker.js', import.meta.url), ...)`
    // is what bundlers recognise and bundle.
    this.worker = this.workerUrl
      ? new Worker(this.workerUrl, { type: 'module', name: 'polyscene' })
      : new Worker(new URL('./worker.js', import.meta.url), { type: 'module', name: 'polyscene' });
    this.worker.onmessage = (ev) => this.#onMessage(ev.data);
    this.worker.onerror = (ev) => {
      ev.preventDefault?.();
      const message = `worker failed: ${ev.message || 'could not start (is www/pkg built?)'}`;
      this.#emit('error', { run: this.run, fatal: true, message });
      this.#readyReject(new Error(message));
      this.#restart();
    };
    /** Resolves with the worker's 'ready' message ({ defaults }) once its wasm is loaded. */
    this.ready = new Promise((resolve, reject) => {
      this.#readyResolve = resolve;
      this.#readyReject = reject;
    });
    this.ready.catch(() => {}); // also reported as an 'error' event
    // Calls that were waiting in the worker that was replaced.
    for (const call of this.calls.values()) this.#post(call.message);
  }

  #readyResolve = () => {};
  #readyReject = () => {};

  #restart({ crash = true } = {}) {
    if (crash) {
      if (this.restarts >= 3) {
        // Give up: keep showing the error.
        for (const [id, call] of this.calls) this.#settle(id, call, new Error('the polyscene worker failed 3 times'));
        return;
      }
      this.restarts++;
    }
    this.worker.terminate();
    this.#start();
    if (this.lastConfigure) this.#post({ ...this.lastConfigure, run: ++this.run, play: false });
  }

  #emit(type, detail) {
    this.dispatchEvent(new CustomEvent(type, { detail }));
  }

  #onMessage(m) {
    if (m.type === 'ready') this.#readyResolve(m);
    if (m.type === 'progress' || m.type === 'result') {
      const call = this.calls.get(m.request);
      if (!call) return; // aborted
      if (m.type === 'progress') {
        call.onProgress?.(m);
        this.#emit('progress', m);
      } else {
        this.#settle(m.request, call, m.error === undefined ? null : new Error(m.error), m.polygons);
      }
      return;
    }
    if (m.type === 'error' && m.fatal && m.run === 0) this.#readyReject(new Error(m.message));
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

  /**
   * One-shot `detect(points, options)` in the worker: a promise of the
   * polygons. `points` is copied (structured clone), so it stays usable here
   * and the call can be sent again if the worker is replaced. `onProgress`
   * (and 'progress' events) hears `{ stage: 'started', points }` when the
   * worker begins it, then `{ stage: 'round', points, round, pointsLeft,
   * polygons }` after the cascade's first round and at most every 50 ms.
   * `signal` (an AbortSignal) rejects the promise with `signal.reason` at
   * once; a call the worker had already been sent is stopped by replacing
   * the worker (a fresh wasm instance, a few tens of ms; the running wasm
   * call cannot hear a message): a run in progress then restarts paused
   * from its first scan, with a 'reset' event, and other calls are sent
   * again.
   */
  detect(points, options, { signal, onProgress } = {}) {
    if (signal?.aborted) return Promise.reject(signal.reason);
    const request = this.nextRequest++;
    return new Promise((resolve, reject) => {
      const call = { message: { type: 'detect', request, points, options }, resolve, reject, onProgress, signal };
      if (signal) {
        call.onAbort = () => {
          this.#settle(request, call, signal.reason);
          this.#restart({ crash: false });
        };
        signal.addEventListener('abort', call.onAbort, { once: true });
      }
      this.calls.set(request, call);
      this.#post(call.message);
    });
  }

  #settle(request, call, error, value) {
    this.calls.delete(request);
    call.signal?.removeEventListener('abort', call.onAbort);
    if (error) call.reject(error);
    else call.resolve(value);
  }

  terminate() {
    this.worker.terminate();
    for (const [id, call] of this.calls) this.#settle(id, call, new Error('the polyscene worker was terminated'));
  }
}
