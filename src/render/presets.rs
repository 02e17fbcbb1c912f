//! Camera placements derived from the planet's own features, so that documentation images and tests find a
//! mountain range or a river on any seed.

use glam::DVec3;

use crate::{
    river::{
        samples::sample_step,
        system::{finest_piece_near, RiverSystem, Segment},
    },
    world::World,
};

/// The cameras `render --preset` and the README's pictures use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// The whole planet from orbit, centred on the first river.
    Orbit,
    /// Above the planet's highest peak, looking across its range from the side of the first river's mouth.
    Mountains,
    /// Close above the first river's lower course (its widest segment over land), looking along it.
    River,
    /// Two world units (metres in config/earth.xml) above the first river's water surface on its lower course
    /// (the widest segment whose middle runs over land), looking downstream along it: the deepest levels of
    /// detail.
    Ground,
}

/// Appendix A's planet, for which the presets' distances were chosen: its radius (the orbit and the mountains,
/// a range seen whole, scale with a planet's radius) and its widest river (the river view scales with a planet's
/// rivers). Earth's rivers are a 32,000th of its radius, Appendix A's a 200th: a river view at the radius's scale
/// looked at an Earth river from 155 km up, and saw none.
const APPENDIX_A_RADIUS: f64 = 1024.0;
const APPENDIX_A_WIDEST_RIVER: f64 = 5.0;

/// The beaches' share of the relief above sea level: the river presets look at rivers above them.
const BEACH: f32 = 0.05;

/// Height of the ground preset's eye above the river's water, in world units.
pub const GROUND_EYE_HEIGHT: f64 = 2.0;

/// (eye, look-at) for `preset`, or `None` when the planet has no river.
pub fn camera(preset: Preset, world: &World) -> Option<(DVec3, DVec3)> {
    let system = world.network.systems.first()?;
    let r = world.planet.radius;
    let up = |d: DVec3| d.normalize();
    let height = |d: DVec3| world.planet.height_at(d) as f64;
    let sea = world.planet.sea_level as f64;
    // Distances in Appendix A's world units, and the world units they stand for on this planet.
    let unit = r / APPENDIX_A_RADIUS;
    Some(match preset {
        Preset::Orbit => {
            let d = up(system.source + DVec3::Y * 0.25);
            (d * r * 3.2, DVec3::ZERO)
        }
        Preset::Mountains => {
            let top = highest_point(world);
            let away = (top - system.mouth).normalize_or(top.any_orthonormal_vector());
            let eye_dir = up(top + away * 0.06);
            (
                eye_dir * (r + height(eye_dir).max(sea) + 70.0 * unit),
                top * (r + height(top)),
            )
        }
        Preset::River => river_view(world, system),
        Preset::Ground => {
            let segment = lower_course(world, system);
            // Where the deepest levels draw the river: its finest piece there.
            let network = &world.network;
            let finest = sample_step(network, segment.narrowest());
            let piece =
                finest_piece_near(segment, segment.curve.point(0.5), finest, &network.params);
            let middle = piece.curve.point(0.5);
            // The kernel's water surface in a river (Procedure 5): the basin's top less the water offset.
            let river = &world.config.river;
            let water = (piece.height_at(0.5) + river.basin_depth - river.basin_water_offset)
                .max(world.planet.sea_level) as f64;
            let here = up(system.frame.to_sphere(middle));
            // Look at the water 25 eye heights downstream.
            let ahead = middle + piece.curve.derivative(0.5).normalize() * 25.0 * GROUND_EYE_HEIGHT;
            let ahead = up(system.frame.to_sphere(ahead));
            (here * (r + water + GROUND_EYE_HEIGHT), ahead * (r + water))
        }
    })
}

/// The river preset's eye and target for `system`: above the widest part of its lower course, looking down the
/// river from behind.
pub fn river_view(world: &World, system: &RiverSystem) -> (DVec3, DVec3) {
    let r = world.planet.radius;
    let height = |d: DVec3| world.planet.height_at(d) as f64;
    // Appendix A's river distances at this planet's river scale.
    let river = &world.config.river;
    let river_unit =
        (river.starting_width * river.ending_factor.max(1.0)) as f64 / APPENDIX_A_WIDEST_RIVER;
    // The river as drawn at the scale of the view: pieces no longer than the look ahead.
    let ahead = 40.0 * river_unit;
    let coarse = lower_course(world, system);
    let segment = finest_piece_near(
        coarse,
        coarse.curve.point(0.5),
        ahead,
        &world.network.params,
    );
    let middle = segment.curve.point(0.5);
    let target = system.frame.to_sphere(middle);
    let along = system
        .frame
        .to_sphere(middle + segment.curve.derivative(0.5).normalize() * ahead);
    let back = (target - along).normalize();
    // 0.03 radians of Appendix A's planet, at this planet's river scale.
    let eye_dir = (target + back * 0.03 * APPENDIX_A_RADIUS * river_unit / r).normalize();
    (
        eye_dir * (r + height(eye_dir).max(world.planet.sea_level as f64) + 25.0 * river_unit),
        target * (r + height(target)),
    )
}

/// The direction of the highest point of the precomputed heights.
fn highest_point(world: &World) -> DVec3 {
    let lattice = &world.planet.lattice;
    let (index, _) =
        lattice.data.iter().enumerate().fold(
            (0, f32::MIN),
            |best, (k, &h)| if h > best.1 { (k, h) } else { best },
        );
    let (face, i, j) = lattice.point_of(index);
    lattice.direction(lattice.key(face, i, j))
}

/// The widest segment of `system` whose middle runs over land above the coast's beaches (its lower course, where
/// rivers are widest and meander; a river of the thesis's model may cross a bay on its way and run on at the
/// bay's depth), or its middle segment if none does.
fn lower_course<'a>(world: &World, system: &'a RiverSystem) -> &'a Segment {
    let sea = world.planet.sea_level;
    let inland = sea + BEACH * (world.config.planet.max_mountain_height - sea);
    let on_land = |s: &&Segment| {
        world
            .planet
            .is_land(system.frame.to_sphere(s.curve.point(0.5)))
            && s.height_at(0.5) > inland
    };
    system
        .segments
        .iter()
        .filter(on_land)
        .max_by(|a, b| a.widths.0.total_cmp(&b.widths.0))
        .unwrap_or(&system.segments[system.segments.len() / 2])
}

impl crate::named::Named for Preset {
    const ALL: &'static [(&'static str, Self)] = &[
        ("orbit", Self::Orbit),
        ("mountains", Self::Mountains),
        ("river", Self::River),
        ("ground", Self::Ground),
    ];
}
