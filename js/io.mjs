// polyscene/io: point files in, ready for `detect(points, { stride })` and
// `scenario.addScan(points, { stride, pose })`.
//
//   - readPoints(input): LAS/LAZ, PCD, PLY or raw float32, the format told
//     by the file's header (never a file with a header read as raw points);
//   - readKittiBin(input): one KITTI .bin scan (float32 x, y, z, intensity);
//   - kittiSequence({ scans, poses, calib }): a KITTI odometry sequence, its
//     camera-0 poses turned into LiDAR poses (Tr^-1 . P . Tr) with calib.txt's
//     Tr, as the CLI does (src/io/kitti.rs); findKittiSequence(files) finds
//     those parts in a folder's files (KITTI's layout or a flat one).
//
// Inputs are bytes (ArrayBuffer, a typed array, a Blob or File) and text
// (poses, calib): the same calls run in a browser, a worker and Node
// (polyscene/io/node adds file paths). Errors are `Error`s whose message
// names the file (when a name is known) and the problem.
//
// Coordinates keep the precision of the file: float32 fields give a
// Float32Array, float64 and integer fields (LAS's scaled integers: x * scale
// + offset) a Float64Array, which `detect` and `addScan` take as it is (map
// coordinates are re-centred in float64 inside).
//
// LAS and LAZ go through @loaders.gl/las (loaded on first use); PCD, PLY and
// KITTI are read here: loaders.gl's PCD and PLY loaders return float32
// positions (a UTM northing loses half a metre) and its PCD loader reads
// every binary field as float32 (a double field gives garbage).

const PREFIX = 'polyscene/io';

function ioError(name, what) {
  return new Error(`${PREFIX}: ${name ? `${name}: ` : ''}${what}`);
}

// ---------------------------------------------------------------------------
// Inputs

/** The bytes of `input` (ArrayBuffer, ArrayBufferView, Blob/File) as a Uint8Array, and its name. */
async function bytesOf(input, name, what = 'a point file') {
  const label = name ?? (typeof input?.name === 'string' && input.name ? input.name : undefined);
  if (input instanceof Uint8Array) return { bytes: input, name: label };
  if (input instanceof ArrayBuffer) return { bytes: new Uint8Array(input), name: label };
  if (ArrayBuffer.isView(input)) return { bytes: new Uint8Array(input.buffer, input.byteOffset, input.byteLength), name: label };
  if (input && typeof input.arrayBuffer === 'function') return { bytes: new Uint8Array(await input.arrayBuffer()), name: label };
  if (typeof input === 'string') {
    throw new TypeError(`${PREFIX}: ${what} must be bytes (ArrayBuffer, a typed array, a Blob or File), got a string; to read a path in Node, use polyscene/io/node`);
  }
  throw new TypeError(`${PREFIX}: ${what} must be bytes (ArrayBuffer, a typed array, a Blob or File), got ${input === null ? 'null' : typeof input}`);
}

/** Text given as a string, bytes or a Blob/File (poses, calib). */
async function textOf(input, what) {
  if (typeof input === 'string') return { text: input, name: undefined };
  if (input && typeof input.text === 'function' && typeof input.arrayBuffer === 'function') {
    return { text: await input.text(), name: input.name || undefined };
  }
  if (input instanceof ArrayBuffer || ArrayBuffer.isView(input)) {
    const { bytes } = await bytesOf(input, undefined, what);
    return { text: new TextDecoder().decode(bytes), name: undefined };
  }
  throw new TypeError(`${PREFIX}: ${what} must be text (a string, bytes, a Blob or File), got ${input === null ? 'null' : typeof input}`);
}

const latin1 = (bytes, start, end) => {
  let s = '';
  for (let i = start; i < end && i < bytes.length; i++) s += String.fromCharCode(bytes[i]);
  return s;
};

// ---------------------------------------------------------------------------
// Formats

/**
 * The format of a file that begins with `head` (512 bytes are plenty):
 * 'las', 'pcd', 'ply', or 'raw' (no header: little-endian float32).
 * Headers of formats not read here and text files throw (`name` is put in
 * the message), so that no header is ever read as points. Same rules as the
 * CLI (src/io/points.rs, `Format::sniff`).
 */
export function sniffFormat(head, name) {
  const bytes = head instanceof Uint8Array ? head : new Uint8Array(head.buffer ?? head, head.byteOffset ?? 0, head.byteLength);
  const starts = (s) => s.length <= bytes.length && [...s].every((c, i) => bytes[i] === c.charCodeAt(0));
  if (starts('LASF')) return 'las';
  if (starts('ply\n') || starts('ply\r')) return 'ply';
  if (isPcd(bytes)) return 'pcd';
  const known = [
    ['\x1f\x8b', 'a gzip-compressed file: decompress it first'],
    ['PK\x03\x04', 'a zip archive: unpack it first'],
    ['\x89HDF', 'an HDF5 file, which polyscene does not read'],
    ['\x93NUMPY', 'a NumPy .npy file, which polyscene does not read'],
    ['ASTM-E57', 'an E57 file, which polyscene does not read'],
    ['\x28\xb5\x2f\xfd', 'a zstd-compressed file: decompress it first'],
  ];
  for (const [magic, what] of known) if (starts(magic)) throw ioError(name, what);
  const n = Math.min(bytes.length, 512);
  let text = n >= 4;
  for (let i = 0; i < n && text; i++) {
    const b = bytes[i];
    text = b === 9 || b === 10 || b === 13 || (b >= 0x20 && b <= 0x7e);
  }
  if (text) {
    throw ioError(name, 'a text file (ASCII XYZ or CSV?), which polyscene does not read: write the points as PLY, PCD or LAS, or as raw float32');
  }
  return 'raw';
}

/** A PCD header: `# .PCD` first, or `VERSION` as the first line that is not a `#` comment. */
function isPcd(bytes) {
  let i = 0;
  if (latin1(bytes, 0, 6) === '# .PCD') return true;
  while (bytes[i] === 0x23) {
    while (i < bytes.length && bytes[i] !== 0x0a) i++;
    if (i >= bytes.length) return false;
    i++;
  }
  return latin1(bytes, i, i + 7) === 'VERSION';
}

/**
 * The points of a point file: LAS/LAZ, PCD or PLY by their header, or raw
 * little-endian float32 when no header is recognised, with `options.stride`
 * values a point (3, or 4 as KITTI's x, y, z, intensity; a raw file without
 * a stride is an error that asks for it). `options.name` names the file in
 * errors (a File's own name is used otherwise).
 *
 * Resolves to `{ points, stride, count, format, name, crs? }` (see io.d.ts).
 * Rejects with an Error naming the file and the problem: empty (0 bytes) or
 * a header with no points, a header of another format or a text file, a size that is not a whole
 * number of points, a file cut short, NaN or infinite coordinates, a format
 * without x, y, z.
 */
export async function readPoints(input, options = {}) {
  const { bytes, name } = await bytesOf(input, options.name);
  if (bytes.length === 0) throw ioError(name, 'empty file (0 bytes): no points');
  const format = sniffFormat(bytes.subarray(0, 512), name);
  const some = (cloud, why) => {
    if (cloud.count === 0) throw ioError(name, `a ${format.toUpperCase()} file with no points (${why})`);
    return cloud;
  };
  switch (format) {
    case 'las':
      return readLasBytes(bytes, name);
    case 'pcd':
      return some(readPcdBytes(bytes, name), 'POINTS 0, or every point NaN: no return');
    case 'ply':
      return some(readPlyBytes(bytes, name), 'element vertex 0');
    default: {
      const stride = options.stride;
      if (stride === undefined) {
        throw ioError(name, `no LAS/LAZ, PCD or PLY header, so raw little-endian float32 (${bytes.length} bytes); say how many values a point has: { stride: 4 } (x, y, z, intensity, as KITTI .bin) or { stride: 3 }, or use readKittiBin`);
      }
      return decodeRaw(bytes, stride, name);
    }
  }
}

/**
 * One KITTI `.bin` scan: little-endian float32 x, y, z, reflectance
 * (stride 4) in the LiDAR frame. A file with a LAS, PCD or PLY header, a
 * text file, an empty file or a size that is not a multiple of 16 bytes is
 * refused.
 */
export async function readKittiBin(input, options = {}) {
  const { bytes, name } = await bytesOf(input, options.name, 'a KITTI .bin scan');
  if (bytes.length === 0) throw ioError(name, 'empty file (0 bytes): no points');
  const format = sniffFormat(bytes.subarray(0, 512), name);
  if (format !== 'raw') {
    throw ioError(name, `a ${format.toUpperCase()} file, not a KITTI .bin scan (raw float32): read it with readPoints`);
  }
  return decodeRaw(bytes, 4, name, 'kitti-bin');
}

const LITTLE_ENDIAN_HOST = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;

function decodeRaw(bytes, stride, name, format = 'raw') {
  if (stride !== 3 && stride !== 4) throw ioError(name, `stride must be 3 or 4 (values a point), got ${stride}`);
  const size = 4 * stride;
  if (bytes.length % size !== 0) {
    throw ioError(name, `file size ${bytes.length} bytes is not a multiple of ${size} (stride ${stride} x 4-byte floats): not a raw float32 file, or cut short`);
  }
  let points;
  if (LITTLE_ENDIAN_HOST) {
    points = new Float32Array(new Uint8Array(bytes).buffer); // a copy (a Node Buffer's slice() is a view)
  } else {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    points = new Float32Array(bytes.length / 4);
    for (let i = 0; i < points.length; i++) points[i] = view.getFloat32(4 * i, true);
  }
  for (let i = 0; i < points.length; i++) {
    if (!Number.isFinite(points[i])) throw ioError(name, `point ${Math.floor(i / stride)} has a NaN or infinite value`);
  }
  // The array carries its stride (not enumerable): detect and addScan refuse
  // it without { stride: 4 } instead of reading x, y, z, intensity as x, y, z.
  if (stride !== 3) Object.defineProperty(points, 'stride', { value: stride });
  return { points, stride, count: points.length / stride, format, name };
}

// ---------------------------------------------------------------------------
// PLY

const PLY_TYPES = {
  char: ['Int8', 1], int8: ['Int8', 1],
  uchar: ['Uint8', 1], uint8: ['Uint8', 1],
  short: ['Int16', 2], int16: ['Int16', 2],
  ushort: ['Uint16', 2], uint16: ['Uint16', 2],
  int: ['Int32', 4], int32: ['Int32', 4],
  uint: ['Uint32', 4], uint32: ['Uint32', 4],
  float: ['Float32', 4], float32: ['Float32', 4],
  double: ['Float64', 8], float64: ['Float64', 8],
};

/** The header of a file that begins with "ply": end offset, format, elements. */
function plyHeader(bytes, name) {
  // The header is ASCII and ends with a line "end_header".
  let end = -1;
  const limit = Math.min(bytes.length, 1 << 16);
  const head = latin1(bytes, 0, limit);
  const m = /(^|\n)end_header\r?\n/.exec(head);
  if (m) end = m.index + m[0].length;
  if (end < 0) throw ioError(name, 'PLY header without a line end_header (a truncated or damaged file?)');
  const lines = head.slice(0, end).split(/\r?\n/);
  let format;
  const elements = [];
  for (let k = 1; k < lines.length; k++) {
    const words = lines[k].trim().split(/\s+/);
    const lineNo = k + 1;
    switch (words[0]) {
      case '':
      case 'comment':
      case 'obj_info':
      case 'end_header':
        break;
      case 'format':
        if (!['ascii', 'binary_little_endian', 'binary_big_endian'].includes(words[1])) {
          throw ioError(name, `PLY header line ${lineNo}: format ${words[1]} (expected ascii, binary_little_endian or binary_big_endian)`);
        }
        format = words[1];
        break;
      case 'element': {
        const count = Number(words[2]);
        if (words.length !== 3 || !Number.isSafeInteger(count) || count < 0) {
          throw ioError(name, `PLY header line ${lineNo}: expected "element NAME COUNT", found "${lines[k].trim()}"`);
        }
        elements.push({ name: words[1], count, properties: [] });
        break;
      }
      case 'property': {
        const element = elements[elements.length - 1];
        if (!element) throw ioError(name, `PLY header line ${lineNo}: a property before any element`);
        if (words[1] === 'list') {
          if (words.length !== 5 || !PLY_TYPES[words[2]] || !PLY_TYPES[words[3]]) {
            throw ioError(name, `PLY header line ${lineNo}: expected "property list COUNT_TYPE ITEM_TYPE NAME", found "${lines[k].trim()}"`);
          }
          element.properties.push({ name: words[4], list: true, countType: PLY_TYPES[words[2]], type: PLY_TYPES[words[3]] });
        } else {
          if (words.length !== 3 || !PLY_TYPES[words[1]]) {
            throw ioError(name, `PLY header line ${lineNo}: expected "property TYPE NAME" with a PLY type, found "${lines[k].trim()}"`);
          }
          element.properties.push({ name: words[2], list: false, type: PLY_TYPES[words[1]], typeName: words[1] });
        }
        break;
      }
      default:
        throw ioError(name, `PLY header line ${lineNo}: unknown keyword "${words[0]}"`);
    }
  }
  if (!format) throw ioError(name, 'PLY header without a format line');
  return { end, format, elements };
}

function readPlyBytes(bytes, name) {
  const { end, format, elements } = plyHeader(bytes, name);
  const vertex = elements.find((e) => e.name === 'vertex');
  if (!vertex) throw ioError(name, 'PLY without a vertex element');
  const slots = ['x', 'y', 'z'].map((axis) => {
    const i = vertex.properties.findIndex((p) => p.name === axis);
    if (i < 0) throw ioError(name, `PLY vertex properties are ${vertex.properties.map((p) => p.name).join(' ')}: no '${axis}' (x, y, z are needed)`);
    if (vertex.properties[i].list) throw ioError(name, `PLY vertex property '${axis}' is a list, not a number`);
    return i;
  });
  const f32 = slots.every((i) => vertex.properties[i].type[0] === 'Float32');
  // Before allocating: a vertex takes at least 2 bytes a property in ascii, its scalars in binary.
  const least = vertex.properties.reduce((sum, p) => sum + (format === 'ascii' ? 2 : p.list ? p.countType[1] : p.type[1]), 0);
  if (vertex.count * least > bytes.length - end + 1) {
    if (format !== 'ascii' && vertex.properties.every((p) => !p.list) && elements[0] === vertex) {
      const fit = Math.floor((bytes.length - end) / least);
      throw ioError(name, `PLY vertex ${fit} of ${vertex.count}: the file ends there (${bytes.length} bytes; a truncated file?)`);
    }
    throw ioError(name, `the PLY header promises ${vertex.count} vertices; ${bytes.length - end} bytes of data cannot hold them (a truncated or damaged file?)`);
  }
  const points = new (f32 ? Float32Array : Float64Array)(vertex.count * 3);
  const put = (k, values) => {
    const [x, y, z] = slots.map((i) => values[i]);
    if (!(Number.isFinite(x) && Number.isFinite(y) && Number.isFinite(z))) {
      throw ioError(name, `PLY vertex ${k} has a NaN or infinite coordinate`);
    }
    points[3 * k] = x;
    points[3 * k + 1] = y;
    points[3 * k + 2] = z;
  };
  if (format === 'ascii') {
    plyAscii(bytes, end, elements, vertex, put, name);
  } else {
    plyBinary(bytes, end, format === 'binary_little_endian', elements, vertex, put, name);
  }
  return { points, stride: 3, count: vertex.count, format: 'ply', name };
}

function plyAscii(bytes, start, elements, vertex, put, name) {
  const body = new TextDecoder().decode(bytes.subarray(start));
  const tokens = body.split(/\s+/);
  let t = tokens[0] === '' ? 1 : 0;
  const number = (element, k) => {
    if (t >= tokens.length || tokens[t] === '') {
      throw ioError(name, `PLY ${element.name} ${k} of ${element.count}: the file ends there (a truncated file?)`);
    }
    const s = tokens[t++];
    const v = /^[-+]?nan$/i.test(s) ? NaN : /^[-+]?inf(inity)?$/i.test(s) ? (s[0] === '-' ? -Infinity : Infinity) : Number(s);
    if (Number.isNaN(v) && !/nan/i.test(s)) throw ioError(name, `PLY ${element.name} ${k}: "${s}" is not a number`);
    return v;
  };
  for (const element of elements) {
    const values = new Array(element.properties.length);
    for (let k = 0; k < element.count; k++) {
      element.properties.forEach((p, i) => {
        if (p.list) {
          const n = number(element, k);
          for (let j = 0; j < n; j++) number(element, k);
        } else {
          values[i] = number(element, k);
        }
      });
      if (element === vertex) put(k, values);
    }
  }
}

function plyBinary(bytes, start, little, elements, vertex, put, name) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let at = start;
  const read = ([type, size], element, k) => {
    if (at + size > bytes.length) {
      throw ioError(name, `PLY ${element.name} ${k} of ${element.count}: the file ends there (${bytes.length} bytes; a truncated file?)`);
    }
    const v = view[`get${type}`](at, little);
    at += size;
    return v;
  };
  for (const element of elements) {
    const values = new Array(element.properties.length);
    const fixed = element.properties.every((p) => !p.list);
    const rowSize = element.properties.reduce((s, p) => s + (p.list ? 0 : p.type[1]), 0);
    if (fixed && element !== vertex) {
      // Skipped whole (faces of fixed size, other elements).
      if (at + rowSize * element.count > bytes.length) {
        throw ioError(name, `PLY ${element.name}: ${element.count} of ${rowSize} bytes do not fit in the file (${bytes.length} bytes; a truncated file?)`);
      }
      at += rowSize * element.count;
      continue;
    }
    if (fixed && at + rowSize * element.count > bytes.length) {
      const fit = Math.floor((bytes.length - at) / rowSize);
      throw ioError(name, `PLY ${element.name} ${fit} of ${element.count}: the file ends there (${bytes.length} bytes; a truncated file?)`);
    }
    for (let k = 0; k < element.count; k++) {
      for (let i = 0; i < element.properties.length; i++) {
        const p = element.properties[i];
        if (p.list) {
          const n = read(p.countType, element, k);
          if (at + n * p.type[1] > bytes.length) {
            throw ioError(name, `PLY ${element.name} ${k} of ${element.count}: the file ends there (${bytes.length} bytes; a truncated file?)`);
          }
          at += n * p.type[1];
        } else {
          values[i] = read(p.type, element, k);
        }
      }
      if (element === vertex) put(k, values);
    }
  }
}

// ---------------------------------------------------------------------------
// PCD

const PCD_TYPES = {
  F4: ['Float32', 4], F8: ['Float64', 8],
  I1: ['Int8', 1], I2: ['Int16', 2], I4: ['Int32', 4], I8: ['BigInt64', 8],
  U1: ['Uint8', 1], U2: ['Uint16', 2], U4: ['Uint32', 4], U8: ['BigUint64', 8],
};

function pcdHeader(bytes, name) {
  const head = latin1(bytes, 0, Math.min(bytes.length, 1 << 16));
  const h = {};
  let at = 0;
  let lineNo = 0;
  for (;;) {
    const nl = head.indexOf('\n', at);
    if (nl < 0) throw ioError(name, 'PCD header without a DATA line (a truncated or damaged file?)');
    const line = head.slice(at, nl).replace(/\r$/, '').trim();
    at = nl + 1;
    lineNo++;
    if (line === '' || line.startsWith('#')) continue;
    const [key, ...words] = line.split(/\s+/);
    const k = key.toUpperCase();
    if (!['VERSION', 'FIELDS', 'SIZE', 'TYPE', 'COUNT', 'WIDTH', 'HEIGHT', 'VIEWPOINT', 'POINTS', 'DATA'].includes(k)) {
      throw ioError(name, `PCD header line ${lineNo}: unknown keyword "${key}"`);
    }
    h[k] = words;
    if (k === 'DATA') break;
  }
  const fields = h.FIELDS;
  if (!fields?.length) throw ioError(name, 'PCD header without FIELDS');
  const list = (k, fallback) => {
    const v = h[k] ?? fallback;
    if (!v || v.length !== fields.length) {
      throw ioError(name, `PCD header: ${k} has ${v?.length ?? 0} entries for ${fields.length} FIELDS`);
    }
    return v;
  };
  const sizes = list('SIZE').map(Number);
  const types = list('TYPE');
  const counts = list('COUNT', fields.map(() => '1')).map(Number);
  const defs = fields.map((f, i) => {
    const type = PCD_TYPES[`${types[i].toUpperCase()}${sizes[i]}`];
    if (!type) throw ioError(name, `PCD field '${f}': TYPE ${types[i]} with SIZE ${sizes[i]} is not a PCD type`);
    if (!Number.isSafeInteger(counts[i]) || counts[i] < 1) throw ioError(name, `PCD field '${f}': COUNT ${h.COUNT?.[i]}`);
    return { name: f, type, count: counts[i] };
  });
  const int = (k) => (h[k] ? Number(h[k][0]) : undefined);
  const width = int('WIDTH');
  const height = int('HEIGHT') ?? 1;
  const points = int('POINTS') ?? (width !== undefined ? width * height : undefined);
  if (!Number.isSafeInteger(points) || points < 0) throw ioError(name, `PCD header: POINTS ${h.POINTS?.[0]} (expected a count)`);
  const data = h.DATA[0]?.toLowerCase();
  if (!['ascii', 'binary', 'binary_compressed'].includes(data)) {
    throw ioError(name, `PCD DATA ${h.DATA[0]} (expected ascii, binary or binary_compressed)`);
  }
  return { end: at, defs, points, data };
}

function readPcdBytes(bytes, name) {
  const { end, defs, points: promised, data } = pcdHeader(bytes, name);
  const index = ['x', 'y', 'z'].map((axis) => {
    const i = defs.findIndex((d) => d.name === axis);
    if (i < 0) throw ioError(name, `PCD fields are ${defs.map((d) => d.name).join(' ')}: no '${axis}' (x, y, z are needed)`);
    if (defs[i].count !== 1) throw ioError(name, `PCD field '${axis}' has COUNT ${defs[i].count}, expected 1`);
    return i;
  });
  const f32 = index.every((i) => defs[i].type[0] === 'Float32');
  // Before allocating: a point takes at least 2 bytes a value in ascii, its
  // record in binary, and LZF expands at most about 100-fold.
  const rowBytes = defs.reduce((s, d) => s + d.type[1] * d.count, 0);
  const least = data === 'ascii' ? 2 * defs.reduce((s, d) => s + d.count, 0) : data === 'binary' ? rowBytes : rowBytes / 128;
  if (promised * least > bytes.length - end + 1) {
    if (data === 'binary') {
      const fit = Math.max(0, Math.floor((bytes.length - end) / rowBytes));
      throw ioError(name, `PCD point ${fit} of ${promised}: the file ends there (${bytes.length} bytes, ${rowBytes} a point; a truncated file?)`);
    }
    throw ioError(name, `the PCD header promises ${promised} points; ${bytes.length - end} bytes of data cannot hold them (a truncated or damaged file?)`);
  }
  const out = new (f32 ? Float32Array : Float64Array)(promised * 3);
  let kept = 0;
  const put = (k, x, y, z) => {
    // NaN is PCL's "no return" (organized clouds): the point is left out.
    if (Number.isNaN(x) || Number.isNaN(y) || Number.isNaN(z)) return;
    if (!(Number.isFinite(x) && Number.isFinite(y) && Number.isFinite(z))) {
      throw ioError(name, `PCD point ${k} has an infinite coordinate`);
    }
    out[3 * kept] = x;
    out[3 * kept + 1] = y;
    out[3 * kept + 2] = z;
    kept++;
  };
  // Byte offset of each field within a record (binary), and of its first value (ascii: value index).
  const rowSize = defs.reduce((s, d) => s + d.type[1] * d.count, 0);
  const valueIndex = [];
  const byteOffset = [];
  let v = 0;
  let b = 0;
  for (const d of defs) {
    valueIndex.push(v);
    byteOffset.push(b);
    v += d.count;
    b += d.type[1] * d.count;
  }
  const get = (view, type, at) => Number(view[`get${type[0]}`](at, true));
  if (data === 'ascii') {
    const lines = new TextDecoder().decode(bytes.subarray(end)).split('\n');
    let k = 0;
    for (const line of lines) {
      const words = line.trim().split(/\s+/);
      if (words[0] === '') continue;
      if (k >= promised) throw ioError(name, `PCD: more than the ${promised} points of the header`);
      if (words.length !== v) throw ioError(name, `PCD point ${k}: ${words.length} values, expected ${v}`);
      const [x, y, z] = index.map((i) => {
        const s = words[valueIndex[i]];
        const n = /^[-+]?nan$/i.test(s) ? NaN : Number(s);
        if (Number.isNaN(n) && !/nan/i.test(s)) throw ioError(name, `PCD point ${k}: "${s}" is not a number`);
        return n;
      });
      put(k, x, y, z);
      k++;
    }
    if (k !== promised) throw ioError(name, `PCD point ${k} of ${promised}: the file ends there (a truncated file?)`);
  } else if (data === 'binary') {
    if (end + promised * rowSize > bytes.length) {
      const fit = Math.max(0, Math.floor((bytes.length - end) / rowSize));
      throw ioError(name, `PCD point ${fit} of ${promised}: the file ends there (${bytes.length} bytes, ${rowSize} a point; a truncated file?)`);
    }
    const view = new DataView(bytes.buffer, bytes.byteOffset + end, promised * rowSize);
    for (let k = 0; k < promised; k++) {
      const at = k * rowSize;
      const [x, y, z] = index.map((i) => get(view, defs[i].type, at + byteOffset[i]));
      put(k, x, y, z);
    }
  } else {
    if (end + 8 > bytes.length) throw ioError(name, 'PCD binary_compressed: the file ends before the sizes (a truncated file?)');
    const sizes = new DataView(bytes.buffer, bytes.byteOffset + end, 8);
    const compressed = sizes.getUint32(0, true);
    const size = sizes.getUint32(4, true);
    if (end + 8 + compressed > bytes.length) {
      throw ioError(name, `PCD binary_compressed: ${compressed} compressed bytes promised, ${bytes.length - end - 8} in the file (a truncated file?)`);
    }
    if (size !== promised * rowSize) {
      throw ioError(name, `PCD binary_compressed: ${size} bytes uncompressed, expected ${promised} points x ${rowSize} bytes`);
    }
    const raw = lzfDecompress(bytes.subarray(end + 8, end + 8 + compressed), size, name);
    const view = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
    // Field-major: every point's first field, then every point's second, ...
    const fieldStart = byteOffset.map((o) => o * promised);
    for (let k = 0; k < promised; k++) {
      const [x, y, z] = index.map((i) => get(view, defs[i].type, fieldStart[i] + k * defs[i].type[1]));
      put(k, x, y, z);
    }
  }
  const points = kept === promised ? out : out.slice(0, 3 * kept);
  return { points, stride: 3, count: kept, format: 'pcd', name };
}

/** LZF (liblzf, as PCL's binary_compressed uses it), checked against overruns. */
function lzfDecompress(input, size, name) {
  const out = new Uint8Array(size);
  let i = 0;
  let o = 0;
  const bad = () => ioError(name, 'PCD binary_compressed: the LZF data is damaged');
  while (i < input.length) {
    const ctrl = input[i++];
    if (ctrl < 32) {
      const n = ctrl + 1;
      if (o + n > size || i + n > input.length) throw bad();
      out.set(input.subarray(i, i + n), o);
      i += n;
      o += n;
    } else {
      let n = ctrl >> 5;
      if (n === 7) {
        if (i >= input.length) throw bad();
        n += input[i++];
      }
      if (i >= input.length) throw bad();
      const back = o - ((ctrl & 0x1f) << 8) - input[i++] - 1;
      n += 2;
      if (back < 0 || o + n > size) throw bad();
      for (let j = 0; j < n; j++) out[o++] = out[back + j];
    }
  }
  if (o !== size) throw bad();
  return out;
}

// ---------------------------------------------------------------------------
// LAS / LAZ

/** The LAS public header block, the point layout and the CRS from the (E)VLRs. */
function lasHeader(bytes, name) {
  if (bytes.length < 227) throw ioError(name, `LAS header cut short (${bytes.length} bytes; a LAS header has at least 227)`);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const major = view.getUint8(24);
  const minor = view.getUint8(25);
  const headerSize = view.getUint16(94, true);
  const pointsOffset = view.getUint32(96, true);
  const vlrCount = view.getUint32(100, true);
  const formatByte = view.getUint8(104);
  const pointFormat = formatByte & 0x3f;
  const compressed = (formatByte & 0xc0) !== 0;
  const recordLength = view.getUint16(105, true);
  let count = view.getUint32(107, true);
  const scale = [131, 139, 147].map((o) => view.getFloat64(o, true));
  const offset = [155, 163, 171].map((o) => view.getFloat64(o, true));
  const version = `${major}.${minor}`;
  if (major !== 1 || minor > 4) throw ioError(name, `LAS version ${version}: expected 1.0 to 1.4`);
  if (minor >= 4) {
    if (bytes.length < 375) throw ioError(name, `LAS 1.4 header cut short (${bytes.length} bytes; it has 375)`);
    const count64 = Number(view.getBigUint64(247, true));
    if (count64 > 0) count = count64;
  }
  if (pointFormat > 10) throw ioError(name, `LAS point format ${pointFormat}: expected 0 to 10`);
  if (recordLength < 12) throw ioError(name, `LAS point records of ${recordLength} bytes: too short for x, y, z`);
  if (!scale.every((s) => Number.isFinite(s) && s !== 0) || !offset.every(Number.isFinite)) {
    throw ioError(name, `LAS scale ${scale.join(', ')} or offset ${offset.join(', ')} is not finite and non-zero`);
  }
  if (headerSize < 227 || pointsOffset < headerSize) {
    throw ioError(name, `LAS header size ${headerSize} and point offset ${pointsOffset} do not fit`);
  }
  // Variable-length records after the header; extended ones (LAS 1.4) after the points.
  const records = [];
  let at = headerSize;
  for (let k = 0; k < vlrCount; k++) {
    if (at + 54 > pointsOffset || at + 54 > bytes.length) break;
    const length = view.getUint16(at + 20, true);
    records.push({ user: cString(bytes, at + 2, 16), id: view.getUint16(at + 18, true), start: at + 54, length });
    at += 54 + length;
  }
  if (minor >= 4) {
    let e = Number(view.getBigUint64(235, true));
    const evlrCount = view.getUint32(243, true);
    for (let k = 0; k < evlrCount && e > 0 && e + 60 <= bytes.length; k++) {
      const length = Number(view.getBigUint64(e + 20, true));
      records.push({ user: cString(bytes, e + 2, 16), id: view.getUint16(e + 18, true), start: e + 60, length });
      e += 60 + length;
    }
  }
  return { version, pointFormat, compressed, recordLength, count, pointsOffset, scale, offset, crs: lasCrs(bytes, view, records) };
}

function cString(bytes, start, length) {
  let end = start;
  while (end < start + length && end < bytes.length && bytes[end] !== 0) end++;
  return new TextDecoder().decode(bytes.subarray(start, end));
}

/** The CRS of LASF_Projection records: OGC WKT (2112), GeoTIFF keys (34735, 34737). */
function lasCrs(bytes, view, records) {
  const crs = {};
  for (const r of records) {
    if (r.user !== 'LASF_Projection' || r.start + r.length > bytes.length) continue;
    if (r.id === 2112) {
      const wkt = cString(bytes, r.start, r.length).trim();
      if (wkt) crs.wkt = wkt;
    } else if (r.id === 34735 && r.length >= 8) {
      const keys = view.getUint16(r.start + 6, true);
      const geoKeys = {};
      for (let k = 0; k < keys && r.start + 8 + 8 * k + 8 <= r.start + r.length; k++) {
        const p = r.start + 8 + 8 * k;
        const id = view.getUint16(p, true);
        const location = view.getUint16(p + 2, true);
        const value = view.getUint16(p + 6, true);
        if (location === 0) geoKeys[id] = value;
      }
      crs.geoKeys = geoKeys;
      // ProjectedCSTypeGeoKey, else GeographicTypeGeoKey; 32767 is "user-defined".
      const horizontal = geoKeys[3072] ?? geoKeys[2048];
      if (horizontal && horizontal !== 32767) crs.epsg = horizontal;
      if (geoKeys[4096] && geoKeys[4096] !== 32767) crs.verticalEpsg = geoKeys[4096];
    } else if (r.id === 34737) {
      const ascii = cString(bytes, r.start, r.length).replace(/\|+$/, '').trim();
      if (ascii) crs.citation = ascii;
    }
  }
  if (crs.epsg === undefined && crs.wkt) {
    // The WKT's own authority: its last AUTHORITY["EPSG","n"] / ID["EPSG",n] is the CRS's.
    const ids = [...crs.wkt.matchAll(/(?:AUTHORITY|ID)\s*\[\s*"EPSG"\s*,\s*"?(\d+)"?\s*\]/gi)];
    const top = ids.length ? Number(ids[ids.length - 1][1]) : undefined;
    if (top && /^\s*(PROJCS|PROJCRS|GEOGCS|GEOGCRS|COMPD_CS|COMPOUNDCRS)/i.test(crs.wkt)) crs.wktEpsg = top;
  }
  if (crs.wkt === undefined && crs.epsg === undefined) return undefined;
  // What polyscene/geo's geoFrame({ crs }) takes: the EPSG code when there is one, else the WKT.
  const code = crs.epsg ?? crs.wktEpsg;
  crs.definition = code ? `EPSG:${code}` : crs.wkt;
  return crs;
}

let lasLoader;

/** @loaders.gl/las, imported on first use (a page that reads no LAS file does not load it). */
async function loadersGlLas() {
  lasLoader ??= import('@loaders.gl/las').then((m) => m.LASLoader);
  return lasLoader;
}

async function readLasBytes(bytes, name) {
  const h = lasHeader(bytes, name);
  const kind = h.compressed ? 'LAZ' : 'LAS';
  if (h.count === 0) throw ioError(name, `the ${kind} header promises no points`);
  if (!h.compressed && h.pointsOffset + h.count * h.recordLength > bytes.length) {
    const fit = Math.max(0, Math.floor((bytes.length - h.pointsOffset) / h.recordLength));
    throw ioError(name, `the LAS header promises ${h.count} points, the file holds ${fit} (a truncated or damaged file?)`);
  }
  // @loaders.gl/las (laz-perf) reads LAS and LAZ 1.0-1.3 in point formats 0-3.
  const loadersGl = Number(h.version.split('.')[1]) <= 3 && h.pointFormat <= 3;
  let points;
  if (loadersGl) {
    const LASLoader = await loadersGlLas();
    // A buffer of its own: the loader reads `byteOffset` 0 and slices it.
    const buffer = bytes.byteOffset === 0 && bytes.byteLength === bytes.buffer.byteLength ? bytes.buffer : new Uint8Array(bytes).buffer;
    let mesh;
    try {
      mesh = LASLoader.parseSync(buffer, { las: { fp64: true, skip: 1, colorDepth: 8 } });
    } catch (e) {
      throw ioError(name, `${kind} points: the decoder of @loaders.gl/las failed (${e?.message ?? e}): a truncated or damaged file?`);
    }
    points = mesh?.attributes?.POSITION?.value;
    if (!(points instanceof Float64Array)) throw ioError(name, `${kind}: @loaders.gl/las gave no float64 positions`);
    if (points.length !== 3 * h.count) {
      throw ioError(name, `the ${kind} header promises ${h.count} points, the file holds ${points.length / 3} (a truncated or damaged file?)`);
    }
  } else if (h.compressed) {
    throw ioError(name, `LAZ ${h.version} in point format ${h.pointFormat}: @loaders.gl/las's LAZ decoder reads LAS 1.0-1.3 in point formats 0-3; decompress it to LAS first (laszip, pdal translate, or the polyscene CLI, which reads it)`);
  } else {
    // Every point format starts with x, y, z as little-endian int32.
    points = new Float64Array(3 * h.count);
    const view = new DataView(bytes.buffer, bytes.byteOffset + h.pointsOffset, h.count * h.recordLength);
    for (let k = 0; k < h.count; k++) {
      const at = k * h.recordLength;
      for (let i = 0; i < 3; i++) points[3 * k + i] = view.getInt32(at + 4 * i, true) * h.scale[i] + h.offset[i];
    }
  }
  for (let i = 0; i < points.length; i++) {
    if (!Number.isFinite(points[i])) throw ioError(name, `${kind} point ${Math.floor(i / 3)} has a NaN or infinite coordinate (scale or offset?)`);
  }
  const out = { points, stride: 3, count: h.count, format: h.compressed ? 'laz' : 'las', name };
  if (h.crs) out.crs = h.crs;
  return out;
}

// ---------------------------------------------------------------------------
// KITTI sequences

/** A column-major 4x4 (Float64Array(16), the layout addScan takes) from a row-major 3x4 [R | t]. */
function fromRows(n) {
  return Float64Array.from([n[0], n[4], n[8], 0, n[1], n[5], n[9], 0, n[2], n[6], n[10], 0, n[3], n[7], n[11], 1]);
}

/** Why a column-major 4x4 is not rigid, or undefined (same test as the core's check_rigid). */
function notRigid(m) {
  if (!m.every(Number.isFinite)) return 'it has a NaN or infinite entry';
  let dev = 0;
  for (let a = 0; a < 3; a++) {
    for (let b = 0; b < 3; b++) {
      let dot = 0;
      for (let i = 0; i < 3; i++) dot += m[4 * a + i] * m[4 * b + i];
      dev = Math.max(dev, Math.abs(dot - (a === b ? 1 : 0)));
    }
  }
  if (dev > 1e-4) return `its rotation part is not orthonormal (max |R^T R - I| = ${dev}); scaling or shear is not allowed`;
  const det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
  if (det < 0) return 'its rotation is a reflection (determinant -1)';
  return undefined;
}

/** Product of two column-major 4x4s. */
function mul(a, b) {
  const out = new Float64Array(16);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[4 * k + r] * b[4 * c + k];
      out[4 * c + r] = s;
    }
  }
  return out;
}

/**
 * Inverse of a column-major 4x4 (cofactors, in f64), as glam's
 * DMat4::inverse that the CLI uses: KITTI's Tr is rigid only to its printed
 * digits, so its transpose is not its inverse to 1e-7.
 */
function inverse(m) {
  const [a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33] = m;
  const b00 = a00 * a11 - a01 * a10;
  const b01 = a00 * a12 - a02 * a10;
  const b02 = a00 * a13 - a03 * a10;
  const b03 = a01 * a12 - a02 * a11;
  const b04 = a01 * a13 - a03 * a11;
  const b05 = a02 * a13 - a03 * a12;
  const b06 = a20 * a31 - a21 * a30;
  const b07 = a20 * a32 - a22 * a30;
  const b08 = a20 * a33 - a23 * a30;
  const b09 = a21 * a32 - a22 * a31;
  const b10 = a21 * a33 - a23 * a31;
  const b11 = a22 * a33 - a23 * a32;
  const det = b00 * b11 - b01 * b10 + b02 * b09 + b03 * b08 - b04 * b07 + b05 * b06;
  const d = 1 / det;
  return Float64Array.from([
    (a11 * b11 - a12 * b10 + a13 * b09) * d,
    (a02 * b10 - a01 * b11 - a03 * b09) * d,
    (a31 * b05 - a32 * b04 + a33 * b03) * d,
    (a22 * b04 - a21 * b05 - a23 * b03) * d,
    (a12 * b08 - a10 * b11 - a13 * b07) * d,
    (a00 * b11 - a02 * b08 + a03 * b07) * d,
    (a32 * b02 - a30 * b05 - a33 * b01) * d,
    (a20 * b05 - a22 * b02 + a23 * b01) * d,
    (a10 * b10 - a11 * b08 + a13 * b06) * d,
    (a01 * b08 - a00 * b10 - a03 * b06) * d,
    (a30 * b04 - a31 * b02 + a33 * b00) * d,
    (a21 * b02 - a20 * b04 - a23 * b00) * d,
    (a11 * b07 - a10 * b09 - a12 * b06) * d,
    (a00 * b09 - a01 * b07 + a02 * b06) * d,
    (a31 * b01 - a30 * b03 - a32 * b00) * d,
    (a20 * b03 - a21 * b01 + a22 * b00) * d,
  ]);
}

function numbersOf(rest, what, name) {
  const words = rest.trim().split(/\s+/).filter(Boolean);
  return words.map((w) => {
    const v = Number(w);
    if (!Number.isFinite(v)) throw ioError(name, `${what}: "${w}" is not a number`);
    return v;
  });
}

/**
 * KITTI poses (`poses/NN.txt`): one pose per non-empty line, 12 numbers,
 * the row-major 3x4 [R | t]; lines starting with '#' are skipped. Returns
 * column-major Float64Array(16)s. Each is checked to be rigid.
 */
export function parseKittiPoses(text, options = {}) {
  const name = options.name;
  if (typeof text !== 'string') throw new TypeError(`${PREFIX}: poses must be text`);
  const out = [];
  text.split('\n').forEach((line, i) => {
    const t = line.trim();
    if (t === '' || t.startsWith('#')) return;
    const n = numbersOf(t, `poses line ${i + 1}`, name);
    if (n.length !== 12) throw ioError(name, `poses line ${i + 1}: expected 12 numbers, found ${n.length}`);
    const m = fromRows(n);
    const why = notRigid(m);
    if (why) throw ioError(name, `poses line ${i + 1}: ${why}`);
    out.push(m);
  });
  return out;
}

/**
 * KITTI's calibration: the LiDAR-to-camera-0 transform `Tr` (column-major
 * Float64Array(16)) from the line `Tr:` of odometry's calib.txt
 * (`Tr_velo_to_cam:` and `Tr_velo_cam:` are read too; 12 numbers, row-major
 * 3x4) or from the lines `R:` (9) and `T:` (3) of the raw data's
 * calib_velo_to_cam.txt. Checked to be rigid.
 */
export function parseKittiCalib(text, options = {}) {
  const name = options.name;
  if (typeof text !== 'string') throw new TypeError(`${PREFIX}: calib must be text`);
  let tr;
  let r;
  let t;
  text.split('\n').forEach((line, i) => {
    const colon = line.indexOf(':');
    if (colon < 0) return;
    const key = line.slice(0, colon).trim();
    if (!['Tr', 'Tr_velo_to_cam', 'Tr_velo_cam', 'R', 'T'].includes(key)) return;
    const n = numbersOf(line.slice(colon + 1), `calib line ${i + 1} (${key})`, name);
    const expected = key === 'R' ? 9 : key === 'T' ? 3 : 12;
    if (n.length !== expected) throw ioError(name, `calib line ${i + 1} (${key}): expected ${expected} numbers, found ${n.length}`);
    if (key === 'R') r = n;
    else if (key === 'T') t = n;
    else tr ??= n;
  });
  const rows = tr ?? (r && t ? [r[0], r[1], r[2], t[0], r[3], r[4], r[5], t[1], r[6], r[7], r[8], t[2]] : undefined);
  if (!rows) throw ioError(name, 'no LiDAR-to-camera transform: expected a line `Tr:` with 12 numbers (KITTI odometry calib.txt), or lines `R:` and `T:`');
  const m = fromRows(rows);
  const why = notRigid(m);
  if (why) throw ioError(name, `calib Tr: ${why}`);
  return m;
}

/**
 * World-from-LiDAR poses from KITTI's world-from-camera-0 poses and the
 * calibration's `tr` (LiDAR to camera 0): `Tr^-1 . P . Tr` each, in the
 * frame of the LiDAR at scan 0 (z up). Column-major Float64Array(16)s.
 */
export function kittiLidarPoses(cameraPoses, tr) {
  const inv = inverse(tr);
  return cameraPoses.map((p) => mul(mul(inv, p), tr));
}

/** The base name of a path or File name. */
const baseName = (s) => String(s).split(/[\\/]/).pop();

/** A scan entry's name: `{ name }`, a File's name or webkitRelativePath, or `{ path }`. */
function entryName(entry) {
  return entry?.path ?? (entry?.webkitRelativePath || undefined) ?? entry?.name;
}

/** An entry's size in bytes, when it is known without reading it. */
function entrySize(entry) {
  const data = entry?.data ?? entry;
  if (typeof data?.size === 'number') return data.size;
  if (typeof data?.byteLength === 'number') return data.byteLength;
  return undefined;
}

/**
 * A KITTI odometry sequence from its parts, read one scan at a time:
 *
 *   scans   the velodyne/ files: File/Blob objects with a name, or
 *           `{ name, data }` (data: bytes or a Blob); a name is NNNNNN.bin,
 *           the scan number (a path's directories are ignored);
 *   poses   poses/NN.txt (text, bytes or a File): KITTI's camera-0 poses,
 *           line k for scan k;
 *   calib   sequences/NN/calib.txt (text, bytes or a File), whose Tr maps
 *           LiDAR to camera 0: the poses become LiDAR poses Tr^-1 . P . Tr;
 *   lidarPoses  true: the poses are world-from-LiDAR already (no calib);
 *   skipMissing true: replay the scans that are there when numbers are
 *           missing (each with the pose of its number);
 *   skipEmpty   true: leave out empty (0-byte) scans instead of refusing them.
 *
 * Nothing is guessed: without calib (and without lidarPoses) the sequence
 * is refused; scans and poses are matched by number, never by position.
 * Resolves to `{ length, scans: [{ number, name }], poses, calib, read(i),
 * [Symbol.asyncIterator] }`; `read(i)` resolves to the scan's
 * `{ points, stride: 4, count, pose, number, name, format: 'kitti-bin' }`.
 */
export async function kittiSequence(options = {}) {
  const { scans, poses, calib, lidarPoses = false, skipMissing = false, skipEmpty = false } = options;
  if (lidarPoses && calib !== undefined) {
    throw new Error(`${PREFIX}: calib converts camera poses; lidarPoses says there is nothing to convert: give one of them`);
  }
  if (scans === undefined || typeof scans[Symbol.iterator] !== 'function') {
    throw new TypeError(`${PREFIX}: scans must be a list of .bin files (File/Blob objects or { name, data })`);
  }
  const list = [];
  for (const entry of scans) {
    const path = entryName(entry);
    if (typeof path !== 'string' || path === '') throw new TypeError(`${PREFIX}: every scan needs a name (NNNNNN.bin): a File, or { name, data }`);
    const base = baseName(path);
    const m = /^(\d{1,9})\.bin$/.exec(base);
    if (!m) throw ioError(path, 'not a scan file name: scans are NNNNNN.bin, the scan number, which is also the line of its pose');
    list.push({ number: Number(m[1]), name: path, entry, bytes: entrySize(entry) });
  }
  if (list.length === 0) throw new Error(`${PREFIX}: no .bin scans given`);
  list.sort((a, b) => a.number - b.number || (a.name < b.name ? -1 : 1));
  for (let k = 1; k < list.length; k++) {
    if (list[k].number === list[k - 1].number) throw ioError(list[k].name, `scan number ${list[k].number} again (also ${list[k - 1].name})`);
  }
  if (!skipMissing) {
    list.forEach((s, k) => {
      if (s.number !== k) {
        throw new Error(`${PREFIX}: scan ${String(k).padStart(6, '0')}.bin is missing (the next is ${s.name}): scans are matched with poses by number; to replay the scans that are there, each with the pose of its number, pass skipMissing: true`);
      }
    });
  }
  const empty = list.filter((s) => s.bytes === 0);
  if (empty.length && !skipEmpty) throw ioError(empty[0].name, 'empty file (0 bytes), not a scan: pass skipEmpty: true to leave empty scans out');

  if (poses === undefined) throw new TypeError(`${PREFIX}: poses (KITTI's poses/NN.txt) are needed`);
  const posesText = await textOf(poses, 'poses');
  const posesName = posesText.name ?? options.posesName ?? 'poses';
  let all = parseKittiPoses(posesText.text, { name: posesName });
  let tr;
  if (!lidarPoses) {
    if (calib === undefined) {
      throw ioError(posesName, "KITTI poses are camera-0 poses, and no calib was given (calib.txt, whose Tr maps LiDAR to camera): pass calib, or lidarPoses: true if these poses are world-from-LiDAR already");
    }
    const calibText = await textOf(calib, 'calib');
    tr = parseKittiCalib(calibText.text, { name: calibText.name ?? options.calibName ?? 'calib' });
    all = kittiLidarPoses(all, tr);
  }
  const kept = list.filter((s) => s.bytes !== 0);
  const last = list[list.length - 1].number;
  const fits = skipMissing ? last < all.length : last + 1 === all.length;
  if (!fits) {
    throw ioError(posesName, `${all.length} poses for scans numbered 0 to ${last}${skipMissing ? '' : ' (one pose per scan, line k for scan k)'}`);
  }
  const lidar = kept.map((s) => all[s.number]);
  const read = async (i) => {
    if (!Number.isInteger(i) || i < 0 || i >= kept.length) throw new RangeError(`${PREFIX}: scan index ${i} (0 to ${kept.length - 1})`);
    const s = kept[i];
    const data = s.entry?.data ?? s.entry;
    const scan = await readKittiBin(data, { name: s.name });
    return { ...scan, pose: Float64Array.from(lidar[i]), number: s.number };
  };
  return {
    length: kept.length,
    scans: kept.map(({ number, name }) => ({ number, name })),
    skippedEmpty: list.filter((s) => s.bytes === 0).map(({ number, name }) => ({ number, name })),
    poses: lidar,
    calib: tr,
    read,
    async *[Symbol.asyncIterator]() {
      for (let i = 0; i < kept.length; i++) yield await read(i);
    },
  };
}

/**
 * Find a KITTI sequence among a folder's files (a browser's directory pick,
 * whose Files have `webkitRelativePath`, or `{ path, data }` entries) and
 * open it with kittiSequence. The layouts, as the CLI reads them:
 *
 *   - KITTI's: .../sequences/NN/velodyne/NNNNNN.bin, poses in
 *     sequences/NN/poses.txt or poses/NN.txt, calib in sequences/NN/calib.txt
 *     (`options.sequence` picks NN when there are several);
 *   - a sequence folder: velodyne/NNNNNN.bin, poses.txt, calib.txt beside;
 *   - a flat folder: NNNNNN.bin and poses.txt holding world-from-LiDAR poses
 *     (polyscene's simulated drives); a calib.txt there is refused unless
 *     options say which frame the poses are in (calib or lidarPoses).
 *
 * Other options are passed to kittiSequence (calib or poses given there
 * replace the found ones).
 */
export async function findKittiSequence(files, options = {}) {
  const entries = [...files].map((f) => ({ path: String(entryName(f) ?? '').replace(/\\/g, '/'), data: f?.data ?? f }));
  const bins = entries.filter((e) => /(^|\/)\d{1,9}\.bin$/.test(e.path));
  if (bins.length === 0) throw new Error(`${PREFIX}: no NNNNNN.bin scans among the ${entries.length} files given`);
  const find = (path) => entries.find((e) => e.path === path || e.path.endsWith(`/${path}`));
  const dirOf = (p) => p.slice(0, p.lastIndexOf('/') + 1);
  const velodyne = bins.filter((e) => /(^|\/)velodyne\/\d{1,9}\.bin$/.test(e.path));
  let scans;
  let poses;
  let calib;
  let kitti;
  if (velodyne.length) {
    // The sequence folders (.../NN/) that hold a velodyne/ folder.
    const seqDirs = [...new Set(velodyne.map((e) => dirOf(e.path).replace(/velodyne\/$/, '')))].sort();
    let seqDir;
    if (seqDirs.length === 1 && options.sequence === undefined) seqDir = seqDirs[0];
    else {
      const id = options.sequence;
      const ids = seqDirs.map((d) => d.split('/').filter(Boolean).pop() ?? '');
      if (id === undefined) throw new Error(`${PREFIX}: several sequences (${ids.join(', ')}): pick one with { sequence: ID }`);
      seqDir = seqDirs.find((d, i) => ids[i] === id);
      if (seqDir === undefined) throw new Error(`${PREFIX}: no sequence ${id} (found ${ids.join(', ')})`);
    }
    const id = seqDir.split('/').filter(Boolean).pop() ?? '';
    scans = velodyne.filter((e) => dirOf(e.path) === `${seqDir}velodyne/`);
    const root = seqDir.replace(/sequences\/[^/]+\/$/, '');
    poses = entries.find((e) => e.path === `${seqDir}poses.txt`) ?? (seqDir !== root ? entries.find((e) => e.path === `${root}poses/${id}.txt`) : undefined);
    if (!poses && options.poses === undefined) {
      throw new Error(`${PREFIX}: no poses for ${seqDir || 'the sequence'}: looked for ${seqDir}poses.txt${seqDir !== root ? ` and ${root}poses/${id}.txt` : ''}; give them as { poses }`);
    }
    calib = entries.find((e) => e.path === `${seqDir}calib.txt`);
    kitti = true;
  } else {
    const dirs = [...new Set(bins.map((e) => dirOf(e.path)))];
    if (dirs.length > 1) throw new Error(`${PREFIX}: .bin scans in several folders (${dirs.join(', ')}) and no velodyne/ folder: give one sequence`);
    scans = bins;
    poses = find(`${dirs[0]}poses.txt`);
    if (!poses && options.poses === undefined) throw new Error(`${PREFIX}: no ${dirs[0]}poses.txt beside the scans; give the poses as { poses }`);
    calib = find(`${dirs[0]}calib.txt`);
    kitti = false;
  }
  const opts = { ...options };
  delete opts.sequence;
  opts.scans = scans.map((e) => ({ name: e.path, data: e.data }));
  opts.poses ??= poses?.data;
  opts.posesName ??= poses?.path;
  if (!opts.lidarPoses && opts.calib === undefined) {
    if (kitti) {
      if (!calib) {
        throw ioError(poses?.path, 'KITTI poses are camera-0 poses, and calib.txt (whose Tr maps LiDAR to camera) is missing beside velodyne/: pass { calib }, or { lidarPoses: true } if these poses are world-from-LiDAR already');
      }
      opts.calib = calib.data;
      opts.calibName = calib.path;
    } else if (calib) {
      throw ioError(calib.path, `a KITTI calibration beside ${poses?.path ?? 'the poses'}: if those are KITTI camera poses, pass { calib } to convert them to LiDAR poses; if they are world-from-LiDAR already, pass { lidarPoses: true }`);
    } else {
      opts.lidarPoses = true;
    }
  }
  return kittiSequence(opts);
}
