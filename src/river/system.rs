//! The river-system model both generators build (Chapter 5): a system's 2D frame, its Hermite segments with bed
//! heights and widths (5.1), their subdivision per level of detail with bounded random displacement (5.2.2) and
//! the tributaries it spawns (5.2.3), and the convex hull and extended hull that enclose a system (3.7, 6.3).
//! The thesis's random-walk rivers (network.rs) and the drainage model's reaches (drainage.rs) become these.
//!
//! Each river system lives in its own 2D frame: the gnomonic projection about the system's centre, scaled by the
//! radius. Great circles are straight lines there (so patch edges, which are great circles, stay straight) and
//! distances are world units, exact at the centre and within a few percent over a river.

use glam::{DVec2, DVec3};

use super::{
    hull,
    spline::{rotate, Hermite},
};
use crate::{
    config::{Config, RiverModel},
    drainage::meanders,
    rng::{self, Rng},
};

const STREAM_SUBDIVIDE: u64 = 0x52_0002;
const STREAM_TRIBUTARY: u64 = 0x52_0003;
const STREAM_MEANDER: u64 = 0x52_0004;
/// A piece meanders when its channel holds at most this many half wavelengths (and at least two): pieces shrink
/// five times a level, so the first piece of a river that is short enough holds more than two.
const MOST_MEANDER_HALVES: f64 = 10.0;
/// Knots per meander wavelength of a piece that meanders: Hermite pieces a sixth of a wavelength long, with the
/// course's own directions at their ends, follow the sine-generated curve to a few thousandths of a wavelength.
const KNOTS_PER_WAVELENGTH: f64 = 6.0;
/// Pieces of the first levels of subdivision never meander: a river that would (a wavelength above about a
/// twentieth of its base segment, two lattice cells) swings across a belt wide enough to reach the rivers that
/// join it, whose lattice paths converge on the confluence (the default planet's river view showed loops of a
/// main stem and its tributary overlapping); from this depth on, belts stay within a few hundredths of a cell.
const FIRST_MEANDER_DEPTH: u32 = 2;
/// A meandering piece's wavelength and swing vary by this factor from piece to piece (up to 15 % either way), as
/// real meanders are not a regular wave.
const PIECE_VARIATION: (f64, f64) = (0.85, 1.15);
/// Points along a piece's valley line for its arc length.
const VALLEY_SAMPLES: usize = 64;
/// Tributaries of tributaries at most.
pub const MAX_GENERATION: u32 = 2;
/// Deepest subdivision ever made.
pub const MAX_DEPTH: u32 = 12;

/// A river system's 2D frame (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct RiverFrame {
    /// The unit direction the frame is centred on (the tangent plane touches the sphere there).
    pub centre: DVec3,
    /// The frame's first axis in the tangent plane.
    pub e1: DVec3,
    /// The frame's second axis (`centre x e1`).
    pub e2: DVec3,
    /// The planet's radius: frame coordinates are world units.
    pub radius: f64,
}

impl RiverFrame {
    /// The frame at `centre` whose first axis points towards `towards`, on a sphere of `radius`.
    pub fn new(centre: DVec3, towards: DVec3, radius: f64) -> Self {
        let e1 = (towards - centre * towards.dot(centre)).normalize();
        Self {
            centre,
            e1,
            e2: centre.cross(e1),
            radius,
        }
    }

    /// The frame position of a direction; `None` for directions more than ~84 degrees from the centre.
    pub fn to_plane(&self, d: DVec3) -> Option<DVec2> {
        let c = d.dot(self.centre);
        (c > 0.1).then(|| {
            let q = d / c;
            DVec2::new(q.dot(self.e1), q.dot(self.e2)) * self.radius
        })
    }

    /// The unit direction of a frame position.
    pub fn to_sphere(&self, p: DVec2) -> DVec3 {
        (self.centre + (self.e1 * p.x + self.e2 * p.y) / self.radius).normalize()
    }
}

/// A piece of a river at some depth of subdivision: its curve in the system's frame, and the river-bed height and
/// full width at both ends (linear in between, 5.1).
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    /// The course in the system's frame.
    pub curve: Hermite,
    /// The bed height at the start and at the end.
    pub heights: (f32, f32),
    /// The full width at the start and at the end.
    pub widths: (f32, f32),
    /// Identity of this piece (a hash of its path from the initial segment): all its randomness derives from it.
    pub key: u64,
    /// Subdivision depth (0: an initial segment).
    pub depth: u32,
    /// 0 for the main river, 1 for its tributaries, 2 for theirs.
    pub generation: u32,
    /// Key of the branch (main river or tributary) this piece belongs to, and of the branch it flows into.
    pub branch: u64,
    /// See `branch` (`None` for a main river).
    pub parent_branch: Option<u64>,
    /// Key of the river this piece lies on, from its source to where it ends: a branch's own, except that a
    /// drainage river's main stem keeps its key through the confluences where its tributaries join it. Its samples
    /// carry it ([`crate::shader_types::RiverSample::river`]), so the two rivers of a confluence can be told apart.
    pub river: u64,
    /// A lake's piece (beyond the thesis, docs/rivers.md): its height is the lake's water level, and its samples
    /// put that level on the vertices within half its width, where the terrain below it is drawn under water.
    pub lake: bool,
}

impl Segment {
    /// The bed height at curve parameter `t` (linear between the ends, 5.1).
    pub fn height_at(&self, t: f64) -> f32 {
        self.heights.0 + (self.heights.1 - self.heights.0) * t as f32
    }

    /// The full width at curve parameter `t` (linear between the ends, 5.1).
    pub fn width_at(&self, t: f64) -> f32 {
        self.widths.0 + (self.widths.1 - self.widths.0) * t as f32
    }

    /// The smaller of the widths at the two ends.
    pub fn narrowest(&self) -> f64 {
        self.widths.0.min(self.widths.1) as f64
    }

    /// Length of the Bézier control polygon (at least the curve's length).
    pub fn polygon_length(&self) -> f64 {
        let c = self.curve.control_points();
        c[0].distance(c[1]) + c[1].distance(c[2]) + c[2].distance(c[3])
    }
}

/// The parameters of subdivision, from the configuration.
#[derive(Clone, Copy, Debug)]
pub struct SubdivisionParams {
    /// The planet's master seed: every piece's randomness derives from it and the piece's key.
    pub seed: u64,
    /// Pieces a segment is split into (`segments`).
    pub pieces: u32,
    /// How far an inner knot moves at most, times the segment's length over `pieces` (5.2.2).
    pub displacement: f64,
    /// Probability that a segment spawns a tributary (5.2.3).
    pub tributary_probability: f64,
    /// The narrowest river drawn.
    pub min_width: f32,
    /// Beyond the thesis: with the drainage model on eroded relief, the planet's relief over its radius, against
    /// which a piece's slope sets the swing of the meanders it gets when it is first short enough to hold them
    /// (`meander_knots`); `None` (other models, or `fine-meanders` off): the thesis's random displacement only.
    pub meander_relief_slope: Option<f64>,
}

impl SubdivisionParams {
    /// The parameters of `config` for the planet of `seed`.
    pub fn from_config(config: &Config, seed: u64) -> Self {
        Self {
            seed,
            pieces: config.river.segments.max(2),
            displacement: config.river.displacement as f64,
            tributary_probability: config.river.tributary_probability as f64,
            min_width: config.river.min_width,
            meander_relief_slope: (config.river.model == RiverModel::Drainage
                && config.planet.relief_model.has_valleys()
                && config.river.fine_meanders)
                .then(|| {
                    (config.planet.max_mountain_height - config.planet.sea_level_height) as f64
                        / config.planet.radius as f64
                }),
        }
    }

    /// How far any geometry descending from a piece of control-polygon length `length` (finer pieces and their
    /// tributaries) can stray from the piece's control polygon: a geometric series over the levels below,
    /// doubled for safety.
    pub fn descendant_margin(&self, length: f64) -> f64 {
        2.0 * length * (self.displacement + 1.3) / (self.pieces as f64 - 1.0)
    }
}

/// Section 5.2.2: splits `segment` into `pieces` pieces, moving each inner knot by a random vector of at most
/// `displacement x length / pieces` and turning its tangent by up to 30 degrees. The ends and their tangents stay,
/// and neighbouring pieces share knot and tangent, so the river stays C1. Section 5.2.3: with
/// `tributary-probability`, a tributary joins at a random inner knot. Deterministic per piece: randomness comes
/// from the piece's key only.
///
/// Beyond the thesis (drainage model on eroded relief, docs/rivers.md "Meanders below the base lattice"): the
/// first piece of a river short enough to hold its meanders (`meander_knots`) is split along a sine-generated
/// course instead, so rivers narrower than the base lattice resolves meander at the levels that draw them.
pub fn subdivide(segment: &Segment, params: &SubdivisionParams) -> (Vec<Segment>, Option<Segment>) {
    let (knots, at) = match meander_knots(segment, params) {
        Some(meandering) => meandering,
        None => displaced_knots(segment, params),
    };
    let m = knots.len() as u32 - 1;
    let children: Vec<Segment> = (0..m as usize)
        .map(|k| {
            let (t0, t1) = (at[k], at[k + 1]);
            Segment {
                curve: Hermite {
                    p0: knots[k].0,
                    d0: knots[k].1,
                    p1: knots[k + 1].0,
                    d1: knots[k + 1].1,
                },
                heights: (segment.height_at(t0), segment.height_at(t1)),
                widths: (segment.width_at(t0), segment.width_at(t1)),
                key: rng::hash(segment.key, &[k as u64]),
                depth: segment.depth + 1,
                ..*segment
            }
        })
        .collect();

    let mut trib_rng = Rng::new(params.seed, &[STREAM_TRIBUTARY, segment.key]);
    let spawn = segment.generation < MAX_GENERATION
        && trib_rng.unit() < params.tributary_probability as f32;
    let tributary = spawn.then(|| {
        // The junction is an inner knot in the downstream half, and the tributary about as long as the segment's
        // part upstream of it, so it stays beside its own segment instead of reaching the pieces upstream.
        let k = (m as usize).div_ceil(2) + trib_rng.below(m as u64 / 2) as usize;
        let k = k.min(m as usize - 1);
        let (junction, flow) = knots[k];
        let t = at[k];
        let width = segment.width_at(t);
        let tributary_length = segment.curve.chord() * t * trib_rng.range_f64(0.8, 1.0);
        let widths = (
            (width * 0.4).max(params.min_width),
            (width * 0.6).max(params.min_width),
        );
        // Too short for its width: no tributary (it would be a blob, not a river).
        if tributary_length < 8.0 * widths.1 as f64 {
            return None;
        }
        // The tributary must meet its parent only at the junction: try a few angles and sides, keep the first
        // that stays clear of the (already displaced) parent pieces, or spawn none.
        let parent_points: Vec<DVec2> = children
            .iter()
            .flat_map(|c| (0..=16).map(move |s| c.curve.point(s as f64 / 16.0)))
            .collect();
        let clearance = 0.5 * (width + widths.1) as f64;
        let back = -flow.normalize();
        let start = (0..4).find_map(|_| {
            let sign = if trib_rng.unit() < 0.5 { -1.0 } else { 1.0 };
            let angle = sign * trib_rng.range_f64(22.0, 45.0).to_radians();
            let start = junction + rotate(back, angle) * tributary_length;
            let curve = Hermite {
                p0: start,
                d0: junction - start,
                p1: junction,
                d1: flow.normalize() * tributary_length,
            };
            let clear = (0..=24).all(|s| {
                let p = curve.point(s as f64 / 32.0);
                parent_points.iter().all(|q| q.distance(p) > clearance)
            });
            clear.then_some(start)
        })?;
        let height_end = segment.height_at(t);
        let slope = (segment.heights.0 - segment.heights.1).max(0.0)
            / segment.curve.chord().max(1e-9) as f32;
        let key = rng::hash(segment.key, &[0x7472_6962]);
        Some(Segment {
            curve: Hermite {
                p0: start,
                d0: (junction - start),
                p1: junction,
                d1: flow.normalize() * tributary_length,
            },
            heights: (height_end + slope * tributary_length as f32, height_end),
            widths,
            key,
            depth: segment.depth + 1,
            generation: segment.generation + 1,
            branch: key,
            parent_branch: Some(segment.branch),
            river: key,
            lake: false,
        })
    });
    (children, tributary.flatten())
}

/// The knots of a subdivision (positions and tangents) and the parameters of the parent's curve they stand for.
type Knots = (Vec<(DVec2, DVec2)>, Vec<f64>);

/// Section 5.2.2's knots of `segment` (positions and tangents) and their curve parameters: `pieces` pieces, each
/// inner knot moved by a random vector of at most `displacement x length / pieces` and its tangent turned by up
/// to 30 degrees.
fn displaced_knots(
    segment: &Segment,
    params: &SubdivisionParams,
) -> (Vec<(DVec2, DVec2)>, Vec<f64>) {
    let m = params.pieces;
    let mut rng = Rng::new(params.seed, &[STREAM_SUBDIVIDE, segment.key]);
    let length = segment.polygon_length();
    let at: Vec<f64> = (0..=m).map(|k| k as f64 / m as f64).collect();
    let mut knots: Vec<(DVec2, DVec2)> = at
        .iter()
        .map(|&t| {
            (
                segment.curve.point(t),
                segment.curve.derivative(t) / m as f64,
            )
        })
        .collect();
    for knot in knots.iter_mut().take(m as usize).skip(1) {
        let angle = rng.range_f64(0.0, std::f64::consts::TAU);
        let distance = rng.range_f64(0.0, params.displacement * length / m as f64);
        knot.0 += DVec2::new(angle.cos(), angle.sin()) * distance;
        knot.1 = rotate(knot.1, rng.range_f64(-30.0, 30.0).to_radians());
    }
    (knots, at)
}

/// The wavelength of a river's meanders at `segment` (eleven channel widths; Leopold and Wolman 1960).
pub fn meander_wavelength(segment: &Segment) -> f64 {
    meanders::WAVELENGTH_WIDTHS * 0.5 * (segment.widths.0 + segment.widths.1) as f64
}

/// Beyond the thesis: the knots of `segment` along a sine-generated meandering course about its curve (the
/// valley line; [`meanders::sine_course`]) and the curve parameters they lie across from, where the segment's
/// channel holds two to [`MOST_MEANDER_HALVES`] half wavelengths of its river's meanders, it lies at least
/// [`FIRST_MEANDER_DEPTH`] deep and its slope leaves them a swing: the swing falls with the slope as on the base lattice (`meander_relief_slope`), and the
/// wavelength and swing vary by up to 15 % from piece to piece, and which side the first bend takes, as real
/// meanders do. The course leaves and joins the valley line along it (the ends and their directions stay, so the
/// river stays smooth through its neighbours), and deeper pieces are too short to meander again.
fn meander_knots(segment: &Segment, params: &SubdivisionParams) -> Option<Knots> {
    let relief_slope = params.meander_relief_slope?;
    if segment.lake || segment.depth < FIRST_MEANDER_DEPTH {
        return None;
    }
    let mut rng = Rng::new(params.seed, &[STREAM_MEANDER, segment.key]);
    let wavelength =
        meander_wavelength(segment) * rng.range_f64(PIECE_VARIATION.0, PIECE_VARIATION.1);
    // Too short for two half wavelengths even at the longest it can be (its control polygon's length) and the
    // largest swing: decided without measuring the valley line, which most pieces are (the same answer as below).
    let longest = segment.polygon_length() * (1.0 + 1e-9);
    let widest_swing = meanders::swing_on(0.0) * PIECE_VARIATION.1;
    if meanders::half_wavelengths(longest, wavelength, widest_swing) < 2.0 {
        return None;
    }
    let valley = ValleyLine::new(&segment.curve);
    let length = valley.length();
    let drop = (segment.heights.0 - segment.heights.1).max(0.0) as f64;
    let swing = meanders::swing_on(drop / length.max(f64::MIN_POSITIVE) / relief_slope)
        * rng.range_f64(PIECE_VARIATION.0, PIECE_VARIATION.1);
    let halves = meanders::half_wavelengths(length, wavelength, swing);
    if swing < meanders::MIN_SWING || !(2.0..=MOST_MEANDER_HALVES).contains(&halves) {
        return None;
    }
    let side = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
    // Twice the knots: the points between them give each knot's tangent.
    let course = meanders::sine_course(length, wavelength, swing, 2.0 * KNOTS_PER_WAVELENGTH);
    let at: Vec<f64> = course.iter().map(|&(x, _)| valley.parameter(x)).collect();
    let points: Vec<DVec2> = course
        .iter()
        .zip(&at)
        .map(|(&(_, y), &t)| {
            let along = segment.curve.derivative(t).normalize_or_zero();
            segment.curve.point(t) + DVec2::new(-along.y, along.x) * (side * y)
        })
        .collect();
    let last = points.len() - 1;
    let knots = (0..=last)
        .step_by(2)
        .map(|i| {
            let tangent = match i {
                0 => {
                    segment.curve.derivative(0.0).normalize_or_zero()
                        * 2.0
                        * points[0].distance(points[1])
                }
                i if i == last => {
                    segment.curve.derivative(1.0).normalize_or_zero()
                        * 2.0
                        * points[last - 1].distance(points[last])
                }
                i => points[i + 1] - points[i - 1],
            };
            (points[i], tangent)
        })
        .collect();
    Some((knots, at.into_iter().step_by(2).collect()))
}

/// A segment's curve sampled by arc length, as the valley line its meanders swing about.
struct ValleyLine {
    /// Arc length at each of [`VALLEY_SAMPLES`] + 1 evenly spaced curve parameters.
    lengths: Vec<f64>,
}

impl ValleyLine {
    fn new(curve: &Hermite) -> Self {
        let mut lengths = Vec::with_capacity(VALLEY_SAMPLES + 1);
        lengths.push(0.0);
        let mut previous = curve.point(0.0);
        for k in 1..=VALLEY_SAMPLES {
            let p = curve.point(k as f64 / VALLEY_SAMPLES as f64);
            lengths.push(lengths[k - 1] + p.distance(previous));
            previous = p;
        }
        Self { lengths }
    }

    fn length(&self) -> f64 {
        self.lengths[VALLEY_SAMPLES]
    }

    /// The curve parameter at arc length `x`.
    fn parameter(&self, x: f64) -> f64 {
        let (i, t) = meanders::arc_position(&self.lengths, x);
        (i as f64 + t) / VALLEY_SAMPLES as f64
    }
}

/// A river from a mountain to the sea with all its tributaries.
#[derive(Clone, Debug)]
pub struct RiverSystem {
    /// Its index among the planet's systems (its randomness derives from it).
    pub id: u32,
    /// The 2D frame its curves live in.
    pub frame: RiverFrame,
    /// The initial segments (5.2.1), depth 0.
    pub segments: Vec<Segment>,
    /// Convex hull of every control point of the system down to `hull-levels`, tributaries included (5.2.3).
    pub hull: Vec<DVec2>,
    /// The hull grown by the influence distance and by how far deeper levels can stray (6.3).
    pub extended: Vec<DVec2>,
    /// Unit direction of its main river's source.
    pub source: DVec3,
    /// Unit direction of its main river's mouth.
    pub mouth: DVec3,
    /// Angular radius around `frame.centre` that contains the extended hull.
    pub cap_angle: f64,
    /// Beyond the thesis: the influence distance of its samples (0: `influence-distance`, as the thesis).
    pub reach: f32,
}

/// Every piece of a river system down to `depth`, tributaries included, in a deterministic order.
pub fn pieces_to_depth(
    segments: &[Segment],
    depth: u32,
    params: &SubdivisionParams,
) -> Vec<Segment> {
    let mut out = Vec::new();
    let mut stack: Vec<Segment> = segments.iter().rev().copied().collect();
    while let Some(s) = stack.pop() {
        out.push(s);
        if s.depth < depth {
            let (children, tributary) = subdivide(&s, params);
            if let Some(t) = tributary {
                stack.push(t);
            }
            stack.extend(children.into_iter().rev());
        }
    }
    out
}

/// The finest piece of `segment`'s own branch near `point` (a frame position), subdivided until it is at most
/// `length` long (or [`MAX_DEPTH`] deep): the river as patches of the deepest levels draw it, which meanders away
/// from the coarse curve by the displacements of every subdivision. Descends one child at a time.
pub fn finest_piece_near(
    segment: &Segment,
    point: DVec2,
    length: f64,
    params: &SubdivisionParams,
) -> Segment {
    let mut piece = *segment;
    while piece.depth < MAX_DEPTH && piece.polygon_length() > length {
        let (children, _) = subdivide(&piece, params);
        let distance = |s: &Segment| {
            (0..=8)
                .map(|k| s.curve.point(k as f64 / 8.0).distance(point))
                .fold(f64::MAX, f64::min)
        };
        piece = children
            .into_iter()
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))
            .unwrap_or(piece);
    }
    piece
}

/// The streams one finer level adds, as river systems.
#[derive(Clone, Debug)]
pub struct StreamLevel {
    /// The patch level from which they are drawn.
    pub level: u32,
    /// The streams, as river systems.
    pub systems: Vec<RiverSystem>,
    /// Reaches (from a head or confluence to the next confluence, course or the sea).
    pub reaches: usize,
    /// Time taken to route the level and choose its streams, milliseconds.
    pub ms: f64,
    /// The network drawn down to this level: the base rivers and every level's streams up to this one.
    pub drawn: crate::drainage::drawn::DrawnMeasures,
}

/// A system of `segments` in `frame`: its hull over `hull_levels` levels of subdivision, tributaries included
/// (5.2.3), and the hull extended by the influence distance and by how far deeper levels can stray (6.3).
pub fn enclose(
    config: &Config,
    params: &SubdivisionParams,
    (id, hull_levels): (u32, u32),
    frame: RiverFrame,
    segments: Vec<Segment>,
    (source, mouth): (DVec3, DVec3),
) -> RiverSystem {
    let r = &config.river;
    let pieces = pieces_to_depth(&segments, hull_levels, params);
    let points: Vec<DVec2> = pieces
        .iter()
        .flat_map(|p| p.curve.control_points())
        .collect();
    let hull = hull::convex_hull(&points);
    let margin = pieces
        .iter()
        .filter(|p| p.depth == hull_levels)
        .map(|p| params.descendant_margin(p.polygon_length()) + p.widths.0.max(p.widths.1) as f64)
        .fold(0.0, f64::max);
    let extended = hull::extend(&hull, r.influence_distance as f64 + margin);
    let cap_angle = extended
        .iter()
        .map(|p| frame.to_sphere(*p).angle_between(frame.centre))
        .fold(0.0, f64::max);
    RiverSystem {
        id,
        frame,
        segments,
        hull,
        extended,
        source,
        mouth,
        cap_angle,
        reach: 0.0,
    }
}

/// Whether two systems' convex hulls overlap (5.2.1), compared in the first system's frame.
pub fn hulls_meet(a: &RiverSystem, b: &RiverSystem) -> bool {
    if a.frame.centre.angle_between(b.frame.centre) > a.cap_angle + b.cap_angle {
        return false;
    }
    let other: Option<Vec<DVec2>> = b
        .hull
        .iter()
        .map(|p| a.frame.to_plane(b.frame.to_sphere(*p)))
        .collect();
    other.is_none_or(|o| hull::intersects(&a.hull, &o))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight piece along x, `length` long and `width` wide, falling by `drop`.
    fn straight(length: f64, width: f32, drop: f32) -> Segment {
        let along = DVec2::new(length, 0.0);
        Segment {
            curve: Hermite {
                p0: DVec2::ZERO,
                d0: along,
                p1: along,
                d1: along,
            },
            heights: (drop, 0.0),
            widths: (width, width),
            key: 7,
            depth: FIRST_MEANDER_DEPTH,
            generation: 0,
            branch: 7,
            parent_branch: None,
            river: 7,
            lake: false,
        }
    }

    fn params(meanders: bool) -> SubdivisionParams {
        SubdivisionParams {
            seed: 3,
            pieces: 5,
            displacement: 0.0,
            tributary_probability: 0.0,
            min_width: 1.0,
            meander_relief_slope: meanders.then_some(16.0 / 1024.0),
        }
    }

    /// Length along the pieces' curves over the chord.
    fn sinuosity(pieces: &[Segment]) -> f64 {
        let length: f64 = pieces
            .iter()
            .map(|p| {
                (0..32)
                    .map(|i| {
                        p.curve
                            .point(i as f64 / 32.0)
                            .distance(p.curve.point((i + 1) as f64 / 32.0))
                    })
                    .sum::<f64>()
            })
            .sum();
        let (first, last) = (pieces[0].curve.p0, pieces[pieces.len() - 1].curve.p1);
        length / first.distance(last)
    }

    #[test]
    fn a_gentle_river_narrower_than_its_piece_meanders_through_it_and_keeps_its_ends() {
        // Three wavelengths of a river 2 wide (wavelength 22) on a slope of a tenth of the relief slope.
        let segment = straight(66.0, 2.0, 16.0 / 1024.0 * 66.0 * 0.1);
        let (children, _) = subdivide(&segment, &params(true));
        assert!(children.len() > 5, "{} pieces", children.len());
        assert!(sinuosity(&children) > 1.25, "{}", sinuosity(&children));
        let (first, last) = (children[0], children[children.len() - 1]);
        assert_eq!(
            (first.curve.p0, last.curve.p1),
            (segment.curve.p0, segment.curve.p1)
        );
        // It leaves and joins along its valley, so it stays smooth through its neighbours.
        assert!(first.curve.d0.normalize().dot(DVec2::X) > 0.9999);
        assert!(last.curve.d1.normalize().dot(DVec2::X) > 0.9999);
        // Neighbouring pieces share knot and direction.
        for w in children.windows(2) {
            assert_eq!(w[0].curve.p1, w[1].curve.p0);
            assert!(w[0].curve.d1.normalize().dot(w[1].curve.d0.normalize()) > 0.9999);
        }
        // The belt: within a fifth of a wavelength of the valley.
        let belt = children
            .iter()
            .flat_map(|c| (0..=8).map(move |i| c.curve.point(i as f64 / 8.0).y.abs()))
            .fold(0.0, f64::max);
        assert!(belt < 0.2 * 22.0 * 1.15, "{belt}");
        // Beds never rise, and the pieces it made are too short to meander again.
        assert!(children.iter().all(|c| c.heights.0 >= c.heights.1));
        for c in &children {
            assert_eq!(subdivide(c, &params(true)).0.len(), 5);
        }
    }

    #[test]
    fn steep_rivers_long_pieces_the_first_levels_and_the_thesis_keep_its_subdivision() {
        // A slope of three times the relief slope (a tenth of the flat swing).
        let steep = straight(66.0, 2.0, 3.0 * 16.0 / 1024.0 * 66.0);
        let steep = sinuosity(&subdivide(&steep, &params(true)).0);
        assert!(steep < 1.01, "{steep}");
        // Fifty wavelengths: left to the finer pieces.
        let long = straight(1100.0, 2.0, 0.0);
        assert_eq!(subdivide(&long, &params(true)).0.len(), 5);
        let gentle = straight(66.0, 2.0, 0.0);
        assert!(subdivide(&gentle, &params(true)).0.len() > 5);
        // The first levels of subdivision do not meander, however narrow the river.
        let shallow = Segment {
            depth: FIRST_MEANDER_DEPTH - 1,
            ..gentle
        };
        assert_eq!(subdivide(&shallow, &params(true)).0.len(), 5);
        // Without displacement, the thesis's knots stay on the curve, evenly spaced.
        let (thesis, _) = subdivide(&gentle, &params(false));
        assert_eq!(thesis.len(), 5);
        for (k, piece) in thesis.iter().enumerate() {
            assert!(
                piece
                    .curve
                    .p0
                    .distance(DVec2::new(66.0 * k as f64 / 5.0, 0.0))
                    < 1e-9
            );
        }
    }
}
