//! River networks (Chapter 5): every river system of a planet. The thesis's rivers run as Hermite splines from
//! mountains to the sea (5.1, 5.2.1); with the drainage model, the systems are its reaches (drainage.rs). Both are
//! systems of the one model in system.rs.

use glam::DVec3;

use super::{
    spline::{rotate, Hermite},
    system::{
        enclose, hulls_meet, pieces_to_depth, RiverFrame, RiverSystem, Segment, StreamLevel,
        SubdivisionParams,
    },
};
use crate::{
    config::Config,
    planet::Planet,
    rng::{self, Rng},
};

const STREAM_DIRECTION: u64 = 0x52_0001;

/// The longest river, as an angle on the sphere: keeps every river well inside its frame's hemisphere.
const MAX_RIVER_ANGLE: f64 = 0.6;

/// All river systems of a planet.
#[derive(Clone, Debug)]
pub struct RiverNetwork {
    /// Every river system (a river from its mouth with its tributaries, 5.1).
    pub systems: Vec<RiverSystem>,
    /// The streams finer levels add (drainage model, beyond the thesis; docs/rivers.md "Rivers at every scale"),
    /// coarsest level first: they influence patches of their level and finer.
    pub streams: Vec<StreamLevel>,
    /// How segments are subdivided as the levels grow (5.2).
    pub params: SubdivisionParams,
    /// Subdivision levels included in each river's convex hull (5.2.3).
    pub hull_levels: u32,
    /// How far from a river its samples shape the terrain (Procedure 3).
    pub influence_distance: f64,
    /// Samples per half river width (6.4).
    pub samples_per_half_width: u32,
    /// At most this many samples per vertex spacing (0: no limit; `samples-per-vertex-spacing`).
    pub samples_per_vertex_spacing: u32,
    /// Sources that found no river within `max-attempts` directions.
    pub abandoned_sources: usize,
}

impl RiverNetwork {
    /// Section 5.2.1: one river per mountain where possible. From the mountain top, walk the sphere in a random
    /// direction until the base terrain is no longer land; the Hermite tangents are end minus start, the start one
    /// rotated by 15-45 degrees, the end one flowing straight into the sea. A river whose hull meets another
    /// system's hull tries another direction, up to `max-attempts`.
    ///
    /// With the drainage model, the systems are the planet's drainage network instead ([`super::drainage`]).
    pub fn generate(planet: &Planet, config: &Config, seed: u32) -> Self {
        let params = SubdivisionParams::from_config(config, seed as u64);
        let r = &config.river;
        let network = |systems, streams, abandoned_sources| Self {
            systems,
            streams,
            params,
            hull_levels: r.hull_levels,
            influence_distance: r.influence_distance as f64,
            samples_per_half_width: r.samples_per_half_width,
            samples_per_vertex_spacing: r.samples_per_vertex_spacing,
            abandoned_sources,
        };
        if let Some(drainage) = &planet.drainage {
            let systems = super::drainage::systems(drainage, planet.radius, config, &params);
            let streams =
                super::drainage::stream_levels(planet, config, &params, systems.len() as u32);
            return network(systems, streams, 0);
        }
        let step = (0.25f64).to_radians();
        let mut systems: Vec<RiverSystem> = Vec::new();
        let mut abandoned = 0;
        for (index, mountain) in planet.mountains.iter().enumerate() {
            let source = DVec3::from_array(mountain.direction);
            let mut rng = Rng::new(seed as u64, &[STREAM_DIRECTION, index as u64]);
            let mut placed = false;
            for _ in 0..r.max_attempts {
                let heading = rng.range_f64(0.0, std::f64::consts::TAU);
                let tangent = {
                    let east = DVec3::Y.cross(source).try_normalize().unwrap_or(DVec3::X);
                    let north = source.cross(east);
                    east * heading.cos() + north * heading.sin()
                };
                let Some(mouth) = walk_to_sea(planet, source, tangent, step) else {
                    continue;
                };
                let id = systems.len() as u32;
                let system = build_system(planet, config, &params, id, source, mouth, &mut rng);
                if systems.iter().all(|other| !hulls_meet(&system, other)) {
                    systems.push(system);
                    placed = true;
                    break;
                }
            }
            if !placed {
                abandoned += 1;
            }
        }
        network(systems, Vec::new(), abandoned)
    }

    /// Rivers and tributaries down to `depth`.
    pub fn count(&self, depth: u32) -> (usize, usize) {
        let tributaries = self
            .systems
            .iter()
            .map(|s| {
                pieces_to_depth(&s.segments, depth, &self.params)
                    .iter()
                    .filter(|p| p.generation > 0 && p.branch == p.key)
                    .count()
            })
            .sum();
        (self.systems.len(), tributaries)
    }

    /// The full width of the widest water: the widest river's end or lake. Subdivision interpolates the initial
    /// segments' widths and tributaries are narrower than their parents, so the initial segments bound it.
    pub fn widest(&self) -> f64 {
        self.systems
            .iter()
            .flat_map(|s| &s.segments)
            .map(|segment| segment.widths.0.max(segment.widths.1) as f64)
            .fold(0.0, f64::max)
    }
}

/// Walks from `source` along the great circle of `tangent` until the terrain is sea; `None` if that takes more
/// than the longest river.
fn walk_to_sea(planet: &Planet, source: DVec3, tangent: DVec3, step: f64) -> Option<DVec3> {
    let mut angle = 0.0;
    while angle < MAX_RIVER_ANGLE {
        angle += step;
        let p = source * angle.cos() + tangent * angle.sin();
        if !planet.is_land(p) {
            return Some(p);
        }
    }
    None
}

fn build_system(
    planet: &Planet,
    config: &Config,
    params: &SubdivisionParams,
    id: u32,
    source: DVec3,
    mouth: DVec3,
    rng: &mut Rng,
) -> RiverSystem {
    let r = &config.river;
    let frame = RiverFrame::new((source + mouth).normalize(), mouth, planet.radius);
    let (s, e) = (
        frame.to_plane(source).unwrap_or_default(),
        frame.to_plane(mouth).unwrap_or_default(),
    );
    let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
    let whole = Hermite {
        p0: s,
        d0: rotate(e - s, sign * rng.range_f64(15.0, 45.0).to_radians()),
        p1: e,
        d1: e - s,
    };
    let m = r.segments;
    // Heights: from the source's terrain down to at most sea level at the mouth, never rising, and never above
    // the terrain at a knot (so rivers cut valleys instead of riding on embankments).
    let mut heights = Vec::with_capacity(m as usize + 1);
    for k in 0..=m {
        let t = k as f64 / m as f64;
        let terrain = planet.height_at(frame.to_sphere(whole.point(t)));
        let previous = heights.last().copied().unwrap_or(f32::MAX);
        let mut h = terrain.min(previous);
        if k == m {
            h = h.min(planet.sea_level);
        }
        heights.push(h);
    }
    let width = |t: f64| r.starting_width * (1.0 + (r.ending_factor - 1.0) * t as f32);
    let branch = rng::hash(params.seed, &[0x6d61_696e, id as u64]);
    let segments: Vec<Segment> = (0..m as usize)
        .map(|k| {
            let (t0, t1) = (k as f64 / m as f64, (k + 1) as f64 / m as f64);
            Segment {
                curve: whole.piece(t0, t1),
                heights: (heights[k], heights[k + 1]),
                widths: (width(t0), width(t1)),
                key: rng::hash(branch, &[k as u64]),
                depth: 0,
                generation: 0,
                branch,
                parent_branch: None,
                river: branch,
                lake: false,
            }
        })
        .collect();
    enclose(
        config,
        params,
        (id, r.hull_levels),
        frame,
        segments,
        (source, mouth),
    )
}
