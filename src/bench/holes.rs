//! The no-holes check (docs/rendering.md, "No holes"): no pixel whose view ray hits the planet below its lowest
//! terrain may be left uncovered, whatever the level of detail and the streaming did. Used by the render tests
//! and every tenth frame of the descent.
//!
//! The check reads the colour target's alpha, not its colour: the frame is cleared with alpha 0, every opaque
//! surface writes 1, and the blended passes (the sky, the thesis's water) keep the alpha beneath them
//! (`gpu::pipeline::Blend`). So the clear colour can be the one a user sees: the descent's frames were cleared to
//! magenta for the check until the thirty-eighth session, and the sky, which lets the clear colour through its
//! transmittance, came out magenta in every picture of the descent.

use glam::DVec4;

use crate::runtime::camera::Camera;

/// The clear colour `colour` as the check needs it: alpha 0, which only uncovered pixels keep.
pub fn hole_check_clear(colour: [f32; 3]) -> [f32; 4] {
    [colour[0], colour[1], colour[2], 0.0]
}

/// The colour [`Holes::shown_on`] paints holes with (no terrain colour is pure magenta).
const HOLE_MARK: image::Rgba<u8> = image::Rgba([255, 0, 255, 255]);

/// The uncovered pixels of a frame whose rays hit the planet.
pub struct Holes {
    /// The holes, as (x, y).
    pub pixels: Vec<(u32, u32)>,
    /// The pixels whose ray hits the sphere below the lowest terrain: those that must be covered.
    pub inside: usize,
}

impl Holes {
    /// Finds the pixels of `image` (rendered from `camera`, cleared by [`hole_check_clear`]) that no surface
    /// covered although their ray hits the sphere of `inner_radius` (below the lowest terrain).
    pub fn find(image: &image::RgbaImage, camera: &Camera, inner_radius: f64) -> Self {
        let inverse = camera.clip().inverse();
        let (w, h) = image.dimensions();
        let mut holes = Self {
            pixels: Vec::new(),
            inside: 0,
        };
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
            holes.inside += 1;
            if pixel.0[3] == 0 {
                holes.pixels.push((x, y));
            }
        }
        holes
    }

    /// How many holes there are.
    pub fn count(&self) -> usize {
        self.pixels.len()
    }

    /// `image` as a picture to save: opaque (the check's alpha is not transparency), with the holes magenta.
    pub fn shown_on(&self, image: &image::RgbaImage) -> image::RgbaImage {
        let mut shown = image.clone();
        shown.pixels_mut().for_each(|p| p.0[3] = 255);
        for &(x, y) in &self.pixels {
            shown.put_pixel(x, y, HOLE_MARK);
        }
        shown
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A camera looking at a planet of radius 1 from 3 away: the middle pixel's ray hits it, a corner's misses.
    fn setting() -> (Camera, image::RgbaImage) {
        let camera = Camera::look_at(DVec3::new(0.0, 0.0, 3.0), DVec3::ZERO, 60.0, 1.0, 0.01);
        (camera, image::RgbaImage::new(9, 9))
    }

    #[test]
    fn an_uncovered_pixel_on_the_planet_is_a_hole_and_space_is_not() {
        let (camera, mut image) = setting();
        // Everything uncovered: only the planet's pixels count.
        let holes = Holes::find(&image, &camera, 1.0);
        assert!(holes.inside > 0 && holes.inside < 81, "{}", holes.inside);
        assert_eq!(holes.count(), holes.inside);
        assert!(holes.pixels.contains(&(4, 4)));
        assert!(!holes.pixels.contains(&(0, 0)));
        // Covered by an opaque surface (alpha 1), whatever its colour, magenta included.
        image.pixels_mut().for_each(|p| *p = HOLE_MARK);
        image.put_pixel(4, 4, image::Rgba([12, 34, 56, 0]));
        let holes = Holes::find(&image, &camera, 1.0);
        assert_eq!(holes.pixels, vec![(4, 4)]);
        // The picture is opaque, with the hole marked.
        let shown = holes.shown_on(&image);
        assert_eq!(*shown.get_pixel(4, 4), HOLE_MARK);
        assert!(shown.pixels().all(|p| p.0[3] == 255));
    }
}
