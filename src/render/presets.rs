//! Camera placements derived from the planet's own features, so that documentation images and tests find a
//! mountain range or a river on any seed.

use glam::DVec3;

use crate::{
    river::{network::finest_piece_near, samples::sample_step},
    world::World,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// The whole planet from orbit, centred on the first river.
    Orbit,
    /// Above the first river's source mountain, looking across the range.
    Mountains,
    /// Close above the first river's middle, looking along it.
    River,
    /// Two world units (metres in config/earth.xml) above the first river's water surface near its middle (the
    /// middle of the segment nearest the river's middle that runs over land), looking downstream along it: the
    /// deepest levels of detail.
    Ground,
}

/// The radius of Appendix A's planet, for which the presets' distances were chosen.
const APPENDIX_A_RADIUS: f64 = 1024.0;

/// Height of the ground preset's eye above the river's water, in world units.
pub const GROUND_EYE_HEIGHT: f64 = 2.0;

/// (eye, look-at) for `preset`, or `None` when the planet has no river.
pub fn camera(preset: Preset, world: &World) -> Option<(DVec3, DVec3)> {
    let system = world.network.systems.first()?;
    let r = world.planet.radius;
    let up = |d: DVec3| d.normalize();
    let height = |d: DVec3| world.planet.height_at(d) as f64;
    // Distances were chosen on Appendix A's planet (radius 1024) and scale with the radius.
    let unit = r / APPENDIX_A_RADIUS;
    let sea = world.planet.sea_level as f64;
    Some(match preset {
        Preset::Orbit => {
            let d = up(system.source + DVec3::Y * 0.25);
            (d * r * 3.2, DVec3::ZERO)
        }
        Preset::Mountains => {
            let top = system.source;
            let away = (system.source - system.mouth).normalize();
            let eye_dir = up(top + away * 0.06);
            (
                eye_dir * (r + height(eye_dir).max(sea) + 70.0 * unit),
                top * (r + height(top)),
            )
        }
        Preset::River => {
            let middle = system.segments[system.segments.len() / 2].curve.point(0.5);
            let target = system.frame.to_sphere(middle);
            let along = system.frame.to_sphere(
                middle
                    + system.segments[system.segments.len() / 2]
                        .curve
                        .derivative(0.5)
                        .normalize()
                        * 40.0
                        * unit,
            );
            let back = (target - along).normalize();
            let eye_dir = up(target + back * 0.03);
            (
                eye_dir * (r + height(eye_dir).max(sea) + 25.0 * unit),
                target * (r + height(target)),
            )
        }
        Preset::Ground => {
            // The segment nearest the river's middle whose middle runs over land above sea level (a river of
            // the thesis's model may cross a bay on its way and run on at the bay's depth).
            let count = system.segments.len();
            let on_land = |s: &&crate::river::network::Segment| {
                world
                    .planet
                    .is_land(system.frame.to_sphere(s.curve.point(0.5)))
                    && s.height_at(0.5) > world.planet.sea_level
            };
            let mut by_distance: Vec<usize> = (0..count).collect();
            by_distance.sort_by_key(|k| k.abs_diff(count / 2));
            let segment = by_distance
                .iter()
                .map(|&k| &system.segments[k])
                .find(on_land)
                .unwrap_or(&system.segments[count / 2]);
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

impl crate::named::Named for Preset {
    const ALL: &'static [(&'static str, Self)] = &[
        ("orbit", Self::Orbit),
        ("mountains", Self::Mountains),
        ("river", Self::River),
        ("ground", Self::Ground),
    ];
}
