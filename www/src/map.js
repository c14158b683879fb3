// The map dashboard (map.html): the growing polygon map on a slippy map
// (MapLibre GL JS), in longitude and latitude through polyscene/geo.
//
// Fed by the same worker as the 3D view (src/worker.js via src/client.js):
// the simulated drive live, the user's scans (KITTI .bin + poses.txt, with
// calib.txt for KITTI's camera poses) placed at the frame's origin, one
// LAS/LAZ, PCD or PLY cloud through polyscene/io (one-shot detection; a LAS
// with a CRS sets the frame to it), or a saved snapshot. Ground and other
// polygons are drawn as footprints, walls as thin extruded outlines of their
// height. Offline: the style is one background layer, no tiles, no glyphs,
// no sprites; every file comes from this server.
//
// The frame comes from the form or the URL: ?lat=..&lon=..&alt=..&heading=..
// (a local frame; heading: compass bearing of the world's +x axis, default
// 90: x east) or ?crs=EPSG:32632 (clouds already in map coordinates).
//
// For scripts and tests: window.polysceneMap = { map, frame, state, client }.

import * as maplibregl from 'maplibre-gl';
import { geoFrame, mapFeatures } from 'polyscene/geo';
import { PolysceneClient } from './client.js';
import { readScanFiles, readSnapshotText, FileError } from './files.js';
import { kittiSequence, readPoints, sniffFormat } from 'polyscene/io';

const $ = (id) => document.getElementById(id);
const EMPTY = { type: 'FeatureCollection', features: [] };
// Karlsruhe, where KITTI drove: a default origin for data without one.
const DEFAULT_ORIGIN = { lat: 49.0069, lon: 8.4037, alt: 115, heading: 90 };
const SIM = { kind: 'sim', layout: 'street', seed: 1 };
const OPTIONS = { preset: 'gpp2' };
const MAX_TRAIL = 5000;

const state = {
  frame: null,
  polygons: [], // the latest Polygon[] (world metres), as the worker sent them
  features: EMPTY, // mapFeatures(polygons, frame)
  poses: [], // [x, y, z] world positions of the sensor, one per scan
  scans: 0,
  total: 0,
  source: '',
  playing: true,
  restored: false,
  mapReady: false,
  mapError: null,
};

// ------------------------------------------------------------------ frame

function frameFromUrl() {
  const q = new URLSearchParams(location.search);
  if (q.get('crs')) return { crs: q.get('crs') };
  const num = (k, d) => (q.has(k) && q.get(k) !== '' ? Number(q.get(k)) : d);
  return {
    origin: { lat: num('lat', DEFAULT_ORIGIN.lat), lon: num('lon', DEFAULT_ORIGIN.lon), alt: num('alt', DEFAULT_ORIGIN.alt) },
    heading: num('heading', DEFAULT_ORIGIN.heading),
  };
}

function fillForm(spec) {
  const o = spec.origin ?? DEFAULT_ORIGIN;
  $('f-lat').value = o.lat;
  $('f-lon').value = o.lon;
  $('f-alt').value = o.alt ?? 0;
  $('f-heading').value = spec.heading ?? DEFAULT_ORIGIN.heading;
  $('f-crs').value = spec.crs ?? '';
}

function formSpec() {
  const crs = $('f-crs').value.trim();
  if (crs) return { crs };
  const n = (id) => ($(id).value === '' ? undefined : Number($(id).value));
  return { origin: { lat: n('f-lat'), lon: n('f-lon'), alt: n('f-alt') ?? 0 }, heading: n('f-heading') ?? 90 };
}

function setFrame(spec) {
  state.frame = geoFrame(spec); // throws with a message naming the field
  redraw();
  centre(true);
}

// ------------------------------------------------------------------ map

const style = {
  version: 8,
  sources: {
    footprints: { type: 'geojson', data: EMPTY },
    trail: { type: 'geojson', data: EMPTY },
    vehicle: { type: 'geojson', data: EMPTY },
  },
  layers: [
    { id: 'background', type: 'background', paint: { 'background-color': '#0b0f16' } },
    {
      id: 'ground',
      type: 'fill',
      source: 'footprints',
      filter: ['==', ['get', 'kind'], 'ground'],
      paint: { 'fill-color': '#5b6b80', 'fill-opacity': 0.55, 'fill-outline-color': '#8aa0bb' },
    },
    {
      id: 'other',
      type: 'fill',
      source: 'footprints',
      filter: ['==', ['get', 'kind'], 'other'],
      paint: { 'fill-color': '#7ee787', 'fill-opacity': 0.6 },
    },
    {
      id: 'walls',
      type: 'fill-extrusion',
      source: 'footprints',
      filter: ['==', ['get', 'kind'], 'wall'],
      paint: {
        'fill-extrusion-color': '#49c6ff',
        'fill-extrusion-base': ['get', 'base'],
        'fill-extrusion-height': ['get', 'height'],
        'fill-extrusion-opacity': 0.85,
      },
    },
    { id: 'trail', type: 'line', source: 'trail', paint: { 'line-color': '#ffb454', 'line-width': 2, 'line-opacity': 0.8 } },
    {
      id: 'vehicle',
      type: 'circle',
      source: 'vehicle',
      paint: { 'circle-radius': 6, 'circle-color': '#ffb454', 'circle-stroke-color': '#0b0f16', 'circle-stroke-width': 2 },
    },
  ],
};

let map = null;

function makeMap() {
  const [lon, lat] = state.frame.toLonLat(0, 0, 0);
  try {
    map = new maplibregl.Map({
      container: 'map',
      style,
      center: [lon, lat],
      zoom: 17.5,
      pitch: 50,
      maxPitch: 75,
      attributionControl: false,
      fadeDuration: 0,
    });
  } catch (e) {
    state.mapError = e.message || String(e);
    toast(`the map cannot be drawn here (${state.mapError}); the data is still computed`);
    return;
  }
  map.addControl(new maplibregl.NavigationControl({ visualizePitch: true }), 'top-right');
  map.addControl(new maplibregl.ScaleControl({ unit: 'metric' }), 'bottom-left');
  map.on('error', (e) => {
    state.mapError = e.error?.message || String(e.error || e);
    console.warn('polyscene map:', state.mapError);
  });
  map.on('load', () => {
    state.mapReady = true;
    redraw();
    centre(true);
  });
}

/** Push the current polygons, trail and vehicle to the map's sources. */
function redraw() {
  const f = state.frame;
  state.features = state.polygons.length ? mapFeatures(state.polygons, f) : EMPTY;
  const trail = state.poses.map(([x, y, z]) => f.toLonLat(x, y, z).slice(0, 2));
  const last = trail.at(-1);
  const counts = { ground: 0, wall: 0, other: 0 };
  for (const x of state.features.features) counts[x.properties.kind]++;
  setStat('stat-ground', counts.ground);
  setStat('stat-walls', counts.wall);
  setStat('stat-other', counts.other);
  if (!state.mapReady) return;
  map.getSource('footprints').setData(state.features);
  map.getSource('trail').setData(trail.length > 1 ? { type: 'Feature', properties: {}, geometry: { type: 'LineString', coordinates: trail } } : EMPTY);
  map.getSource('vehicle').setData(last ? { type: 'Feature', properties: {}, geometry: { type: 'Point', coordinates: last } } : EMPTY);
}

/** Centre the map on the vehicle (following) or, with `fit`, on everything. */
function centre(fit = false) {
  if (!state.mapReady) return;
  const f = state.frame;
  if (!fit && $('follow').checked && state.poses.length) {
    const [x, y, z] = state.poses.at(-1);
    map.jumpTo({ center: f.toLonLat(x, y, z).slice(0, 2) });
    return;
  }
  if (!fit) return;
  const b = new maplibregl.LngLatBounds();
  for (const x of state.features.features) for (const c of x.geometry.coordinates[0]) b.extend(c);
  for (const [x, y, z] of state.poses) b.extend(f.toLonLat(x, y, z).slice(0, 2));
  if (!b.isEmpty()) map.fitBounds(b, { padding: { top: 40, bottom: 40, left: 320, right: 40 }, maxZoom: 19, duration: 0 });
  else {
    const [lon, lat] = f.toLonLat(0, 0, 0);
    map.jumpTo({ center: [lon, lat] });
  }
}

// ------------------------------------------------------------------ worker

const client = new PolysceneClient();

client.addEventListener('reset', (e) => {
  state.polygons = [];
  state.poses = [];
  state.scans = 0;
  state.total = e.detail.source.total;
  state.source = e.detail.source.label;
  state.restored = false;
  $('source-label').textContent = state.source;
  setStat('stat-scan', 0, `– / ${state.total}`);
  redraw();
});

client.addEventListener('scan', (e) => {
  const m = e.detail;
  if (m.polygons) state.polygons = m.polygons;
  state.poses.push([m.pose[12], m.pose[13], m.pose[14]]);
  if (state.poses.length > MAX_TRAIL) state.poses.splice(0, state.poses.length - MAX_TRAIL);
  state.scans = m.index + 1;
  setStat('stat-scan', state.scans, `${state.scans} / ${m.total}`);
  redraw();
  centre(state.scans === 1);
});

client.addEventListener('restored', (e) => {
  state.polygons = e.detail.polygons;
  state.scans = e.detail.scans;
  state.restored = true;
  setStat('stat-scan', state.scans, `${state.scans} · snapshot`);
  redraw();
  centre(true);
});

client.addEventListener('state', (e) => {
  state.playing = e.detail.playing;
  $('btn-play').textContent = state.playing ? 'pause' : 'play';
});

client.addEventListener('error', (e) => toast(e.detail.message));

function runSim() {
  client.configure(OPTIONS, SIM, { play: true });
}

// ------------------------------------------------------------------ files

/** The format of a file from its first bytes (polyscene/io's rules; throws on a format not read). */
async function formatOf(file) {
  return sniffFormat(new Uint8Array(await file.slice(0, 512).arrayBuffer()), file.name);
}

/** One LAS/LAZ, PCD or PLY cloud: read by polyscene/io, detected at once in the worker. */
async function openCloud(file) {
  const cloud = await readPoints(file);
  let where = 'placed by the frame above';
  if (cloud.crs) {
    const spec = { crs: cloud.crs.definition };
    state.frame = geoFrame(spec); // throws (a WKT proj4 cannot read): the frame stays
    fillForm(spec);
    where = `placed by its CRS, ${cloud.crs.epsg || cloud.crs.wktEpsg ? cloud.crs.definition : 'WKT'}`;
  }
  client.pause();
  toast(`${file.name}: ${cloud.count.toLocaleString('en')} points (${cloud.format.toUpperCase()}), detecting…`, 'info');
  const polygons = await client.detect(cloud.points, { ...OPTIONS, stride: cloud.stride });
  state.polygons = polygons;
  state.poses = [];
  state.scans = 1;
  state.total = 1;
  state.source = `${file.name} · ${cloud.format.toUpperCase()} · one-shot · ${where}`;
  $('source-label').textContent = state.source;
  setStat('stat-scan', 1, 'one-shot');
  redraw();
  centre(true);
}

/** KITTI .bin scans with poses.txt and calib.txt: camera-0 poses turned into LiDAR poses by polyscene/io. */
async function kittiWithCalib(files) {
  const calib = files.find((f) => /calib/i.test(f.name));
  const texts = files.filter((f) => f !== calib && f.name.toLowerCase().endsWith('.txt'));
  if (texts.length !== 1) throw new FileError(`with ${calib.name}, give one poses file (KITTI's poses/NN.txt), not ${texts.length}`);
  const seq = await kittiSequence({ scans: files.filter((f) => f.name.toLowerCase().endsWith('.bin')), poses: texts[0], calib });
  const scans = [];
  for await (const s of seq) scans.push({ name: s.name, points: s.points, pose: s.pose });
  const label = `${scans.length} KITTI scans · ${scans[0].name} … ${scans.at(-1).name} · camera poses + ${calib.name}`;
  return { label, scans };
}

async function openScans(files) {
  try {
    if (files.length === 1 && (await formatOf(files[0])) !== 'raw') {
      await openCloud(files[0]);
      return;
    }
    const set = files.some((f) => /calib.*\.txt$/i.test(f.name)) ? await kittiWithCalib(files) : await readScanFiles(files);
    client.configure(OPTIONS, { kind: 'files', label: set.label, scans: set.scans }, { play: true });
    toast(`loaded ${set.label}`, 'info');
  } catch (e) {
    toast(e instanceof FileError || /^polyscene\/io: /.test(e?.message) ? e.message : `could not read the files: ${e.message || e}`);
  }
}

async function openSnapshot(file) {
  let text;
  try {
    text = await readSnapshotText(file);
  } catch (e) {
    toast(e.message);
    return;
  }
  client.restore(text, file.name);
}

// ------------------------------------------------------------------ page

function setStat(id, value, text = String(value)) {
  const el = $(id);
  el.dataset.value = String(value);
  el.textContent = text;
}

function toast(text, kind = 'error') {
  const el = document.createElement('div');
  el.className = `toast ${kind}`;
  el.textContent = text;
  $('toasts').append(el);
  while ($('toasts').children.length > 4) $('toasts').firstChild.remove();
  setTimeout(() => el.remove(), kind === 'error' ? 12000 : 5000);
  if (kind === 'error') console.warn('polyscene map:', text);
}

function wire() {
  $('btn-play').onclick = () => (state.playing ? client.pause() : client.play());
  $('btn-sim').onclick = runSim;
  $('btn-scans').onclick = () => $('scan-input').click();
  $('btn-snapshot').onclick = () => $('snapshot-input').click();
  $('scan-input').addEventListener('change', () => {
    const files = [...$('scan-input').files];
    $('scan-input').value = '';
    if (files.length) openScans(files);
  });
  $('snapshot-input').addEventListener('change', () => {
    const f = $('snapshot-input').files[0];
    $('snapshot-input').value = '';
    if (f) openSnapshot(f);
  });
  $('frame-form').addEventListener('submit', (e) => {
    e.preventDefault();
    try {
      setFrame(formSpec());
    } catch (err) {
      toast(err.message || String(err));
    }
  });
}

let spec = frameFromUrl();
try {
  state.frame = geoFrame(spec);
} catch (e) {
  toast(`${e.message}; using the default origin`);
  spec = { origin: { ...DEFAULT_ORIGIN }, heading: DEFAULT_ORIGIN.heading };
  state.frame = geoFrame(spec);
}
fillForm(spec);
wire();
makeMap();
runSim();

window.polysceneMap = {
  get map() {
    return map;
  },
  get frame() {
    return state.frame;
  },
  state,
  client,
};
