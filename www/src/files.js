// Reading the user's scans: KITTI .bin (+ optional poses.txt), PCD, PLY.
// Everything becomes { name, points: Float32Array stride 4 (x, y, z,
// intensity), pose: Float64Array(16) column-major world-from-sensor | null }.
// PCD and PLY are parsed by three.js's own loaders; a .bin is a flat
// little-endian Float32Array.
//
// Every problem is a FileError whose message names the file and says what
// was expected; nothing here throws anything else.

import { PCDLoader } from 'three/addons/loaders/PCDLoader.js';
import { PLYLoader } from 'three/addons/loaders/PLYLoader.js';

export class FileError extends Error {}

/**
 * The text of a snapshot file (a .json from "scenario snapshot"), checked to
 * be one: a FileError naming the file otherwise. Both pages load snapshots.
 */
export async function readSnapshotText(file) {
  try {
    const text = await file.text();
    const o = JSON.parse(text);
    if (!o || typeof o !== 'object' || !('params' in o)) throw new Error('it is JSON, but not a polyscene snapshot (no "params")');
    return text;
  } catch (e) {
    throw new FileError(`${file.name}: cannot load the snapshot: ${e.message || e}`);
  }
}

const SCAN_EXT = ['.bin', '.pcd', '.ply'];

function ext(name) {
  const i = name.lastIndexOf('.');
  return i < 0 ? '' : name.slice(i).toLowerCase();
}

const byName = (a, b) => a.name.localeCompare(b.name, undefined, { numeric: true });

function bytes(n) {
  return n < 1024 ? `${n} bytes` : n < 1 << 20 ? `${(n / 1024).toFixed(1)} KiB` : `${(n / (1 << 20)).toFixed(1)} MiB`;
}

/** A KITTI velodyne .bin: float32 x, y, z, intensity per point. */
export function parseKittiBin(name, buf) {
  if (buf.byteLength === 0) throw new FileError(`${name}: the file is empty`);
  if (buf.byteLength % 16 !== 0) {
    throw new FileError(
      `${name}: ${bytes(buf.byteLength)} is not a whole number of KITTI points ` +
        `(a .bin holds float32 x, y, z, intensity: 16 bytes a point; ${buf.byteLength % 16} bytes left over)`,
    );
  }
  const points = new Float32Array(buf.slice(0));
  for (let i = 0; i < points.length; i++) {
    if (!Number.isFinite(points[i])) {
      throw new FileError(`${name}: point ${i >> 2} has a non-finite value (${points[i]}); is it really a KITTI .bin?`);
    }
  }
  return points;
}

/** Interleave a three.js geometry's positions (+ intensity) to stride 4. */
function fromGeometry(name, geometry, kind) {
  const pos = geometry?.getAttribute?.('position');
  if (!pos || pos.count === 0) throw new FileError(`${name}: no points found in this ${kind} file`);
  const n = pos.count;
  const inten = geometry.getAttribute('intensity');
  const out = new Float32Array(n * 4);
  for (let i = 0; i < n; i++) {
    const x = pos.getX(i);
    const y = pos.getY(i);
    const z = pos.getZ(i);
    if (!Number.isFinite(x) || !Number.isFinite(y) || !Number.isFinite(z)) {
      throw new FileError(`${name}: point ${i} has a non-finite coordinate; the ${kind} file looks corrupt`);
    }
    out[i * 4] = x;
    out[i * 4 + 1] = y;
    out[i * 4 + 2] = z;
    out[i * 4 + 3] = inten ? inten.getX(i) : 0;
  }
  geometry.dispose?.();
  return out;
}

export function parsePcd(name, buf) {
  const head = new TextDecoder('latin1').decode(new Uint8Array(buf, 0, Math.min(buf.byteLength, 4096)));
  if (!/^\s*(#.*\r?\n\s*)*(VERSION|FIELDS)\b/i.test(head) || !/[\r\n]DATA\s+(ascii|binary|binary_compressed)\b/i.test(head)) {
    throw new FileError(`${name}: not a PCD file (expected a header with FIELDS … and DATA ascii|binary|binary_compressed)`);
  }
  if (!/^FIELDS\s.*\bx\b.*\by\b.*\bz\b/im.test(head)) {
    throw new FileError(`${name}: this PCD file has no x y z fields`);
  }
  let pts;
  try {
    pts = new PCDLoader().parse(buf);
  } catch (e) {
    throw new FileError(`${name}: cannot read this PCD file (${e.message || e})`);
  }
  return fromGeometry(name, pts.geometry, 'PCD');
}

export function parsePly(name, buf) {
  const head = new TextDecoder('latin1').decode(new Uint8Array(buf, 0, Math.min(buf.byteLength, 4096)));
  if (!/^ply\r?\n/.test(head) || !/end_header/.test(head)) {
    throw new FileError(`${name}: not a PLY file (expected 'ply' on the first line and an end_header line)`);
  }
  let geo;
  try {
    geo = new PLYLoader().parse(buf);
  } catch (e) {
    throw new FileError(`${name}: cannot read this PLY file (${e.message || e})`);
  }
  return fromGeometry(name, geo, 'PLY');
}

/**
 * KITTI odometry poses: one line per scan, 12 numbers, the row-major 3x4
 * [R | t] world-from-sensor. Returned as column-major 4x4 (Matrix4.elements).
 */
export function parsePoses(name, text) {
  const poses = [];
  const lines = text.split(/\r?\n/);
  for (let li = 0; li < lines.length; li++) {
    const line = lines[li].trim();
    if (!line || line.startsWith('#')) continue;
    const v = line.split(/[\s,]+/).map(Number);
    if (v.length !== 12 || v.some((x) => !Number.isFinite(x))) {
      throw new FileError(`${name}, line ${li + 1}: expected 12 numbers (a KITTI pose, row-major 3x4), got '${line.slice(0, 60)}'`);
    }
    const m = new Float64Array(16);
    for (let r = 0; r < 3; r++) for (let c = 0; c < 4; c++) m[c * 4 + r] = v[r * 4 + c];
    m[15] = 1;
    poses.push(m);
  }
  if (poses.length === 0) throw new FileError(`${name}: no poses in the file`);
  return poses;
}

/**
 * Read a set of files (a FileList or File[]) into scans.
 * Returns { label, scans: [{ name, points, pose }] } in name order.
 */
export async function readScanFiles(files) {
  files = [...files];
  if (files.length === 0) throw new FileError('no files given');
  const scanFiles = files.filter((f) => SCAN_EXT.includes(ext(f.name))).sort(byName);
  const poseFiles = files.filter((f) => ext(f.name) === '.txt');
  const other = files.filter((f) => !SCAN_EXT.includes(ext(f.name)) && ext(f.name) !== '.txt');
  if (other.length) {
    throw new FileError(
      `${other.map((f) => f.name).join(', ')}: unsupported file type; expected KITTI .bin scans (with an optional poses.txt), .pcd or .ply`,
    );
  }
  if (scanFiles.length === 0) throw new FileError('a poses file alone is not enough: add the .bin scans it belongs to');
  if (poseFiles.length > 1) throw new FileError(`give one poses file, not ${poseFiles.length} (${poseFiles.map((f) => f.name).join(', ')})`);

  let poses = null;
  if (poseFiles.length) {
    poses = parsePoses(poseFiles[0].name, await poseFiles[0].text());
    if (poses.length < scanFiles.length) {
      throw new FileError(`${poseFiles[0].name} has ${poses.length} poses for ${scanFiles.length} scans`);
    }
  }

  const scans = [];
  for (let i = 0; i < scanFiles.length; i++) {
    const f = scanFiles[i];
    const buf = await f.arrayBuffer();
    const e = ext(f.name);
    const points = e === '.bin' ? parseKittiBin(f.name, buf) : e === '.pcd' ? parsePcd(f.name, buf) : parsePly(f.name, buf);
    scans.push({ name: f.name, points, pose: poses ? poses[i] : null });
  }
  const label =
    scans.length === 1 ? scans[0].name : `${scans.length} scans · ${scans[0].name} … ${scans[scans.length - 1].name}${poses ? ' · with poses' : ''}`;
  return { label, scans };
}
