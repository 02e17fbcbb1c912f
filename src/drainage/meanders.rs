//! Meanders (beyond the thesis, with the eroded relief; docs/rivers.md, "Meanders"): rivers on gentle slopes
//! wind through their valleys instead of following the lattice's straight steps. A reach's course is a
//! sine-generated curve (Langbein and Leopold 1966), the shape of least total curvature that real meanders take:
//! its direction swings about the valley's by `omega cos(2 pi s / lambda)` along the channel's length s, with a
//! wavelength of eleven channel widths (bend radius about 2.3 widths; Leopold and Wolman 1960) and a swing that
//! grows as the valley's slope falls (Schumm 1963: sinuosity rises on gentler slopes), so steep rivers stay
//! straight. The valley's line is the reach's lattice path smoothed (Catmull-Rom); a reach holds a whole number
//! of half wavelengths (the nearest to eleven widths), so its course crosses the valley line at both ends
//! (confluences and mouths stay where they are), and its belt keeps within a quarter of a base cell of it, so two
//! rivers, whose lattice paths are at least 0.7 cells apart away from their confluences, do not cross; where two
//! courses still would (two valley lines converging on one mouth), both keep their lattice paths.

use glam::DVec3;

use super::ReachPath;

/// Wavelength of meanders in channel widths.
pub const WAVELENGTH_WIDTHS: f64 = 11.0;
/// The swing of the course's direction on a flat valley floor (radians): a sine-generated curve with this swing
/// has a sinuosity of 1 / J0(1.45) = 1.85 (squeezed into the belt, less), a freely meandering lowland river's
/// (Langbein and Leopold 1966 measure swings of 1-2 radians). With 1.25 (1.55) seeds 1-3's median streams measured
/// 1.25-1.28, at the foot of the 1.3-1.6 of real lowland rivers, and seed 1's 1.23 once the coasts gained their
/// finest octave; 1.45 gives 1.32 / 1.37 / 1.32 on seeds 1-3 and 1.34-1.37 on seeds 4-6 (docs/rivers.md,
/// "Meanders").
const FLAT_SWING: f64 = 1.45;
/// The valley slope (drop over run, as a share of the planet's relief over its radius) at which the swing has
/// fallen to half of the flat one. The median order-3 reach of the default planet has 0.22. At 0.5 seed 3's median
/// stream sinuosity was 1.23, below the 1.3-1.6 of real lowland rivers; on the diffused relief with binary
/// junctions (docs/planet.md, "Diffusion while the network forms") 0.7 gave 1.248 / 1.267 / 1.252 on seeds 1-3 and
/// 0.8 gives 1.253 / 1.276 / 1.271; 1.0 gave 1.269 / 1.286 / 1.292, but level 4 then painted the meanders below
/// its spacing too far from level 6's (tests/render.rs).
const HALF_SWING_SLOPE: f64 = 0.8;
/// The curvature at the apex of the tightest meander a river of `half_width` draws (a flat valley's): a
/// sine-generated course turns at most `2 pi swing / wavelength` per unit of length.
pub fn apex_curvature(half_width: f64) -> f64 {
    2.0 * std::f64::consts::PI * FLAT_SWING / (WAVELENGTH_WIDTHS * 2.0 * half_width)
}

/// Courses swinging less than this (radians) stay on their valley line.
pub const MIN_SWING: f64 = 0.05;
/// Meanders shorter than this many base cells are left to the finer levels of detail (the thesis's subdivision).
const SHORTEST_WAVELENGTH_CELLS: f64 = 0.5;
/// Longer wavelengths are shortened to this: the belt must stay within [`BELT_CELLS`].
const LONGEST_WAVELENGTH_CELLS: f64 = 1.5;
/// Half-width of the meander belt at most, in base cells.
const BELT_CELLS: f64 = 0.25;
/// Points of the course per wavelength.
const POINTS_PER_WAVELENGTH: f64 = 12.0;
/// Integration steps per point.
const STEPS_PER_POINT: usize = 4;
/// Valley-line samples per lattice step.
const VALLEY_SAMPLES: usize = 8;

/// What the meanders of a planet depend on.
pub struct MeanderScale {
    /// A base cell, radians.
    pub cell: f64,
    /// The planet's radius (world units per radian).
    pub radius: f64,
    /// Relief over radius: the slope that `HALF_SWING_SLOPE` is a share of.
    pub relief_slope: f64,
}

/// `reach` with its points along its meandering course (first and last point unchanged), beds and areas
/// following the valley (beds never rise), or the reach as it is where it is too steep, too short or too narrow
/// to meander at the base lattice's scale. `width(area)` is a channel's full width in world units.
pub fn meander(reach: &ReachPath, scale: &MeanderScale, width: &impl Fn(f64) -> f64) -> ReachPath {
    let valley = Valley::new(&reach.points);
    let length = valley.length();
    if reach.points.len() < 3 || length <= 0.0 {
        return reach.clone();
    }
    let middle = reach.areas[reach.areas.len() / 2];
    let wavelength = WAVELENGTH_WIDTHS * width(middle) / scale.radius;
    if wavelength < SHORTEST_WAVELENGTH_CELLS * scale.cell {
        return reach.clone();
    }
    let wavelength = wavelength.min(LONGEST_WAVELENGTH_CELLS * scale.cell);
    let drop = (reach.beds[0] - reach.beds[reach.beds.len() - 1]) as f64;
    let swing = swing_on(drop / (length * scale.radius) / scale.relief_slope);
    if swing < MIN_SWING {
        return reach.clone();
    }
    let course = sine_course(length, wavelength, swing, POINTS_PER_WAVELENGTH);
    let widest = course.iter().map(|c| c.1.abs()).fold(0.0, f64::max);
    let squeeze = (BELT_CELLS * scale.cell / widest.max(1e-12)).min(1.0);
    let points: Vec<DVec3> = course
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| {
            if i == 0 {
                return reach.points[0];
            }
            if i == course.len() - 1 {
                return *reach.points.last().expect("not empty");
            }
            let (at, along) = valley.at(x);
            let across = at.cross(along).normalize_or_zero();
            (at + across * y * squeeze).normalize()
        })
        .collect();
    // Beds and areas by the position along the valley, between the lattice nodes around it; the ends exactly the
    // reach's, as its end points are (an interpolated last bed a rounding below it would rise into the next reach).
    let (mut beds, areas): (Vec<f32>, Vec<f64>) = course
        .iter()
        .map(|&(x, _)| {
            let (i, t) = valley.node_at(x);
            let j = (i + 1).min(reach.beds.len() - 1);
            let bed = reach.beds[i] + (reach.beds[j] - reach.beds[i]) * t as f32;
            (bed, reach.areas[i] + (reach.areas[j] - reach.areas[i]) * t)
        })
        .unzip();
    let last = beds.len() - 1;
    (beds[0], beds[last]) = (reach.beds[0], reach.beds[reach.beds.len() - 1]);
    ReachPath {
        points,
        beds: monotone(beds),
        areas,
        strahler: reach.strahler,
        downstream: reach.downstream,
    }
}

/// The reaches of `lattice` with meandering courses ([`meander`]), except that where two courses would cross
/// (near a shared mouth, where two valley lines converge) both keep their lattice paths, which never cross.
pub fn meander_all(
    lattice: &[ReachPath],
    scale: &MeanderScale,
    width: impl Fn(f64) -> f64,
) -> Vec<ReachPath> {
    let mut reaches: Vec<ReachPath> = lattice.iter().map(|r| meander(r, scale, &width)).collect();
    let mut meandering = vec![true; reaches.len()];
    loop {
        // Only meandering reaches can be given back their lattice paths (lattice paths that cross each other,
        // where the routing could not turn a diagonal, stay as they are).
        let crossing: Vec<usize> = crossing_reaches(&reaches)
            .into_iter()
            .filter(|&r| meandering[r])
            .collect();
        if crossing.is_empty() {
            return reaches;
        }
        for r in crossing {
            reaches[r] = lattice[r].clone();
            meandering[r] = false;
        }
    }
}

/// Reaches whose course crosses another's: segments (great-circle arcs) whose ends lie on opposite sides of each
/// other's circle, found through a hash of small cells; segments that share an end (a confluence) do not count.
pub fn crossing_reaches(reaches: &[ReachPath]) -> std::collections::BTreeSet<usize> {
    const CELL: f64 = 0.004;
    let key = |p: DVec3| (p / CELL).floor().as_ivec3();
    let mut cells: std::collections::HashMap<glam::IVec3, Vec<(usize, usize)>> = Default::default();
    for (r, reach) in reaches.iter().enumerate() {
        for i in 0..reach.points.len().saturating_sub(1) {
            let (a, b) = (key(reach.points[i]), key(reach.points[i + 1]));
            cells.entry(a).or_default().push((r, i));
            if b != a {
                cells.entry(b).or_default().push((r, i));
            }
        }
    }
    let segment = |(r, i): (usize, usize)| (reaches[r].points[i], reaches[r].points[i + 1]);
    let mut crossing = std::collections::BTreeSet::new();
    for list in cells.values() {
        for (x, &s) in list.iter().enumerate() {
            for &t in &list[x + 1..] {
                let ((a, b), (c, d)) = (segment(s), segment(t));
                if s.0 == t.0 || a == c || a == d || b == c || b == d {
                    continue;
                }
                let apart = |n: DVec3, p: DVec3, q: DVec3| n.dot(p) * n.dot(q) < 0.0;
                if apart(a.cross(b), c, d) && apart(c.cross(d), a, b) && a.dot(c) > 0.0 {
                    crossing.insert(s.0);
                    crossing.insert(t.0);
                }
            }
        }
    }
    crossing
}

/// The swing of a course whose valley falls by `slope` (drop over run, as a share of the planet's relief over its
/// radius): `FLAT_SWING` on a flat floor, half of it at `HALF_SWING_SLOPE` (Schumm 1963).
pub fn swing_on(slope: f64) -> f64 {
    FLAT_SWING / (1.0 + (slope / HALF_SWING_SLOPE).powi(2))
}

/// A sine-generated course along a valley line of `length` (any unit): its direction swings about the valley's by
/// `swing cos(2 pi s / wavelength)` along the channel's length s, over the whole number of half wavelengths nearest
/// to `wavelength` (at least one), so it crosses the valley line at both ends. Points (x along the valley, y across
/// it), `points_per_wavelength` per wavelength, from (0, 0) to (`length`, 0); over half a wavelength from each end
/// the course eases onto the valley line (y and its slope 0 at the ends), so it leaves and joins along the valley.
pub fn sine_course(
    length: f64,
    wavelength: f64,
    swing: f64,
    points_per_wavelength: f64,
) -> Vec<(f64, f64)> {
    let channel = length * sinuosity_of(swing);
    let halves = half_wavelengths(length, wavelength, swing).max(1.0);
    let wavelength = 2.0 * channel / halves;
    // Integrate the sine-generated curve in the valley's frame.
    let steps = (halves * 0.5 * points_per_wavelength).ceil() as usize * STEPS_PER_POINT;
    let ds = channel / steps as f64;
    let (mut x, mut y) = (0.0, 0.0);
    let mut course = vec![(0.0, 0.0)];
    for step in 0..steps {
        let theta = swing * (std::f64::consts::TAU * (step as f64 + 0.5) * ds / wavelength).cos();
        x += theta.cos() * ds;
        y += theta.sin() * ds;
        if (step + 1) % STEPS_PER_POINT == 0 {
            course.push((x, y));
        }
    }
    // Onto the valley's ends exactly (the integration leaves a little drift).
    let (end_x, end_y) = *course.last().expect("not empty");
    // Near its ends the course eases onto the valley line over a quarter wavelength, so a tributary meets its main
    // stem along its valley instead of swinging across the other's course (over half a wavelength, the short base
    // reaches of the diffused relief barely wound: docs/planet.md, "Diffusion while the network forms").
    let ease = |x: f64| {
        let t = (x.min(length - x) / (0.25 * wavelength)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    };
    course
        .iter()
        .map(|&(x, y)| {
            let x = x * length / end_x;
            (x, (y - end_y * x / length) * ease(x))
        })
        .collect()
}

/// How many half wavelengths of about `wavelength` a sine-generated course of `swing` fits along a valley of
/// `length` (the nearest whole number; 0 where the valley is shorter than a quarter wavelength's channel).
pub fn half_wavelengths(length: f64, wavelength: f64, swing: f64) -> f64 {
    (2.0 * length * sinuosity_of(swing) / wavelength).round()
}

/// Beds that never rise downstream (float rounding in the interpolation could).
fn monotone(mut beds: Vec<f32>) -> Vec<f32> {
    for i in 1..beds.len() {
        beds[i] = beds[i].min(beds[i - 1]);
    }
    beds
}

/// The sinuosity of a sine-generated curve of swing `omega`: 1 / J0(omega), J0 being the mean of
/// cos(omega cos phi) over a period (Langbein and Leopold 1966). J0 from its power series, sum over k of
/// (-omega^2 / 4)^k / (k!)^2: every course asks for it, and the mean over 64 points it replaces (128 cosines a
/// call) was most of `generate`'s time (docs/rivers.md, "Meanders below the base lattice"). For the swings used (at
/// most 1.25 x 1.15) the terms fall below 1e-17 of the sum by k = 12.
pub fn sinuosity_of(omega: f64) -> f64 {
    let q = -0.25 * omega * omega;
    let (mut term, mut j0) = (1.0, 1.0);
    for k in 1..=16 {
        term *= q / (k * k) as f64;
        j0 += term;
    }
    1.0 / j0
}

/// Where arc length `x` falls along a line sampled at the rising arc `lengths` (at least two): the sample
/// segment holding it and the share of the way along it.
pub fn arc_position(lengths: &[f64], x: f64) -> (usize, f64) {
    let i = lengths
        .partition_point(|&l| l <= x)
        .clamp(1, lengths.len() - 1)
        - 1;
    let span = lengths[i + 1] - lengths[i];
    let t = if span > 0.0 {
        ((x - lengths[i]) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (i, t)
}

/// A reach's valley line: its lattice path smoothed by a Catmull-Rom spline, sampled by arc length.
struct Valley {
    /// Points along the line, [`VALLEY_SAMPLES`] per lattice step.
    samples: Vec<DVec3>,
    /// Arc length (radians) at each sample.
    lengths: Vec<f64>,
}

impl Valley {
    fn new(nodes: &[DVec3]) -> Self {
        let n = nodes.len();
        let node = |i: isize| nodes[i.clamp(0, n as isize - 1) as usize];
        let mut samples = Vec::with_capacity(n * VALLEY_SAMPLES);
        for i in 0..n.saturating_sub(1) {
            let (p0, p1, p2, p3) = (
                node(i as isize - 1),
                node(i as isize),
                node(i as isize + 1),
                node(i as isize + 2),
            );
            for k in 0..VALLEY_SAMPLES {
                let t = k as f64 / VALLEY_SAMPLES as f64;
                let (t2, t3) = (t * t, t * t * t);
                let p = 0.5
                    * (2.0 * p1
                        + (p2 - p0) * t
                        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3);
                samples.push(p.normalize());
            }
        }
        samples.extend(nodes.last());
        let mut lengths = vec![0.0];
        for w in samples.windows(2) {
            lengths.push(lengths.last().expect("not empty") + w[0].angle_between(w[1]));
        }
        Self { samples, lengths }
    }

    fn length(&self) -> f64 {
        *self.lengths.last().expect("not empty")
    }

    /// The sample segment holding arc length `x`, and the share of the way along it.
    fn segment(&self, x: f64) -> (usize, f64) {
        arc_position(&self.lengths, x)
    }

    /// The point at arc length `x` and the line's direction there.
    fn at(&self, x: f64) -> (DVec3, DVec3) {
        let (i, t) = self.segment(x);
        let (a, b) = (self.samples[i], self.samples[i + 1]);
        ((a + (b - a) * t).normalize(), (b - a).normalize_or_zero())
    }

    /// The lattice node before arc length `x`, and the share of the way to the next.
    fn node_at(&self, x: f64) -> (usize, f64) {
        let (i, t) = self.segment(x);
        let position = (i as f64 + t) / VALLEY_SAMPLES as f64;
        (position.floor() as usize, position.fract())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinuosity_is_one_over_j0_of_the_swing() {
        for k in 0..=40 {
            let omega = k as f64 * 0.05;
            // The mean of cos(omega cos phi) over a period, by the midpoint rule (exact for it to rounding).
            let n = 1000;
            let mean = (0..n)
                .map(|i| {
                    (omega * (std::f64::consts::TAU * (i as f64 + 0.5) / n as f64).cos()).cos()
                })
                .sum::<f64>()
                / n as f64;
            assert!((sinuosity_of(omega) - 1.0 / mean).abs() < 1e-12, "{omega}");
        }
        // The flat valley's swing: 1 / J0(1.45) = 1.8534 (the doc comment's 1.85).
        assert!((sinuosity_of(FLAT_SWING) - 1.8534).abs() < 1e-3);
    }

    fn straight_reach(steps: usize, drop: f32) -> ReachPath {
        let cell = std::f64::consts::FRAC_PI_2 / 128.0;
        let points: Vec<DVec3> = (0..=steps)
            .map(|i| DVec3::new((i as f64 * cell).cos(), (i as f64 * cell).sin(), 0.0))
            .collect();
        let beds = (0..=steps)
            .map(|i| 10.0 - drop * i as f32 / steps as f32)
            .collect();
        ReachPath {
            points,
            beds,
            areas: vec![1e-3; steps + 1],
            strahler: 3,
            downstream: None,
        }
    }

    fn scale() -> MeanderScale {
        MeanderScale {
            cell: std::f64::consts::FRAC_PI_2 / 128.0,
            radius: 1024.0,
            relief_slope: 16.0 / 1024.0,
        }
    }

    fn sinuosity(r: &ReachPath) -> f64 {
        let length: f64 = r.points.windows(2).map(|w| w[0].angle_between(w[1])).sum();
        length / r.points[0].angle_between(*r.points.last().unwrap())
    }

    #[test]
    fn a_gentle_river_meanders_within_its_belt_and_keeps_its_ends() {
        let reach = straight_reach(40, 0.2);
        let m = meander(&reach, &scale(), &|_| 1.0);
        assert!(sinuosity(&m) > 1.3, "{}", sinuosity(&m));
        assert_eq!(m.points[0], reach.points[0]);
        assert_eq!(m.points.last(), reach.points.last());
        // The belt: every point within a quarter cell of the straight valley (the plane z = 0).
        let belt = m.points.iter().map(|p| p.z.abs()).fold(0.0, f64::max);
        assert!(belt <= 0.25 * scale().cell * 1.01, "{belt}");
        assert!(m.beds.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(m.beds[0], reach.beds[0]);
        assert_eq!(m.beds.last(), reach.beds.last());
    }

    #[test]
    fn crossing_courses_are_found_and_courses_that_meet_at_a_confluence_are_not() {
        let at = |x: f64, y: f64| DVec3::new(1.0, x, y).normalize();
        let path = |points: Vec<DVec3>| ReachPath {
            beds: vec![0.0; points.len()],
            areas: vec![1.0; points.len()],
            points,
            strahler: 1,
            downstream: None,
        };
        let across = path(vec![at(0.0, -0.01), at(0.0, 0.0005), at(0.0, 0.01)]);
        let along = path(vec![at(-0.01, 0.0), at(0.0005, 0.0), at(0.01, 0.0)]);
        let joining = path(vec![at(-0.01, -0.01), at(0.0, 0.0005)]);
        assert_eq!(
            crossing_reaches(&[across.clone(), along]),
            [0, 1].into_iter().collect()
        );
        assert!(crossing_reaches(&[across, joining]).is_empty());
    }

    #[test]
    fn a_steep_river_stays_straight_and_a_creek_is_left_to_finer_levels() {
        // A drop of 24 over 40 cells (500 units) is a slope of 0.047, three times the relief slope (fourteen times
        // the median order-3 reach's): a swing of a tenth of the flat one.
        let steep = meander(&straight_reach(40, 24.0), &scale(), &|_| 1.0);
        assert!(sinuosity(&steep) < 1.01, "{}", sinuosity(&steep));
        let creek = meander(&straight_reach(40, 0.2), &scale(), &|_| 0.1);
        assert_eq!(creek.points.len(), 41);
    }
}
