// Types of polyscene/io (js/io.mjs).

/** Bytes of a file: what a file input, fetch() or fs.readFile give. */
export type Bytes = ArrayBuffer | ArrayBufferView | Blob;

/** Text of a small file (poses, calib): a string, its bytes or a File. */
export type Text = string | ArrayBuffer | ArrayBufferView | Blob;

/** A file's format, as told by its header ("raw": no header, float32). */
export type PointFormat = "las" | "laz" | "pcd" | "ply" | "raw" | "kitti-bin";

/** The coordinate reference system of a LAS file (its LASF_Projection records). */
export interface LasCrs {
  /** What polyscene/geo's `geoFrame({ crs })` takes: "EPSG:n" when a code is known, else the WKT. */
  definition: string;
  /** EPSG code of the GeoTIFF keys (ProjectedCSTypeGeoKey, else GeographicTypeGeoKey). */
  epsg?: number;
  /** EPSG code of the vertical CRS (VerticalCSTypeGeoKey). */
  verticalEpsg?: number;
  /** OGC WKT record (2112), as written. */
  wkt?: string;
  /** EPSG code of the WKT's own AUTHORITY / ID, when there are no GeoTIFF keys. */
  wktEpsg?: number;
  /** GeoAsciiParamsTag text (34737). */
  citation?: string;
  /** The GeoTIFF keys whose value is in the key directory: key id -> value. */
  geoKeys?: Record<number, number>;
}

/** The points of a file, ready for `detect(points, { stride })` or `scenario.addScan(points, { stride, pose })`. */
export interface PointCloud {
  /**
   * Interleaved x, y, z[, intensity] in metres, `stride` values a point:
   * float32 where the file holds float32, float64 where it holds float64 or
   * integers (LAS: x * scale + offset).
   */
  points: Float32Array | Float64Array;
  /** Values a point: 3 (x, y, z) for files with a header; 4 for KITTI .bin (x, y, z, reflectance), or the given stride for raw files. */
  stride: 3 | 4;
  /** Number of points (PCD: NaN points, PCL's "no return", are left out). */
  count: number;
  format: PointFormat;
  /** The file's name, when known. */
  name?: string;
  /** LAS/LAZ: the CRS, when the file has one. */
  crs?: LasCrs;
}

/** A scan of a KITTI sequence: its points and its world-from-LiDAR pose. */
export interface KittiScan extends PointCloud {
  stride: 4;
  points: Float32Array;
  /** World-from-LiDAR pose, column-major 4x4 (the layout `addScan` takes). */
  pose: Float64Array;
  /** The scan number (its file name, its line in the poses file). */
  number: number;
}

export interface ReadOptions {
  /** Names the file in errors (a File's own name is used otherwise). */
  name?: string;
  /** Values a point of a raw float32 file (no header): 3 or 4. No default: a raw file without it is an error. */
  stride?: 3 | 4;
}

/**
 * The points of a point file: LAS/LAZ (through @loaders.gl/las, loaded on
 * first use), PCD (ascii, binary, binary_compressed) or PLY (ascii, binary
 * little/big-endian) by their header, or raw little-endian float32 with
 * `options.stride`. Rejects with an Error naming the file and the problem.
 */
export function readPoints(input: Bytes, options?: ReadOptions): Promise<PointCloud>;

/** One KITTI .bin scan (float32 x, y, z, reflectance: stride 4); a file with a header, or whose size is not a multiple of 16 bytes, is refused. */
export function readKittiBin(input: Bytes, options?: { name?: string }): Promise<PointCloud & { stride: 4; points: Float32Array }>;

/** The format of a file from its first bytes; throws on headers of formats not read and on text files. */
export function sniffFormat(head: Uint8Array | ArrayBuffer, name?: string): "las" | "pcd" | "ply" | "raw";

/** KITTI poses (12 numbers a line, row-major 3x4) as column-major 4x4s; each checked to be rigid. */
export function parseKittiPoses(text: string, options?: { name?: string }): Float64Array[];

/** KITTI calibration: Tr (LiDAR to camera 0) from `Tr:` (or `Tr_velo_to_cam:`), or `R:` and `T:`, column-major 4x4. */
export function parseKittiCalib(text: string, options?: { name?: string }): Float64Array;

/** World-from-LiDAR poses `Tr^-1 . P . Tr` from KITTI's camera-0 poses and calib's Tr. */
export function kittiLidarPoses(cameraPoses: ArrayLike<number>[], tr: ArrayLike<number>): Float64Array[];

/** A scan file: a File (its name or webkitRelativePath), or a name or path with its bytes. */
export type ScanEntry = Blob & { name: string } | { name: string; data: Bytes } | { path: string; data: Bytes };

export interface KittiSequenceOptions {
  /** The scans, NNNNNN.bin (the scan number; directories in a path are ignored). */
  scans: Iterable<ScanEntry>;
  /** poses/NN.txt: camera-0 poses (or world-from-LiDAR with `lidarPoses`), line k for scan k. */
  poses: Text;
  /** calib.txt, whose Tr maps LiDAR to camera 0. Needed unless `lidarPoses`. */
  calib?: Text;
  /** The poses are world-from-LiDAR already: no calib, no conversion. Default false. */
  lidarPoses?: boolean;
  /** Replay the scans that are there when numbers are missing. Default false (a gap is an error). */
  skipMissing?: boolean;
  /** Leave out empty (0-byte) scans. Default false (an empty scan is an error). */
  skipEmpty?: boolean;
  /** Names the poses file in errors (a File's own name is used otherwise). */
  posesName?: string;
  /** Names the calibration file in errors. */
  calibName?: string;
}

/** A KITTI sequence: its scans and their LiDAR poses; the points are read one scan at a time. */
export interface KittiSequence extends AsyncIterable<KittiScan> {
  /** Number of scans (empty ones left out with `skipEmpty` are not counted). */
  readonly length: number;
  readonly scans: { number: number; name: string }[];
  readonly skippedEmpty: { number: number; name: string }[];
  /** World-from-LiDAR pose of each scan (column-major 4x4), in the frame of the LiDAR at scan 0. */
  readonly poses: Float64Array[];
  /** The calibration's Tr the poses were converted with; undefined with `lidarPoses`. */
  readonly calib: Float64Array | undefined;
  /** Scan `index` (0 to length - 1): its points and pose. */
  read(index: number): Promise<KittiScan>;
}

/** Open a KITTI sequence from its parts; rejects on a missing calib, a missing or extra scan number, or poses that do not match. */
export function kittiSequence(options: KittiSequenceOptions): Promise<KittiSequence>;

/** A file of a folder: a File from a directory pick (webkitRelativePath), or a path with its bytes or text. */
export type FolderEntry = File | { path: string; data: Bytes | string };

/**
 * Find a KITTI sequence among a folder's files (KITTI's layout:
 * sequences/NN/velodyne/, poses/NN.txt or sequences/NN/poses.txt,
 * sequences/NN/calib.txt; or a flat folder of NNNNNN.bin with poses.txt of
 * LiDAR poses) and open it.
 */
export function findKittiSequence(
  files: Iterable<FolderEntry>,
  options?: Partial<KittiSequenceOptions> & { sequence?: string },
): Promise<KittiSequence>;
