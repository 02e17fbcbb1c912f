//! Lakes from afar (beyond the thesis; docs/rendering.md, "Lakes from afar"): how far each point of the
//! precomputed lattice lies below the level of the lake that reaches it, as one six-layer texture the terrain pass
//! samples where its patches are coarser than that lattice. A coarse patch's vertices miss a lake smaller than
//! their spacing (or catch one vertex of it and draw a blob); the map's bilinear zero contour is the shore of the
//! refined surface at the lake's level, whatever the mesh.

use glam::DVec3;

use crate::{
    drainage::LakeShape,
    gpu::{
        bindless::{Bindless, Slot},
        Access, Context, Extent2D, Format, GpuError, Image, ImageDesc,
    },
    planet::{
        cube::{PatchId, FACES, FACE_AXES},
        heights::FaceLattice,
    },
};

/// The texture and the bindless slot the shaders find it at.
pub(super) struct LakeMap {
    /// Held while `slot` points at it.
    _image: Image,
    slot: Slot,
    /// log2 of the map's cells per face edge.
    cells_log2: u32,
    /// Per level coarser than the map's, face and patch (row-major): whether a lake reaches a lattice point of the
    /// patch, so that only those patches' fragments read the map.
    patches_with_lakes: Vec<Vec<bool>>,
}

impl LakeMap {
    /// Uploads the lake depths of `lakes` over `lattice` (the planet's precomputed heights, of patch level
    /// `map_level`); `None` without lakes.
    pub(super) fn new(
        ctx: &Context,
        bindless: &mut Bindless,
        lattice: &FaceLattice,
        lakes: &[LakeShape],
        radius: f64,
        relief: f32,
        map_level: u32,
    ) -> Result<Option<Self>, GpuError> {
        if lakes.is_empty() {
            return Ok(None);
        }
        let depths = lake_depths(lattice, lakes, radius, relief);
        let side = lattice.side() as u32;
        let image = ctx.create_image(&ImageDesc {
            name: "lake map",
            extent: Extent2D {
                width: side,
                height: side,
            },
            layers: FACES as u32,
            format: Format::R32_SFLOAT,
            uses: &[Access::GraphicsSampled, Access::TransferWrite],
            array: true,
        })?;
        let layer = (side * side) as usize;
        ctx.run_and_wait("upload lake map", |rec| {
            rec.overwrite_images(&[&image], &[Access::TransferWrite]);
            for face in 0..FACES {
                rec.upload_image_layer(
                    &image,
                    face as u32,
                    bytemuck::cast_slice(&depths.data[face * layer..(face + 1) * layer]),
                )?;
            }
            rec.use_images(&[&image], &[Access::GraphicsSampled]);
            Ok(())
        })?;
        // The slot travels in the push constants' f32 above six mode bits and below the cells' exponent
        // (`bits`): the renderer takes it before any patch's, so it is small.
        let slot = bindless
            .allocate(ctx)
            .filter(|slot| slot.0 + 1 < 1 << 14)
            .ok_or_else(|| {
                GpuError::Invalid("no bindless slot below 16383 for the lake map".to_string())
            })?;
        bindless.write(ctx, slot, &image, false);
        let cells_log2 = lattice.cells.trailing_zeros();
        Ok(Some(Self {
            _image: image,
            slot,
            cells_log2,
            patches_with_lakes: patches_with_lakes(&depths, map_level, relief),
        }))
    }

    /// Whether a lake reaches a lattice point of `patch` that the map holds; false for patches as fine as the map
    /// and finer, which draw their lakes in the mesh.
    pub(super) fn has_lakes(&self, patch: PatchId) -> bool {
        self.patches_with_lakes
            .get(patch.level as usize)
            .is_some_and(|flags| flags[patch.index()])
    }

    /// What the push constants carry of the map (`planet.z` above its six mode bits, glsl/terrain_common.glsl):
    /// 64 x (slot + 1) and 2^20 x log2 of its cells per face edge, each exact in the f32 it travels in.
    pub(super) fn bits(&self) -> u32 {
        64 * (self.slot.0 + 1) + (self.cells_log2 << 20)
    }
}

/// For every patch level below `levels` (those coarser than the map: the precomputed level; patch grids of 2^level
/// per face edge), whether a point a lake reaches (above `-relief`) lies in each patch, its borders included.
fn patches_with_lakes(depths: &FaceLattice, levels: u32, relief: f32) -> Vec<Vec<bool>> {
    let side = depths.side();
    let mut flags: Vec<Vec<bool>> = (0..levels)
        .map(|level| vec![false; FACES << (2 * level)])
        .collect();
    for face in 0..FACES {
        for j in 0..side {
            for i in 0..side {
                if depths.data[depths.index(face, i as u32, j as u32)] <= -relief {
                    continue;
                }
                for (level, flags) in flags.iter_mut().enumerate() {
                    let per_edge = 1usize << level;
                    let cells_per_patch = (depths.cells >> level) as usize;
                    // The patches whose closed range holds the point (two or four on their borders).
                    let range = |t: usize| {
                        let first = t.saturating_sub(1) / cells_per_patch;
                        first..=(t / cells_per_patch).min(per_edge - 1)
                    };
                    for y in range(j) {
                        for x in range(i) {
                            flags[(face * per_edge + y) * per_edge + x] = true;
                        }
                    }
                }
            }
        }
    }
    flags
}

/// Per point of `lattice`: the level of the highest lake whose reach covers it (a base cell from the lake's
/// points, as the kernel's lake samples reach: docs/kernel.md, "Lakes") minus the point's height, or `-relief`
/// (the planet's height range) where no lake reaches: far below any shore, so the bilinear contour between such a
/// point and one under a lake hugs the lake's side.
pub fn lake_depths(
    lattice: &FaceLattice,
    lakes: &[LakeShape],
    radius: f64,
    relief: f32,
) -> FaceLattice {
    let mut levels = FaceLattice::new(lattice.cells, f32::NEG_INFINITY);
    let cell_angle = std::f64::consts::FRAC_PI_2 / lattice.cells as f64;
    for lake in lakes {
        // One base cell: the lake's area over its points (lake_system's sample width).
        let reach = (lake.area / lake.points.len().max(1) as f64).sqrt() / radius;
        let window = (reach / cell_angle).ceil() as i64 + 1;
        for &p in &lake.points {
            for (face, &(n, a, b)) in FACE_AXES.iter().enumerate() {
                let facing = p.dot(n);
                if facing <= 0.0 {
                    continue;
                }
                let on_face = p / facing;
                let (u, v) = (on_face.dot(a), on_face.dot(b));
                let to_index = |t: f64| ((t + 1.0) * 0.5 * lattice.cells as f64).round() as i64;
                let (ci, cj) = (to_index(u), to_index(v));
                let last = lattice.cells as i64;
                for j in (cj - window).max(0)..=(cj + window).min(last) {
                    for i in (ci - window).max(0)..=(ci + window).min(last) {
                        let (i, j) = (i as u32, j as u32);
                        let q: DVec3 = lattice.direction(lattice.key(face, i, j));
                        if crate::planet::cube::angle(p, q) <= reach {
                            let k = levels.index(face, i, j);
                            levels.data[k] = levels.data[k].max(lake.level);
                        }
                    }
                }
            }
        }
    }
    for (level, &height) in levels.data.iter_mut().zip(&lattice.data) {
        *level = match level.is_finite() {
            true => *level - height,
            false => -relief,
        };
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lake_reaches_the_points_within_a_cell_of_its_own_on_every_face_it_touches() {
        // A flat lattice at height 0 with a one-point lake of level 2 on the edge between faces 0 and 4.
        let lattice = FaceLattice::new(16, 0.0);
        let point = lattice.direction(lattice.key(0, 0, 8));
        let cell = std::f64::consts::FRAC_PI_2 / 16.0;
        let radius = 100.0;
        let area = (cell * radius) * (cell * radius);
        let lakes = [LakeShape {
            points: vec![point],
            level: 2.0,
            area,
        }];
        let depths = lake_depths(&lattice, &lakes, radius, 4.0);
        let mut reached = 0;
        for face in 0..FACES {
            for j in 0..=16 {
                for i in 0..=16 {
                    let q = lattice.direction(lattice.key(face, i, j));
                    let value = depths.get(face, i, j);
                    if crate::planet::cube::angle(point, q) <= cell * 0.99 {
                        assert_eq!(value, 2.0, "face {face} ({i}, {j})");
                        reached += 1;
                    } else if crate::planet::cube::angle(point, q) > cell * 1.2 {
                        assert_eq!(value, -4.0, "face {face} ({i}, {j})");
                    }
                }
            }
        }
        // The point itself on both faces, and its lattice neighbours on each.
        assert!(reached >= 6, "{reached}");
        assert_eq!(depths.get(4, 16, 8), 2.0);
        // Level 1 (2 x 2 patches of 8 cells): face 0's points (0..=1, 7..=9) lie in its patches x 0, y 0 and 1; face
        // 4's (15..=16, 7..=9) in x 1, y 0 and 1; no other face is reached.
        let flags = patches_with_lakes(&depths, 4, 4.0);
        let marked: Vec<(usize, usize, usize)> = (0..FACES)
            .flat_map(|f| (0..2).flat_map(move |y| (0..2).map(move |x| (f, x, y))))
            .filter(|&(f, x, y)| flags[1][(f * 2 + y) * 2 + x])
            .collect();
        assert_eq!(marked, vec![(0, 0, 0), (0, 0, 1), (4, 1, 0), (4, 1, 1)]);
        assert!(flags[0][0] && flags[0][4] && !flags[0][1]);
        assert_eq!(flags.len(), 4, "levels 0 to 3, coarser than the map");
    }
}
