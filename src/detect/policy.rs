//! Which of the cascade's rules apply: one-shot detection and the
//! scenario's detection on each scan's leftovers differ in fourteen of them
//! (thirteen while the scenario's map is empty,
//! [`CascadePolicy::on_empty_map`]), and in one more when the scenario's
//! pool is in play ([`CascadePolicy::pooled`]).

/// The rule set of one detection cascade. The parameters ([`Params`])
/// say how much (distances, areas, budgets); the policy says which rules
/// run. [`CascadePolicy::one_shot`] is the full set, for a whole cloud;
/// [`CascadePolicy::scenario_leftovers`] is the paper's cascade, for the
/// points a scan's expansion left (about a tenth of a scan, mostly
/// clutter), where a band lost in one scan comes back with the next.
///
/// [`Params`]: crate::params::Params
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CascadePolicy {
    /// RANSAC never tries a plane through the viewpoint unless the sensor
    /// stands on it: such a plane holds the laser rings at the sensor's
    /// height, and a band of every surface it crosses would leave play with
    /// it. (Candidates through the viewpoint are rejected under every
    /// policy.)
    pub skip_edge_on_hypotheses: bool,
    /// RANSAC draws no sliver triples (three points almost in a line fix a
    /// line, not a plane, and the noise across it tilts the plane at
    /// random).
    pub reject_slivers: bool,
    /// RANSAC draws all three points of a triple from one voxel
    /// (`sampleRadius`), never from across the cloud when the voxel is
    /// sparse ([`PlanePool::local_triples`](super::ransac::PlanePool::local_triples)).
    pub local_triples: bool,
    /// Hypotheses scored per round: `maxHypotheses` times this.
    pub hypothesis_scale: usize,
    /// The ground's clustering tolerance grows with range beyond
    /// `groundClusterRange`, as the gaps between laser rings do; so do the
    /// gaps a riser's evidence may leave (`riser::Spacing`).
    pub range_pulled_ground: bool,
    /// Ground footprints fill the gaps between laser rings that the
    /// range-pulled clustering bridged, so the outline follows every ring
    /// the clustering joined.
    pub bridge_ring_gaps: bool,
    /// Concave outlines leave out the holes of `minArea` or more inside
    /// them, where nothing was seen ([`Footprint::outline_region`](crate::geometry::Footprint::outline_region)):
    /// one cloud is all there is to see. The scenario's outlines keep them
    /// filled: a later scan sees into them, and expansion takes points
    /// only near an outline, so the points seen in a hole went to detection
    /// and, under a drifting pose, came back as a copy of the surface
    /// around it (a duplicate pair on the bench's drifting crossing drive,
    /// seed 1).
    pub cut_holes: bool,
    /// Every cluster of a round's plane with `minInliers` points is judged,
    /// not only the largest: one plane often holds several surfaces (the
    /// sides of cars parked in a row, the facades along a street). Such a
    /// cluster, when rejected, stays in play once (none of its points was
    /// kept so before): it was judged on the band of its surface that a
    /// plane fitted to another one held, and can come back whole with its
    /// own plane.
    pub every_cluster: bool,
    /// Candidates whose plane passes through the viewpoint, away from it,
    /// are rejected as laser rings (see `seen_edge_on`).
    pub reject_edge_on_candidates: bool,
    /// What tells ground from other near-horizontal planes.
    pub ground: GroundBy,
    /// A final pass merges the pieces of one surface that different rounds
    /// or clusters found (with outlines that can merge, see
    /// [`HullKind`](crate::params::HullKind)).
    pub merge_pieces: bool,
    /// A candidate that fails only the roughness test, or passes it with
    /// fewer of its points near its plane than a surface has or seen only
    /// as single laser rings (from one known sensor), is often two
    /// surfaces that one plane holds within the inlier distance: a road and
    /// a plaza 10 cm higher (two parallel layers with a gap between them), a
    /// road and the sidewalk a curb above it under a plane tilted to hold
    /// one at each side, the two faces of a facade bent by a few degrees.
    /// Its dominant layer is judged on its own and the rest stays in play,
    /// instead of the whole candidate leaving play (or a tilted plane over
    /// both being accepted). See `Judge::dominant_layer`.
    pub split_rough_layers: bool,
    /// When `maxRejections` rounds in a row accepted nothing, the points of
    /// every sampling voxel that holds no plane (their spread across the
    /// best-fitting one over 1.5 times the median spread of the supports
    /// accepted so far) leave play,
    /// once, and the cascade goes on. Such a stall comes from planes through
    /// clutter (rows of trunks, poles, bins) that score more than a sparse
    /// far facade or car side and make candidates that fail; the surfaces
    /// behind them then never get a round. Only after a stall: before it,
    /// voxels where two surfaces meet are not planar either.
    pub clear_scattered_on_stall: bool,
    /// Points a round's plane explains nothing with (a rejected candidate,
    /// or all its inliers when no connected patch has `minInliers` points)
    /// leave play, except those on another surface the plane crosses:
    /// points of a sampling voxel whose live points (at least 8) lie on a
    /// plane of their own, as flat as a kept surface (the spread of
    /// [`clear_scattered_on_stall`]), more than 30 degrees off the
    /// round's. A plane that spared any is set aside: no later hypothesis
    /// within 2 degrees and its inlier distance of it is tried. A LiDAR's
    /// rings cross a street's facades and car sides at the same heights
    /// from every pose along it, so a horizontal plane at such a height
    /// holds a band of each, as lines (rejected) or fragments (too small);
    /// without this rule each such round takes those bands out of play,
    /// and sparse facades and car sides end up missed.
    ///
    /// [`clear_scattered_on_stall`]: CascadePolicy::clear_scattered_on_stall
    pub spare_crossing_surfaces: bool,
    /// With [`spare_crossing_surfaces`], a rejected candidate's points are
    /// spared the same way (otherwise only a plane's inliers without a
    /// large enough patch are). Needs the viewpoint: the bands it keeps in
    /// play include the laser rings at the sensor's own height, and without
    /// a viewpoint nothing rejects a horizontal patch they form later.
    ///
    /// [`spare_crossing_surfaces`]: CascadePolicy::spare_crossing_surfaces
    pub spare_rejected: bool,
    /// With [`spare_crossing_surfaces`], a candidate more than half of
    /// whose points lie on other surfaces crossing its plane (by the same
    /// test) is judged again on its other points alone, and when that
    /// fails it is rejected as a plane through their bands (its points
    /// spared, its plane set aside). The bands that sparing keeps in play
    /// can line up with a plane of their own: the edges of a row of parked
    /// cars' roofs and the road beside their feet hold a slab at 48 degrees
    /// that passes every other test. A roof seen at a grazing angle, whose
    /// candidate holds the top rows of the car's sides, keeps its own
    /// points. Off in one-shot detection: there it was more precise on
    /// the own simulator's whole drives, but the crossing drive's mean
    /// error rose from 4.1 to 4.5 mm and the 1.2M-point location seen
    /// from its mean pose took 1.09x the time (BENCHMARKS.md).
    ///
    /// [`spare_crossing_surfaces`]: CascadePolicy::spare_crossing_surfaces
    pub judge_without_crossing_bands: bool,
    /// Candidates that are domes seen from below are rejected: above the
    /// sensor on average, facing down towards it or within 15 degrees of
    /// level, and bent (a quadric
    /// explains more than half of their spread off the plane and turns by
    /// more than 20 degrees across them; `Shaped::domed`). A slab cut from
    /// a tree crown's underside passes every other test. Off in one-shot
    /// detection for now: there each dome rejected is a failed round, the
    /// cascade reaches `maxRejections` sooner: on the bench's crossing
    /// locations seen from their mean pose, precision 0.987 -> 0.994 but 2
    /// of 102 far cars lost (BENCHMARKS.md).
    pub reject_domes: bool,
    /// After the merge pass, the short faces between two near-horizontal
    /// primitives a step apart (curbs, steps) become primitives of their
    /// own where points fill the step, or join a primitive on their plane
    /// whose outline they meet (see the `riser` module): such a face
    /// is narrower than `minWidth` and the two surfaces' inlier slabs take
    /// most of its points, so no round finds it.
    pub find_risers: bool,
    /// After the rounds, a second cascade at three times the scale
    /// (clustering tolerance, footprint cell, outline radius, sampling
    /// voxel), with a third of `minInliers`, runs on the points no
    /// primitive explains whose neighbourhood is sparser than one point
    /// per footprint cell (the `coarse` module):
    /// far facades seen along a street, a plateau's top seen from below
    /// its edge. Its primitives keep their coarser footprint and merge
    /// with the first pass's pieces of the same surface. Only for a cloud
    /// seen from nowhere (a map accumulated from many poses, where a
    /// sparse surface was seen sparsely from all of them): in one scan a
    /// sparse surface is a few laser rings, and the coarse outline spans
    /// the gaps between them, where nothing was seen (on the two real
    /// scans its polygons had 26-58 % of their area within 0.2 m of a
    /// point, and the scans' share fell from 0.888 to 0.75).
    pub coarse_pass: bool,
    /// The input holds points thinned to one a `poolVoxel` (the scenario's
    /// pool), so a candidate needs only the points a `minArea` polygon
    /// holds on that grid at `minOccupancy` (75 with the defaults) instead
    /// of `minInliers`, when that is fewer (`pool_support`): at one point
    /// a voxel a surface of `minArea` holds at most 150, and a far car
    /// side, seen a few rings at a time, gathers fewer than `minInliers`
    /// over the pool's scans. Near-horizontal candidates at ground depth
    /// below the sensor still need `minInliers`: far ground is laser
    /// rings seen at a grazing angle, each a line, and a plane fitted to
    /// a few of them tilts (1-3 degrees along the curbs of the independent
    /// bench's crossing drives, where without this exception two plazas
    /// became one polygon across the road between them).
    pub pool_support: bool,
}

/// The least support of a candidate with [`CascadePolicy::pool_support`]:
/// `minInliers`, or the points a `minArea` polygon holds at `minOccupancy`
/// of the pool's grid (one point a `poolVoxel`) when that is fewer; at
/// least 3.
pub(crate) fn pool_support(p: &crate::params::Params) -> usize {
    let capacity = p.min_occupancy * p.min_area / (p.pool_voxel * p.pool_voxel);
    // A float to integer cast saturates (a NaN gives 0).
    p.min_inliers.min(capacity.ceil() as usize).max(3)
}

impl CascadePolicy {
    /// One-shot detection of a whole cloud: every rule, and ground decided
    /// from the cloud's local floor, with or without a viewpoint (a cloud
    /// accumulated over a drive has no one sensor height, and a plateau
    /// or ramp is ground at its own height).
    pub const fn one_shot() -> Self {
        CascadePolicy {
            skip_edge_on_hypotheses: true,
            reject_slivers: true,
            local_triples: true,
            hypothesis_scale: 1,
            range_pulled_ground: true,
            bridge_ring_gaps: true,
            cut_holes: true,
            every_cluster: true,
            reject_edge_on_candidates: true,
            ground: GroundBy::LocalFloor,
            merge_pieces: true,
            split_rough_layers: true,
            clear_scattered_on_stall: true,
            spare_crossing_surfaces: true,
            spare_rejected: true,
            judge_without_crossing_bands: false,
            reject_domes: false,
            find_risers: true,
            coarse_pass: false,
            pool_support: false,
        }
    }

    /// The same rules for a cloud seen from no known position (a map, a
    /// tile): none of the rules that need the viewpoint, and the coarse
    /// pass for the surfaces seen sparsely from every pose.
    pub const fn without_viewpoint(self) -> Self {
        CascadePolicy {
            skip_edge_on_hypotheses: false,
            range_pulled_ground: false,
            bridge_ring_gaps: false,
            reject_edge_on_candidates: false,
            spare_rejected: false,
            ground: GroundBy::LocalFloor,
            coarse_pass: true,
            ..self
        }
    }

    /// For a cloud gathered from known sensor positions
    /// ([`detect_from`](super::detect_from)): candidates seen edge-on from
    /// every one of them are rejected as laser rings; the other rules stay
    /// as they are.
    pub const fn seen_from_all(self) -> Self {
        CascadePolicy {
            reject_edge_on_candidates: true,
            ..self
        }
    }

    /// The paper's cascade, as the scenario runs it on the points its
    /// primitives did not explain and on its pool of earlier leftovers:
    /// the largest cluster of each round's plane, fixed clustering
    /// tolerances, twice the hypotheses, no merge pass (the scenario merges
    /// with its own primitives afterwards), no split of rough candidates
    /// into layers but on a scan that meets an empty map
    /// ([`on_empty_map`](CascadePolicy::on_empty_map); on every scan's
    /// leftovers it left a duplicate pair on the bench's drifting drives).
    /// The sampler draws no sliver
    /// triples: the pool holds laser rings of many scans, thinned to a
    /// voxel grid, and three points of one ring fix a line, not a plane.
    /// Judging every cluster there measured less precise and less
    /// accurate, and the growing ground tolerance neutral (BENCHMARKS.md).
    /// A stalled cascade clears the voxels that hold no plane, as one-shot
    /// detection does: the pool holds the tree crowns and other clutter of
    /// the last scans, horizontal planes through them (1,000-2,500
    /// inliers, no patch of `minInliers`) took the ten rounds, and the far
    /// car sides the pool held (150-250 points each) never got one.
    /// Crossing surfaces are spared: a round whose plane
    /// has no large enough patch would otherwise take every band of the
    /// far car sides it crosses out of play, and the cascade stops at
    /// `maxRejections` before any round reaches them; a candidate made
    /// mostly of such bands is judged without them
    /// (`judge_without_crossing_bands`). A rejected candidate's points are
    /// not spared (on the own simulator's street drive that made the map
    /// less precise and 4x less accurate). Triples may reach
    /// across the cloud from a sparse voxel, as in the paper's sampler:
    /// with local triples only, one primitive of the simulated street's
    /// first scan came out tilted enough for the second scan's alignment
    /// to turn it (0.037 degrees), and every later scan with it (mean error
    /// 4.9 -> 18 mm); with that turn refused, the pool's local planes found
    /// the undersides of the independent bench's tree crowns (crossing
    /// precision 0.989 -> 0.957; BENCHMARKS.md). No coarse pass: it found
    /// most far cars of the bench's crossing drives but joined rows of
    /// parked cars with their curb into planes (precision 1.000 -> 0.913).
    /// Ground is judged from the scan's pose. Risers are not found here: the scenario finds them
    /// after this detection, between the primitives the scan reached and
    /// from all of the scan's points (a curb's face is mostly explained by
    /// the road's and the sidewalk's expansion, never a leftover), with the
    /// evidence spacing of the scan's sensor (`riser::Spacing`).
    pub const fn scenario_leftovers() -> Self {
        CascadePolicy {
            skip_edge_on_hypotheses: false,
            reject_slivers: true,
            local_triples: false,
            hypothesis_scale: 2,
            range_pulled_ground: false,
            bridge_ring_gaps: false,
            cut_holes: false,
            every_cluster: false,
            reject_edge_on_candidates: true,
            ground: GroundBy::Viewpoint,
            merge_pieces: false,
            split_rough_layers: false,
            clear_scattered_on_stall: true,
            spare_crossing_surfaces: true,
            spare_rejected: false,
            judge_without_crossing_bands: true,
            reject_domes: true,
            find_risers: false,
            coarse_pass: false,
            pool_support: false,
        }
    }

    /// [`CascadePolicy::scenario_leftovers`] for an input that holds
    /// points of the scenario's pool: with
    /// [`pool_support`](CascadePolicy::pool_support). A scan's own
    /// leftovers alone (no pool point in play) need `minInliers`, as in
    /// the paper.
    pub const fn pooled(self) -> Self {
        CascadePolicy {
            pool_support: true,
            ..self
        }
    }

    /// [`CascadePolicy::scenario_leftovers`] for a scan that meets an
    /// empty map, with expansion on (normally the first scan; also the
    /// scans after it while none found a primitive, and the first after an
    /// empty snapshot): expansion explained none of it, so the cascade runs
    /// on a whole scan, and a candidate that may hold two
    /// surfaces is judged on its dominant layer, as in one-shot detection
    /// ([`split_rough_layers`](CascadePolicy::split_rough_layers)).
    /// Without it such a candidate (a road and the plaza a curb above it)
    /// left play whole, roads and plazas with it, in 5 of 12 RANSAC seeds
    /// of `a_first_scan_keeps_roads_and_plazas_a_step_above_them`; on the
    /// independent bench's drifting drives a first scan kept a road plane
    /// tilted 0.6 degrees across a curb, which took in the plaza beside
    /// it, and the map ended with a duplicate pair (BENCHMARKS.md).
    pub const fn on_empty_map(self) -> Self {
        CascadePolicy {
            split_rough_layers: true,
            ..self
        }
    }
}

/// What tells ground from other near-horizontal planes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroundBy {
    /// `groundDepth` below the sensor's height (a sensor on a vehicle).
    Viewpoint,
    /// On the cloud's local floor: the lowest points of each 4 m column,
    /// and up to 0.5 m above them (a curb, a sidewalk, a ramp's rise).
    LocalFloor,
}

impl Default for CascadePolicy {
    fn default() -> Self {
        CascadePolicy::one_shot()
    }
}
