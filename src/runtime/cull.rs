//! Discarding patches the camera cannot see (Section 6.2.2): those beyond the horizon (the thesis's back-facing
//! test, made conservative for terrain height) and those outside the view frustum. Both tests bound every point
//! a patch can place on screen (terrain included), so no patch with a visible pixel is culled. Beyond the thesis,
//! which culls whole patches, the tests run per quadrant: a patch at the edge of the view draws only what shows.

use glam::{DMat4, DVec3, DVec4};

use super::lod::Selected;
use crate::planet::cube::{angle, PatchId};

/// The six planes of a view frustum, inward normals, as (normal, distance): inside when `n . p + d >= 0`.
#[derive(Clone, Copy, Debug)]
pub struct Frustum {
    planes: [DVec4; 6],
}

impl Frustum {
    /// From a world-to-clip matrix with depth in [0, 1] (Vulkan). A plane at infinity (the far plane of an
    /// infinite projection) has no normal and never culls.
    pub fn from_matrix(m: DMat4) -> Self {
        let r = |i: usize| m.row(i);
        let planes = [
            r(3) + r(0),
            r(3) - r(0),
            r(3) + r(1),
            r(3) - r(1),
            r(2),
            r(3) - r(2),
        ]
        .map(|p| {
            let length = p.truncate().length();
            if length > 1e-12 {
                p / length
            } else {
                DVec4::new(0.0, 0.0, 0.0, 1.0)
            }
        });
        Self { planes }
    }

    /// Whether a sphere touches the frustum.
    pub fn touches_sphere(&self, centre: DVec3, radius: f64) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(centre) + p.w >= -radius)
    }
}

/// Heights every point of the planet lies between (base terrain and rivers).
#[derive(Clone, Copy, Debug)]
pub struct HeightRange {
    /// The lowest, above the sphere of the planet's radius (negative below it).
    pub min: f64,
    /// The highest.
    pub max: f64,
}

/// A sphere containing every point of a patch between the heights of `range`, with a margin of a tenth of a
/// quarter patch's chord. Its centre lies on the patch's centre direction, and a point's distance from it grows
/// with the point's angle from that direction and is convex in the point's height; the patch's edges are
/// great-circle arcs (gnomonic faces), along which the angle is largest at an end, so the farthest point is a
/// corner at the lowest or highest height: four corners give the radius a grid over the patch gives (25 points
/// did, at six times the cost: it was most of the culling's time in the thesis's stress flight).
pub fn bounding_sphere(patch: PatchId, radius: f64, range: HeightRange) -> (DVec3, f64) {
    let centre_dir = patch.center();
    let centre = centre_dir * (radius + 0.5 * (range.min + range.max));
    let mut r: f64 = 0.0;
    for d in patch.corners() {
        for h in [range.min, range.max] {
            r = r.max(centre.distance(d * (radius + h)));
        }
    }
    let step = patch
        .sphere_point(0.0, 0.0)
        .distance(patch.sphere_point(0.25, 0.25))
        * (radius + range.max);
    (centre, r + 0.1 * step + 1e-3)
}

/// Whether the whole patch is hidden behind the planet: every point of it (up to the highest terrain) lies
/// beyond the horizon of the lowest terrain. Conservative on a sphere: the angle from the camera direction to the
/// nearest point of the patch exceeds the horizon angle of the camera plus that of the highest point.
pub fn beyond_horizon(patch: PatchId, camera: DVec3, radius: f64, range: HeightRange) -> bool {
    let low = radius + range.min;
    let high = radius + range.max;
    let distance = camera.length();
    if distance <= low {
        return false;
    }
    let nearest = (angle(patch.center(), camera) - patch.cap_angle()).max(0.0);
    let horizon = (low / distance).acos() + (low / high).min(1.0).acos();
    nearest > horizon
}

/// `selected` less the quadrants the camera at `camera` cannot see through `frustum`, every point of the patch
/// lying between the heights of `range`; `None` when no quadrant shows.
pub fn visible_quadrants(
    selected: &Selected,
    camera: DVec3,
    frustum: &Frustum,
    radius: f64,
    range: HeightRange,
) -> Option<Selected> {
    let seen = |q: &u32| {
        let quadrant = selected.patch.child(*q);
        let (centre, r) = bounding_sphere(quadrant, radius, range);
        !beyond_horizon(quadrant, camera, radius, range) && frustum.touches_sphere(centre, r)
    };
    let quadrants = (0..4)
        .filter(|q| selected.quadrants & (1 << q) != 0)
        .filter(seen)
        .fold(0, |mask, q| mask | 1 << q);
    (quadrants != 0).then_some(Selected {
        patch: selected.patch,
        quadrants,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The corners bound the patch as a 9 x 9 grid over it does, to the bit, on every patch of levels 0-4 of
    /// every face and on small and tall height ranges.
    #[test]
    fn the_corners_are_the_farthest_points_of_a_patch() {
        let radius = 1024.0;
        for level in 0..=4u8 {
            for face in 0..6u8 {
                let n = 1u32 << level;
                for k in 0..n * n {
                    let patch = PatchId {
                        face,
                        level,
                        x: k % n,
                        y: k / n,
                    };
                    for (min, max) in [(0.0, 0.0), (-3.0, 40.0), (-0.5, 0.7)] {
                        let range = HeightRange { min, max };
                        let (centre, r) = bounding_sphere(patch, radius, range);
                        let mut grid: f64 = 0.0;
                        for j in 0..=8 {
                            for i in 0..=8 {
                                let d = patch.sphere_point(i as f64 / 8.0, j as f64 / 8.0);
                                for h in [min, max] {
                                    grid = grid.max(centre.distance(d * (radius + h)));
                                }
                            }
                        }
                        let step = patch
                            .sphere_point(0.0, 0.0)
                            .distance(patch.sphere_point(0.25, 0.25))
                            * (radius + max);
                        assert_eq!(r, grid + 0.1 * step + 1e-3, "{patch:?} {min} {max}");
                    }
                }
            }
        }
    }
}
