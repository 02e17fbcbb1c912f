//! The camera: position in world coordinates (planet centre at the origin), orientation, and a reversed-Z
//! infinite perspective for Vulkan (depth 1 at the near plane, 0 at infinity; clip y pointing down), in f64.
//! Reversed Z with a 32-bit float depth buffer keeps depth precise from a metre above the ground to orbit.

use glam::{DMat4, DVec3, DVec4};

/// A view of the planet: where from, where to, and the perspective.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The eye (planet centre at the origin).
    pub position: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Approximate up (made orthogonal to `forward`).
    pub up: DVec3,
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Width over height of the viewport.
    pub aspect: f64,
    /// The near plane's distance (`near_plane`).
    pub near: f64,
}

/// The near plane for a camera `altitude` above the drawn surface below it: a twentieth of it, between 1 cm and 10
/// units, so that the surface in front of the camera is never clipped (with reversed Z the depth stays precise
/// whatever the near plane).
pub fn near_plane(altitude: f64) -> f64 {
    (altitude * 0.05).clamp(0.01, 10.0)
}

impl Camera {
    /// A camera at `eye` looking at `target`, with up towards the planet's outward normal at the eye.
    pub fn look_at(eye: DVec3, target: DVec3, fov_y_degrees: f64, aspect: f64, near: f64) -> Self {
        let forward = (target - eye).normalize();
        let mut up = eye.normalize_or(DVec3::Y);
        if up.cross(forward).length() < 1e-6 {
            up = forward.any_orthonormal_vector();
        }
        Self {
            position: eye,
            forward,
            up,
            fov_y: fov_y_degrees.to_radians(),
            aspect,
            near,
        }
    }

    /// World -> view (camera at the origin, looking down -Z, right-handed).
    pub fn view(&self) -> DMat4 {
        self.rotation() * DMat4::from_translation(-self.position)
    }

    /// Camera-relative world -> view: the rotation only (for camera-relative rendering).
    pub fn rotation(&self) -> DMat4 {
        let f = self.forward.normalize();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        DMat4::from_cols(
            DVec4::new(s.x, u.x, -f.x, 0.0),
            DVec4::new(s.y, u.y, -f.y, 0.0),
            DVec4::new(s.z, u.z, -f.z, 0.0),
            DVec4::W,
        )
    }

    /// View -> clip: reversed-Z, infinite far plane, y down.
    pub fn projection(&self) -> DMat4 {
        let f = 1.0 / (self.fov_y * 0.5).tan();
        DMat4::from_cols(
            DVec4::new(f / self.aspect, 0.0, 0.0, 0.0),
            DVec4::new(0.0, -f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 0.0, -1.0),
            DVec4::new(0.0, 0.0, self.near, 0.0),
        )
    }

    /// World -> clip.
    pub fn clip(&self) -> DMat4 {
        self.projection() * self.view()
    }
}
