// Writers of point files for the tests of polyscene/io (tests/js/io.test.mjs,
// tests/package/package.test.mjs): LAS 1.2 and 1.4 with a CRS record, PCD
// (ascii, binary, binary_compressed), PLY (ascii, binary little- and
// big-endian), raw float32, a KITTI calib.txt and poses. Independent of the
// readers: written from the format specifications (LAS 1.4 R15, PCD v0.7,
// PLY), with the same conventions as tests/cli.rs's writers.

/** Where the map-coordinate copies of a cloud lie (UTM-like; whole metres). */
export const UTM = [500_000, 4_500_000, 50];

/** Points on a 1/1024 m grid: exact in float32 near the origin, in float64 at UTM and in LAS with scale 1/1024. */
export function onGrid(points, stride) {
  const out = [];
  for (let i = 0; i < points.length; i += stride) out.push([0, 1, 2].map((k) => Math.round(points[i + k] * 1024) / 1024));
  return out;
}

/** Raw little-endian float32, stride 4 (x, y, z, intensity 0.5), moved by `shift`. */
export function rawBin(points, shift = [0, 0, 0]) {
  const out = new Float32Array(points.length * 4);
  points.forEach((p, i) => {
    for (let k = 0; k < 3; k++) out[4 * i + k] = p[k] + shift[k];
    out[4 * i + 3] = 0.5;
  });
  return new Uint8Array(out.buffer);
}

const ascii = (s) => new TextEncoder().encode(s);
function concat(parts) {
  const out = new Uint8Array(parts.reduce((s, p) => s + p.length, 0));
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  return out;
}

/**
 * LAS, uncompressed: version 1.2 point format 0, or 1.4 point format 6;
 * scale 1/1024 m and offset `shift` (stored integers exact). `crs`:
 * { epsg } as a GeoKeyDirectoryTag record, { wkt } as an OGC WKT record.
 */
export function las(points, shift, { version = '1.2', crs } = {}) {
  const v14 = version === '1.4';
  const headerSize = v14 ? 375 : 227;
  const format = v14 ? 6 : 0;
  const recordLength = v14 ? 30 : 20;
  const vlrs = [];
  if (crs?.epsg) {
    const keys = [[1024, 0, 1, 1], [3072, 0, 1, crs.epsg]]; // GTModelTypeGeoKey = projected, ProjectedCSTypeGeoKey
    const dir = new Uint16Array([1, 1, 0, keys.length, ...keys.flat()]);
    vlrs.push({ id: 34735, data: new Uint8Array(dir.buffer) });
  }
  if (crs?.wkt) vlrs.push({ id: 2112, data: concat([ascii(crs.wkt), new Uint8Array(1)]) });
  const vlrBytes = vlrs.map(({ id, data }) => {
    const h = new Uint8Array(54 + data.length);
    const view = new DataView(h.buffer);
    h.set(ascii('LASF_Projection'), 2);
    view.setUint16(18, id, true);
    view.setUint16(20, data.length, true);
    h.set(data, 54);
    return h;
  });
  const pointsOffset = headerSize + vlrBytes.reduce((s, b) => s + b.length, 0);
  const header = new Uint8Array(headerSize);
  const h = new DataView(header.buffer);
  header.set(ascii('LASF'), 0);
  h.setUint8(24, 1);
  h.setUint8(25, v14 ? 4 : 2);
  header.set(ascii('polyscene tests'), 58);
  h.setUint16(94, headerSize, true);
  h.setUint32(96, pointsOffset, true);
  h.setUint32(100, vlrs.length, true);
  h.setUint8(104, format);
  h.setUint16(105, recordLength, true);
  h.setUint32(107, v14 ? 0 : points.length, true); // legacy count: 0 for format 6
  const scale = 1 / 1024;
  for (let k = 0; k < 3; k++) {
    h.setFloat64(131 + 8 * k, scale, true);
    h.setFloat64(155 + 8 * k, shift[k], true);
  }
  const min = [0, 1, 2].map((k) => Math.min(...points.map((p) => p[k])) + shift[k]);
  const max = [0, 1, 2].map((k) => Math.max(...points.map((p) => p[k])) + shift[k]);
  for (let k = 0; k < 3; k++) {
    h.setFloat64(179 + 16 * k, max[k], true);
    h.setFloat64(187 + 16 * k, min[k], true);
  }
  if (v14) h.setBigUint64(247, BigInt(points.length), true);
  const body = new Uint8Array(points.length * recordLength);
  const b = new DataView(body.buffer);
  points.forEach((p, i) => {
    for (let k = 0; k < 3; k++) b.setInt32(i * recordLength + 4 * k, Math.round(p[k] * 1024), true);
  });
  return concat([header, ...vlrBytes, body]);
}

/** PCD: ascii float32 with intensity and one NaN point; binary float64 moved by `shift`; binary_compressed float32 (LZF). */
export function pcd(points, kind, shift = [0, 0, 0]) {
  const n = points.length;
  if (kind === 'ascii') {
    const lines = [];
    points.forEach((p, i) => {
      lines.push(`${p[0]} ${p[1]} ${p[2]} 0.5`);
      if (i === 10) lines.push('nan nan nan 0');
    });
    return ascii(
      `# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH ${n + 1}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ${n + 1}\nDATA ascii\n${lines.join('\n')}\n`,
    );
  }
  if (kind === 'binary') {
    const body = new Float64Array(n * 3);
    points.forEach((p, i) => {
      for (let k = 0; k < 3; k++) body[3 * i + k] = p[k] + shift[k];
    });
    const head = ascii(`VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH ${n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS ${n}\nDATA binary\n`);
    return concat([head, new Uint8Array(body.buffer)]);
  }
  // binary_compressed: fields x, y, z, intensity (u8), field-major, LZF.
  const raw = new Uint8Array(n * 13);
  const view = new DataView(raw.buffer);
  points.forEach((p, i) => {
    for (let k = 0; k < 3; k++) view.setFloat32(4 * (k * n + i), p[k], true);
    raw[12 * n + i] = 7;
  });
  const packed = lzfCompress(raw);
  const sizes = new Uint8Array(8);
  new DataView(sizes.buffer).setUint32(0, packed.length, true);
  new DataView(sizes.buffer).setUint32(4, raw.length, true);
  const head = ascii(`VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH ${n}\nHEIGHT 1\nPOINTS ${n}\nDATA binary_compressed\n`);
  return concat([head, sizes, packed]);
}

/** A plain LZF compressor (liblzf's format: literal runs and back references). */
export function lzfCompress(input) {
  const out = [];
  const table = new Map();
  let lit = [];
  const flush = () => {
    for (let i = 0; i < lit.length; i += 32) {
      const run = lit.slice(i, i + 32);
      out.push(run.length - 1, ...run);
    }
    lit = [];
  };
  let i = 0;
  while (i < input.length) {
    const key = i + 2 < input.length ? (input[i] << 16) | (input[i + 1] << 8) | input[i + 2] : -1;
    const ref = key >= 0 ? table.get(key) : undefined;
    if (key >= 0) table.set(key, i);
    const off = ref === undefined ? -1 : i - ref - 1;
    if (ref !== undefined && off < 8192) {
      let len = 0;
      while (len < 264 && i + len < input.length && input[ref + len] === input[i + len]) len++;
      if (len >= 3) {
        flush();
        const l = len - 2;
        if (l < 7) out.push((l << 5) | (off >> 8), off & 0xff);
        else out.push((7 << 5) | (off >> 8), l - 7, off & 0xff);
        i += len;
        continue;
      }
    }
    lit.push(input[i++]);
  }
  flush();
  return Uint8Array.from(out);
}

/**
 * PLY with an empty face element: ascii float32 (its size padded by a
 * comment to a multiple of 16 bytes, the size of a raw stride-4 file),
 * binary little-endian float64 moved by `shift`, or binary big-endian float32.
 */
export function ply(points, kind, shift = [0, 0, 0]) {
  const n = points.length;
  const format = { ascii: 'ascii', le64: 'binary_little_endian', be32: 'binary_big_endian' }[kind];
  const type = kind === 'le64' ? 'double' : 'float';
  let body;
  if (kind === 'ascii') {
    body = ascii(points.map((p) => `${p[0]} ${p[1]} ${p[2]}\n`).join(''));
  } else {
    const size = kind === 'le64' ? 8 : 4;
    body = new Uint8Array(n * 3 * size);
    const view = new DataView(body.buffer);
    points.forEach((p, i) => {
      for (let k = 0; k < 3; k++) {
        if (kind === 'le64') view.setFloat64(8 * (3 * i + k), p[k] + shift[k], true);
        else view.setFloat32(4 * (3 * i + k), p[k], false);
      }
    });
  }
  const header = (pad) =>
    ascii(`ply\nformat ${format} 1.0\ncomment ${'x'.repeat(pad)}\nelement vertex ${n}\nproperty ${type} x\nproperty ${type} y\nproperty ${type} z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n`);
  const pad = ((16 - ((header(1).length + body.length) % 16)) % 16) + 1;
  return concat([header(pad), body]);
}

/** KITTI odometry's calib.txt of sequence 00 (Tr: LiDAR to camera 0). */
export const CALIB_00 = `P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00
Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 -7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01
`;

/** Column-major 4x4 product (independent of polyscene/io's). */
export function mat4Mul(a, b) {
  const out = new Float64Array(16);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) out[4 * c + r] += a[4 * k + r] * b[4 * c + k];
  return out;
}

/** Inverse of a column-major 4x4 by Gauss-Jordan elimination (not assuming rigidity). */
export function mat4Inverse(m) {
  const a = [0, 1, 2, 3].map((r) => [0, 1, 2, 3].map((c) => m[4 * c + r]).concat([0, 1, 2, 3].map((c) => (c === r ? 1 : 0))));
  for (let c = 0; c < 4; c++) {
    let p = c;
    for (let r = c + 1; r < 4; r++) if (Math.abs(a[r][c]) > Math.abs(a[p][c])) p = r;
    [a[c], a[p]] = [a[p], a[c]];
    const d = a[c][c];
    for (let k = 0; k < 8; k++) a[c][k] /= d;
    for (let r = 0; r < 4; r++) {
      if (r === c) continue;
      const f = a[r][c];
      for (let k = 0; k < 8; k++) a[r][k] -= f * a[c][k];
    }
  }
  const out = new Float64Array(16);
  for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) out[4 * c + r] = a[r][4 + c];
  return out;
}

/** The 12 row-major numbers of a KITTI pose line for a column-major 4x4. */
export function poseLine(m) {
  const rows = [0, 1, 2].flatMap((r) => [0, 1, 2, 3].map((c) => m[4 * c + r]));
  return rows.map((v) => v.toExponential(17)).join(' ');
}

/** Tr (column-major) of CALIB_00, parsed here independently. */
export function calibTr() {
  const n = CALIB_00.split('\n').find((l) => l.startsWith('Tr:')).slice(3).trim().split(/\s+/).map(Number);
  return Float64Array.from([n[0], n[4], n[8], 0, n[1], n[5], n[9], 0, n[2], n[6], n[10], 0, n[3], n[7], n[11], 1]);
}
