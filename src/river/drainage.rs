//! River systems from a drainage network (drainage model, beyond the thesis; docs/rivers.md): every reach becomes
//! Hermite segments through its nodes, with widths from its drainage area and its bed heights, so that everything
//! downstream (LoD subdivision 5.2.2, procedural tributaries 5.2.3, hulls 6.3, samples 6.4, the kernel) works on
//! them as on the thesis's rivers.

use glam::{DVec2, DVec3};

use super::{
    spline::Hermite,
    system::{
        enclose, meander_wavelength, subdivide, RiverFrame, RiverSystem, Segment, StreamLevel,
        SubdivisionParams, MAX_DEPTH, MAX_GENERATION,
    },
};
use crate::{
    config::Config,
    drainage::{
        drawn, finer, meander_reaches,
        streams::{lay_beds, new_streams, Courses, Junction, StreamRule},
        Drainage, LakeShape, ReachPath,
    },
    planet::{cube::PatchId, height_on, Planet},
    rng,
};

/// Largest angle between a system's anchor (where it ends) and any of its points; reaches beyond it start a
/// system of their own, so that the gnomonic frame stays within a few percent of true distances.
const SYSTEM_ANGLE: f64 = 0.3;
/// Subdivision levels in a drainage system's hull at most: its segments are a few lattice cells long already, and
/// the extended hull's margin covers whatever finer levels add.
const DRAINAGE_HULL_LEVELS: u32 = 1;
/// A finer level's stream joins a drawn course within this many cells of the coarser level.
const JOIN_CELLS: f64 = 0.75;
/// Points of a reach per Hermite segment (lattice nodes, or points of a meandering course).
const NODES_PER_SEGMENT: usize = 2;

/// The river systems of `drainage`: each mouth's tree, split where it grows beyond `SYSTEM_ANGLE`; the system
/// of the largest river first.
pub fn systems(
    drainage: &Drainage,
    radius: f64,
    config: &Config,
    params: &SubdivisionParams,
) -> Vec<RiverSystem> {
    let reaches = &drainage.reaches;
    // Upstream reaches of each reach, and the system (anchor reach) each reach joins, downstream first.
    let mut upstream: Vec<Vec<usize>> = vec![Vec::new(); reaches.len()];
    for (k, r) in reaches.iter().enumerate() {
        if let Some(d) = r.downstream {
            upstream[d].push(k);
        }
    }
    let mut anchor = vec![usize::MAX; reaches.len()];
    let mut stack: Vec<usize> = (0..reaches.len())
        .filter(|&k| reaches[k].downstream.is_none())
        .collect();
    for &root in &stack {
        anchor[root] = root;
    }
    while let Some(k) = stack.pop() {
        for &u in &upstream[k] {
            let own = anchor[k];
            let end = *reaches[own].points.last().unwrap();
            let fits = reaches[u]
                .points
                .iter()
                .all(|p| crate::planet::cube::angle(*p, end) <= SYSTEM_ANGLE);
            anchor[u] = if fits { own } else { u };
            stack.push(u);
        }
    }
    let width = |area: f64| reach_width(config, drainage, area);
    let branch = |k: usize| reach_branch(params, k);
    let rivers = river_keys(reaches, &branch);
    let mut roots: Vec<usize> = (0..reaches.len()).filter(|&k| anchor[k] == k).collect();
    let mouth_area = |k: usize| reaches[k].areas.last().copied().unwrap_or(0.0);
    roots.sort_by(|a, b| mouth_area(*b).total_cmp(&mouth_area(*a)));
    let mut systems: Vec<RiverSystem> = roots
        .iter()
        .enumerate()
        .map(|(id, &root)| {
            let members: Vec<usize> = (0..reaches.len()).filter(|&k| anchor[k] == root).collect();
            let mouth = *reaches[root].points.last().unwrap();
            let source = trunk_head(drainage, &upstream, root);
            let frame = RiverFrame::new(mouth, source, radius);
            let segments = members
                .iter()
                .flat_map(|&k| reach_segments(reaches, (k, 0), &frame, &width, (&branch, &rivers)))
                .collect();
            let hull_levels = config.river.hull_levels.min(DRAINAGE_HULL_LEVELS);
            enclose(
                config,
                params,
                (id as u32, hull_levels),
                frame,
                segments,
                (source, mouth),
            )
        })
        .collect();
    for lake in &drainage.lakes {
        let id = systems.len() as u32;
        systems.push(lake_system(lake, id, radius, config, params));
    }
    systems
}

/// The river key of each reach ([`Segment::river`]): a reach that is the largest inflow (by drainage area) of the
/// reach it joins continues that reach's river; any other is a river's last reach, and the river takes its branch
/// key.
fn river_keys(reaches: &[ReachPath], branch: &impl Fn(usize) -> u64) -> Vec<u64> {
    let area = |k: usize| reaches[k].areas.last().copied().unwrap_or(0.0);
    let mut main_inflow = vec![usize::MAX; reaches.len()];
    for (k, r) in reaches.iter().enumerate() {
        if let Some(d) = r.downstream {
            let m = main_inflow[d];
            if m == usize::MAX || area(k) > area(m) {
                main_inflow[d] = k;
            }
        }
    }
    (0..reaches.len())
        .map(|k| {
            let mut last = k;
            while let Some(d) = reaches[last].downstream.filter(|&d| main_inflow[d] == last) {
                last = d;
            }
            branch(last)
        })
        .collect()
}

/// The Hermite segments of reach `k` in `frame`, two of its points long, tangents Catmull-Rom; where it joins
/// another reach, it leaves along the other's first direction: C1 at the confluence (5.2.3). Pieces of
/// `generation` [`MAX_GENERATION`] spawn no procedural tributaries. `branch`: each reach's branch key; `rivers`:
/// each reach's river key ([`river_keys`]).
fn reach_segments(
    reaches: &[ReachPath],
    (k, generation): (usize, u32),
    frame: &RiverFrame,
    width: &impl Fn(f64) -> f32,
    (branch, rivers): (&impl Fn(usize) -> u64, &[u64]),
) -> Vec<Segment> {
    let plane = |p: &DVec3| frame.to_plane(*p).unwrap_or_default();
    let reach = &reaches[k];
    let points: Vec<DVec2> = reach.points.iter().map(plane).collect();
    let joins = reach
        .downstream
        .map(|d| reaches[d].points.iter().map(plane).collect::<Vec<_>>());
    let knots: Vec<usize> = knot_indices(points.len());
    knots
        .windows(2)
        .enumerate()
        .map(|(s, pair)| {
            let (a, b) = (pair[0], pair[1]);
            let tangent = |i: usize| tangent_at(&points, &knots, i, joins.as_deref());
            let span = (b - a) as f64;
            Segment {
                curve: Hermite {
                    p0: points[a],
                    d0: tangent(a) * span,
                    p1: points[b],
                    d1: tangent(b) * span,
                },
                heights: (reach.beds[a], reach.beds[b]),
                widths: (width(reach.areas[a]), width(reach.areas[b])),
                key: rng::hash(branch(k), &[s as u64]),
                depth: 0,
                generation,
                branch: branch(k),
                parent_branch: reach.downstream.map(branch),
                river: rivers[k],
                lake: false,
            }
        })
        .collect()
}

/// The branch key of base reach `k`: its pieces' randomness derives from it.
fn reach_branch(params: &SubdivisionParams, k: usize) -> u64 {
    rng::hash(params.seed, &[0x6472_6169, k as u64])
}

/// The length (radians) of the base reaches that `wanted` accepts as the deepest levels draw them: their pieces
/// subdivided (5.2.2, with the meanders below the base lattice) until each is at most half a meander wavelength
/// long, each measured along its curve on the sphere; 0 for the others. The sinuosity geomorphology compares with
/// rivers measured on maps that show their channels (docs/geomorphology.md).
pub fn drawn_reach_lengths(
    (systems, params): (&[RiverSystem], &SubdivisionParams),
    drainage: &Drainage,
    wanted: impl Fn(usize) -> bool + Sync,
) -> Vec<f64> {
    use rayon::prelude::*;
    let reach_of: std::collections::HashMap<u64, usize> = (0..drainage.reaches.len())
        .filter(|&k| wanted(k))
        .map(|k| (reach_branch(params, k), k))
        .collect();
    let lengths: Vec<(usize, f64)> = systems
        .par_iter()
        .flat_map_iter(|system| {
            system.segments.iter().filter_map(|segment| {
                let k = *reach_of.get(&segment.branch).filter(|_| !segment.lake)?;
                Some((k, drawn_length(segment, &system.frame, params)))
            })
        })
        .collect();
    let mut out = vec![0.0; drainage.reaches.len()];
    for (k, length) in lengths {
        out[k] += length;
    }
    out
}

/// The length (radians) of `segment` as the deepest levels draw it ([`drawn_reach_lengths`]).
fn drawn_length(segment: &Segment, frame: &RiverFrame, params: &SubdivisionParams) -> f64 {
    const POINTS: usize = 4;
    let mut length = 0.0;
    let mut stack = vec![*segment];
    while let Some(piece) = stack.pop() {
        if piece.depth >= MAX_DEPTH || piece.polygon_length() <= 0.5 * meander_wavelength(&piece) {
            let points: Vec<DVec3> = (0..POINTS)
                .map(|i| frame.to_sphere(piece.curve.point(i as f64 / (POINTS - 1) as f64)))
                .collect();
            length += points
                .windows(2)
                .map(|w| w[0].angle_between(w[1]))
                .sum::<f64>();
        } else {
            stack.extend(subdivide(&piece, params).0);
        }
    }
    length
}

/// The streams a finer patch `level` adds ([`crate::drainage::streams`]) as river systems, ids from `first_id`:
/// the streams whose trees end in one patch of the level below form one system, in a frame about that patch's
/// centre (a few hundredths of a radian across, so the gnomonic frame is near exact), so a patch tests tens of
/// systems rather than thousands of small trees, and each system's pieces only where its hull meets the patch.
pub fn stream_systems(
    streams: &[ReachPath],
    (level, base_level, first_id): (u32, u32, u32),
    drainage: &Drainage,
    radius: f64,
    config: &Config,
    params: &SubdivisionParams,
) -> Vec<RiverSystem> {
    let bucket_level = level.saturating_sub(1) as u8;
    let mut buckets: std::collections::BTreeMap<PatchId, Vec<usize>> = Default::default();
    for k in 0..streams.len() {
        let mut mouth = k;
        while let Some(d) = streams[mouth].downstream {
            mouth = d;
        }
        let end = *streams[mouth].points.last().unwrap();
        buckets
            .entry(PatchId::containing(end, bucket_level))
            .or_default()
            .push(k);
    }
    let width = |area: f64| reach_width(config, drainage, area);
    let branch = |k: usize| rng::hash(params.seed, &[0x7374_7265, level as u64, k as u64]);
    let rivers = river_keys(streams, &branch);
    // Each level's streams carve valleys half as wide as the coarser level's: the river kernel pulls the terrain
    // within its influence distance towards the bed, and streams a cell apart would otherwise level the hills
    // between them.
    let reach = config.river.influence_distance / 4f32.powi((level - base_level) as i32);
    buckets
        .into_iter()
        .enumerate()
        .map(|(id, (patch, members))| {
            let centre = patch.center();
            let frame = RiverFrame::new(centre, patch.corners()[0], radius);
            let segments = members
                .iter()
                .flat_map(|&k| {
                    reach_segments(
                        streams,
                        (k, MAX_GENERATION),
                        &frame,
                        &width,
                        (&branch, &rivers),
                    )
                })
                .collect();
            // The hull of the segments themselves: thousands of short pieces, whose descendants the extended
            // hull's margin covers.
            RiverSystem {
                reach,
                ..enclose(
                    config,
                    params,
                    (first_id + id as u32, 0),
                    frame,
                    segments,
                    (centre, centre),
                )
            }
        })
        .collect()
}

/// The streams each level above the base lattice's adds, up to `stream-levels` levels above it: each level's
/// network routed anew ([`crate::drainage::finer`]), and of it the streams no coarser level draws
/// ([`crate::drainage::streams`]), joining the base rivers, the base lakes and the coarser levels' streams within
/// three quarters of a coarser cell, or where, within a river's valley, they stop heading towards it; they meander
/// as the base rivers do. System ids from `first_id`.
pub fn stream_levels(
    planet: &Planet,
    config: &Config,
    params: &SubdivisionParams,
    first_id: u32,
) -> Vec<StreamLevel> {
    let Some(drainage) = &planet.drainage else {
        return Vec::new();
    };
    let base = planet.stats.base_level;
    // A lattice cell of `level` (radians along a face's middle): the planet holds the lattice of its precomputed level.
    let cell = |level: u32| {
        std::f64::consts::FRAC_PI_2 / planet.lattice.cells as f64
            * 2f64.powi(planet.precomputed_level as i32 - level as i32)
    };
    let mut drawn: Vec<ReachPath> = drainage.reaches.clone();
    // Where each drawn reach flows out: the head of the reach below, or where it joins a coarser course.
    let head = |reach: usize| Junction { reach, at: 0.0 };
    let mut outlets: Vec<Option<Junction>> = drawn.iter().map(|r| r.downstream.map(head)).collect();
    let mut levels = Vec::new();
    let mut next_id = first_id;
    for level in base + 1..=base + config.river.stream_levels {
        let since = std::time::Instant::now();
        let ground = planet.face_lattice(level);
        // Routed along lattice paths; only the streams kept meander.
        let finer = finer::routed_at(planet, config, level, &mut ground.clone());
        let coarser = (level - 1 - base) as i32;
        let rule = StreamRule {
            coarser_source_area: config.river.source_area as f64 / 4f64.powi(coarser),
            sea_level: config.planet.sea_level_height,
            join: JOIN_CELLS * cell(level - 1),
            valley: config.river.influence_distance as f64 / planet.radius,
        };
        let mut courses = Courses::new(rule.join.max(rule.valley));
        courses.add_reaches(&drawn, rule.join / 4.0, |area| {
            0.5 * reach_width(config, drainage, area) as f64 / planet.radius
        });
        courses.add_lakes(&drainage.lakes);
        let (streams, joins) = new_streams(&finer.reaches, &courses, &rule);
        let mut streams = meander_reaches(
            &streams,
            ground.cells,
            &config.planet,
            &config.river,
            drainage.largest_area,
        );
        // Within its influence distance the river kernel pulls the terrain towards a course's bed (6.6): a stream
        // there lies on that valley side, not on the level's own ground, or it would stand above it and spill.
        let basin = config.river.basin_depth;
        lay_beds(&mut streams, |p| {
            let own = height_on(&ground, p);
            match courses.nearest(p, rule.valley) {
                Some((course, d)) if !course.lake => {
                    let (bed, t) = (course.height, (d / rule.valley) as f32);
                    bed - basin + (own - bed + basin).max(0.0) * t
                }
                _ => own,
            }
        });
        let systems = stream_systems(
            &streams,
            (level, base, next_id),
            drainage,
            planet.radius,
            config,
            params,
        );
        next_id += systems.len() as u32;
        log::info!(
            "streams of level {level}: {} reaches in {} systems",
            streams.len(),
            systems.len()
        );
        let first = drawn.len();
        outlets.extend(
            streams
                .iter()
                .zip(joins)
                .map(|(reach, join)| join.or(reach.downstream.map(|d| head(first + d)))),
        );
        let ms = since.elapsed().as_secs_f64() * 1e3;
        levels.push(StreamLevel {
            level,
            reaches: streams.len(),
            systems,
            ms,
            drawn: drawn::measure(&outlets),
        });
        drawn.extend(streams);
    }
    levels
}

/// A lake as a river system whose pieces carry its water level: one short straight piece through each of its
/// lattice points, a base cell long and two wide, so that the vertices within a cell of the lake get the level
/// (the kernel's lake samples) and the terrain below it is drawn under water there: the shore is the refined
/// terrain's contour at the level, which lies between the lake's last lattice point and the first one above it. The
/// pieces are at the deepest subdivision already (no meanders, no tributaries) and carve nothing.
fn lake_system(
    lake: &LakeShape,
    id: u32,
    radius: f64,
    config: &Config,
    params: &SubdivisionParams,
) -> RiverSystem {
    let centre = lake.points.iter().copied().sum::<DVec3>().normalize();
    let frame = RiverFrame::new(centre, centre.any_orthonormal_vector() + centre, radius);
    // The distance between neighbouring lattice points of the lake: its area over its points.
    let cell = (lake.area / lake.points.len().max(1) as f64).sqrt();
    let width = (2.0 * cell) as f32;
    let branch = rng::hash(params.seed, &[0x6c61_6b65, id as u64]);
    let half = DVec2::new(0.5 * cell, 0.0);
    let segments = lake
        .points
        .iter()
        .enumerate()
        .filter_map(|(k, p)| {
            let at = frame.to_plane(*p)?;
            Some(Segment {
                curve: Hermite {
                    p0: at - half,
                    d0: half * 2.0,
                    p1: at + half,
                    d1: half * 2.0,
                },
                heights: (lake.level, lake.level),
                widths: (width, width),
                key: rng::hash(branch, &[k as u64]),
                depth: MAX_DEPTH,
                generation: 0,
                branch,
                parent_branch: None,
                river: branch,
                lake: true,
            })
        })
        .collect();
    enclose(config, params, (id, 0), frame, segments, (centre, centre))
}

/// A reach's full width at `area` (hydraulic geometry, [`crate::drainage::width`]).
pub fn reach_width(config: &Config, drainage: &Drainage, area: f64) -> f32 {
    crate::drainage::width(&config.river, drainage.largest_area, area)
}

/// The head of the longest chain of reaches above `root` by drainage area (the main stem).
fn trunk_head(drainage: &Drainage, upstream: &[Vec<usize>], root: usize) -> DVec3 {
    let mut at = root;
    while let Some(&next) = upstream[at].iter().max_by(|a, b| {
        let area = |k: usize| drainage.reaches[k].areas.last().copied().unwrap_or(0.0);
        area(**a).total_cmp(&area(**b))
    }) {
        at = next;
    }
    drainage.reaches[at].points[0]
}

/// Every [`NODES_PER_SEGMENT`]-th node, and the last.
fn knot_indices(len: usize) -> Vec<usize> {
    let mut knots: Vec<usize> = (0..len).step_by(NODES_PER_SEGMENT).collect();
    if knots.last() != Some(&(len - 1)) {
        knots.push(len - 1);
    }
    knots
}

/// The flow direction per node spacing at node `i` of a reach (Catmull-Rom between its neighbouring nodes); at
/// the last node of a reach that joins another, the other's direction at its first node.
fn tangent_at(points: &[DVec2], knots: &[usize], i: usize, joins: Option<&[DVec2]>) -> DVec2 {
    let last = points.len() - 1;
    let own = if i == 0 {
        points[1] - points[0]
    } else if i == last {
        points[last] - points[last - 1]
    } else {
        (points[i + 1] - points[i - 1]) * 0.5
    };
    match joins {
        Some(next) if i == last && next.len() > 1 && i == *knots.last().unwrap() => {
            (next[1] - next[0]).normalize_or_zero() * own.length()
        }
        _ => own,
    }
}
