//! Quadtree level of detail (Section 6.2.1, Procedure 2): a patch is refined while the camera is nearer than its
//! level's switch distance, which comes from Eq. 6.1 (the thesis) or from the level's geometric error projected to
//! a number of pixels (screen-space error, beyond the thesis).

use std::sync::Arc;

use glam::DVec3;

use super::error_field::ErrorField;
use crate::drainage::meanders::apex_curvature;
use crate::planet::{
    cube::{angle, PatchId, FACES},
    Planet,
};

/// A patch to draw and which of its quadrants (bit q: child q, see [`PatchId::child`]) are not covered by finer
/// patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Selected {
    /// The patch.
    pub patch: PatchId,
    /// Its quadrants drawn, as above.
    pub quadrants: u8,
}

/// Eq. 6.1: the distance below which a patch of level `lod` is refined.
pub fn threshold(radius: f64, switch_factor: f64, lod: u32) -> f64 {
    radius * switch_factor / (1u64 << lod) as f64
}

/// Beyond the thesis: the error of a level's river data, for the screen-space rule. The kernel measures rivers
/// at the vertices within the influence distance of their samples (6.5), so on a level whose vertices are more
/// than twice that apart (`spacing`, in the patch frame), a river or lake between two vertices reaches neither and
/// is not drawn: water up to the widest's width (`widest`) is missing. Closer vertices always measure it (the banks
/// painted from what they measured have an error of their own, [`painted_bank_error`]).
pub fn river_error(spacing: f64, influence_distance: f64, widest: f64) -> f64 {
    if spacing > 2.0 * influence_distance {
        widest
    } else {
        0.0
    }
}

/// Beyond the thesis: how far a river painted from the signed distances at vertices `spacing` apart (in the patch
/// frame) can draw its banks from where they are, for the screen-space rule; 0 where the mesh carves it instead
/// (`spacing` below the `half_width`, Section 8.4's rule). Interpolated linearly, the signed distance to a straight
/// river is exact, and the bank (where it equals the half width, changing by one unit per unit) lies where it is.
/// Across a bend of curvature k the distance's second derivative at the inner bank is k / (1 - k w), and linear
/// interpolation over a triangle misses by up to half of that times the square of its circumradius, s / sqrt 2 for
/// the mesh's right triangles of legs s. The tightest bend is a meander's apex
/// (`drainage::meanders::apex_curvature`, about 0.41 / w). At most the half width: a river drawn further aside
/// is at worst a river of its width drawn elsewhere.
pub fn painted_bank_error(spacing: f64, half_width: f64) -> f64 {
    if half_width <= 0.0 || spacing < half_width {
        return 0.0;
    }
    let k = apex_curvature(half_width);
    (spacing * spacing / 4.0 * k / (1.0 - k * half_width)).min(half_width)
}

/// The parameters of the selection: the switch distance of every patch.
#[derive(Clone, Debug)]
pub struct LodParams {
    /// The planet's radius: distances are measured to patches on this sphere.
    pub radius: f64,
    /// No patch finer than this level is selected.
    pub max_level: u32,
    switch: Switch,
}

/// Where switch distances come from.
#[derive(Clone, Debug)]
enum Switch {
    /// Per level 0..=max_level: the distance below which a patch of that level is refined (visited).
    Levels(Vec<f64>),
    /// The error field's corner values times the pixels' distance per unit of error.
    Field { errors: Arc<ErrorField>, scale: f64 },
}

impl LodParams {
    /// The thesis's rule: Eq. 6.1 at every level.
    pub fn distance(radius: f64, switch_factor: f64, max_level: u32) -> Self {
        Self {
            radius,
            max_level,
            switch: Switch::Levels(
                (0..=max_level)
                    .map(|level| threshold(radius, switch_factor, level))
                    .collect(),
            ),
        }
    }

    /// Screen-space error (beyond the thesis): a patch is visited while the error its parent would show over it
    /// (`errors`, nested so that a child's range lies inside its parent's and patches meet only patches one level
    /// apart) would cover more than `pixels` pixels, i.e. while it is nearer than
    /// `error x pixels_per_radian / pixels`, where `pixels_per_radian` is the viewport height over
    /// 2 tan(fov_y / 2). No patch is then drawn with more than `pixels` of error.
    pub fn screen_space(
        radius: f64,
        errors: Arc<ErrorField>,
        pixels_per_radian: f64,
        pixels: f64,
        max_level: u32,
    ) -> Self {
        Self {
            radius,
            max_level,
            switch: Switch::Field {
                errors,
                scale: pixels_per_radian / pixels,
            },
        }
    }

    /// The switch distances at `patch`'s corners (0,0), (1,0), (0,1), (1,1); bilinear across the patch, they are
    /// where its vertices are fully morphed into the parent's mesh.
    pub fn switch_distances(&self, patch: PatchId) -> [f64; 4] {
        let level = (patch.level as u32).min(self.max_level);
        match &self.switch {
            Switch::Levels(t) => [t[level as usize]; 4],
            Switch::Field { errors, scale } => errors.corners(patch).map(|e| e * scale),
        }
    }

    /// The distance below which `patch` is visited: the largest of its corners' switch distances, so that where
    /// it is not visited, every point of it lies beyond the switch distance there.
    pub fn threshold(&self, patch: PatchId) -> f64 {
        self.switch_distances(patch).into_iter().fold(0.0, f64::max)
    }

    /// The smallest switch distance over `patch`: a vertex nearer than it is not fully morphed.
    pub fn nearest_switch(&self, patch: PatchId) -> f64 {
        self.switch_distances(patch)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    /// The largest switch distance of `level` anywhere (the same everywhere for Eq. 6.1).
    pub fn level_threshold(&self, level: u32) -> f64 {
        let level = level.min(self.max_level);
        match &self.switch {
            Switch::Levels(t) => t[level as usize],
            Switch::Field { errors, scale } => errors.worst(level) * scale,
        }
    }
}

/// Procedure 2 from the six roots: a child is visited while the distance from the camera to its centre, projected
/// onto the planet's sphere (the thesis's rule), is below the threshold of the child's level; a visited patch
/// draws the quadrants whose child was not visited (all four at the deepest level).
pub fn select(camera: DVec3, params: &LodParams) -> Vec<Selected> {
    select_by(params, &|p| centre_distance(p, camera, params.radius))
}

/// Procedure 2 with the distance to the nearest point a patch can have (beyond the thesis, as CDLOD selects by
/// a node's bounding box): `bounds(patch)` gives the lowest and highest height its vertices can take. Every
/// vertex of a patch is then at least that far from the camera, so a patch appears (or disappears) only where
/// all its vertices are beyond its level's threshold, where morphing has made it look like its parent
/// (docs/rendering.md). On an Earth-sized planet it also keeps refining close above high ground, where the
/// distance to the centre projected onto the sphere never falls below the ground's height.
pub fn select_nearest(
    camera: DVec3,
    params: &LodParams,
    bounds: &dyn Fn(PatchId) -> (f64, f64),
) -> Vec<Selected> {
    select_by(params, &|p| {
        nearest_distance(p, camera, params.radius, bounds(p))
    })
}

/// The heights every drawn point of `patch` lies between, for [`select_nearest`]: the surface range (base heights
/// and river beds) of the patch or of its nearest resident ancestor, which `nearest` gives with that ancestor's
/// level, widened by what finer levels add; without one the planet's precomputed bound of its base heights.
/// Then the sea surface, and a river basin's depth either way for river beds and water.
pub fn surface_bounds(
    planet: &Planet,
    basin_depth: f64,
    patch: PatchId,
    nearest: Option<(u8, (f32, f32))>,
) -> (f64, f64) {
    let (lo, hi) = match nearest {
        Some((level, (lo, hi))) => {
            let extra = if level == patch.level {
                0.0
            } else {
                planet.rule.remaining_range(level as u32)
            };
            (lo - extra, hi + extra)
        }
        None => planet.patch_bounds(patch),
    };
    (
        lo as f64 - basin_depth,
        hi.max(planet.sea_level) as f64 + basin_depth,
    )
}

/// Procedure 2 with any distance of a patch from the camera.
fn select_by(params: &LodParams, distance: &dyn Fn(PatchId) -> f64) -> Vec<Selected> {
    let mut out = Vec::new();
    for face in 0..FACES {
        visit(PatchId::root(face), params, distance, &mut out);
    }
    out
}

fn visit(
    patch: PatchId,
    params: &LodParams,
    distance: &dyn Fn(PatchId) -> f64,
    out: &mut Vec<Selected>,
) {
    if patch.level as u32 >= params.max_level {
        out.push(Selected {
            patch,
            quadrants: 0b1111,
        });
        return;
    }
    let mut quadrants = 0u8;
    for q in 0..4 {
        let child = patch.child(q);
        if distance(child) < params.threshold(child) {
            visit(child, params, distance, out);
        } else {
            quadrants |= 1 << q;
        }
    }
    if quadrants != 0 {
        out.push(Selected { patch, quadrants });
    }
}

/// Whether `patch` is close enough to be visited (Eq. 6.1's distance to its centre).
pub fn refines(patch: PatchId, camera: DVec3, params: &LodParams) -> bool {
    centre_distance(patch, camera, params.radius) < params.threshold(patch)
}

/// Eq. 6.1's distance: from the camera to the patch centre projected onto the sphere.
fn centre_distance(patch: PatchId, camera: DVec3, radius: f64) -> f64 {
    camera.distance(patch.center() * radius)
}

/// A lower bound of the distance from the camera to any point of `patch` with a height in `[lo, hi]`: the
/// nearest point of the spherical cap around the patch, between those radii.
pub fn nearest_distance(patch: PatchId, camera: DVec3, radius: f64, (lo, hi): (f64, f64)) -> f64 {
    let rho = camera.length();
    let phi = (angle(patch.center(), camera) - patch.cap_angle()).max(0.0);
    let r = (rho * phi.cos()).clamp(radius + lo, radius + hi);
    // |camera - r u|^2 = (rho - r)^2 + 4 rho r sin^2(phi / 2): no cancellation close to the surface.
    let half = (0.5 * phi).sin();
    ((rho - r).powi(2) + 4.0 * rho * r * half * half).sqrt()
}
