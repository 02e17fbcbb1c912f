//! What the viewer's camera stands on (beyond the thesis): the drawn surface below it, terrain or water, at the
//! finest level of detail, as `runtime::surface` makes it on the CPU: the patch under the camera is made when
//! the camera enters it, so the camera cannot sink into detail finer than the precomputed heights or into a
//! river's water.

use glam::DVec3;

use crate::{
    kernel::KernelParams,
    planet::cube::PatchId,
    runtime::surface::{carve_patch, CarvedPatch},
    world::World,
};

/// The drawn surface's patch under the camera, made on the CPU when the camera enters it.
pub struct Ground {
    level: u8,
    patch: Option<CarvedPatch>,
}

impl Ground {
    /// Patches of `world`'s finest drawn level, none made yet.
    pub fn new(world: &World) -> Self {
        Self {
            level: world.config.rendering.max_level_of_detail as u8,
            patch: None,
        }
    }

    /// The height above the radius of the drawn surface below `position`.
    pub fn height_below(&mut self, position: DVec3, world: &World) -> f64 {
        let n = world.config.rendering.vertices;
        let under = PatchId::containing(position, self.level);
        let patch = match &self.patch {
            Some(p) if p.patch == under => p,
            _ => {
                let heights = world.planet.patch_heights(under);
                let base = |i: u32, j: u32| heights.get(i as i64, j as i64);
                let params = KernelParams::from_config(&world.config);
                let carved = carve_patch(under, base, &world.planet, &world.network, n, &params);
                self.patch.insert(carved)
            }
        };
        patch.surface(position.normalize(), n, world.planet.sea_level) as f64
    }
}
