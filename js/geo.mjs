// polyscene/geo: polygons out to maps. GeoJSON (WGS84 lon/lat, heights in
// metres above the ellipsoid) and binary glTF from the polygons of
// `scenario.polygons()` / `detect()` or the columns of `polygonsFlat()` /
// `detectFlat()`, through a real coordinate reference system (proj4):
//
//   - a local frame: the polyscene world is metres around a geographic
//     origin { lon, lat, alt } with a heading (the compass bearing of the
//     world's +x axis): east/north/up is exact (through earth-centred
//     coordinates), not a flat-earth approximation;
//   - a projected CRS: the world is already in map coordinates (a UTM zone,
//     any EPSG code proj4 knows or a proj string), optionally shifted by an
//     offset.
//
// Walls stay walls: every polygon is written with its three coordinates
// (a vertical polygon is a 3D ring with varying heights, not a zero-area
// 2D ring) and a `kind` property: "ground", "wall" or "other".
//
// A standalone ES module; its only dependency is proj4 (npm).

import proj4 from 'proj4';

/** Kinds in the order of `FlatPolygons.kinds` (0, 1, 2). */
export const KINDS = Object.freeze(['ground', 'wall', 'other']);

/** Largest angle between a wall's normal and the horizontal (degrees), as in the core (`polyscene::flat`). */
export const WALL_MAX_TILT_DEG = 20;

const WGS84 = 'EPSG:4326';
const GEOCENT = '+proj=geocent +datum=WGS84 +units=m +no_defs';
const RAD = Math.PI / 180;

// ---------------------------------------------------------------------------
// Frames

function finite(v, what) {
  if (typeof v !== 'number' || !Number.isFinite(v)) throw new TypeError(`polyscene/geo: ${what} must be a finite number, got ${v}`);
  return v;
}

/** The proj4 definition of a CRS given as "EPSG:n", a proj string or WKT. */
function crsDefinition(crs) {
  if (typeof crs !== 'string' || crs.trim() === '') throw new TypeError(`polyscene/geo: crs must be a string such as "EPSG:32632" or a proj string, got ${crs}`);
  const m = /^EPSG:(\d+)$/i.exec(crs.trim());
  if (!m) return crs; // a proj string or WKT: proj4 parses it
  const code = `EPSG:${m[1]}`;
  if (proj4.defs(code)) return code;
  const n = Number(m[1]);
  // WGS84 UTM zones (north 326zz, south 327zz), even where proj4 lacks them.
  if ((n >= 32601 && n <= 32660) || (n >= 32701 && n <= 32760)) {
    return `+proj=utm +zone=${n % 100}${n >= 32701 ? ' +south' : ''} +datum=WGS84 +units=m +no_defs`;
  }
  throw new Error(`polyscene/geo: proj4 does not know ${code}; pass its proj string instead (crs: "+proj=..."), or register it first with proj4.defs("${code}", "...")`);
}

/**
 * A geographic frame for polygons in polyscene's world coordinates (metres).
 *
 * `spec` is one of
 *   { origin: { lon, lat, alt = 0 }, heading = 90 }
 *       a local frame: world (0, 0, 0) is the origin (degrees, metres above
 *       the WGS84 ellipsoid), z is up, and `heading` is the compass bearing
 *       of the world's +x axis in degrees clockwise from true north. The
 *       default 90 makes x east and y north; a vehicle frame (x forward,
 *       y left) takes the vehicle's heading (0 north, 90 east).
 *   { crs: 'EPSG:32632' | '+proj=...', offset = [0, 0, 0] }
 *       world = map coordinates - offset (easting, northing, height in the
 *       CRS's units); height is passed through.
 *
 * Returns { kind: 'local' | 'crs', spec, toLonLat(x, y, z) -> [lon, lat, h],
 * fromLonLat(lon, lat, h) -> [x, y, z], up(x, y, z) -> height above the frame's
 * horizontal (metres), east(x, y) / north(x, y) -> metres east / north of the
 * origin (local) or of the offset (crs) }.
 */
export function geoFrame(spec) {
  if (!spec || typeof spec !== 'object') throw new TypeError('polyscene/geo: geoFrame needs { origin: { lon, lat, alt }, heading } or { crs }');
  if (spec.origin && spec.crs) throw new TypeError('polyscene/geo: give either origin (a local frame) or crs, not both');
  if (spec.origin) return localFrame(spec);
  if (spec.crs) return crsFrame(spec);
  throw new TypeError('polyscene/geo: geoFrame needs { origin: { lon, lat, alt }, heading } or { crs }');
}

function localFrame(spec) {
  const { origin, heading = 90 } = spec;
  const lon = finite(origin.lon, 'origin.lon');
  const lat = finite(origin.lat, 'origin.lat');
  const alt = finite(origin.alt ?? 0, 'origin.alt');
  finite(heading, 'heading');
  if (Math.abs(lat) > 90) throw new RangeError(`polyscene/geo: origin.lat must be within [-90, 90], got ${lat}`);
  if (Math.abs(lon) > 180) throw new RangeError(`polyscene/geo: origin.lon must be within [-180, 180], got ${lon}`);
  const [ox, oy, oz] = proj4(WGS84, GEOCENT, [lon, lat, alt]);
  const sl = Math.sin(lon * RAD), cl = Math.cos(lon * RAD);
  const sp = Math.sin(lat * RAD), cp = Math.cos(lat * RAD);
  const sh = Math.sin(heading * RAD), ch = Math.cos(heading * RAD);
  // world (x, y) -> east, north: +x at bearing `heading`, +y 90 degrees to its left.
  const en = (x, y) => [x * sh - y * ch, x * ch + y * sh];
  const fromEn = (e, n) => [e * sh + n * ch, -e * ch + n * sh];
  return {
    kind: 'local',
    spec: { origin: { lon, lat, alt }, heading },
    east: (x, y) => en(x, y)[0],
    north: (x, y) => en(x, y)[1],
    up: (x, y, z) => z,
    enu: (x, y, z) => [...en(x, y), z],
    toLonLat(x, y, z = 0) {
      const [e, n] = en(x, y);
      const u = z;
      const X = ox - sl * e - sp * cl * n + cp * cl * u;
      const Y = oy + cl * e - sp * sl * n + cp * sl * u;
      const Z = oz + cp * n + sp * u;
      const [lo, la, h] = proj4(GEOCENT, WGS84, [X, Y, Z]);
      return [lo, la, h];
    },
    fromLonLat(lo, la, h = alt) {
      const [X, Y, Z] = proj4(WGS84, GEOCENT, [lo, la, h]);
      const dx = X - ox, dy = Y - oy, dz = Z - oz;
      const e = -sl * dx + cl * dy;
      const n = -sp * cl * dx - sp * sl * dy + cp * dz;
      const u = cp * cl * dx + cp * sl * dy + sp * dz;
      return [...fromEn(e, n), u];
    },
  };
}

function crsFrame(spec) {
  const def = crsDefinition(spec.crs);
  const offset = spec.offset ?? [0, 0, 0];
  if (!Array.isArray(offset) || offset.length !== 3) throw new TypeError('polyscene/geo: offset must be [x, y, z]');
  offset.forEach((v, i) => finite(v, `offset[${i}]`));
  let converter;
  try {
    converter = proj4(def, WGS84);
  } catch (e) {
    throw new Error(`polyscene/geo: proj4 cannot use the crs ${spec.crs}: ${e.message ?? e}`);
  }
  const [ex, ny, hz] = offset;
  return {
    kind: 'crs',
    spec: { crs: spec.crs, offset: [ex, ny, hz] },
    east: (x) => x,
    north: (x, y) => y,
    up: (x, y, z) => z,
    enu: (x, y, z) => [x, y, z],
    toLonLat(x, y, z = 0) {
      const [lo, la] = converter.forward([x + ex, y + ny]);
      return [lo, la, z + hz];
    },
    fromLonLat(lo, la, h = hz) {
      const [x, y] = converter.inverse([lo, la]);
      return [x - ex, y - ny, h - hz];
    },
  };
}

// ---------------------------------------------------------------------------
// Polygons in, one shape

/** A kind name from a polygon's `ground` flag and normal (the core's rule). */
export function kindOf(polygon) {
  if (polygon.ground) return 'ground';
  const nz = polygon.normal?.[2];
  if (typeof nz === 'number' && Math.abs(nz) <= Math.sin(WALL_MAX_TILT_DEG * RAD)) return 'wall';
  return 'other';
}

/**
 * Polygons as a list of { id, kind, normal: [x, y, z], area, vertices:
 * Float64Array (x, y, z interleaved, open ring), properties } from either
 * `Polygon[]` (polygons(), detect()) or `FlatPolygons` (polygonsFlat(),
 * detectFlat()). `properties` holds the other fields of a Polygon.
 */
export function polygonRows(polygons) {
  if (Array.isArray(polygons)) {
    return polygons.map((p, i) => {
      if (!p || !(p.vertices?.length >= 9) || p.vertices.length % 3 !== 0) {
        throw new TypeError(`polyscene/geo: polygon ${i} needs vertices (x, y, z interleaved, at least 3 vertices)`);
      }
      const { id, normal, vertices, area, ground, kind, ...rest } = p;
      return { id, kind: kind ?? kindOf(p), normal: [...normal], area, vertices: Float64Array.from(vertices), properties: rest };
    });
  }
  if (polygons && polygons.ringOffsets && polygons.positions) {
    const { positions, ringOffsets, ids, normals, areas, kinds } = polygons;
    const n = ids.length;
    if (ringOffsets.length !== n + 1) throw new TypeError(`polyscene/geo: ringOffsets has ${ringOffsets.length} entries for ${n} polygons (expected n + 1)`);
    const rows = [];
    for (let i = 0; i < n; i++) {
      const a = ringOffsets[i], b = ringOffsets[i + 1];
      if (b * 3 > positions.length || b < a) throw new RangeError(`polyscene/geo: ringOffsets[${i + 1}] = ${b} is out of range`);
      rows.push({
        id: ids[i],
        kind: KINDS[kinds[i]] ?? 'other',
        normal: [normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]],
        area: areas[i],
        vertices: positions.slice(3 * a, 3 * b),
        properties: {},
      });
    }
    return rows;
  }
  throw new TypeError('polyscene/geo: expected Polygon[] (scenario.polygons(), detect()) or FlatPolygons (polygonsFlat(), detectFlat())');
}

/** Area of a planar 3D ring (Newell's method), x, y, z interleaved, open. */
export function ringArea3D(xyz) {
  let sx = 0, sy = 0, sz = 0;
  const n = xyz.length / 3;
  for (let i = 0; i < n; i++) {
    const j = (i + 1) % n;
    const [x0, y0, z0] = [xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]];
    const [x1, y1, z1] = [xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]];
    sx += (y0 - y1) * (z0 + z1);
    sy += (z0 - z1) * (x0 + x1);
    sz += (x0 - x1) * (y0 + y1);
  }
  return 0.5 * Math.hypot(sx, sy, sz);
}

// ---------------------------------------------------------------------------
// GeoJSON

const r9 = (v) => Math.round(v * 1e9) / 1e9;
const r3 = (v) => Math.round(v * 1e3) / 1e3;

/**
 * A GeoJSON FeatureCollection (RFC 7946: WGS84 lon/lat in degrees, height in
 * metres above the ellipsoid), one Polygon Feature per polygon with 3D
 * positions [lon, lat, height] and a closed ring. Properties: id, kind
 * ("ground" | "wall" | "other"), area (m^2, the polygon's own area, kept for
 * walls), normal (world frame), base and top (lowest and highest height
 * above the frame's horizontal, m), and the polygon's other fields.
 * Ground and other polygons follow the right-hand rule seen from above;
 * a wall's ring stays in its own plane (counter-clockwise seen from its
 * normal side). The collection's `polyscene` member records the frame.
 */
export function toGeoJSON(polygons, frame) {
  if (!frame?.toLonLat) throw new TypeError('polyscene/geo: toGeoJSON needs a frame from geoFrame(...)');
  const features = polygonRows(polygons).map((p) => {
    const v = p.vertices;
    const n = v.length / 3;
    let order = [...Array(n).keys()];
    if (p.kind !== 'wall') {
      let s = 0;
      for (let i = 0; i < n; i++) {
        const j = (i + 1) % n;
        const [e0, n0] = frame.enu(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        const [e1, n1] = frame.enu(v[3 * j], v[3 * j + 1], v[3 * j + 2]);
        s += e0 * n1 - e1 * n0;
      }
      if (s < 0) order = order.reverse();
    }
    const ring = order.map((i) => {
      const [lo, la, h] = frame.toLonLat(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
      return [r9(lo), r9(la), r3(h)];
    });
    ring.push(ring[0].slice());
    let base = Infinity, top = -Infinity;
    for (let i = 0; i < n; i++) {
      const u = frame.up(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
      base = Math.min(base, u);
      top = Math.max(top, u);
    }
    return {
      type: 'Feature',
      id: p.id,
      geometry: { type: 'Polygon', coordinates: [ring] },
      properties: { id: p.id, kind: p.kind, area: r3(p.area ?? ringArea3D(v)), normal: p.normal.map((x) => Math.round(x * 1e6) / 1e6), base: r3(base), top: r3(top), ...p.properties },
    };
  });
  return {
    type: 'FeatureCollection',
    features,
    polyscene: { frame: frame.spec, coordinates: 'WGS84 lon, lat (degrees), height above the WGS84 ellipsoid (m)' },
  };
}

/**
 * What a 2D map draws: a FeatureCollection of footprints in lon/lat. Ground
 * and other polygons: their outline (2D). Walls: a thin rectangle along the
 * wall's horizontal extent (`wallThickness`, m, default 0.3) with `base` and
 * `height` properties (m above `groundHeight`, base clamped at 0) for an
 * extrusion (MapLibre's fill-extrusion-base / fill-extrusion-height).
 * `groundHeight` (m, in the frame's heights) defaults to the lowest vertex of
 * the ground polygons (of all polygons when none is ground), so walls stand
 * on the map whether the world's zero is the road, the sensor or sea level.
 * Every feature has id, kind and area (the polygon's own area).
 */
export function mapFeatures(polygons, frame, { wallThickness = 0.3, groundHeight } = {}) {
  if (!frame?.toLonLat) throw new TypeError('polyscene/geo: mapFeatures needs a frame from geoFrame(...)');
  finite(wallThickness, 'wallThickness');
  const rows = polygonRows(polygons);
  if (groundHeight === undefined) {
    const lowest = (list) => {
      let m = Infinity;
      for (const p of list) for (let i = 0; i < p.vertices.length; i += 3) m = Math.min(m, frame.up(p.vertices[i], p.vertices[i + 1], p.vertices[i + 2]));
      return m;
    };
    const ground = rows.filter((p) => p.kind === 'ground');
    groundHeight = lowest(ground.length ? ground : rows);
    if (!Number.isFinite(groundHeight)) groundHeight = 0;
  } else {
    finite(groundHeight, 'groundHeight');
  }
  const features = [];
  for (const p of rows) {
    const v = p.vertices;
    const n = v.length / 3;
    const props = { id: p.id, kind: p.kind, area: r3(p.area ?? ringArea3D(v)) };
    let ring;
    if (p.kind === 'wall') {
      // The wall's horizontal direction t, and its horizontal normal m.
      const [nx, ny] = p.normal;
      const len = Math.hypot(nx, ny) || 1;
      const mx = nx / len, my = ny / len;
      const tx = -my, ty = mx;
      let t0 = Infinity, t1 = -Infinity, s = 0, zmin = Infinity, zmax = -Infinity;
      for (let i = 0; i < n; i++) {
        const t = v[3 * i] * tx + v[3 * i + 1] * ty;
        t0 = Math.min(t0, t);
        t1 = Math.max(t1, t);
        s += v[3 * i] * mx + v[3 * i + 1] * my;
        const u = frame.up(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        zmin = Math.min(zmin, u);
        zmax = Math.max(zmax, u);
      }
      s /= n;
      const h = wallThickness / 2;
      const at = (t, o) => [t * tx + (s + o) * mx, t * ty + (s + o) * my];
      ring = [at(t0, -h), at(t1, -h), at(t1, h), at(t0, h)].map(([x, y]) => frame.toLonLat(x, y, 0));
      props.base = r3(Math.max(0, zmin - groundHeight));
      props.height = r3(Math.max(props.base, zmax - groundHeight));
    } else {
      ring = [];
      for (let i = 0; i < n; i++) ring.push(frame.toLonLat(v[3 * i], v[3 * i + 1], v[3 * i + 2]));
    }
    const coords = ring.map(([lo, la]) => [r9(lo), r9(la)]);
    coords.push(coords[0].slice());
    features.push({ type: 'Feature', id: p.id, geometry: { type: 'Polygon', coordinates: [coords] }, properties: props });
  }
  return { type: 'FeatureCollection', features };
}

// ---------------------------------------------------------------------------
// glTF

/**
 * Binary glTF 2.0 (.glb) of a triangle mesh (`scenario.mesh()`: positions
 * relative to `mesh.origin`, indices, one polygon id per triangle), one glTF
 * mesh per polygon, named `polygon-<id>`, with extras { id, kind, area } when
 * `polygons` (Polygon[] or FlatPolygons) gives them.
 *
 * Axes are glTF's: metres, +y up. With a local frame, +x is east and -z is
 * north, around the geographic origin (the scene's extras carry the frame
 * and `originLonLatAlt`); with a CRS frame, +x is easting and -z northing,
 * relative to `mesh.origin` + the frame's offset, which the root node's
 * translation does not carry (f32 positions): `extras.originMap` holds it.
 *
 * Returns a Uint8Array.
 */
export function toGLB(mesh, polygons = null, frame = null) {
  if (!mesh?.positions || !mesh?.indices || !mesh?.polygonIds) throw new TypeError('polyscene/geo: toGLB needs a Mesh (scenario.mesh())');
  const rows = polygons ? new Map(polygonRows(polygons).map((p) => [p.id, p])) : new Map();
  const origin = mesh.origin ?? [0, 0, 0];
  const enu = frame ? frame.enu : (x, y, z) => [x, y, z];
  // The mesh origin in the output axes; vertices are relative to it (f32).
  const [oe, on, ou] = enu(origin[0], origin[1], origin[2]);
  const byId = new Map();
  const nt = mesh.indices.length / 3;
  for (let t = 0; t < nt; t++) {
    const id = mesh.polygonIds[t];
    if (!byId.has(id)) byId.set(id, []);
    byId.get(id).push(t);
  }
  const chunks = [];
  let byteLength = 0;
  const bufferViews = [], accessors = [], meshes = [], nodes = [];
  const push = (typed, target) => {
    const bytes = new Uint8Array(typed.buffer, typed.byteOffset, typed.byteLength);
    bufferViews.push({ buffer: 0, byteOffset: byteLength, byteLength: bytes.length, target });
    chunks.push(bytes);
    byteLength += bytes.length;
    const pad = (4 - (byteLength % 4)) % 4;
    if (pad) {
      chunks.push(new Uint8Array(pad));
      byteLength += pad;
    }
    return bufferViews.length - 1;
  };
  for (const [id, tris] of [...byId].sort((a, b) => a[0] - b[0])) {
    const remap = new Map();
    const pos = [];
    const idx = new Uint32Array(tris.length * 3);
    let k = 0;
    for (const t of tris) {
      for (let s = 0; s < 3; s++) {
        const vi = mesh.indices[3 * t + s];
        if (!remap.has(vi)) {
          remap.set(vi, pos.length / 3);
          const x = origin[0] + mesh.positions[3 * vi];
          const y = origin[1] + mesh.positions[3 * vi + 1];
          const z = origin[2] + mesh.positions[3 * vi + 2];
          const [e, n, u] = enu(x, y, z);
          pos.push(e - oe, u - ou, -(n - on)); // glTF: x east, y up, z south
        }
        idx[k++] = remap.get(vi);
      }
    }
    const p32 = Float32Array.from(pos);
    const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p32.length; i++) {
      min[i % 3] = Math.min(min[i % 3], p32[i]);
      max[i % 3] = Math.max(max[i % 3], p32[i]);
    }
    const pv = push(p32, 34962);
    accessors.push({ bufferView: pv, componentType: 5126, count: p32.length / 3, type: 'VEC3', min, max });
    const iv = push(idx, 34963);
    accessors.push({ bufferView: iv, componentType: 5125, count: idx.length, type: 'SCALAR' });
    const row = rows.get(id);
    const extras = { id };
    if (row) Object.assign(extras, { kind: row.kind, area: row.area });
    meshes.push({ name: `polygon-${id}`, primitives: [{ attributes: { POSITION: accessors.length - 2 }, indices: accessors.length - 1, mode: 4 }], extras });
    nodes.push({ name: `polygon-${id}`, mesh: meshes.length - 1 });
  }
  const sceneExtras = { generator: 'polyscene/geo', axes: 'metres; +x east (easting), +y up, -z north (northing)' };
  if (frame?.kind === 'local') {
    sceneExtras.frame = frame.spec;
    sceneExtras.originLonLatAlt = frame.toLonLat(origin[0], origin[1], origin[2]);
  } else if (frame?.kind === 'crs') {
    sceneExtras.frame = frame.spec;
    sceneExtras.originMap = [origin[0] + frame.spec.offset[0], origin[1] + frame.spec.offset[1], origin[2] + frame.spec.offset[2]];
  } else {
    sceneExtras.originWorld = [...origin];
  }
  const root = { name: 'polyscene', children: nodes.map((_, i) => i + 1) };
  if (frame?.kind === 'local') root.translation = [oe, ou, -on];
  const gltf = {
    asset: { version: '2.0', generator: 'polyscene/geo' },
    scene: 0,
    scenes: [{ name: 'polyscene', nodes: [0], extras: sceneExtras }],
    nodes: [root, ...nodes],
    meshes,
    accessors,
    bufferViews,
    buffers: [{ byteLength }],
  };
  if (meshes.length === 0) {
    delete gltf.meshes;
    delete gltf.accessors;
    delete gltf.bufferViews;
    delete gltf.buffers;
    delete root.children;
  }
  let json = new TextEncoder().encode(JSON.stringify(gltf));
  const jsonPad = (4 - (json.length % 4)) % 4;
  const jsonChunk = new Uint8Array(json.length + jsonPad).fill(0x20);
  jsonChunk.set(json);
  json = jsonChunk;
  const hasBin = byteLength > 0;
  const total = 12 + 8 + json.length + (hasBin ? 8 + byteLength : 0);
  const out = new Uint8Array(total);
  const dv = new DataView(out.buffer);
  dv.setUint32(0, 0x46546c67, true); // "glTF"
  dv.setUint32(4, 2, true);
  dv.setUint32(8, total, true);
  dv.setUint32(12, json.length, true);
  dv.setUint32(16, 0x4e4f534a, true); // "JSON"
  out.set(json, 20);
  if (hasBin) {
    let at = 20 + json.length;
    dv.setUint32(at, byteLength, true);
    dv.setUint32(at + 4, 0x004e4942, true); // "BIN\0"
    at += 8;
    for (const c of chunks) {
      out.set(c, at);
      at += c.length;
    }
  }
  return out;
}
