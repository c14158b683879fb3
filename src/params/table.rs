// The pipeline's options, declared once: for each, the flat camelCase key
// of JSON snapshots and the JS options (the snake_case name before `:`),
// its Rust type, where it lives in `Params`, its unit, its valid range and
// its documentation (which gives the default). Included by
// `src/params/mod.rs` (serde form, validation) and by `build.rs` (the
// TypeScript `PipelineOptions`, from which the table of docs/API.md is made).
// The order is the order of the keys in snapshots.
options! {
    /// Inlier distance to a plane for non-ground planes (m). Default 0.10,
    /// below the depth of a door recess.
    distance: f64 = other.distance, "m", Check::Positive(100.0);
    /// Inlier distance for ground planes (m). Default 0.08, below half the
    /// height of a curb, so the road and a sidewalk stay two planes.
    ground_distance: f64 = ground.distance, "m", Check::Positive(100.0);
    /// Largest tilt from horizontal for a plane to count as ground (deg).
    /// Default 15.
    ground_max_tilt: f64 = ground_max_tilt, "deg", Check::Between(0.0, 90.0);
    /// In the scenario, ground lies at least this far below the scan's
    /// sensor (m), measured where it lies; a horizontal plane higher up (a
    /// car's roof, a table) is an ordinary primitive, even fitted a few
    /// degrees off level. One-shot detection decides ground from the local
    /// floor instead. Default 1.3 (sensors on a car roof sit 1.7-2 m up).
    ground_depth: f64 = ground_depth, "m", Check::NonNegative;
    /// Sensor position for one-shot detection (world, m): normals of
    /// non-horizontal planes point towards it, the ground's clustering
    /// tolerance grows with range from it, and a plane through it (seen
    /// edge-on: laser rings) is dropped unless it reaches within 1 m of it.
    /// Ground is decided from the cloud's local floor either way. Default
    /// null: the origin when a sensor could have stood there (a scan in its
    /// own frame), else none (a map: no rules that need a viewpoint, and a
    /// second pass at three times the scale finds the surfaces the map
    /// holds too sparsely for the first). A scenario refuses it: it takes
    /// each scan's sensor position from its pose.
    viewpoint: Option<[f64; 3]> = viewpoint, "m", Check::FiniteOrNull;
    /// Fewest inliers a plane needs, and fewest support points a primitive
    /// needs; the cascade stops when the best plane has fewer. The
    /// scenario's detection on its pool asks for fewer where that holds
    /// fewer points: what a `minArea` polygon holds at `minOccupancy` of
    /// the pool's grid (75 by default), except for near-horizontal planes
    /// well below the sensor. gpp2 default 150, gpp1 400.
    min_inliers: usize = min_inliers, "", Check::Count(3, 100_000_000);
    /// Most plane hypotheses scored per round of one-shot detection (a
    /// bound on work); the scenario's detection on each scan's leftover
    /// points, with the plain sampler, scores up to twice as many. Default
    /// 200.
    max_hypotheses: usize = max_hypotheses, "", Check::Count(1, 1_000_000);
    /// Confidence that the best plane was sampled, for the adaptive stop
    /// (0..1, below 1). Default 0.995.
    confidence: f64 = confidence, "0..1", Check::Open01;
    /// Radius of the neighbourhood the 2nd and 3rd sample points are drawn
    /// from (m). Default 1.0.
    sample_radius: f64 = sample_radius, "m", Check::Positive(1000.0);
    /// Seed of the random generator; same seed, same result. Default 7.
    seed: u64 = seed, "", Check::Any;
    /// Euclidean clustering tolerance of non-ground planes (m): inliers
    /// closer than this (in the plane) are connected. Default 0.5.
    cluster_tolerance: f64 = other.cluster_tolerance, "m", Check::Positive(1000.0);
    /// Euclidean clustering tolerance of ground planes (m), near the
    /// viewpoint; one-shot detection lets it grow beyond
    /// `groundClusterRange`. Default 0.5.
    ground_cluster_tolerance: f64 = ground.cluster_tolerance, "m", Check::Positive(1000.0);
    /// Range (m) beyond which one-shot detection lets the ground's
    /// clustering tolerance grow as the gaps between laser rings do: at
    /// range `r`, `groundClusterTolerance * (r / groundClusterRange)^2`
    /// along the line of sight and about `groundClusterTolerance * r / (2 *
    /// groundClusterRange)` across it; the ground's footprint then fills the
    /// gaps this bridged. Default 20; a value beyond the cloud's extent
    /// turns it off.
    ground_cluster_range: f64 = ground_cluster_range, "m", Check::Positive(1e9);
    /// Convex or concave outlines. Default concave.
    hull: HullKind = hull, "", Check::Any;
    /// Concave outline radius for non-ground primitives (m): gaps and
    /// notches narrower than `2 * alpha` are filled. Default 0.5.
    alpha: f64 = other.alpha, "m", Check::Positive(1000.0);
    /// Concave outline radius for ground primitives (m), seen at grazing
    /// angles with wide gaps between laser rings. Default 1.0.
    ground_alpha: f64 = ground.alpha, "m", Check::Positive(1000.0);
    /// Raster cell size of footprints (m): the resolution of concave
    /// outlines; the occupancy test counts blocks of 2 x 2 cells. Default
    /// 0.2.
    cell: f64 = other.cell, "m", Check::Between(0.01, 100.0);
    /// Raster cell size of ground footprints (m). Default 0.2.
    ground_cell: f64 = ground.cell, "m", Check::Between(0.01, 100.0);
    /// Outline simplification tolerance (m). Default 0.1.
    simplify: f64 = simplify, "m", Check::Between(0.0, 100.0);
    /// Most vertices of an outline; the simplification tolerance is raised
    /// until it fits. Default 256 (a mapped road takes 100-120 at the
    /// default tolerance).
    max_vertices: usize = max_vertices, "", Check::Count(4, 100_000);
    /// Smallest polygon area accepted (m^2), the paper's A_t. gpp2 default
    /// 1.5, gpp1 7.
    min_area: f64 = min_area, "m^2", Check::NonNegative;
    /// Smallest width of a polygon across its narrowest direction (m):
    /// rejects the thin strips a plane cuts out of a crossing surface.
    /// Default 0.4.
    min_width: f64 = min_width, "m", Check::NonNegative;
    /// Largest RMS distance of the support from its plane, as a fraction of
    /// the inlier distance: a real surface sits within the sensor noise,
    /// points spread evenly through the inlier slab (a plane slicing
    /// through objects) give about 0.58. Default 0.45.
    max_roughness: f64 = max_roughness, "", Check::Positive(10.0);
    /// Least share of the support's local patches (cells of `2 * cell`)
    /// whose own normal agrees with the plane's within 15 degrees: a plane
    /// cutting through crossing surfaces collects points whose local
    /// normals are perpendicular to it. Default 0.6.
    min_normal_consistency: f64 = min_normal_consistency, "0..1", Check::Fraction;
    /// Which solidity test to apply. Default occupancy.
    solidity: SolidityKind = solidity, "", Check::Any;
    /// Least support points per m^2 with `solidity: density`. Default 48.
    min_density: f64 = min_density, "", Check::NonNegative;
    /// Least occupied share of the area with `solidity: occupancy` (0..1):
    /// the share of the outline's area in blocks of 2 x 2 footprint cells
    /// that hold support. Default 0.5.
    min_occupancy: f64 = min_occupancy, "0..1", Check::Fraction;
    /// Most primitives one detection returns. gpp2 default 200, gpp1 60.
    max_primitives: usize = max_primitives, "", Check::Count(1, 100_000);
    /// The cascade stops after this many rounds in a row accepted nothing
    /// (what is left is clutter). One-shot detection first takes the
    /// points of voxels that hold no plane out of play and goes on, once.
    /// Default 10.
    max_rejections: usize = max_rejections, "", Check::Count(1, 1_000_000);
    /// Work budget of one detection, in point-to-plane distance evaluations
    /// (about a nanosecond each natively). Default 2e9.
    max_work: u64 = max_work, "", Check::AtLeastOne;
    /// Grow existing primitives with each scan before detecting new ones.
    /// Default true; false gives the paper's "without expansion" mode.
    expansion: bool = expansion, "", Check::Any;
    /// Before expanding, align each scan to the map: a point-to-plane fit
    /// of a sample of its points to the polygons they lie on refines its
    /// pose (rotation about the sensor and translation), in the directions
    /// those polygons pin down. The correction carries over to the next
    /// scan. It catches pose drift of up to `alignReach` a scan; exact
    /// poses are left exactly as given. Needs `expansion`. Default true.
    align_scans: bool = align_scans, "", Check::Any;
    /// Largest pose error a scan's alignment corrects (m, at 10 m from the
    /// sensor for rotations): the first gate of its point-to-plane pairs.
    /// Default 0.3.
    align_reach: f64 = align_reach, "m", Check::Positive(10.0);
    /// Perpendicular gate of expansion, ground (m): at most this, and at
    /// most three times the primitive's own RMS residual (never below
    /// 0.03 m), so a primitive takes what continues it, not the edges of
    /// surfaces crossing it. Default 0.08.
    ground_expand_across: f64 = ground.expand_across, "m", Check::Positive(100.0);
    /// Longitudinal growth reach per step, ground (m). Default 2.0.
    ground_expand_along: f64 = ground.expand_along, "m", Check::Positive(1000.0);
    /// Perpendicular gate of expansion, other primitives (m), adapted to
    /// the primitive's residual like the ground's. Default 0.08.
    expand_across: f64 = other.expand_across, "m", Check::Positive(100.0);
    /// Longitudinal growth reach per step, other primitives (m). Default
    /// 0.6.
    expand_along: f64 = other.expand_along, "m", Check::Positive(1000.0);
    /// Largest angle between two primitives' planes for a merge (deg): the
    /// scenario's after every scan, and one-shot detection's final pass.
    /// Default 8.
    merge_angle: f64 = merge_angle, "deg", Check::Positive(90.0);
    /// Largest RMS distance of the smaller primitive's outline vertices and
    /// centroid from the larger one's plane for a merge of pieces that touch
    /// (m); keep it below the height of a curb. A piece lying over the
    /// other merges within `distance`. Default 0.08.
    merge_distance: f64 = merge_distance, "m", Check::Positive(100.0);
    /// Outlines closer than this are touching, for a merge (m). Default
    /// 0.3.
    merge_gap: f64 = merge_gap, "m", Check::Between(0.0, 100.0);
    /// The scenario keeps the points no primitive explained for this many
    /// scans (the pool), and each scan's detection sees them beside its
    /// own leftovers, so a surface that comes into view a little in each
    /// scan (a far facade, the end of a car, a curb, a ramp at grazing
    /// range) is found once its points add up. 0 turns the pool off (each
    /// scan's detection sees its own leftovers, as in the paper). Default
    /// 20.
    pool_scans: usize = pool_scans, "scans", Check::Count(0, 10_000);
    /// Voxel side of the pool (m): it keeps one point a voxel, the newest,
    /// in a grid anchored at the world origin (and one a voxel of the
    /// curb faces it holds for the riser step). Default 0.1.
    pool_voxel: f64 = pool_voxel, "m", Check::Between(0.01, 10.0);
    /// Most points the pool holds; the oldest go first. Bounds its memory
    /// (32 bytes a point) and the detection time it adds; 0 turns the pool
    /// off. Default 100000.
    pool_max_points: usize = pool_max_points, "", Check::Count(0, 100_000_000);
}
