//! The no-holes check (docs/rendering.md, "No holes"): with the clear colour magenta, no pixel whose view ray hits
//! the planet below its lowest terrain may show the clear colour, whatever the level of detail and the streaming
//! did. Used by the render tests and every tenth frame of the descent.

use glam::DVec4;

use crate::runtime::camera::Camera;

/// The clear colour the check looks for (no terrain colour is pure magenta).
pub const HOLE_COLOUR: [f32; 4] = [1.0, 0.0, 1.0, 1.0];

/// Pixels of `image` (rendered from `camera` with [`HOLE_COLOUR`] as the clear colour) that show the clear colour
/// although their ray hits the sphere of `inner_radius` (below the lowest terrain), and how many such rays there
/// are: (holes, inside).
pub fn hole_pixels(image: &image::RgbaImage, camera: &Camera, inner_radius: f64) -> (usize, usize) {
    let inverse = camera.clip().inverse();
    let (w, h) = image.dimensions();
    let (mut holes, mut inside) = (0, 0);
    for (x, y, pixel) in image.enumerate_pixels() {
        let ndc = |v: f64, n: u32| (v + 0.5) / n as f64 * 2.0 - 1.0;
        let unproject = |z: f64| {
            let p = inverse * DVec4::new(ndc(x as f64, w), ndc(y as f64, h), z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (unproject(1.0), unproject(1e-6));
        let dir = (far - near).normalize();
        let b = near.dot(dir);
        let c = near.length_squared() - inner_radius * inner_radius;
        if b * b - c < 0.0 || -b - (b * b - c).sqrt() < 0.0 {
            continue;
        }
        inside += 1;
        if pixel.0[0] == 255 && pixel.0[1] == 0 && pixel.0[2] == 255 {
            holes += 1;
        }
    }
    (holes, inside)
}
