// polyscene/geo (js/geo.mjs): frames through proj4, GeoJSON, map footprints, glTF.
import test from "node:test";
import assert from "node:assert/strict";
import { register } from "node:module";
import { ps, psSim } from "./common.mjs";

register("./resolve-www.mjs", import.meta.url);
const geo = await import("../../js/geo.mjs");
const proj4 = (await import("proj4")).default;

// WGS84 by hand (independent of proj4 and of js/geo.mjs).
const A = 6378137.0;
const F = 1 / 298.257223563;
const E2 = F * (2 - F);
const RAD = Math.PI / 180;
const N = (phi) => A / Math.sqrt(1 - E2 * Math.sin(phi) ** 2); // prime vertical radius
const M = (phi) => (A * (1 - E2)) / (1 - E2 * Math.sin(phi) ** 2) ** 1.5; // meridian radius
/** Meridian arc from the equator to latitude phi (Simpson, 2000 steps). */
function meridianArc(phi) {
  const n = 2000;
  const h = phi / n;
  let s = M(0) + M(phi);
  for (let i = 1; i < n; i++) s += (i % 2 ? 4 : 2) * M(i * h);
  return (s * h) / 3;
}
/** Metres between two lon/lat points near latitude phi (equirectangular, fine over metres). */
function metresApart([lo1, la1], [lo2, la2]) {
  const phi = la1 * RAD;
  return Math.hypot((lo2 - lo1) * RAD * N(phi) * Math.cos(phi), (la2 - la1) * RAD * M(phi));
}

const ORIGIN = { lon: 7.0, lat: 45.0, alt: 200 };

test("a local point 1 km north and 1 km east lands on the hand-computed lon/lat (1 cm)", () => {
  const f = geo.geoFrame({ origin: ORIGIN }); // heading 90: x east, y north
  const phi = ORIGIN.lat * RAD;
  const d = 1000;
  // The origin is 200 m above the ellipsoid: the radii of curvature there are 200 m longer.
  const m = M(phi) + ORIGIN.alt;
  const nc = (N(phi) + ORIGIN.alt) * Math.cos(phi);
  // North along the tangent plane: latitude grows by atan(d / M).
  const north = f.toLonLat(0, d, 0);
  const northHand = [ORIGIN.lon, ORIGIN.lat + Math.atan(d / m) / RAD];
  assert.ok(metresApart(north, northHand) < 0.01, `${metresApart(north, northHand)} m`);
  assert.ok(Math.abs(north[2] - (ORIGIN.alt + (d * d) / (2 * m))) < 0.01, `height ${north[2]}`);
  // East along the tangent plane: it leaves the parallel outwards by
  // delta = d^2 / (2 (N + alt) cos phi), i.e. delta sin phi south and delta cos phi up.
  const east = f.toLonLat(d, 0, 0);
  const delta = (d * d) / (2 * nc);
  const eastHand = [ORIGIN.lon + Math.atan(d / nc) / RAD, ORIGIN.lat - (delta * Math.sin(phi)) / m / RAD];
  assert.ok(metresApart(east, eastHand) < 0.01, `${metresApart(east, eastHand)} m`);
  assert.ok(Math.abs(east[2] - (ORIGIN.alt + delta * Math.cos(phi))) < 0.01, `height ${east[2]}`);
  // The origin itself, and z as height.
  const o = f.toLonLat(0, 0, 12.5);
  assert.ok(metresApart(o, [ORIGIN.lon, ORIGIN.lat]) < 1e-6);
  assert.ok(Math.abs(o[2] - 212.5) < 1e-6);
});

test("the local frame agrees with an independent proj4 projection (transverse Mercator at the origin) to 1 mm", () => {
  // On the ellipsoid (alt 0), where the projection's scale is 1 at the origin.
  const f = geo.geoFrame({ origin: { ...ORIGIN, alt: 0 } });
  const tm = proj4(`+proj=tmerc +lat_0=${ORIGIN.lat} +lon_0=${ORIGIN.lon} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs`, "EPSG:4326");
  for (const [x, y] of [[700, -400], [-250, 900], [30, 40]]) {
    const ours = f.toLonLat(x, y, 0);
    const theirs = tm.forward([x, y]);
    assert.ok(metresApart(ours, theirs) < 0.001, `(${x}, ${y}): ${metresApart(ours, theirs)} m`);
  }
});

test("heading turns the world's x axis to its compass bearing, y to its left", () => {
  const enu = geo.geoFrame({ origin: ORIGIN, heading: 90 });
  const north = geo.geoFrame({ origin: ORIGIN, heading: 0 });
  const h30 = geo.geoFrame({ origin: ORIGIN, heading: 30 });
  const close = (a, b) => metresApart(a, b) < 1e-4 && Math.abs(a[2] - b[2]) < 1e-4;
  assert.ok(close(north.toLonLat(100, 0, 0), enu.toLonLat(0, 100, 0)), "heading 0: +x is north");
  assert.ok(close(north.toLonLat(0, 100, 0), enu.toLonLat(-100, 0, 0)), "heading 0: +y is west");
  const c = Math.cos(30 * RAD), s = Math.sin(30 * RAD);
  assert.ok(close(h30.toLonLat(100, 0, 0), enu.toLonLat(100 * s, 100 * c, 0)), "heading 30: +x is 30 degrees east of north");
  assert.ok(close(h30.toLonLat(0, 100, 2), enu.toLonLat(-100 * c, 100 * s, 2)), "heading 30: +y is 90 degrees to the left");
  // fromLonLat inverts toLonLat.
  const back = h30.fromLonLat(...h30.toLonLat(123.4, -56.7, 8.9));
  assert.ok(Math.hypot(back[0] - 123.4, back[1] + 56.7, back[2] - 8.9) < 1e-6, `${back}`);
});

test("a UTM frame puts the hand-computed northing of 45 degrees on 45 degrees; an offset shifts the world", () => {
  const northing = 0.9996 * meridianArc(45 * RAD); // zone central meridian: easting 500000
  const utm = geo.geoFrame({ crs: "EPSG:32632" });
  const [lon, lat, h] = utm.toLonLat(500000, northing, 31);
  assert.ok(Math.abs(lon - 9) < 1e-9, `lon ${lon}`);
  assert.ok(Math.abs(lat - 45) * RAD * M(45 * RAD) < 0.01, `lat ${lat}`);
  assert.equal(h, 31);
  const shifted = geo.geoFrame({ crs: "EPSG:32632", offset: [500000, 4982000, 100] });
  const [lon2, lat2, h2] = shifted.toLonLat(0, northing - 4982000, 31);
  assert.ok(metresApart([lon, lat], [lon2, lat2]) < 1e-6);
  assert.equal(h2, 131);
  // A southern zone proj4 may lack is built from its code.
  const south = geo.geoFrame({ crs: "EPSG:32755" }).toLonLat(500000, 10000000);
  assert.ok(Math.abs(south[0] - 147) < 1e-9 && Math.abs(south[1]) < 1e-9, `${south}`);
});

test("bad frames are errors that say what is wrong", () => {
  assert.throws(() => geo.geoFrame({}), /origin.*crs/);
  assert.throws(() => geo.geoFrame({ origin: { lon: 7, lat: 95 } }), /origin\.lat/);
  assert.throws(() => geo.geoFrame({ origin: { lon: "7", lat: 45 } }), /origin\.lon/);
  assert.throws(() => geo.geoFrame({ origin: ORIGIN, heading: NaN }), /heading/);
  assert.throws(() => geo.geoFrame({ crs: "EPSG:999999" }), /EPSG:999999/);
  assert.throws(() => geo.geoFrame({ origin: ORIGIN, crs: "EPSG:32632" }), /not both/);
  assert.throws(() => geo.toGeoJSON([{ id: 1, vertices: [0, 0, 0] }], geo.geoFrame({ origin: ORIGIN })), /polygon 0/);
});

/** A vertical 10 m x 3 m wall along x at y = 8, and a 10 m x 7 m ground patch. */
const WALL = { id: 7, normal: [0, -1, 0], ground: false, area: 30, vertices: new Float64Array([0, 8, 0, 0, 8, 3, 10, 8, 3, 10, 8, 0]) };
const GROUND = { id: 3, normal: [0, 0, 1], ground: true, area: 70, vertices: new Float64Array([0, 0, 0, 10, 0, 0, 10, 7, 0, 0, 7, 0]) };

test("walls are written as 3D polygons that keep their area, with kind properties", () => {
  for (const heading of [90, 17]) {
    const f = geo.geoFrame({ origin: ORIGIN, heading });
    const fc = geo.toGeoJSON([GROUND, WALL], f);
    assert.equal(fc.type, "FeatureCollection");
    const [g, w] = fc.features;
    assert.equal(g.properties.kind, "ground");
    assert.equal(w.properties.kind, "wall");
    assert.equal(w.properties.area, 30);
    const ring = w.geometry.coordinates[0];
    assert.deepEqual(ring[0], ring.at(-1), "closed ring");
    const heights = ring.map((c) => c[2]);
    assert.ok(Math.max(...heights) - Math.min(...heights) > 2.99, `heights ${heights}`);
    // Back to metres: the ring's own area is the wall's (1e-3 relative).
    const xyz = ring.slice(0, -1).flatMap(([lo, la, h]) => f.fromLonLat(lo, la, h));
    assert.ok(Math.abs(geo.ringArea3D(xyz) - 30) < 0.03, `wall area ${geo.ringArea3D(xyz)}`);
    const gx = g.geometry.coordinates[0].slice(0, -1).flatMap(([lo, la, h]) => f.fromLonLat(lo, la, h));
    assert.ok(Math.abs(geo.ringArea3D(gx) - 70) < 0.07);
    // Right-hand rule for the ground: counter-clockwise seen from above.
    const gr = g.geometry.coordinates[0];
    let s = 0;
    for (let i = 0; i + 1 < gr.length; i++) s += gr[i][0] * gr[i + 1][1] - gr[i + 1][0] * gr[i][1];
    assert.ok(s > 0, "counter-clockwise");
    assert.deepEqual(fc.polyscene.frame, f.spec);
  }
});

test("every wall of a simulated drive keeps its area through GeoJSON; flat and object input agree", () => {
  const sim = psSim.simulate({ seed: 1 });
  const s = new ps.Scenario();
  for (let k = 0; k < 3; k++) {
    const scan = sim.scan(k);
    s.addScan(scan.points, { stride: 4, pose: scan.pose });
  }
  const f = geo.geoFrame({ origin: { lon: -8.41, lat: 40.2, alt: 80 }, heading: 63 });
  const polygons = s.polygons();
  const fc = geo.toGeoJSON(polygons, f);
  const fromFlat = geo.toGeoJSON(s.polygonsFlat(), f);
  assert.deepEqual(fromFlat.features.map((x) => x.geometry), fc.features.map((x) => x.geometry));
  assert.deepEqual(fromFlat.features.map((x) => x.properties.kind), fc.features.map((x) => x.properties.kind));
  const walls = fc.features.filter((x) => x.properties.kind === "wall");
  assert.ok(walls.length >= 2, `${walls.length} walls`);
  for (const w of walls) {
    const xyz = w.geometry.coordinates[0].slice(0, -1).flatMap(([lo, la, h]) => f.fromLonLat(lo, la, h));
    const p = polygons.find((q) => q.id === w.id);
    assert.ok(Math.abs(geo.ringArea3D(xyz) - p.area) < 1e-3 * p.area + 0.01, `wall ${w.id}: ${geo.ringArea3D(xyz)} vs ${p.area}`);
  }
  for (const x of [s, sim]) x.free();
});

test("map footprints: outlines for the ground, thin extrudable rectangles for walls", () => {
  const f = geo.geoFrame({ origin: ORIGIN });
  const fc = geo.mapFeatures([GROUND, WALL], f, { wallThickness: 0.4 });
  const [g, w] = fc.features;
  assert.equal(g.geometry.coordinates[0].length, 5);
  assert.equal(w.properties.base, 0);
  assert.equal(w.properties.height, 3);
  const xyz = w.geometry.coordinates[0].slice(0, -1).flatMap(([lo, la]) => f.fromLonLat(lo, la, ORIGIN.alt));
  // 10 m long, 0.4 m thick, centred on y = 8.
  assert.ok(Math.abs(geo.ringArea3D(xyz) - 4) < 0.01, `footprint area ${geo.ringArea3D(xyz)}`);
  for (let i = 0; i < 4; i++) assert.ok(Math.abs(Math.abs(xyz[3 * i + 1] - 8) - 0.2) < 1e-3);
  // World zero at the sensor, 1.73 m above the road (KITTI): walls still stand on the ground.
  const lift = (p, dz) => ({ ...p, vertices: p.vertices.map((v, i) => (i % 3 === 2 ? v + dz : v)) });
  const kitti = geo.mapFeatures([lift(GROUND, -1.73), lift(WALL, -1.73)], f).features[1].properties;
  assert.deepEqual([kitti.base, kitti.height], [0, 3]);
  // Map coordinates with heights above sea level.
  const utm = geo.geoFrame({ crs: "EPSG:32632", offset: [500000, 4982000, 0] });
  const asl = geo.mapFeatures([lift(GROUND, 250), lift(WALL, 250)], utm).features[1].properties;
  assert.deepEqual([asl.base, asl.height], [0, 3]);
  const given = geo.mapFeatures([WALL], f, { groundHeight: -1 }).features[0].properties;
  assert.deepEqual([given.base, given.height], [1, 4]);
});

test("glTF: a valid .glb (header, chunks, buffer views and accessors within their lengths)", () => {
  const sim = psSim.simulate({ seed: 1 });
  const s = new ps.Scenario();
  const scan = sim.scan(0);
  s.addScan(scan.points, { stride: 4, pose: scan.pose });
  const mesh = s.mesh();
  const f = geo.geoFrame({ origin: ORIGIN, heading: 45 });
  const glb = geo.toGLB(mesh, s.polygonsFlat(), f);
  assert.ok(glb instanceof Uint8Array);
  const dv = new DataView(glb.buffer, glb.byteOffset, glb.byteLength);
  assert.equal(dv.getUint32(0, true), 0x46546c67, "magic glTF");
  assert.equal(dv.getUint32(4, true), 2, "version 2");
  assert.equal(dv.getUint32(8, true), glb.length, "length");
  const jsonLength = dv.getUint32(12, true);
  assert.equal(dv.getUint32(16, true), 0x4e4f534a, "JSON chunk");
  assert.equal(jsonLength % 4, 0);
  const gltf = JSON.parse(new TextDecoder().decode(glb.subarray(20, 20 + jsonLength)));
  const binAt = 20 + jsonLength;
  const binLength = dv.getUint32(binAt, true);
  assert.equal(dv.getUint32(binAt + 4, true), 0x004e4942, "BIN chunk");
  assert.equal(binAt + 8 + binLength, glb.length);
  assert.equal(gltf.asset.version, "2.0");
  assert.equal(gltf.buffers[0].byteLength, binLength);
  for (const v of gltf.bufferViews) assert.ok(v.byteOffset + v.byteLength <= binLength && v.byteOffset % 4 === 0);
  const bin = glb.subarray(binAt + 8);
  const ids = new Set(mesh.polygonIds);
  assert.equal(gltf.meshes.length, ids.size);
  let triangles = 0;
  for (const m of gltf.meshes) {
    const prim = m.primitives[0];
    const pa = gltf.accessors[prim.attributes.POSITION];
    const ia = gltf.accessors[prim.indices];
    const pv = gltf.bufferViews[pa.bufferView];
    const iv = gltf.bufferViews[ia.bufferView];
    assert.equal(pa.componentType, 5126);
    assert.equal(pv.byteLength, pa.count * 12);
    assert.equal(iv.byteLength, ia.count * 4);
    const pos = new Float32Array(bin.slice(pv.byteOffset, pv.byteOffset + pv.byteLength).buffer);
    const idx = new Uint32Array(bin.slice(iv.byteOffset, iv.byteOffset + iv.byteLength).buffer);
    assert.ok(idx.every((i) => i < pa.count));
    for (let c = 0; c < 3; c++) {
      const vals = pos.filter((_, i) => i % 3 === c);
      assert.equal(Math.min(...vals), pa.min[c]);
      assert.equal(Math.max(...vals), pa.max[c]);
    }
    assert.ok(["ground", "wall", "other"].includes(m.extras.kind));
    triangles += ia.count / 3;
  }
  assert.equal(triangles, mesh.polygonIds.length);
  assert.deepEqual(gltf.scenes[0].extras.frame, f.spec);
  for (const x of [s, sim]) x.free();
});
