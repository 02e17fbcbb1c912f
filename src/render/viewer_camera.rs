//! The viewer's camera, in two modes (beyond the thesis, issue "For the people who use it"): fly (move with keys,
//! look with arrows or a drag) and orbit (a drag turns the view around the planet's centre, as a globe turns under
//! the hand); in both, the wheel zooms towards or away from the ground, and speeds follow the altitude.

use std::path::Path;

use glam::{DQuat, DVec3};

use crate::runtime::{camera::Camera, camera_path::FOV_DEGREES};

/// What a drag does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraMode {
    /// A drag looks around; keys move.
    Fly,
    /// A drag turns the view around the planet's centre.
    Orbit,
}

/// Radians per pixel of a drag (fly: the view turns; orbit: at an altitude of one planet radius or more).
const DRAG_RADIANS: f64 = 0.004;

/// How much of the altitude one wheel line takes away (zooming in) or adds (out, as 1 / (1 - ZOOM_STEP) - 1).
const ZOOM_STEP: f64 = 0.15;

/// Position and orientation. The screen's `up` is kept, not derived, so that the view straight down at the
/// planet, where the orbit mode starts, has a steady orientation.
#[derive(Clone, Copy, Debug)]
pub struct ViewerCamera {
    /// Where the camera is (planet centre at the origin).
    pub position: DVec3,
    /// Where it looks (unit).
    pub forward: DVec3,
    /// The screen's up (unit, orthogonal to `forward`).
    pub up: DVec3,
    /// Flying or orbiting.
    pub mode: CameraMode,
}

impl ViewerCamera {
    /// At `eye` looking at `target`, levelled to the planet's horizon.
    pub fn new(eye: DVec3, target: DVec3, mode: CameraMode) -> Self {
        let forward = (target - eye).normalize();
        let mut camera = Self {
            position: eye,
            forward,
            up: forward.any_orthonormal_vector(),
            mode,
        };
        camera.level_up();
        camera
    }

    /// The screen's right (unit).
    pub fn right(&self) -> DVec3 {
        self.forward.cross(self.up).normalize()
    }

    /// The outward normal of the planet below the camera.
    pub fn radial(&self) -> DVec3 {
        self.position.normalize()
    }

    /// Turns the screen's up towards the planet's outward normal (the horizon level), where the view is not
    /// straight down or up; otherwise keeps it.
    fn level_up(&mut self) {
        if let Some(up) =
            (self.radial() - self.forward * self.forward.dot(self.radial())).try_normalize()
        {
            if self.forward.dot(self.radial()).abs() < 0.995 {
                self.up = up;
                return;
            }
        }
        self.up = (self.up - self.forward * self.forward.dot(self.up)).normalize();
    }

    /// Fly: turns the view by `yaw` about the planet's normal and `pitch` about the screen's right.
    pub fn turn(&mut self, yaw: f64, pitch: f64) {
        let f = DQuat::from_axis_angle(self.radial(), -yaw) * self.forward;
        let f = DQuat::from_axis_angle(self.right(), pitch) * f;
        // Keep away from looking straight up or down, where the horizon is undefined.
        if f.dot(self.radial()).abs() < 0.995 {
            self.forward = f.normalize();
            self.level_up();
        }
    }

    /// A drag of (`dx`, `dy`) pixels: fly looks around; orbit turns position and view together around the planet's
    /// centre, the ground following the cursor, by angles that shrink with `altitude` so that a drag moves the
    /// ground across the screen at about the same rate at any height.
    pub fn drag(&mut self, dx: f64, dy: f64, altitude: f64) {
        match self.mode {
            CameraMode::Fly => self.turn(dx * DRAG_RADIANS, -dy * DRAG_RADIANS),
            CameraMode::Orbit => {
                let k = DRAG_RADIANS * (altitude / self.position.length()).clamp(1e-7, 1.0);
                let q = DQuat::from_axis_angle(self.up, -dx * k)
                    * DQuat::from_axis_angle(self.right(), -dy * k);
                self.position = q * self.position;
                self.forward = (q * self.forward).normalize();
                self.up = (q * self.up).normalize();
            }
        }
    }

    /// `lines` of the wheel (positive: in): along the planet's normal, a share of the `altitude` per line, so the
    /// ground is approached ever slower and never reached (the viewer also keeps the camera above it).
    pub fn zoom(&mut self, lines: f64, altitude: f64) {
        let factor = (1.0 - ZOOM_STEP).powf(lines);
        self.position += self.radial() * altitude.max(0.0) * (factor - 1.0);
    }

    /// The camera to render with.
    pub fn camera(&self, aspect: f64, near: f64) -> Camera {
        let mut camera = Camera::look_at(
            self.position,
            self.position + self.forward,
            FOV_DEGREES,
            aspect,
            near,
        );
        camera.up = self.up;
        camera
    }

    /// The JSON sidecar of a screenshot `image` of this view (beyond the thesis: a bookmark): the `seed` and
    /// `frame`, the camera, and the `render` command (with `config` where one was given) that makes the same
    /// image of `size` pixels.
    pub fn sidecar(
        &self,
        image: &str,
        (seed, frame): (u32, u64),
        altitude: f64,
        [w, h]: [u32; 2],
        config: Option<&Path>,
    ) -> serde_json::Value {
        let target = self.position + self.forward * altitude.max(1.0);
        let vector = |v: DVec3| format!("{},{},{}", v.x, v.y, v.z);
        let config = config.map_or(String::new(), |c| format!(" --config {}", c.display()));
        serde_json::json!({
            "image": image,
            "seed": seed,
            "frame": frame,
            "camera": {
                "mode": format!("{:?}", self.mode),
                "position": [self.position.x, self.position.y, self.position.z],
                "forward": [self.forward.x, self.forward.y, self.forward.z],
                "up": [self.up.x, self.up.y, self.up.z],
                "altitude": altitude,
            },
            "render": format!(
                "riverplanet render{config} --seed {seed} --size {w}x{h} --eye={} --look-at={} --up={} \
                 --fov {FOV_DEGREES} --out {image}",
                vector(self.position),
                vector(target),
                vector(self.up)
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn orbit_view() -> ViewerCamera {
        ViewerCamera::new(DVec3::new(0.0, 0.0, 3000.0), DVec3::ZERO, CameraMode::Orbit)
    }

    #[test]
    fn an_orbit_drag_keeps_the_distance_and_the_planet_centre_in_view_and_follows_the_cursor() {
        let mut c = orbit_view();
        let right = c.right();
        c.drag(100.0, 0.0, 2000.0);
        assert!((c.position.length() - 3000.0).abs() < 1e-9);
        // Still looking at the centre.
        assert!(c.forward.dot(-c.radial()) > 1.0 - 1e-12);
        // Dragging right moves the camera left: the ground follows the cursor.
        assert!(c.position.dot(right) < 0.0);
    }

    #[test]
    fn orbit_drags_are_slower_near_the_ground() {
        let turned = |altitude: f64| {
            let mut c = orbit_view();
            c.drag(100.0, 0.0, altitude);
            c.position.angle_between(DVec3::Z)
        };
        assert!(turned(10.0) < turned(1000.0) / 50.0);
    }

    #[test]
    fn the_wheel_approaches_the_ground_without_reaching_it_and_backs_out_again() {
        let mut c = orbit_view();
        let ground = 1000.0;
        for _ in 0..200 {
            let altitude = c.position.length() - ground;
            c.zoom(1.0, altitude);
        }
        let altitude = c.position.length() - ground;
        assert!(altitude > 0.0 && altitude < 1e-6, "altitude {altitude}");
        c.zoom(-3.0, 1.0);
        assert!(c.position.length() - ground > 0.5);
    }

    #[test]
    fn fly_turns_keep_the_horizon_level() {
        let mut c = ViewerCamera::new(
            DVec3::new(0.0, 0.0, 1010.0),
            DVec3::new(100.0, 0.0, 1005.0),
            CameraMode::Fly,
        );
        c.drag(40.0, 10.0, 10.0);
        // The screen's right stays in the local horizontal plane.
        assert!(c.right().dot(c.radial()).abs() < 1e-9);
        assert!((c.up.length() - 1.0).abs() < 1e-12 && c.up.dot(c.forward).abs() < 1e-12);
    }
}
