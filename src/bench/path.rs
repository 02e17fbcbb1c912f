//! The scripted cameras of the experiments (Section 9.2): from orbit down to a river, then low along it towards the
//! sea. The stress test (9.2) moves the camera 25 times faster: the descent is over after a 25th of the frames and
//! the low flight covers 25 times the distance. Beyond the thesis, the descent to the ground: from three radii
//! out straight down to the ground preset (two world units above the first river's water), for the deepest levels
//! of detail.

use glam::DVec3;

use crate::{
    render::presets::GROUND_EYE_HEIGHT,
    runtime::{camera::Camera, camera_path::CameraPath},
    world::World,
};

/// A flight of `frames` frames over `world`.
#[derive(Clone, Debug)]
pub struct Flight {
    /// A recorded camera path replayed frame by frame instead of the scripted cameras.
    recorded: Option<CameraPath>,
    /// The descent to the ground: (eye at the end, look-at at the end); `None` for the thesis's flight.
    ground: Option<(DVec3, DVec3)>,
    start: DVec3,
    end: DVec3,
    radius: f64,
    frames: u32,
    speed: f64,
    aspect: f64,
}

/// Where the descent starts and ends: 3.5 radii from the centre, and 6 units above the ground.
const START_ALTITUDE_RADII: f64 = 2.5;
const END_ALTITUDE: f64 = 6.0;
/// Share of an unstressed flight spent descending.
const DESCENT: f64 = 0.6;

impl Flight {
    /// A flight of `frames` frames; `speed` multiplies the camera's speed (25 in the stress test).
    pub fn new(world: &World, frames: u32, speed: f64, aspect: f64) -> Self {
        let (start, end) = match world.network.systems.first() {
            Some(s) => (s.source, s.mouth),
            None => (DVec3::Z, DVec3::new(0.3, 0.0, 1.0).normalize()),
        };
        Self {
            recorded: None,
            ground: None,
            start,
            end,
            radius: world.planet.radius,
            frames: frames.max(1),
            speed: speed.max(0.01),
            aspect,
        }
    }

    /// The descent to the ground preset in `frames` frames (`None` when the planet has no river): in the first 60 %
    /// (the thesis flight's share of descending) the altitude falls geometrically from two radii (three from the
    /// centre) to the preset's eye while the view turns from the planet's centre to the preset's target; then the
    /// camera stays two units above the water and turns a quarter round, so new views stream in at the bottom.
    pub fn descent(world: &World, frames: u32, aspect: f64) -> Option<Self> {
        let ground = crate::render::presets::camera(crate::render::presets::Preset::Ground, world)?;
        let mut flight = Self::new(world, frames, 1.0, aspect);
        flight.ground = Some(ground);
        Some(flight)
    }

    /// A recorded camera path (beyond the thesis: `view --record`, the viewer's bookmarks), one frame each.
    pub fn recorded(world: &World, path: CameraPath, aspect: f64) -> Self {
        let mut flight = Self::new(world, path.frames.len() as u32, 1.0, aspect);
        flight.recorded = Some(path);
        flight
    }

    /// The camera at `frame`.
    pub fn camera(&self, world: &World, frame: u32) -> Camera {
        if let Some(path) = &self.recorded {
            let last = path.frames.len() - 1;
            return path.frames[(frame as usize).min(last)].camera(self.aspect);
        }
        if let Some((eye, target)) = self.ground {
            return self.descent_camera(eye, target, frame);
        }
        let s = frame as f64 / self.frames as f64 * self.speed;
        let descent = (s / DESCENT).min(1.0);
        // Along the great circle from the source towards the mouth (and beyond, for long flights).
        let axis = self
            .start
            .cross(self.end)
            .try_normalize()
            .unwrap_or(DVec3::Y);
        let span = self.start.angle_between(self.end).max(0.05);
        let travel = span * (0.3 * descent + ((s - DESCENT).max(0.0) / (1.0 - DESCENT)) * 0.7);
        let rotate = |angle: f64| glam::DQuat::from_axis_angle(axis, angle);
        let here = rotate(travel) * self.start;
        let ground = self.radius + world.planet.height_at(here).max(world.planet.sea_level) as f64;
        let high = self.radius * START_ALTITUDE_RADII;
        let altitude = high * (END_ALTITUDE / high).powf(descent);
        let eye = here * (ground + altitude);
        // From looking at the planet's centre to looking ahead along the flight, tilted down.
        let ahead = rotate(travel + span * 0.2) * self.start * ground;
        let target = DVec3::ZERO.lerp(ahead, descent.powf(0.5));
        let target = if (target - eye).length() < 1e-6 {
            DVec3::ZERO
        } else {
            target
        };
        Camera::look_at(
            eye,
            target,
            60.0,
            self.aspect,
            crate::runtime::camera::near_plane(altitude),
        )
    }

    fn descent_camera(&self, end: DVec3, target: DVec3, frame: u32) -> Camera {
        let progress = (frame as f64 / (self.frames - 1).max(1) as f64).min(1.0);
        let s = (progress / DESCENT).min(1.0);
        let turn = ((progress - DESCENT) / (1.0 - DESCENT)).max(0.0) * std::f64::consts::FRAC_PI_2;
        let ground = end.length() - GROUND_EYE_HEIGHT;
        let high = 3.0 * self.radius - ground;
        let altitude = high * (GROUND_EYE_HEIGHT / high).powf(s);
        let eye = end.normalize() * (ground + altitude);
        let target = end + glam::DQuat::from_axis_angle(end.normalize(), turn) * (target - end);
        let look = DVec3::ZERO.lerp(target, s.powf(0.25));
        Camera::look_at(
            eye,
            look,
            60.0,
            self.aspect,
            crate::runtime::camera::near_plane(altitude),
        )
    }
}
