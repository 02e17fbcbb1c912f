//! Camera placements derived from the planet's own features, so that documentation images and tests find a
//! mountain range or a river on any seed.

use glam::DVec3;

use crate::world::World;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// The whole planet from orbit, centred on the first river.
    Orbit,
    /// Above the first river's source mountain, looking across the range.
    Mountains,
    /// Close above the first river's middle, looking along it.
    River,
    /// Two world units (metres in config/earth.xml) above the first river's water at its middle, looking
    /// downstream along it: the deepest levels of detail.
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
            let segment = &system.segments[system.segments.len() / 2];
            let middle = segment.curve.point(0.5);
            let water = segment.height_at(0.5) as f64;
            let here = up(system.frame.to_sphere(middle));
            // Look at the water 25 eye heights downstream.
            let ahead =
                middle + segment.curve.derivative(0.5).normalize() * 25.0 * GROUND_EYE_HEIGHT;
            let ahead = up(system.frame.to_sphere(ahead));
            (here * (r + water + GROUND_EYE_HEIGHT), ahead * (r + water))
        }
    })
}
