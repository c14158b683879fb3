// The polyscene demo page: wires the worker (src/worker.js via
// src/client.js), the three.js view (src/view.js), the controls (lil-gui,
// bound to the very options object passed to the library), the live numbers
// and charts, file loading and exports.

import GUI from 'lil-gui';
import { PolysceneClient } from './client.js';
import { SceneView } from './view.js';
import { Sparkline } from './charts.js';
import { readScanFiles, parseKittiBin, readSnapshotText, FileError } from './files.js';
import { toJSON, toGeoJSON, toGLB, toOBJ, download } from './export.js';
import { idCss } from './palette.js';

// Per-preset values of the thresholds shown in the GUI. Choosing a preset
// resets them. Replaced by the library's own defaultOptions() as soon as the
// worker has loaded it (these are src/params.rs's values, for the first run).
const PRESETS = {
  gpp2: { distance: 0.1, minArea: 1.5, alpha: 0.5, clusterTolerance: 0.5, groundClusterTolerance: 0.5 },
  gpp1: { distance: 0.1, minArea: 7.0, alpha: 0.5, clusterTolerance: 0.5, groundClusterTolerance: 0.5 },
};

// The scans shipped with the page (www/data, licences next to them).
const BUNDLED = {
  'Ouster OS0-128 street scan (real)': {
    url: './data/ouster_os0_128_single_scan_016.bin',
    label: 'Ouster OS0-128 · real street scan · ouster-sdk test data (BSD-3-Clause)',
  },
  'Ouster OS1-64 intersection scan (real)': {
    url: './data/ouster_os1_64_legacy_f12073.bin',
    label: 'Ouster OS1-64 · real intersection scan · lidar-utils test data (MIT)',
  },
};
const SIMULATED = 'Simulated HDL-64E drive';

const $ = (id) => document.getElementById(id);
const fmt = {
  int: (v) => Math.round(v).toLocaleString('en-US'),
  ms: (v) => (v >= 100 ? v.toFixed(0) : v >= 10 ? v.toFixed(1) : v.toFixed(2)),
  ms2: (v) => (v >= 10 ? v.toFixed(0) : v.toFixed(1)),
  rate: (v) => (v >= 1e6 ? `${(v / 1e6).toFixed(2)} M` : v >= 1e3 ? `${(v / 1e3).toFixed(0)} k` : v.toFixed(0)),
  area: (v) => (v >= 1e4 ? `${(v / 1e3).toFixed(1)}k m²` : `${v.toFixed(0)} m²`),
  pct: (v) => `${(v * 100).toFixed(0)} %`,
};

class App {
  constructor() {
    /** The options object passed to `new Scenario(options)`; the GUI edits it in place. */
    this.options = { preset: 'gpp2', hull: 'concave', seed: 7, expansion: true, ...PRESETS.gpp2 };
    /** The scan source: the simulator's layout and seed, or a bundled / loaded file set. */
    this.scene = { source: SIMULATED, layout: 'street', seed: 1 };
    this.playback = {
      playing: true,
      speed: 10,
      follow: true,
      play: () => this.play(),
      pause: () => this.pause(),
      step: () => this.step(),
      restart: () => this.restart(),
      openFiles: () => $('file-input').click(),
    };
    this.geo = { enabled: false, lat: 49.0069, lon: 8.4037, alt: 115, heading: 90 };
    this.fileSources = new Map(); // GUI name -> { label, scans, id }
    this.loads = 0;
    this.latest = { polygons: [], mesh: null, report: null, index: -1, total: 0 };
    // The reports of the current source's scans (the numbers behind the
    // sparklines), kept for inspection: window.polyscene.app.reports.
    this.reports = [];

    this.view = new SceneView($('viewport'));
    this.client = new PolysceneClient();
    this.#charts();
    this.#gui();
    this.#wire();
    this.#dropAndPick();
    this.restart();
    requestAnimationFrame(() => this.#drawCharts());
  }

  // ------------------------------------------------------------ run control

  /** The worker's source descriptor for the current GUI choice (loads bundled scans once). */
  async #source() {
    const s = this.scene.source;
    if (s === SIMULATED) return { key: `sim:${this.scene.layout}:${this.scene.seed}`, kind: 'sim', layout: this.scene.layout, seed: this.scene.seed };
    if (BUNDLED[s]) {
      if (!this.fileSources.has(s)) {
        const b = BUNDLED[s];
        const res = await fetch(b.url);
        if (!res.ok) throw new FileError(`${b.url}: HTTP ${res.status}`);
        const name = b.url.split('/').pop();
        this.fileSources.set(s, { label: b.label, scans: [{ name, points: parseKittiBin(name, await res.arrayBuffer()), pose: null }] });
      }
    }
    const f = this.fileSources.get(s);
    if (!f) throw new Error(`unknown source '${s}'`);
    // The key changes with every load, so a file set loaded again is sent again.
    return { key: `files:${s}:${f.id ?? 0}`, kind: 'files', label: f.label, scans: f.scans };
  }

  /** Start the run again from its first scan with the current options and source. */
  async restart() {
    let src;
    try {
      src = await this.#source();
    } catch (e) {
      this.toast(e.message || String(e));
      return;
    }
    const { key, ...source } = src;
    const send = key !== this.sentSource ? source : undefined;
    this.sentSource = key;
    this.client.configure(this.#libraryOptions(), send, { play: this.playback.playing });
    this.client.setSpeed(this.playback.speed);
  }

  /** The options object for the library: the GUI-bound object, as is. */
  #libraryOptions() {
    return this.options;
  }

  play() {
    if (this.done) {
      this.playback.playing = true;
      this.restart();
    } else {
      this.client.play();
    }
    this.#setPlaying(true);
  }

  pause() {
    this.client.pause();
    this.#setPlaying(false);
  }

  step() {
    if (this.done) return;
    this.client.step();
    this.#setPlaying(false);
  }

  #setPlaying(on) {
    this.playback.playing = on;
    document.body.classList.toggle('playing', on);
    $('btn-play').setAttribute('aria-label', on ? 'Pause' : 'Play');
    this.gui?.controllersRecursive().forEach((c) => c.updateDisplay());
  }

  // ------------------------------------------------------------ worker messages

  #wire() {
    const c = this.client;
    c.addEventListener('reset', (e) => this.#onReset(e.detail));
    c.addEventListener('scan', (e) => this.#onScan(e.detail));
    c.addEventListener('restored', (e) => this.#onRestored(e.detail));
    c.addEventListener('state', (e) => {
      this.done = e.detail.done;
      this.#setPlaying(e.detail.playing);
      document.body.classList.toggle('done', !!e.detail.done);
    });
    c.addEventListener('error', (e) => this.toast(e.detail.message));
    c.addEventListener('ready', (e) => {
      for (const [name, all] of Object.entries(e.detail.defaults || {})) {
        if (!PRESETS[name]) continue;
        for (const k of Object.keys(PRESETS[name])) if (k in all) PRESETS[name][k] = all[k];
      }
    });

    $('btn-play').onclick = () => (this.playback.playing ? this.pause() : this.play());
    $('btn-step').onclick = () => this.step();
    $('btn-restart').onclick = () => this.restart();
    $('btn-follow').onclick = () => this.view.setFollow(!this.view.settings.follow);
    $('btn-open').onclick = () => $('file-input').click();
    this.view.addEventListener('follow', (e) => {
      this.playback.follow = e.detail;
      $('btn-follow').classList.toggle('on', e.detail);
      this.gui.controllersRecursive().forEach((k) => k.updateDisplay());
    });
    window.addEventListener('keydown', (e) => {
      if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
      if (e.key === ' ') {
        e.preventDefault();
        this.playback.playing ? this.pause() : this.play();
      } else if (e.key === 'ArrowRight') this.step();
      else if (e.key === 'f' || e.key === 'F') this.view.setFollow(!this.view.settings.follow);
      else if (e.key === 'r' || e.key === 'R') this.restart();
      else if (e.key === 'Escape') this.#showPick(null);
    });
  }

  #onReset({ source }) {
    this.view.reset();
    this.view.setFollow(true);
    this.latest = { polygons: [], mesh: null, report: null, index: -1, total: source.total };
    this.reports = [];
    this.done = false;
    document.body.classList.remove('done');
    $('source-label').textContent = source.label;
    $('stats').classList.toggle('single', source.total === 1);
    for (const s of this.sparks) s.clear();
    this.#setStat('stat-polygons', 0, '–');
    this.#setStat('stat-time', 0, '–');
    this.#setStat('stat-pps', 0, '–');
    this.#setStat('stat-expansion', 0, '–');
    this.#setStat('stat-scan', 0, `scan – / ${source.total}`);
    $('stat-stages').textContent = 'expansion – · detection – · merge – ms';
    $('progress-fill').style.width = '0%';
    this.#showPick(null);
  }

  #onScan(m) {
    this.view.showScan(m);
    const r = m.report;
    this.latest.report = r;
    this.reports.push(r);
    if (this.reports.length > 10_000) this.reports.splice(0, 5_000);
    this.latest.index = m.index;
    this.latest.total = m.total;
    if (m.polygons) this.latest.polygons = m.polygons;
    if (m.mesh) this.latest.mesh = m.mesh;

    const t = r.timeMs.total;
    this.#setStat('stat-polygons', r.polygonCount, fmt.int(r.polygonCount));
    this.#setStat('stat-time', t, fmt.ms(t));
    this.#setStat('stat-pps', t > 0 ? (r.points / t) * 1000 : 0, t > 0 ? fmt.rate((r.points / t) * 1000) : '–');
    const share = r.points ? r.explainedByExpansion / r.points : 0;
    this.#setStat('stat-expansion', share, fmt.pct(share));
    this.#setStat('stat-scan', m.index + 1, `scan ${m.index + 1} / ${m.total} · ${fmt.int(r.points)} points`);
    $('stat-stages').textContent =
      `alignment ${fmt.ms2(r.timeMs.alignment)} · expansion ${fmt.ms2(r.timeMs.expansion)} · detection ${fmt.ms2(r.timeMs.detection)} · merge ${fmt.ms2(r.timeMs.merge)} ms`;
    $('progress-fill').style.width = `${(100 * (m.index + 1)) / m.total}%`;
    this.sparks[0].push(r.polygonCount);
    this.sparks[1].push(r.sentToDetection);
    this.sparks[2].push(r.totalArea);
    this.sparks[3].push(t);
    if (this.picked !== null && m.polygons) {
      const p = m.polygons.find((q) => q.id === this.picked);
      this.#showPick(p || null, !p);
    }
  }

  /** A restored snapshot: its polygons and surfaces, no scan points. */
  #onRestored(m) {
    this.latest.polygons = m.polygons;
    this.latest.mesh = m.mesh;
    this.latest.index = m.scans - 1;
    // The GUI shows the snapshot's options (a restart runs with them).
    for (const k of Object.keys(this.options)) if (m.options && k in m.options) this.options[k] = m.options[k];
    this.gui?.controllersRecursive().forEach((c) => c.updateDisplay());
    // No scan, no vehicle: centre the view on the polygons (their mean
    // vertex, in whole metres, keeps the local f32 coordinates small).
    const c = [0, 0, 0];
    let n = 0;
    let zmin = Infinity;
    for (const p of m.polygons) {
      for (let i = 0; i < p.vertices.length; i += 3) {
        c[0] += p.vertices[i];
        c[1] += p.vertices[i + 1];
        c[2] += p.vertices[i + 2];
        zmin = Math.min(zmin, p.vertices[i + 2]);
        n++;
      }
    }
    if (n > 0) {
      const at = [c[0] / n, c[1] / n, zmin + 1.8];
      this.view.origin = at.map(Math.round);
      this.view.vehiclePose = new Float64Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, at[0], at[1], at[2], 1]);
      this.view.snapCamera = true;
    }
    this.view.setPolygons(m.polygons);
    this.view.setMesh(m.mesh);
    const area = m.polygons.reduce((a, p) => a + p.area, 0);
    this.#setStat('stat-polygons', m.polygons.length, fmt.int(m.polygons.length));
    this.#setStat('stat-scan', m.scans, `snapshot after ${fmt.int(m.scans)} scans · ${fmt.area(area)}`);
    $('progress-fill').style.width = '100%';
  }

  #setStat(id, value, text) {
    const el = $(id);
    el.dataset.value = String(value);
    el.textContent = text;
  }

  // ------------------------------------------------------------ charts

  #charts() {
    const mk = (id, color, format) => new Sparkline($(`chart-${id}`), { color, format, valueEl: $(`chart-${id}-value`) });
    this.sparks = [
      mk('polygons', '#49c6ff', fmt.int),
      mk('detect', '#ffb454', fmt.int),
      mk('area', '#7ee787', fmt.area),
      mk('time', '#d2a8ff', (v) => `${fmt.ms(v)} ms`),
    ];
  }

  #drawCharts() {
    for (const s of this.sparks) s.draw();
    requestAnimationFrame(() => this.#drawCharts());
  }

  // ------------------------------------------------------------ GUI

  #gui() {
    const gui = new GUI({ title: 'controls' });
    this.gui = gui;
    const restart = () => this.restart();

    const run = gui.addFolder('Run');
    run.add(this.playback, 'play');
    run.add(this.playback, 'pause');
    run.add(this.playback, 'step');
    run.add(this.playback, 'restart');
    run
      .add(this.playback, 'speed', { '1 scan/s': 1, '5 scans/s': 5, '10/s, real time': 10, '20 scans/s': 20, 'max': 0 })
      .name('speed')
      .onChange((v) => this.client.setSpeed(v));
    run
      .add(this.playback, 'follow')
      .name('camera follows')
      .onChange((v) => this.view.setFollow(v));

    const scene = gui.addFolder('Scene');
    const onSource = () => {
      this.#syncSceneControls();
      this.playback.playing = true; // a new source plays at once
      restart();
    };
    this.onSource = onSource;
    this.sourceCtl = scene.add(this.scene, 'source', [SIMULATED, ...Object.keys(BUNDLED)]).onChange(onSource);
    this.layoutCtl = scene.add(this.scene, 'layout', ['street', 'crossing']).onChange(restart);
    this.seedCtl = scene.add(this.scene, 'seed', 1, 99, 1).name('scene seed').onFinishChange(restart);
    scene.add(this.playback, 'openFiles').name('open scans…');
    this.sceneFolder = scene;
    this.#syncSceneControls();

    const det = gui.addFolder('Detection');
    det
      .add(this.options, 'preset', ['gpp2', 'gpp1'])
      .onChange((v) => {
        Object.assign(this.options, PRESETS[v]);
        det.controllers.forEach((c) => c.updateDisplay());
        restart();
      });
    det.add(this.options, 'hull', ['concave', 'convex']).name('outline').onChange(restart);
    det.add(this.options, 'expansion').onChange(restart);
    det.add(this.options, 'distance', 0.02, 0.5, 0.01).name('distance (m)').onFinishChange(restart);
    det.add(this.options, 'minArea', 0.25, 20, 0.25).name('min area (m²)').onFinishChange(restart);
    det.add(this.options, 'alpha', 0.1, 3, 0.05).name('alpha (m)').onFinishChange(restart);
    det.add(this.options, 'clusterTolerance', 0.1, 2, 0.05).name('cluster tol. (m)').onFinishChange(restart);
    det
      .add(this.options, 'groundClusterTolerance', 0.1, 2, 0.05)
      .name('ground cluster tol. (m)')
      .onFinishChange(restart);
    det.add(this.options, 'seed', 0, 999, 1).name('RANSAC seed').onFinishChange(restart);

    const view = gui.addFolder('View');
    const vs = this.view.settings;
    view.add(vs, 'pointSize', 0.5, 6, 0.1).name('point size');
    view.add(vs, 'showPoints').name('points');
    view.add(vs, 'showSurfaces').name('surfaces');
    view.add(vs, 'showOutlines').name('outlines');
    view.add(vs, 'surfaceOpacity', 0.05, 1, 0.01).name('surface opacity');
    view.close();

    const exp = gui.addFolder('Export');
    const actions = {
      json: () => this.#export('json'),
      geojson: () => this.#export('geojson'),
      glb: () => this.#export('glb'),
      obj: () => this.#export('obj'),
      snapshot: () => this.#export('snapshot'),
      loadSnapshot: () => $('snapshot-input').click(),
    };
    exp.add(actions, 'json').name('polygons · JSON');
    exp.add(actions, 'geojson').name('polygons · GeoJSON');
    exp.add(actions, 'glb').name('surfaces · glTF (.glb)');
    exp.add(actions, 'obj').name('surfaces · OBJ');
    exp.add(actions, 'snapshot').name('scenario snapshot');
    exp.add(actions, 'loadSnapshot').name('load a snapshot…');
    const geo = exp.addFolder('Geographic origin (GeoJSON)');
    geo.add(this.geo, 'enabled').name('use origin');
    geo.add(this.geo, 'lat', -90, 90).name('latitude (°)').decimals(7);
    geo.add(this.geo, 'lon', -180, 180).name('longitude (°)').decimals(7);
    geo.add(this.geo, 'alt', -500, 9000).name('altitude (m)').decimals(2);
    geo.add(this.geo, 'heading', 0, 360).name('heading of +x (°)').decimals(2);
    geo.close();
    exp.close();
    if (window.innerHeight < 820) view.close();
  }

  #syncSceneControls() {
    const sim = this.scene.source === SIMULATED;
    this.layoutCtl.enable(sim);
    this.seedCtl.enable(sim);
  }

  #addFileSource(name, set) {
    this.fileSources.set(name, set);
    const names = [SIMULATED, ...Object.keys(BUNDLED), ...[...this.fileSources.keys()].filter((k) => !BUNDLED[k])];
    this.scene.source = name;
    this.sourceCtl = this.sourceCtl.options(names).onChange(this.onSource);
    // options() re-creates the controller at the end of the folder: keep the order.
    const scene = this.sceneFolder;
    scene.$children.insertBefore(this.sourceCtl.domElement, scene.$children.firstChild);
    this.#syncSceneControls();
  }

  // ------------------------------------------------------------ files

  /** Restore a saved snapshot (a .json file from "scenario snapshot"). */
  async loadSnapshot(file) {
    let text;
    try {
      text = await readSnapshotText(file);
    } catch (e) {
      this.toast(e.message);
      return;
    }
    this.pause();
    // The next restart sends its source again (the worker's is the snapshot now).
    this.sentSource = null;
    this.client.restore(text, file.name);
    this.toast(`restored ${file.name}`, 'info');
  }

  async loadFiles(files) {
    if (!files || files.length === 0) return;
    const json = [...files].filter((f) => f.name.toLowerCase().endsWith('.json'));
    if (json.length) {
      if (files.length > 1) {
        this.toast(`${json[0].name}: a snapshot is loaded alone, not together with other files`);
        return;
      }
      return this.loadSnapshot(json[0]);
    }
    let set;
    try {
      set = await readScanFiles(files);
    } catch (e) {
      this.toast(e instanceof FileError ? e.message : `could not read the files: ${e.message || e}`);
      return;
    }
    // The previous file set, if any, gives way: only one loaded set is kept.
    for (const k of [...this.fileSources.keys()]) if (!BUNDLED[k]) this.fileSources.delete(k);
    set.id = ++this.loads;
    const name = `Your files: ${set.label}`.slice(0, 80);
    this.#addFileSource(name, set);
    this.playback.playing = true;
    this.toast(`loaded ${set.label} (${set.scans.reduce((a, s) => a + s.points.length / 4, 0).toLocaleString('en-US')} points)`, 'info');
    this.restart();
  }

  #dropAndPick() {
    const snap = $('snapshot-input');
    snap.addEventListener('change', () => {
      const f = snap.files[0];
      snap.value = '';
      if (f) this.loadSnapshot(f);
    });
    const input = $('file-input');
    input.addEventListener('change', () => {
      const files = [...input.files];
      input.value = '';
      this.loadFiles(files);
    });
    let depth = 0;
    const drop = $('drop');
    const hasFiles = (e) => [...(e.dataTransfer?.types || [])].includes('Files');
    window.addEventListener('dragenter', (e) => {
      if (!hasFiles(e)) return;
      e.preventDefault();
      depth++;
      drop.hidden = false;
    });
    window.addEventListener('dragover', (e) => {
      if (hasFiles(e)) e.preventDefault();
    });
    window.addEventListener('dragleave', () => {
      depth = Math.max(0, depth - 1);
      if (depth === 0) drop.hidden = true;
    });
    window.addEventListener('drop', (e) => {
      if (!hasFiles(e)) return;
      e.preventDefault();
      depth = 0;
      drop.hidden = true;
      this.loadFiles(e.dataTransfer.files);
    });

    this.picked = null;
    this.view.addEventListener('pick', (e) => this.#showPick(e.detail));
    $('pick-close').onclick = () => this.#showPick(null);
  }

  #showPick(p, gone = false) {
    const card = $('pick');
    if (!p) {
      if (gone && this.picked !== null) {
        $('pick-kind').textContent = 'merged away';
        return;
      }
      this.picked = null;
      this.view.select(null);
      card.hidden = true;
      document.body.classList.remove('picking');
      return;
    }
    this.picked = p.id;
    this.view.select(p.id);
    card.hidden = false;
    $('pick-id').textContent = `#${p.id}`;
    $('pick-swatch').style.background = idCss(p.id, p.ground);
    $('pick-kind').textContent = p.ground ? 'ground' : Math.abs(p.normal[2]) < 0.3 ? 'vertical' : 'inclined';
    const n = p.normal.map((v) => (Math.abs(v) < 5e-4 ? 0 : v).toFixed(2)).join(', ');
    const rows = [
      ['area', `${p.area.toFixed(2)} m²`],
      ['normal', `(${n})`],
      ['support', `${fmt.int(p.support)} points`],
      ['density', `${p.density.toFixed(1)} pts/m²`],
      ['vertices', `${p.vertices.length / 3}`],
      ['born at scan', `${p.bornScan}`],
      ['last grown at scan', `${p.lastScan}`],
    ];
    $('pick-fields').replaceChildren(
      ...rows.flatMap(([k, v]) => {
        const dt = document.createElement('dt');
        dt.textContent = k;
        const dd = document.createElement('dd');
        dd.textContent = v;
        return [dt, dd];
      }),
    );
    document.body.classList.add('picking');
    document.body.style.setProperty('--pick-height', `${card.offsetHeight}px`);
  }

  // ------------------------------------------------------------ export

  async #export(kind) {
    const polys = this.latest.polygons;
    if (kind !== 'snapshot' && polys.length === 0) {
      this.toast('nothing to export yet: no polygons', 'info');
      return;
    }
    const stamp = `polyscene-scan${this.latest.index + 1}`;
    try {
      if (kind === 'json') {
        download(toJSON(polys, { source: $('source-label').textContent, scans: this.latest.index + 1, options: this.options }), `${stamp}.json`, 'application/json');
      } else if (kind === 'geojson') {
        const frame = this.geo.enabled ? { origin: { lat: this.geo.lat, lon: this.geo.lon, alt: this.geo.alt }, heading: this.geo.heading } : null;
        download(toGeoJSON(polys, frame), `${stamp}.geojson`, 'application/geo+json');
      } else if (kind === 'glb') {
        if (!this.latest.mesh) throw new Error('no mesh yet');
        download(await toGLB(this.latest.mesh, polys), `${stamp}.glb`, 'model/gltf-binary');
      } else if (kind === 'obj') {
        if (!this.latest.mesh) throw new Error('no mesh yet');
        download(toOBJ(this.latest.mesh, polys), `${stamp}.obj`, 'text/plain');
      } else if (kind === 'snapshot') {
        const snap = await this.client.snapshot();
        if (snap === null) throw new Error('no scenario yet');
        download(typeof snap === 'string' ? snap : JSON.stringify(snap), `${stamp}-snapshot.json`, 'application/json');
      }
    } catch (e) {
      this.toast(`export failed: ${e.message || e}`);
    }
  }

  // ------------------------------------------------------------ messages

  /** An on-page message (kind 'error' or 'info'); errors stay longer. */
  toast(text, kind = 'error') {
    const box = $('toasts');
    const el = document.createElement('div');
    el.className = `toast ${kind}`;
    const msg = document.createElement('span');
    msg.textContent = text;
    const close = document.createElement('button');
    close.textContent = '×';
    close.title = 'Dismiss';
    close.onclick = () => el.remove();
    el.append(msg, close);
    box.append(el);
    while (box.children.length > 4) box.firstChild.remove();
    setTimeout(() => el.remove(), kind === 'error' ? 12000 : 5000);
    if (kind === 'error') console.warn('polyscene:', text);
  }
}

const app = new App();
window.polyscene = { app };
