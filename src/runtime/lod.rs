//! Distance-based quadtree level of detail (Section 6.2.1, Procedure 2, Eq. 6.1).

use glam::DVec3;

use crate::planet::cube::{PatchId, FACES};

/// A patch to draw and which of its quadrants (bit q: child q, see [`PatchId::child`]) are not covered by finer
/// patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Selected {
    pub patch: PatchId,
    pub quadrants: u8,
}

/// Eq. 6.1: the distance below which a patch of level `lod` is refined.
pub fn threshold(radius: f64, switch_factor: f64, lod: u32) -> f64 {
    radius * switch_factor / (1u64 << lod) as f64
}

/// The parameters of the selection.
#[derive(Clone, Copy, Debug)]
pub struct LodParams {
    pub radius: f64,
    pub switch_factor: f64,
    pub max_level: u32,
}

/// Procedure 2 from the six roots: a child is visited while the distance from the camera to its centre, projected
/// onto the planet's sphere (the thesis's rule), is below the threshold of the child's level; a visited patch
/// draws the quadrants whose child was not visited (all four at the deepest level).
pub fn select(camera: DVec3, params: &LodParams) -> Vec<Selected> {
    select_over(camera, params, &|_| 0.0)
}

/// [`select`] with patch centres lifted to the surface: `height(direction)` above the sphere. The thesis projects
/// onto the sphere, which is the same while heights are tiny beside the radius; on an Earth-sized planet with
/// heights in metres a camera over 300 m-high land would never come closer than 300 m to any centre, and detail
/// would stop about level 17 (docs/rendering.md).
pub fn select_over(
    camera: DVec3,
    params: &LodParams,
    height: &dyn Fn(DVec3) -> f64,
) -> Vec<Selected> {
    let mut out = Vec::new();
    for face in 0..FACES {
        visit(PatchId::root(face), camera, params, height, &mut out);
    }
    out
}

fn visit(
    patch: PatchId,
    camera: DVec3,
    params: &LodParams,
    height: &dyn Fn(DVec3) -> f64,
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
        if refines_over(child, camera, params, height) {
            visit(child, camera, params, height, out);
        } else {
            quadrants |= 1 << q;
        }
    }
    if quadrants != 0 {
        out.push(Selected { patch, quadrants });
    }
}

/// Whether `patch` is close enough to be visited (Eq. 6.1).
pub fn refines(patch: PatchId, camera: DVec3, params: &LodParams) -> bool {
    refines_over(patch, camera, params, &|_| 0.0)
}

/// [`refines`] with the centre lifted by `height(direction)`.
pub fn refines_over(
    patch: PatchId,
    camera: DVec3,
    params: &LodParams,
    height: &dyn Fn(DVec3) -> f64,
) -> bool {
    let direction = patch.center();
    let centre = direction * (params.radius + height(direction));
    camera.distance(centre) < threshold(params.radius, params.switch_factor, patch.level as u32)
}
