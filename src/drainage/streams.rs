//! The streams a finer level adds to the drawn network (beyond the thesis; docs/rivers.md, "Rivers at every
//! scale"). Of the network routed again at a finer level ([`super::finer::network_at`]), only what the coarser
//! levels do not draw yet is new: every stream from its head down to where it comes within a join distance of a
//! drawn course (a river, a stream of a coarser level, a lake), or where, within a river's valley (the river
//! kernel's influence distance), it stops heading towards the river; there it ends on that course, its bed no
//! higher than the course's. The finer network's copies of the drawn rivers (re-routed, within about a cell of
//! them) start at or beside a drawn course and so add nothing. Left out, with every stream above it: a stream that
//! grows to a river of the coarser level without meeting a drawn course (a re-routed copy that strayed further),
//! and a stream that ends in a lake only the finer level holds (it would end in nothing drawn).

use glam::{DVec3, IVec3};

use super::{LakeShape, ReachPath};
use crate::fast_hash::FastMap;

/// The drawn courses, as points on the unit sphere with their bed (or lake) heights, in a grid of cells.
pub struct Courses {
    cell: f64,
    cells: FastMap<IVec3, Vec<Course>>,
}

/// A point of a drawn course.
#[derive(Clone, Copy)]
pub struct Course {
    /// Unit direction.
    pub point: DVec3,
    /// The bed's height, or a lake's level.
    pub height: f32,
    /// Half the river's width (radians; 0 for a lake).
    pub half_width: f64,
    /// Whether the point lies on a lake rather than a river.
    pub lake: bool,
    /// Where on the reaches added this point lies (none on a lake).
    pub junction: Option<Junction>,
}

/// A place on a drawn reach where a stream joins it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Junction {
    /// The reach: its index among those [`Courses::add_reaches`] was given.
    pub reach: usize,
    /// The position along it: its point index, with the share of the way to the next point.
    pub at: f64,
}

impl Courses {
    /// An empty set of courses, found fastest within `cell` (radians) of a point.
    pub fn new(cell: f64) -> Self {
        Self {
            cell,
            cells: FastMap::default(),
        }
    }

    fn key(&self, p: DVec3) -> IVec3 {
        (p / self.cell).floor().as_ivec3()
    }

    fn insert(&mut self, course: Course) {
        let key = self.key(course.point);
        self.cells.entry(key).or_default().push(course);
    }

    /// Adds every reach's course, with points no more than `step` (radians) apart, beds and drainage areas
    /// between the course's points linear; `half_width(area)` in radians.
    pub fn add_reaches(
        &mut self,
        reaches: &[ReachPath],
        step: f64,
        half_width: impl Fn(f64) -> f64,
    ) {
        for (r, reach) in reaches.iter().enumerate() {
            for i in 0..reach.points.len() {
                let j = (i + 1).min(reach.points.len() - 1);
                let (a, b) = (reach.points[i], reach.points[j]);
                let pieces = if j == i {
                    1
                } else {
                    (a.distance(b) / step).ceil() as usize
                };
                for k in 0..pieces {
                    let t = k as f64 / pieces as f64;
                    let area = reach.areas[i] + (reach.areas[j] - reach.areas[i]) * t;
                    self.insert(Course {
                        point: a.lerp(b, t).normalize(),
                        height: reach.beds[i] + (reach.beds[j] - reach.beds[i]) * t as f32,
                        half_width: half_width(area),
                        lake: false,
                        junction: Some(Junction {
                            reach: r,
                            at: i as f64 + t,
                        }),
                    });
                }
            }
        }
    }

    /// Adds every lake's points at its level.
    pub fn add_lakes(&mut self, lakes: &[LakeShape]) {
        for lake in lakes {
            for &p in &lake.points {
                self.insert(Course {
                    point: p,
                    height: lake.level,
                    half_width: 0.0,
                    lake: true,
                    junction: None,
                });
            }
        }
    }

    /// The nearest course point within `within` (radians) of `p`, and its distance.
    pub fn nearest(&self, p: DVec3, within: f64) -> Option<(Course, f64)> {
        let key = self.key(p);
        let r = (within / self.cell).ceil() as i32;
        let mut best: Option<(f64, Course)> = None;
        for dx in -r..=r {
            for dy in -r..=r {
                for dz in -r..=r {
                    let Some(points) = self.cells.get(&(key + IVec3::new(dx, dy, dz))) else {
                        continue;
                    };
                    for &course in points {
                        let d = p.distance(course.point);
                        if d <= within && best.is_none_or(|(b, _)| d < b) {
                            best = Some((d, course));
                        }
                    }
                }
            }
        }
        best.map(|(d, course)| (course, d))
    }
}

/// What decides which streams are new.
pub struct StreamRule {
    /// The coarser level's source area (world units squared): where the finer network's streams have grown to
    /// its rivers.
    pub coarser_source_area: f64,
    /// The sea level: a stream whose bed ends there reaches the sea.
    pub sea_level: f32,
    /// The distance (radians) within which a stream joins a course.
    pub join: f64,
    /// The river kernel's influence distance (radians): within it, a stream that stops heading towards the river
    /// joins it, rather than run down its valley beside it.
    pub valley: f64,
}

/// How far a reach of the finer network goes as a new stream.
#[derive(Clone, Copy)]
enum Fate {
    /// Its points up to `at`, then the bank of the course it joins.
    Joins { at: usize, course: Course },
    /// All of it, on into the reach below or into the sea.
    Flows,
    /// Nothing: it is a drawn river's copy, or leads into one or into a lake not drawn.
    Left,
}

/// Where on its way to the course it joins a stream drops to the course's bed (a share of the way).
const MOUTH_STEP: f64 = 0.1;
/// Within a river's valley, a stream heads towards the river while its distance to it falls by at least this
/// share of each step (a heading within 60 degrees of straight at it).
const APPROACH: f64 = 0.5;
/// A stream that has twice the coarser level's source area and still no course near is such a copy that strayed.
const STRAYED_AREA_FACTOR: f64 = 2.0;

/// The new streams of `finer` (a network routed at a finer level) against the `drawn` courses: reaches in flow
/// order, each ending where it joins a drawn course, in the sea, or in the reach below (`downstream`, an index
/// into the result); and for each, where it joins a drawn river (none where it flows on, into the sea or a lake).
pub fn new_streams(
    finer: &[ReachPath],
    drawn: &Courses,
    rule: &StreamRule,
) -> (Vec<ReachPath>, Vec<Option<Junction>>) {
    let fates: Vec<Fate> = finer.iter().map(|reach| fate(reach, drawn, rule)).collect();
    // A reach is drawn if it joins a course with something of its own, or flows into the sea or into a drawn reach.
    // One that starts on a course is drawn only as the mouth of streams that meet there (they reach it first: the
    // finer network lists its reaches upstream first).
    let mut kept: Vec<Option<bool>> = vec![None; finer.len()];
    for start in 0..finer.len() {
        let mut chain = Vec::new();
        let mut at = start;
        let verdict = loop {
            if let Some(known) = kept[at] {
                break known;
            }
            chain.push(at);
            match fates[at] {
                Fate::Joins { at: 0, course } if !course.lake => break chain.len() > 1,
                Fate::Joins { at: i, course } => break i > usize::from(course.lake),
                Fate::Left => break false,
                Fate::Flows => match finer[at].downstream {
                    Some(below) => at = below,
                    None => break *finer[at].beds.last().unwrap() <= rule.sea_level,
                },
            }
        };
        for k in chain {
            kept[k] = Some(verdict);
        }
    }
    let mut index = vec![usize::MAX; finer.len()];
    let mut next = 0;
    for (k, keep) in kept.iter().enumerate() {
        if *keep == Some(true) {
            index[k] = next;
            next += 1;
        }
    }
    let kept = || {
        finer
            .iter()
            .zip(&fates)
            .enumerate()
            .filter(|(k, _)| index[*k] != usize::MAX)
    };
    let joins = kept()
        .map(|(_, (_, fate))| match fate {
            Fate::Joins { course, .. } => course.junction,
            _ => None,
        })
        .collect();
    let streams = kept()
        .map(|(_, (reach, fate))| match *fate {
            Fate::Joins { at, course } if course.lake => ReachPath {
                // At the shore: the lake is drawn wherever the ground lies below its level (docs/kernel.md).
                points: reach.points[..at].to_vec(),
                beds: reach.beds[..at].to_vec(),
                areas: reach.areas[..at].to_vec(),
                strahler: reach.strahler,
                downstream: None,
            },
            Fate::Joins { at, course } => {
                // Into the course's valley at the course's bed: a step just past the last point, then straight on
                // to the river's bank (its samples inside the river would narrow it: docs/kernel.md).
                let last = reach.points[at];
                let bank =
                    course.point + (last - course.point).normalize_or_zero() * course.half_width;
                let mut points = reach.points[..=at].to_vec();
                points.extend([last.lerp(bank, MOUTH_STEP).normalize(), bank.normalize()]);
                let mut beds = reach.beds[..=at].to_vec();
                let bed = course.height.min(beds[at]);
                beds.extend([bed, bed]);
                let mut areas = reach.areas[..=at].to_vec();
                areas.extend([areas[at]; 2]);
                ReachPath {
                    points,
                    beds,
                    areas,
                    strahler: reach.strahler,
                    downstream: None,
                }
            }
            _ => ReachPath {
                downstream: reach.downstream.map(|d| index[d]),
                ..reach.clone()
            },
        })
        .collect();
    (streams, joins)
}

/// Lays the beds of `streams` (in flow order, upstream reaches first, as [`new_streams`] gives them) no higher
/// than the `ground` (the unfilled heights of their level) and never rising downstream, across confluences too.
/// The finer level's routing fills its pits (Priority-Flood); a bed at the filled height would stand above the
/// ground there, and the river kernel would draw a sheet of water around it: lowered, the stream breaches the
/// pit's rim instead, which changes a landscape least (Lindsay 2016).
pub fn lay_beds(streams: &mut [ReachPath], ground: impl Fn(DVec3) -> f32) {
    let mut ceiling = vec![f32::MAX; streams.len()];
    for k in 0..streams.len() {
        let reach = &mut streams[k];
        let mut top = ceiling[k];
        for (bed, &p) in reach.beds.iter_mut().zip(&reach.points) {
            top = top.min(*bed).min(ground(p));
            *bed = top;
        }
        if let Some(d) = reach.downstream {
            ceiling[d] = ceiling[d].min(top);
        }
    }
}

/// Walks `reach` downstream until it comes near a drawn course.
fn fate(reach: &ReachPath, drawn: &Courses, rule: &StreamRule) -> Fate {
    let mut before: Option<(DVec3, f64)> = None;
    for (i, (&p, &area)) in reach.points.iter().zip(&reach.areas).enumerate() {
        let near = drawn.nearest(p, rule.join.max(rule.valley));
        if let Some((course, d)) = near {
            let joins = d <= rule.join;
            let beside = !course.lake
                && d <= rule.valley
                && before.is_some_and(|(q, was)| d > was - APPROACH * p.distance(q));
            // Streams that meet where they reach a river join it together, as the stream they make: the reach
            // below their confluence joins it from its first point (else each would join on its own, and the
            // confluence's order would be lost from the network as drawn). Not where they meet in the river's
            // water: the reach below would have no length to the bank.
            let confluence = i + 1 == reach.points.len() && reach.downstream.is_some();
            if joins && confluence && !course.lake && d > course.half_width {
                return Fate::Flows;
            }
            if joins || beside {
                return Fate::Joins { at: i, course };
            }
        }
        before = near
            .filter(|(course, d)| !course.lake && *d <= rule.valley)
            .map(|(_, d)| (p, d));
        if area >= STRAYED_AREA_FACTOR * rule.coarser_source_area {
            return Fate::Left;
        }
    }
    Fate::Flows
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point `east` radians east and `north` radians north of (1, 0, 0).
    fn at(east: f64, north: f64) -> DVec3 {
        DVec3::new(1.0, east, north).normalize()
    }

    fn reach(points: Vec<DVec3>, strahler: u32, downstream: Option<usize>) -> ReachPath {
        let n = points.len();
        ReachPath {
            beds: (0..n).map(|i| 10.0 - i as f32).collect(),
            areas: vec![1.0; n],
            points,
            strahler,
            downstream,
        }
    }

    /// A drawn river along the equator, joined within 0.01.
    fn equator() -> (Courses, StreamRule) {
        let river = reach(vec![at(-0.2, 0.0), at(0.2, 0.0)], 2, None);
        let mut courses = Courses::new(0.05);
        courses.add_reaches(&[river], 0.001, |_| 0.0005);
        let rule = StreamRule {
            coarser_source_area: 100.0,
            sea_level: -1.0,
            join: 0.01,
            valley: 0.0,
        };
        (courses, rule)
    }

    #[test]
    fn streams_that_meet_on_a_river_join_it_as_the_stream_they_make() {
        // Two streams come down from the north and meet 0.005 from the river (within the join distance), where
        // the reach below them starts.
        let (courses, rule) = equator();
        let confluence = at(0.0, 0.005);
        let finer = vec![
            reach(
                vec![at(-0.05, 0.1), at(-0.02, 0.05), confluence],
                1,
                Some(2),
            ),
            reach(vec![at(0.05, 0.1), at(0.02, 0.05), confluence], 1, Some(2)),
            reach(vec![confluence, at(0.0, 0.0)], 2, None),
        ];
        let (streams, joins) = new_streams(&finer, &courses, &rule);
        assert_eq!(streams.len(), 3, "both streams and the one they make");
        assert_eq!(streams[0].downstream, Some(2));
        assert_eq!(streams[1].downstream, Some(2));
        assert_eq!(
            (joins[0], joins[1]),
            (None, None),
            "they flow on into the stream they make"
        );
        let mouth = joins[2].expect("the stream they make joins the river");
        assert_eq!(mouth.reach, 0);
        assert!((mouth.at - 0.5).abs() < 0.01, "where they meet: {mouth:?}");
        assert_eq!(streams[2].points[0], confluence);
    }

    #[test]
    fn streams_that_meet_in_the_river_join_it_each_with_a_mouth_of_some_length() {
        // The confluence lies on a point of the river's line (a finer lattice point on a coarser course): the reach
        // below it would have no length to the bank (no direction for the kernel: NaN heights), so each stream
        // joins on its own.
        let (courses, rule) = equator();
        let confluence = at(-0.2, 0.0);
        let finer = vec![
            reach(
                vec![at(-0.25, 0.1), at(-0.22, 0.05), confluence],
                1,
                Some(2),
            ),
            reach(
                vec![at(-0.15, 0.1), at(-0.18, 0.05), confluence],
                1,
                Some(2),
            ),
            reach(vec![confluence, at(-0.19, -0.001)], 2, None),
        ];
        let (streams, joins) = new_streams(&finer, &courses, &rule);
        assert_eq!(streams.len(), 2, "each stream joins on its own");
        assert!(joins.iter().all(Option::is_some));
        for stream in &streams {
            let length: f64 = stream.points.windows(2).map(|w| w[0].distance(w[1])).sum();
            assert!(length > 0.01, "a stream of length {length}");
        }
    }

    #[test]
    fn a_reach_that_starts_on_a_river_is_a_copy_of_it() {
        let (courses, rule) = equator();
        let copy = vec![reach(vec![at(-0.1, 0.002), at(0.1, 0.002)], 1, None)];
        assert!(new_streams(&copy, &courses, &rule).0.is_empty());
    }
}
