// Types of polyscene/io/node (js/io-node.mjs): polyscene/io on file paths.
import type { KittiSequence, KittiSequenceOptions, PointCloud, ReadOptions } from './io.mjs';

/** readPoints on a file path (the path names the file in errors). */
export function readPointsFile(path: string, options?: ReadOptions): Promise<PointCloud>;

/** readKittiBin on a file path. */
export function readKittiBinFile(path: string): Promise<PointCloud & { stride: 4; points: Float32Array }>;

/**
 * A KITTI sequence at `dir`: a dataset root (`sequences/NN/velodyne/`, pick
 * NN with `sequence`), a sequence folder (`velodyne/`, `calib.txt`), or a
 * flat folder of NNNNNN.bin with poses.txt (LiDAR poses). `poses` and
 * `calib` may be file paths. Scans are read one at a time.
 */
export function openKittiSequence(
  dir: string,
  options?: Partial<Omit<KittiSequenceOptions, 'scans'>> & { sequence?: string },
): Promise<KittiSequence>;
