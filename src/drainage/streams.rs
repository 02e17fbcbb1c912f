//! The streams a finer level adds to the drawn network (beyond the thesis; docs/rivers.md, "Rivers at every
//! scale"). Of the network routed again at a finer level ([`super::finer::network_at`]), only what the coarser
//! levels do not draw yet is new: every stream from its head down to where it comes within a join distance of a
//! drawn course (a river, a stream of a coarser level, a lake), where it ends on that course, its bed no higher
//! than the course's there. The finer network's copies of the drawn rivers (re-routed, within about a cell of
//! them) start at or beside a drawn course and so add nothing. Left out, with every stream above it: a stream that
//! grows to a river of the coarser level without meeting a drawn course (a re-routed copy that strayed further),
//! and a stream that ends in a lake only the finer level holds (it would end in nothing drawn).

use std::collections::HashMap;

use glam::{DVec3, IVec3};

use super::{LakeShape, ReachPath};

/// The drawn courses, as points on the unit sphere with their bed (or lake) heights, in a grid of cells as wide
/// as the distance at which a stream joins them.
pub struct Courses {
    join: f64,
    cells: HashMap<IVec3, Vec<Course>>,
}

/// A point of a drawn course.
#[derive(Clone, Copy)]
pub struct Course {
    pub point: DVec3,
    /// The bed's height, or a lake's level.
    pub height: f32,
    pub lake: bool,
}

impl Courses {
    /// An empty set of courses, joined within `join` (radians).
    pub fn new(join: f64) -> Self {
        Self {
            join,
            cells: HashMap::new(),
        }
    }

    fn key(&self, p: DVec3) -> IVec3 {
        (p / self.join).floor().as_ivec3()
    }

    fn insert(&mut self, point: DVec3, height: f32, lake: bool) {
        let key = self.key(point);
        self.cells.entry(key).or_default().push(Course {
            point,
            height,
            lake,
        });
    }

    /// Adds every reach's course, with points no more than an eighth of the join distance apart, beds between
    /// the course's points linear.
    pub fn add_reaches(&mut self, reaches: &[ReachPath]) {
        let step = self.join / 8.0;
        for reach in reaches {
            for i in 0..reach.points.len() {
                let (a, bed_a) = (reach.points[i], reach.beds[i]);
                self.insert(a, bed_a, false);
                let Some((&b, &bed_b)) = reach.points.get(i + 1).zip(reach.beds.get(i + 1)) else {
                    continue;
                };
                let pieces = (a.distance(b) / step).ceil() as usize;
                for k in 1..pieces {
                    let t = k as f64 / pieces as f64;
                    let bed = bed_a + (bed_b - bed_a) * t as f32;
                    self.insert(a.lerp(b, t).normalize(), bed, false);
                }
            }
        }
    }

    /// Adds every lake's points at its level.
    pub fn add_lakes(&mut self, lakes: &[LakeShape]) {
        for lake in lakes {
            for &p in &lake.points {
                self.insert(p, lake.level, true);
            }
        }
    }

    /// The nearest course point within `within` (radians) of `p`.
    pub fn nearest(&self, p: DVec3, within: f64) -> Option<Course> {
        let key = self.key(p);
        let r = (within / self.join).ceil() as i32;
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
        best.map(|(_, course)| course)
    }
}

/// What decides which streams are new.
pub struct StreamRule {
    /// The coarser level's source area (world units squared): where the finer network's streams have grown to
    /// its rivers.
    pub coarser_source_area: f64,
    /// The sea level: a stream whose bed ends there reaches the sea.
    pub sea_level: f32,
}

/// How far a reach of the finer network goes as a new stream.
#[derive(Clone, Copy)]
enum Fate {
    /// Its first `at` points, then the course point it joins.
    Joins { at: usize, course: Course },
    /// All of it, on into the reach below or into the sea.
    Flows,
    /// Nothing: it is a drawn river's copy, or leads into one or into a lake not drawn.
    Left,
}

/// Where on its way to the course it joins a stream drops to the course's bed (a share of the way).
const MOUTH_STEP: f64 = 0.1;
/// Once a stream has the coarser level's source area, it joins a course this many join distances away: a
/// re-routed copy of a drawn river runs beside it.
const RIVER_JOIN_FACTOR: f64 = 2.5;
/// A stream that has twice the coarser level's source area and still no course near is such a copy that strayed.
const STRAYED_AREA_FACTOR: f64 = 2.0;

/// The new streams of `finer` (a network routed at a finer level) against the `drawn` courses: reaches in flow
/// order, each ending where it joins a drawn course, in the sea, or in the reach below (`downstream`, an index
/// into the result).
pub fn new_streams(finer: &[ReachPath], drawn: &Courses, rule: &StreamRule) -> Vec<ReachPath> {
    let fates: Vec<Fate> = finer.iter().map(|reach| fate(reach, drawn, rule)).collect();
    // A reach is drawn if it joins a course with something of its own, or flows into the sea or into a drawn reach.
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
    finer
        .iter()
        .zip(&fates)
        .enumerate()
        .filter(|(k, _)| index[*k] != usize::MAX)
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
                // Into the course's valley at the course's bed: a step just past the last point, then straight on.
                let last = reach.points[at - 1];
                let mut points = reach.points[..at].to_vec();
                points.extend([
                    last.lerp(course.point, MOUTH_STEP).normalize(),
                    course.point,
                ]);
                let mut beds = reach.beds[..at].to_vec();
                let bed = course.height.min(beds[at - 1]);
                beds.extend([bed, bed]);
                let mut areas = reach.areas[..at].to_vec();
                areas.extend([areas[at - 1]; 2]);
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
        .collect()
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
    for (i, (&p, &area)) in reach.points.iter().zip(&reach.areas).enumerate() {
        let river = area >= rule.coarser_source_area;
        let within = if river {
            RIVER_JOIN_FACTOR * drawn.join
        } else {
            drawn.join
        };
        if let Some(course) = drawn.nearest(p, within) {
            return Fate::Joins { at: i, course };
        }
        if area >= STRAYED_AREA_FACTOR * rule.coarser_source_area {
            return Fate::Left;
        }
    }
    Fate::Flows
}
