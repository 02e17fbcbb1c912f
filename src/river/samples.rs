//! Which rivers influence a patch (6.3) and their samples at the patch's level of detail (6.4), in the patch's
//! frame: the face plane, relative to the patch corner, scaled by the radius, so that vertex (i, j) sits at
//! `(i, j) * spacing` as the kernel expects.

use glam::{DVec2, DVec3};

use super::{
    hull,
    network::RiverNetwork,
    system::{subdivide, RiverSystem, Segment, MAX_DEPTH},
};
use crate::{
    planet::cube::{self, PatchId},
    shader_types::RiverSample,
};

/// A patch's 2D frame.
#[derive(Clone, Copy, Debug)]
pub struct PatchFrame {
    /// The patch.
    pub patch: PatchId,
    /// The planet's radius.
    pub radius: f64,
    /// Vertices per patch edge.
    pub vertices: u32,
}

impl PatchFrame {
    /// The frame of `patch` on a planet of `radius` with `vertices` per patch edge.
    pub fn new(patch: PatchId, radius: f64, vertices: u32) -> Self {
        Self {
            patch,
            radius,
            vertices,
        }
    }

    /// World units between neighbouring vertices, in the face plane.
    pub fn spacing(&self) -> f64 {
        self.patch.size() / (self.vertices - 1) as f64 * self.radius
    }

    /// The patch-frame position of a direction (projected onto the patch's face plane).
    pub fn to_patch(&self, d: DVec3) -> DVec2 {
        let (_, u, v) = cube::face_of_on(self.patch.face as usize, d);
        let (u0, v0) = self.patch.origin();
        DVec2::new(u - u0, v - v0) * self.radius
    }

    /// The patch's outline in a river frame, or `None` if it is not in the frame's hemisphere.
    fn outline_in(&self, system: &RiverSystem) -> Option<Vec<DVec2>> {
        let [a, b, c, d] = self.patch.corners();
        // Counter-clockwise: (0,0), (1,0), (1,1), (0,1).
        [a, b, d, c]
            .iter()
            .map(|p| system.frame.to_plane(*p))
            .collect()
    }
}

/// Section 6.3: whether `system`'s extended hull meets the patch.
pub fn influences(system: &RiverSystem, frame: &PatchFrame) -> bool {
    let cap = PatchCap::of(frame);
    cap.meets(system, frame, cap.bound(system.cap_angle))
}

/// The cap around a patch's centre that holds the patch: the first, cheap test of every system against the
/// patch, computed once per patch rather than once per system (its corners' angles were most of the time a
/// patch's samples took on a planet of a few thousand systems).
#[derive(Clone, Copy)]
struct PatchCap {
    centre: DVec3,
    angle: f64,
}

impl PatchCap {
    fn of(frame: &PatchFrame) -> Self {
        Self {
            centre: frame.patch.center(),
            angle: frame.patch.cap_angle(),
        }
    }

    /// A quicker first test for `systems`, none of whose caps is wider than `widest` (radians): the cosine of
    /// the angle beyond which none of them can meet this cap, less a margin for rounding, or -2 (no such angle).
    /// A dot product against it passes every system the exact angle passes, and rejects most of a planet's
    /// systems without the arc tangent.
    fn bound(&self, widest: f64) -> f64 {
        let reach = widest + self.angle;
        if reach < std::f64::consts::PI {
            reach.cos() - 1e-9
        } else {
            -2.0
        }
    }

    /// Whether `system`'s extended hull meets the patch of `frame` (this cap's), with `bound` from
    /// [`PatchCap::bound`] of a cap at least as wide as the system's.
    fn meets(&self, system: &RiverSystem, frame: &PatchFrame, bound: f64) -> bool {
        let centre = system.frame.centre;
        if centre.dot(self.centre) < bound * centre.length() * self.centre.length() {
            return false;
        }
        if cube::angle(centre, self.centre) > system.cap_angle + self.angle {
            return false;
        }
        frame
            .outline_in(system)
            .is_some_and(|outline| hull::intersects(&system.extended, &outline))
    }
}

/// The widest cap of `systems`.
fn widest(systems: &[RiverSystem]) -> f64 {
    systems.iter().map(|s| s.cap_angle).fold(0.0, f64::max)
}

/// The systems that influence a patch: the network's, and the streams a patch of its level draws.
pub fn influencing<'a>(
    network: &'a RiverNetwork,
    frame: &'a PatchFrame,
) -> impl Iterator<Item = &'a RiverSystem> {
    let cap = PatchCap::of(frame);
    let bound = cap.bound(widest(&network.systems));
    let rivers = network
        .systems
        .iter()
        .filter(move |s| cap.meets(s, frame, bound));
    let streams = network.streams.iter().flat_map(move |level| {
        let bound = cap.bound(widest(&level.systems));
        level
            .systems
            .iter()
            .filter(move |s| drawn_on(level.level, s, frame) && cap.meets(s, frame, bound))
    });
    rivers.chain(streams)
}

/// Whether a patch draws the streams of `level` in `system`: from their level on, once its vertices lie no
/// further apart than the streams' influence distance. A coarser patch would carve a stream's valley into the odd
/// vertex that happens to lie within its reach, a pit where no valley shows.
fn drawn_on(level: u32, system: &RiverSystem, frame: &PatchFrame) -> bool {
    frame.patch.level as u32 >= level && frame.spacing() <= system.reach as f64
}

/// Whether streams the patch does not draw yet reach it: then its descendants get samples it has not.
fn finer_streams_reach(network: &RiverNetwork, frame: &PatchFrame) -> bool {
    let cap = PatchCap::of(frame);
    network.streams.iter().any(|level| {
        let bound = cap.bound(widest(&level.systems));
        level
            .systems
            .iter()
            .any(|s| !drawn_on(level.level, s, frame) && cap.meets(s, frame, bound))
    })
}

/// A patch's river samples, and whether they are the rivers' final detail.
#[derive(Clone, Debug, Default)]
pub struct PatchSamples {
    /// The samples whose influence reaches the patch.
    pub samples: Vec<RiverSample>,
    /// Whether every piece these samples come from is as fine as any level subdivides it (at [`MAX_DEPTH`] or
    /// no longer than [`sample_step`]) and sampled [`sample_step`] apart. Then every descendant patch gets the
    /// same samples within its reach, so its river data equals the parent's where their vertices coincide: the
    /// condition for taking them from the parent (10.2).
    pub final_detail: bool,
}

/// Section 6.4: the samples of every river influencing the patch, with each river brought to the patch's level
/// of detail: pieces are subdivided until their control polygon is at most four vertex spacings long. Samples
/// lie at most `width / (2 x samples-per-half-width)` apart along each piece (measured in the patch frame), and
/// only samples that can reach the patch are kept.
pub fn patch_samples(network: &RiverNetwork, frame: &PatchFrame) -> PatchSamples {
    let mut out = Vec::new();
    let mut final_detail = true;
    for system in influencing(network, frame) {
        let Some(outline) = frame.outline_in(system) else {
            continue;
        };
        // Pieces no shorter than the samples on them are apart: a shorter one still gets a sample of its own, so
        // near a deep patch (2 cm between vertices) millions of pieces would give millions of samples.
        // A sample matters if it is within reach of the patch; the factor 2 covers the face plane's stretch.
        let reach = 2.0 * network.influence_distance;
        let mut stack: Vec<Segment> = system.segments.iter().rev().copied().collect();
        while let Some(piece) = stack.pop() {
            let control = piece.curve.control_points();
            let centre = (control[0] + control[1] + control[2] + control[3]) / 4.0;
            let spread = control
                .iter()
                .map(|c| c.distance(centre))
                .fold(0.0, f64::max);
            let length = piece.polygon_length();
            let bound = spread
                + network.params.descendant_margin(length)
                + piece.widths.0.max(piece.widths.1) as f64;
            if hull::distance(&outline, centre) > bound + reach {
                continue;
            }
            let target = (4.0 * frame.spacing()).max(sample_step(network, piece.narrowest()));
            if length <= target || piece.depth >= MAX_DEPTH {
                let step = sample_step(network, piece.narrowest());
                final_detail &= (length <= step || piece.depth >= MAX_DEPTH)
                    && sample_floor(network, frame) <= step;
                emit(network, system, frame, &outline, &piece, reach, &mut out);
            } else {
                let (children, tributary) = subdivide(&piece, &network.params);
                if let Some(t) = tributary {
                    stack.push(t);
                }
                stack.extend(children.into_iter().rev());
            }
        }
    }
    PatchSamples {
        samples: out,
        final_detail: final_detail && !finer_streams_reach(network, frame),
    }
}

/// The samples of `piece` within reach of the patch outline.
fn emit(
    network: &RiverNetwork,
    system: &RiverSystem,
    frame: &PatchFrame,
    outline: &[DVec2],
    piece: &Segment,
    reach: f64,
    out: &mut Vec<RiverSample>,
) {
    out.extend(
        piece_samples(network, system, frame, piece)
            .filter(|(p, s)| hull::distance(outline, *p) <= reach + s.width.abs() as f64)
            .map(|(_, s)| s),
    );
}

/// The distance between samples along a river of `width` (6.4): half the prescribed `width / (2 x
/// samples-per-half-width)` in the river frame, because the patch frame can stretch up to 1.8 times more along the
/// flow than across it.
pub fn sample_step(network: &RiverNetwork, width: f64) -> f64 {
    width / (2.0 * network.samples_per_half_width as f64) * 0.5
}

/// The least distance between samples on a patch: the vertex spacing / `samples-per-vertex-spacing` (0: none,
/// as the thesis).
fn sample_floor(network: &RiverNetwork, frame: &PatchFrame) -> f64 {
    match network.samples_per_vertex_spacing {
        0 => 0.0,
        k => frame.spacing() / k as f64,
    }
}

/// Samples of one piece over t in [0, 1) (the next piece starts where this one ends), each with its river-frame
/// position, [`sample_step`] apart; with `samples-per-vertex-spacing` set, at least that share of the patch's
/// vertex spacing apart (beyond the thesis).
pub fn piece_samples<'a>(
    network: &'a RiverNetwork,
    system: &'a RiverSystem,
    frame: &'a PatchFrame,
    piece: &'a Segment,
) -> impl Iterator<Item = (DVec2, RiverSample)> + 'a {
    let floor = sample_floor(network, frame);
    let transform = move |p: DVec2| frame.to_patch(system.frame.to_sphere(p));
    let h = 1e-3 * network.influence_distance;
    let mut t = 0.0;
    std::iter::from_fn(move || {
        if t >= 1.0 {
            return None;
        }
        let p = piece.curve.point(t);
        let d = piece.curve.derivative(t);
        let width = piece.width_at(t) as f64;
        let speed = d.length().max(1e-9);
        // Direction and width through the map from river frame to patch frame, by central differences.
        let along = d / speed;
        let across = along.perp();
        let position = transform(p);
        let derivative = (transform(p + along * h) - transform(p - along * h)) / (2.0 * h) * speed;
        let stretch = (transform(p + across * h) - transform(p - across * h)).length() / (2.0 * h);
        let sample = RiverSample::new(
            position.as_vec2().to_array(),
            derivative.as_vec2().to_array(),
            piece.height_at(t),
            // A lake's samples say what they are by a negative width (RiverSample).
            (width * stretch) as f32 * if piece.lake { -1.0 } else { 1.0 },
        )
        .with_reach(system.reach)
        .on_river(piece.river);
        t += sample_step(network, width).max(floor) / speed;
        Some((p, sample))
    })
}

/// One branch (main river or tributary) of a system as a polyline on the unit sphere.
#[derive(Clone, Debug)]
pub struct Branch {
    /// The branch's key (its segments' `branch`).
    pub key: u64,
    /// The branch this one flows into (`None` for the main river).
    pub parent: Option<u64>,
    /// The full width at its first and its last point.
    pub widths: (f32, f32),
    /// Unit directions, upstream first.
    pub points: Vec<DVec3>,
}

/// Every branch of a system at `depth`, for drawing and GeoJSON; the main river first.
pub fn polylines(network: &RiverNetwork, system: &RiverSystem, depth: u32) -> Vec<Branch> {
    let pieces = super::system::pieces_to_depth(&system.segments, depth, &network.params);
    let mut lines: Vec<Branch> = Vec::new();
    for piece in pieces.iter().filter(|p| p.depth == depth) {
        let points = (0..=8).map(|k| system.frame.to_sphere(piece.curve.point(k as f64 / 8.0)));
        match lines.iter_mut().find(|l| l.key == piece.branch) {
            Some(line) => {
                line.widths.1 = piece.widths.1;
                line.points.extend(points.skip(1));
            }
            None => lines.push(Branch {
                key: piece.branch,
                parent: piece.parent_branch,
                widths: piece.widths,
                points: points.collect(),
            }),
        }
    }
    lines
}
