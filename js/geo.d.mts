// Types of polyscene/geo (js/geo.mjs).

/** What a polygon is: index 0, 1, 2 of `FlatPolygons.kinds`. */
export type PolygonKind = "ground" | "wall" | "other";

/** The kinds in the order of `FlatPolygons.kinds`. */
export declare const KINDS: readonly ["ground", "wall", "other"];

/** Largest angle between a wall's normal and the horizontal (degrees). */
export declare const WALL_MAX_TILT_DEG: number;

/** A polygon as `scenario.polygons()` and `detect()` return it (the fields this module reads). */
export interface PolygonLike {
  id: number;
  /** Unit normal, world frame. */
  normal: ArrayLike<number>;
  /** Outline x, y, z interleaved (world, m), open ring. */
  vertices: ArrayLike<number>;
  /** Outline area (m^2). */
  area?: number;
  ground?: boolean;
  /** Overrides the kind computed from `ground` and `normal`. */
  kind?: PolygonKind;
  [key: string]: unknown;
}

/** Columns as `scenario.polygonsFlat()` and `detectFlat()` return them. */
export interface FlatPolygonsLike {
  positions: Float64Array;
  ringOffsets: Uint32Array;
  ids: Uint32Array;
  normals: Float64Array;
  areas: Float64Array;
  kinds: Uint8Array;
}

export type Polygons = PolygonLike[] | FlatPolygonsLike;

/**
 * A local frame: world (0, 0, 0) is `origin` (degrees; metres above the
 * WGS84 ellipsoid), z is up, and `heading` is the compass bearing of the
 * world's +x axis, in degrees clockwise from true north (default 90: x east,
 * y north).
 */
export interface LocalFrameSpec {
  origin: { lon: number; lat: number; alt?: number };
  heading?: number;
}

/**
 * A projected CRS: world = map coordinates - offset. `crs`: "EPSG:n" (any
 * code proj4 knows; WGS84 UTM zones 326zz/327zz always), a proj string or WKT.
 */
export interface CrsFrameSpec {
  crs: string;
  offset?: [number, number, number];
}

export interface GeoFrame {
  kind: "local" | "crs";
  /** The frame's specification, with defaults filled in. */
  spec: LocalFrameSpec | CrsFrameSpec;
  /** World metres to [lon, lat, height above the ellipsoid (m)]. */
  toLonLat(x: number, y: number, z?: number): [number, number, number];
  /** [lon, lat, height] to world metres. */
  fromLonLat(lon: number, lat: number, h?: number): [number, number, number];
  /** Metres east / north / up in the frame's horizontal (local: of the origin; crs: easting, northing, height). */
  enu(x: number, y: number, z: number): [number, number, number];
  east(x: number, y: number): number;
  north(x: number, y: number): number;
  up(x: number, y: number, z: number): number;
}

/** A frame for world coordinates; throws a TypeError/RangeError/Error naming a bad field. */
export declare function geoFrame(spec: LocalFrameSpec | CrsFrameSpec): GeoFrame;

/** The kind of a polygon from `ground` and its normal (the core's rule). */
export declare function kindOf(polygon: { ground?: boolean; normal?: ArrayLike<number> }): PolygonKind;

export interface PolygonRow {
  id: number;
  kind: PolygonKind;
  normal: [number, number, number];
  area: number;
  vertices: Float64Array;
  properties: Record<string, unknown>;
}

/** Either input form as one list of rows. */
export declare function polygonRows(polygons: Polygons): PolygonRow[];

/** Area of a planar 3D ring (x, y, z interleaved, open), m^2. */
export declare function ringArea3D(xyz: ArrayLike<number>): number;

export interface PolygonFeature {
  type: "Feature";
  id: number;
  geometry: { type: "Polygon"; coordinates: number[][][] };
  properties: {
    id: number;
    kind: PolygonKind;
    /** The polygon's own area (m^2), walls included. */
    area: number;
    normal?: number[];
    /** Lowest / highest height above the frame's horizontal (m). */
    base?: number;
    top?: number;
    /** Walls in mapFeatures: extrusion height (m). */
    height?: number;
    [key: string]: unknown;
  };
}

export interface PolygonCollection {
  type: "FeatureCollection";
  features: PolygonFeature[];
  polyscene?: { frame: LocalFrameSpec | CrsFrameSpec; coordinates: string };
}

/** GeoJSON (RFC 7946), 3D positions [lon, lat, height], walls as 3D polygons with kind "wall". */
export declare function toGeoJSON(polygons: Polygons, frame: GeoFrame): PolygonCollection;

/**
 * 2D footprints in lon/lat for a map; walls as thin rectangles with base / height (m above
 * `groundHeight`, default the lowest ground vertex) for an extrusion.
 */
export declare function mapFeatures(polygons: Polygons, frame: GeoFrame, options?: { wallThickness?: number; groundHeight?: number }): PolygonCollection;

/** The triangle mesh of `scenario.mesh()`. */
export interface MeshLike {
  positions: Float32Array;
  indices: Uint32Array;
  polygonIds: Uint32Array;
  origin: ArrayLike<number>;
}

/** Binary glTF 2.0 (.glb): one mesh per polygon, +y up, +x east, -z north. */
export declare function toGLB(mesh: MeshLike, polygons?: Polygons | null, frame?: GeoFrame | null): Uint8Array;
