// Exports of the current polygons: JSON, GeoJSON (through polyscene/geo),
// glTF (.glb) and OBJ.
// The polygons are what Scenario.polygons() returned; the mesh is
// Scenario.mesh(). Downloads go through a Blob and a temporary link.

import * as THREE from 'three';
import { GLTFExporter } from 'three/addons/exporters/GLTFExporter.js';
import { OBJExporter } from 'three/addons/exporters/OBJExporter.js';
import { geoFrame, kindOf, toGeoJSON as geoJSON } from 'polyscene/geo';
import { idColor } from './palette.js';

const round = (v, k) => Math.round(v * k) / k;

function ring(p) {
  const out = [];
  for (let i = 0; i < p.vertices.length; i += 3) out.push([p.vertices[i], p.vertices[i + 1], p.vertices[i + 2]]);
  return out;
}

/** Plain JSON: every field of every polygon, vertices as [x, y, z] (world, m). */
export function toJSON(polygons, meta = {}) {
  return JSON.stringify(
    {
      generator: 'polyscene demo page',
      frame: 'world, metres, z up',
      ...meta,
      polygons: polygons.map((p) => ({
        id: p.id,
        normal: p.normal,
        offset: p.offset,
        vertices: ring(p),
        area: p.area,
        support: p.support,
        density: p.density,
        ground: p.ground,
        bornScan: p.bornScan,
        lastScan: p.lastScan,
      })),
    },
    null,
    1,
  );
}

/**
 * GeoJSON FeatureCollection, one Polygon Feature per polygon with 3D
 * positions. With `frame` ({ origin: { lat, lon, alt }, heading }, or
 * { crs }: see polyscene/geo's geoFrame) the coordinates are WGS84
 * [lon, lat, height] through polyscene/geo: walls stay 3D polygons, every
 * feature has a `kind` (ground, wall, other). Without it they stay local
 * metres [x, y, z] and the collection says so.
 */
export function toGeoJSON(polygons, frame = null) {
  if (frame) {
    const fc = geoJSON(polygons, geoFrame(frame));
    for (const f of fc.features) f.properties.ground = f.properties.kind === 'ground';
    return JSON.stringify(fc);
  }
  const features = polygons.map((p) => {
    let r = ring(p);
    // Right-hand rule (RFC 7946): exterior rings counter-clockwise seen from above.
    let s = 0;
    for (let i = 0; i < r.length; i++) {
      const [x0, y0] = r[i];
      const [x1, y1] = r[(i + 1) % r.length];
      s += x0 * y1 - x1 * y0;
    }
    const kind = kindOf(p);
    if (s < 0 && kind !== 'wall') r = r.reverse();
    const coords = r.map(([x, y, z]) => [round(x, 1e3), round(y, 1e3), round(z, 1e3)]);
    coords.push(coords[0].slice());
    return {
      type: 'Feature',
      id: p.id,
      geometry: { type: 'Polygon', coordinates: [coords] },
      properties: {
        id: p.id,
        kind,
        area: round(p.area, 1e3),
        normal: p.normal.map((v) => round(v, 1e6)),
        ground: p.ground,
        support: p.support,
        bornScan: p.bornScan,
        lastScan: p.lastScan,
      },
    };
  });
  return JSON.stringify({
    type: 'FeatureCollection',
    features,
    polyscene: {
      coordinates: 'local metres [x, y, z], z up (no geographic frame was set; set an origin and heading to get WGS84 lon/lat)',
    },
  });
}

/**
 * A three.js group with one mesh per polygon (named polygon-<id>, properties
 * in userData, which glTF keeps as extras), rotated to the y-up convention of
 * glTF and OBJ. The mesh origin goes into a node translation (f64), the
 * vertices stay small (f32).
 */
export function toObject3D(mesh, polygons) {
  const byId = new Map(polygons.map((p) => [p.id, p]));
  const tris = new Map();
  const nt = mesh.indices.length / 3;
  for (let t = 0; t < nt; t++) {
    const id = mesh.polygonIds[t];
    if (!tris.has(id)) tris.set(id, []);
    tris.get(id).push(t);
  }
  const placed = new THREE.Group();
  placed.name = 'polyscene-origin';
  placed.position.fromArray(mesh.origin);
  for (const [id, list] of tris) {
    const ground = byId.get(id)?.ground ?? false;
    const remap = new Map();
    const pos = [];
    const idx = [];
    for (const t of list) {
      for (let s = 0; s < 3; s++) {
        const v = mesh.indices[t * 3 + s];
        if (!remap.has(v)) {
          remap.set(v, pos.length / 3);
          pos.push(mesh.positions[v * 3], mesh.positions[v * 3 + 1], mesh.positions[v * 3 + 2]);
        }
        idx.push(remap.get(v));
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    geo.setIndex(idx);
    geo.computeVertexNormals();
    const mat = new THREE.MeshStandardMaterial({ color: new THREE.Color().fromArray(idColor(id, ground)), side: THREE.DoubleSide, roughness: 0.8 });
    mat.name = `polygon-${id}`;
    const m = new THREE.Mesh(geo, mat);
    m.name = `polygon-${id}`;
    const p = byId.get(id);
    if (p) m.userData = { id, area: p.area, normal: p.normal, offset: p.offset, ground: p.ground, support: p.support, bornScan: p.bornScan, lastScan: p.lastScan };
    placed.add(m);
  }
  const root = new THREE.Group();
  root.name = 'polyscene';
  root.rotation.x = -Math.PI / 2; // z-up world -> y-up file
  root.userData = { frame: 'world metres, z up, rotated to y up', origin: mesh.origin };
  root.add(placed);
  root.updateMatrixWorld(true);
  return root;
}

/** Binary glTF (.glb) as an ArrayBuffer. */
export async function toGLB(mesh, polygons) {
  const root = toObject3D(mesh, polygons);
  return new GLTFExporter().parseAsync(root, { binary: true, onlyVisible: false });
}

/** Wavefront OBJ text. */
export function toOBJ(mesh, polygons) {
  return new OBJExporter().parse(toObject3D(mesh, polygons));
}

/** Save `data` (string or ArrayBuffer) as a file download. */
export function download(data, filename, type) {
  const blob = new Blob([data], { type });
  const url = URL.createObjectURL(blob);
  const a = document.createElement('a');
  a.href = url;
  a.download = filename;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}
