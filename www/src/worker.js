// The polyscene worker: owns the wasm module, the Scenario and the scan
// source (the built-in simulator or scans handed over by the page), and runs
// the scans off the main thread. It speaks a small message protocol; see
// PROTOCOL below and src/client.js, the main-thread side.
//
// Started as an ES module worker:
//   new Worker(new URL('./worker.js', import.meta.url), { type: 'module' })
//
// PROTOCOL
// page -> worker
//   { type: 'configure', run, options, source? }
//        Start run `run` from scan 0 with a new Scenario(options). `source` is
//        { kind: 'sim', layout, seed } or
//        { kind: 'files', label, scans: [{ name, points: Float32Array (stride 4,
//          sensor frame), pose: 16 numbers column-major | null }] };
//        omitted: replay the previous source. The worker keeps file scans, so
//        a change of options replays them without the page sending them again.
//   { type: 'play' } | { type: 'pause' } | { type: 'step' }
//   { type: 'speed', scansPerSecond }      0 = as fast as the library goes
//   { type: 'ack', run }                   the page consumed one 'scan' message
//   { type: 'snapshot', request }          ask for scenario.toJSON()
//   { type: 'detect', request, points, options }
//        One-shot detect(points, options) on a world-frame cloud, apart from
//        the run (the run's scenario is untouched).
//   { type: 'restore', run, json, label }  replace the run by Scenario.fromJSON(json)
//        (json: a snapshot's text); answered by 'reset' (source kind
//        'snapshot', total 0), 'restored' and 'state' (done), or by 'error'
// worker -> page
//   { type: 'ready', defaults }            wasm loaded; defaults: every option of
//                                          each preset ({ gpp1, gpp2 }), for a GUI
//   { type: 'reset', run, source: { kind, label, total } }
//   { type: 'scan', run, index, total, name, points, labels, pose, report,
//     polygons?, mesh?, workerMs }
//        points: Float32Array stride 4, sensor frame (transferred);
//        labels: Uint32Array, one per point (transferred);
//        pose: Float64Array(16), column-major world-from-sensor;
//        polygons / mesh: only when the scan changed them (their typed arrays
//        are transferred too).
//   { type: 'state', run, playing, done }
//   { type: 'snapshot', request, json }     json: scenario.toJSONString() (exact)
//   { type: 'progress', request, stage: 'started', points }
//        the worker began a request (messages wait in order until the wasm is
//        loaded, then each runs to its end)
//   { type: 'progress', request, stage: 'round', points, round, pointsLeft, polygons }
//        after a round of the detection cascade (the first, then at most one
//        per PROGRESS_MS); pointsLeft falls towards 0 (a second time in the
//        coarse pass of a cloud seen from nowhere)
//   { type: 'result', request, polygons?, error?, ms }
//        the request's answer: polygons (vertices transferred), or an error
//        message
//   { type: 'restored', run, scans, polygons, mesh, options }
//        the restored scenario: scans it had seen, its polygons and mesh
//        (typed arrays transferred), its options
//   { type: 'error', run, message, fatal }  fatal: the module is unusable,
//                                            start a new worker
//
// Handshake: onmessage is set while the module first runs, before any await,
// so nothing posted before the wasm is loaded is lost: every message waits
// for 'ready' (or the fatal 'error') and then runs in the order it was sent.
//
// Back-pressure: at most MAX_IN_FLIGHT scans are posted and not yet acked, so
// a slow page (software WebGL) never gets a growing queue of scans.

import init, { Scenario, detectWithProgress, defaultOptions } from '../pkg/polyscene.js';
// The simulator is a wasm of its own (polyscene/sim), so that the detection
// wasm does not carry it; its scans go into the Scenario as copies.
import initSim, { simulate } from '../pkg/polyscene_sim.js';

const MAX_IN_FLIGHT = 2;
const PROGRESS_MS = 50;
const IDENTITY = new Float64Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);

const st = {
  run: 0,
  options: null,
  source: null, // { kind: 'sim', layout, seed } | { kind: 'files', label, scans }
  scenario: null,
  sim: null,
  cursor: 0,
  total: 0,
  playing: false,
  interval: 100, // ms between scan starts (10 scans/s, real time for a 10 Hz sensor)
  inFlight: 0,
  timer: null,
  fatal: false,
};

const ready = Promise.all([init(), initSim()])
  .then(() => postMessage({ type: 'ready', defaults: { gpp1: defaultOptions('gpp1'), gpp2: defaultOptions('gpp2') } }))
  .catch((e) => {
    st.fatal = true;
    postMessage({ type: 'error', run: 0, fatal: true, message: `cannot load the polyscene wasm module: ${msg(e)}` });
  });

function msg(e) {
  return (e && e.message) || String(e);
}

function isTrap(e) {
  return typeof WebAssembly !== 'undefined' && e instanceof WebAssembly.RuntimeError;
}

function fail(e, where) {
  const fatal = isTrap(e);
  if (fatal) st.fatal = true;
  st.playing = false;
  clearTimer();
  postMessage({ type: 'error', run: st.run, fatal, message: `${where}: ${msg(e)}` });
  postMessage({ type: 'state', run: st.run, playing: false, done: st.cursor >= st.total });
}

function clearTimer() {
  if (st.timer !== null) clearTimeout(st.timer);
  st.timer = null;
}

function schedule(delay) {
  clearTimer();
  st.timer = setTimeout(tick, delay);
}

function freeAll() {
  try {
    st.scenario?.free?.();
  } catch {
    /* already freed */
  }
  try {
    st.sim?.free?.();
  } catch {
    /* already freed */
  }
  st.scenario = null;
  st.sim = null;
}

function configure({ run, options, source }) {
  clearTimer();
  freeAll();
  st.run = run;
  st.inFlight = 0;
  st.cursor = 0;
  st.total = 0;
  if (source) st.source = source;
  if (!st.source) throw new Error('no scan source given');
  st.options = options;
  const src = st.source;
  let label;
  if (src.kind === 'sim') {
    st.sim = simulate({ layout: src.layout, seed: src.seed });
    st.total = st.sim.length;
    label = src.label || `simulated HDL-64E · ${src.layout} · seed ${src.seed}`;
  } else if (src.kind === 'files') {
    st.total = src.scans.length;
    label = src.label;
  } else if (src.kind === 'snapshot') {
    throw new Error('a restored snapshot has no scans to replay: choose a scan source');
  } else {
    throw new Error(`unknown source kind '${src.kind}'`);
  }
  postMessage({ type: 'reset', run, source: { kind: src.kind, label, total: st.total } });
  // Last: a bad option throws here, after the page knows the new run.
  st.scenario = new Scenario(options);
}

/** Own, transferable copy of a typed array unless it already owns its buffer. */
function owned(a) {
  if (a.byteOffset === 0 && a.buffer.byteLength === a.byteLength && !(typeof SharedArrayBuffer !== 'undefined' && a.buffer instanceof SharedArrayBuffer)) return a;
  return a.slice();
}

/** Polygons and mesh of the scenario, with their typed arrays to transfer. */
function polygonsAndMesh(transfer) {
  const polygons = st.scenario.polygons();
  for (const p of polygons) {
    p.vertices = owned(p.vertices);
    transfer.push(p.vertices.buffer);
  }
  const mesh = st.scenario.mesh();
  mesh.positions = owned(mesh.positions);
  mesh.indices = owned(mesh.indices);
  mesh.polygonIds = owned(mesh.polygonIds);
  transfer.push(mesh.positions.buffer, mesh.indices.buffer, mesh.polygonIds.buffer);
  return { polygons, mesh };
}

/** Replace the run by a scenario restored from a snapshot's JSON text. */
function restore({ run, json, label }) {
  clearTimer();
  st.playing = false;
  // Parsed before anything is replaced: a bad snapshot leaves the run as it was.
  const scenario = Scenario.fromJSON(json);
  freeAll();
  st.run = run;
  st.inFlight = 0;
  st.cursor = 0;
  st.total = 0;
  st.scenario = scenario;
  st.source = { kind: 'snapshot', label: label || 'snapshot' };
  postMessage({ type: 'reset', run, source: { kind: 'snapshot', label: st.source.label, total: 0 } });
  const transfer = [];
  const { polygons, mesh } = polygonsAndMesh(transfer);
  postMessage({ type: 'restored', run, scans: scenario.scans, polygons, mesh, options: scenario.options() }, transfer);
  postMessage({ type: 'state', run, playing: false, done: true });
}

function stepOnce() {
  if (!st.scenario || st.cursor >= st.total) return false;
  const t0 = performance.now();
  const index = st.cursor++;
  let points, pose, name;
  if (st.sim) {
    const s = st.sim.next();
    points = s.points;
    pose = s.pose;
    name = `scan ${index}`;
  } else {
    const f = st.source.scans[index];
    points = f.points;
    pose = f.pose ? Float64Array.from(f.pose) : IDENTITY.slice();
    name = f.name;
  }
  const report = st.scenario.addScan(points, { stride: 4, pose });
  const labels = owned(st.scenario.lastLabels());
  const changed =
    index === 0 || report.added.length > 0 || report.grown.length > 0 || report.merged.length > 0;
  const transfer = [];
  let polygons, mesh;
  if (changed) ({ polygons, mesh } = polygonsAndMesh(transfer));
  // Simulated scans are ours to give away; file scans stay here for replays.
  const shown = st.sim ? owned(points) : points.slice();
  transfer.push(shown.buffer, labels.buffer);
  const poseOut = Float64Array.from(pose);
  st.inFlight++;
  postMessage(
    {
      type: 'scan',
      run: st.run,
      index,
      total: st.total,
      name,
      points: shown,
      labels,
      pose: poseOut,
      report,
      polygons,
      mesh,
      workerMs: performance.now() - t0,
    },
    transfer,
  );
  if (st.cursor >= st.total) {
    st.playing = false;
    postMessage({ type: 'state', run: st.run, playing: false, done: true });
  }
  return true;
}

function tick() {
  st.timer = null;
  if (!st.playing || st.fatal) return;
  if (st.inFlight >= MAX_IN_FLIGHT) return; // resumed by the next ack
  const t0 = performance.now();
  try {
    if (!stepOnce()) {
      st.playing = false;
      postMessage({ type: 'state', run: st.run, playing: false, done: true });
      return;
    }
  } catch (e) {
    fail(e, `scan ${st.cursor - 1}`);
    return;
  }
  if (st.playing) schedule(Math.max(0, st.interval - (performance.now() - t0)));
}

/** A one-shot detection for a 'detect' request: always answers with a 'result'. */
function runDetect({ request, points, options }) {
  const t0 = performance.now();
  const stride = options?.stride ?? 3;
  const total = Math.floor((points?.length ?? 0) / stride);
  postMessage({ type: 'progress', request, stage: 'started', points: total });
  let last = -Infinity;
  const onRound = ({ round, pointsLeft, points: n, polygons }) => {
    const now = performance.now();
    if (round > 1 && now - last < PROGRESS_MS) return;
    last = now;
    postMessage({ type: 'progress', request, stage: 'round', points: n, round, pointsLeft, polygons });
  };
  let polygons;
  try {
    polygons = detectWithProgress(points, options, onRound);
  } catch (e) {
    if (isTrap(e)) st.fatal = true;
    postMessage({ type: 'result', request, error: `detect: ${msg(e)}`, ms: performance.now() - t0 });
    return;
  }
  const transfer = [];
  for (const p of polygons) {
    p.vertices = owned(p.vertices);
    transfer.push(p.vertices.buffer);
  }
  postMessage({ type: 'result', request, polygons, ms: performance.now() - t0 }, transfer);
}

onmessage = async (ev) => {
  await ready;
  const m = ev.data;
  if (st.fatal && m.type === 'detect') {
    postMessage({ type: 'result', request: m.request, error: 'the polyscene module stopped working; restarting it' });
    return;
  }
  if (st.fatal && m.type !== 'snapshot') {
    postMessage({ type: 'error', run: m.run ?? st.run, fatal: true, message: 'the polyscene module stopped working; restarting it' });
    return;
  }
  try {
    switch (m.type) {
      case 'configure': {
        const wasPlaying = m.play ?? st.playing;
        st.playing = false;
        configure(m);
        st.playing = wasPlaying;
        postMessage({ type: 'state', run: st.run, playing: st.playing, done: false });
        if (st.playing) schedule(0);
        break;
      }
      case 'play':
        if (st.cursor >= st.total) break;
        st.playing = true;
        postMessage({ type: 'state', run: st.run, playing: true, done: false });
        if (st.timer === null) schedule(0);
        break;
      case 'pause':
        st.playing = false;
        clearTimer();
        postMessage({ type: 'state', run: st.run, playing: false, done: st.cursor >= st.total });
        break;
      case 'step':
        st.playing = false;
        clearTimer();
        postMessage({ type: 'state', run: st.run, playing: false, done: st.cursor >= st.total });
        stepOnce();
        break;
      case 'speed': {
        const v = Number(m.scansPerSecond);
        st.interval = v > 0 ? 1000 / v : 0;
        if (st.playing) schedule(0);
        break;
      }
      case 'ack':
        if (m.run !== st.run) break;
        st.inFlight = Math.max(0, st.inFlight - 1);
        if (st.playing && st.timer === null) schedule(0);
        break;
      case 'restore':
        restore(m);
        break;
      case 'snapshot':
        postMessage({ type: 'snapshot', request: m.request, json: st.scenario ? st.scenario.toJSONString() : null });
        break;
      case 'detect':
        runDetect(m);
        break;
      default:
        throw new Error(`unknown message type '${m.type}'`);
    }
  } catch (e) {
    fail(e, m.type === 'configure' ? 'options' : m.type === 'restore' ? `snapshot ${m.label || ''}`.trim() : m.type);
  }
};
