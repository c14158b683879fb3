// polyscene/io/node: the readers of polyscene/io on file paths, for Node.
// Each file is read when its points are wanted (a KITTI sequence holds
// gigabytes); everything else is polyscene/io's (in the package, io/node.js
// imports io/index.js).

import fs from 'node:fs';
import path from 'node:path';
import { findKittiSequence, readKittiBin, readPoints } from './io.mjs';

/** A Blob-like view of a file: its size now, its bytes or text when asked. */
function fileEntry(file) {
  let size;
  try {
    size = fs.statSync(file).size;
  } catch (e) {
    throw new Error(`polyscene/io: ${file}: cannot read (${e.code ?? e.message})`);
  }
  return {
    path: file,
    data: {
      name: file,
      size,
      arrayBuffer: async () => {
        const b = await fs.promises.readFile(file);
        return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength);
      },
      text: () => fs.promises.readFile(file, 'utf8'),
    },
  };
}

/** readPoints on a file path (the path names the file in errors). */
export async function readPointsFile(file, options = {}) {
  return readPoints(fileEntry(file).data, { name: file, ...options });
}

/** readKittiBin on a file path. */
export async function readKittiBinFile(file) {
  return readKittiBin(fileEntry(file).data, { name: file });
}

const isDir = (p) => fs.existsSync(p) && fs.statSync(p).isDirectory();
const listFiles = (dir) =>
  fs
    .readdirSync(dir, { withFileTypes: true })
    .filter((e) => e.isFile())
    .map((e) => path.join(dir, e.name));

/**
 * A KITTI sequence at `dir`, in the layouts the CLI reads: a dataset root
 * (`sequences/NN/velodyne/`, with `options.sequence`), a sequence folder
 * (`velodyne/`, `calib.txt`, poses in `poses.txt` or `../../poses/NN.txt`),
 * or a flat folder of NNNNNN.bin and poses.txt (LiDAR poses). Options as
 * findKittiSequence's; `poses` and `calib` may be paths.
 */
export async function openKittiSequence(dir, options = {}) {
  if (!isDir(dir)) throw new Error(`polyscene/io: ${dir}: not a directory`);
  const opts = { ...options };
  for (const key of ['poses', 'calib']) {
    if (typeof opts[key] === 'string' && !opts[key].includes('\n') && fs.existsSync(opts[key])) {
      opts[`${key}Name`] ??= opts[key];
      opts[key] = fileEntry(opts[key]).data;
    }
  }
  const files = [];
  const root = path.join(dir, 'sequences');
  if (isDir(root)) {
    const ids = fs.readdirSync(root).filter((n) => isDir(path.join(root, n))).sort();
    const id = opts.sequence ?? (ids.length === 1 ? ids[0] : undefined);
    if (id === undefined) throw new Error(`polyscene/io: ${dir}: a KITTI dataset root: pick a sequence with { sequence: ID } (found ${ids.join(', ') || 'none'})`);
    if (!ids.includes(id)) throw new Error(`polyscene/io: ${path.join(root, id)}: no such sequence (found ${ids.join(', ') || 'none'})`);
    const seq = path.join(root, id);
    files.push(...listFiles(seq));
    if (isDir(path.join(seq, 'velodyne'))) files.push(...listFiles(path.join(seq, 'velodyne')));
    const poses = path.join(dir, 'poses', `${id}.txt`);
    if (fs.existsSync(poses)) files.push(poses);
  } else {
    files.push(...listFiles(dir));
    if (isDir(path.join(dir, 'velodyne'))) {
      files.push(...listFiles(path.join(dir, 'velodyne')));
      // A sequence folder of a dataset root: ROOT/sequences/NN, poses in ROOT/poses/NN.txt.
      const abs = path.resolve(dir);
      const poses = path.join(abs, '..', '..', 'poses', `${path.basename(abs)}.txt`);
      if (path.basename(path.dirname(abs)) === 'sequences' && fs.existsSync(poses)) files.push(poses);
    }
  }
  delete opts.sequence;
  return findKittiSequence(
    files.filter((f) => /(\.bin|\.txt)$/.test(f)).map((f) => fileEntry(f)),
    opts,
  );
}
