//! What crosses to the shaders each frame, filled in: the push constants every pass reads and the instance of
//! one drawn patch (their layouts in `shader_types`).

use glam::{DMat4, DVec3};

use super::{resident::PatchData, Renderer, ViewMode, COLOUR_BAND_MOUNTAIN_HEIGHT};
use crate::{
    planet::cube::{cube_point, PatchId, FACE_AXES},
    river::samples::PatchFrame,
    runtime::{camera::Camera, lod::Selected},
    shader_types::{FramePush, PatchInstance},
};

impl Renderer<'_> {
    /// This frame's push constants for `camera`.
    /// Whether this frame draws the water in the terrain mesh: `water_in_mesh`, from above the sea.
    pub(super) fn draws_water_in_mesh(&self, camera: &Camera) -> bool {
        self.water_in_mesh
            && camera.position.length() > self.planet.radius + self.planet.sea_level as f64
    }

    pub(super) fn frame_push(&self, camera: &Camera) -> FramePush {
        let radius = self.planet.radius;
        let n = self.config.rendering.vertices;
        let sun = self.sun.unwrap_or_else(|| {
            (camera.position.normalize() * 0.8
                + camera.up.cross(camera.forward).normalize() * 0.5
                + camera.up * 0.3)
                .normalize()
        });
        let sky = self.sky();
        let view_mode = match self.view_mode {
            ViewMode::Shaded => 0,
            ViewMode::Lod => 1,
            ViewMode::PaintedRed => 2,
        };
        FramePush {
            view_projection: to_f32(camera.projection() * camera.rotation()),
            sun: [
                sun.x as f32,
                sun.y as f32,
                sun.z as f32,
                self.planet.sea_level,
            ],
            planet: [
                radius as f32,
                n as f32,
                (self.water_mode as u32
                    + 4 * view_mode
                    + 16 * !self.flowing_water as u32
                    + 32 * self.draws_water_in_mesh(camera) as u32
                    + self.lake_map.as_ref().map_or(0, |m| m.bits())) as f32,
                self.heights.min as f32,
            ],
            extra: [
                sky.map_or(-1.0, |s| s.slot()),
                self.time,
                self.config.planet.max_mountain_height / COLOUR_BAND_MOUNTAIN_HEIGHT,
                self.capture_vertices as u32 as f32,
            ],
            camera: [
                camera.position.x as f32,
                camera.position.y as f32,
                camera.position.z as f32,
                sky.map_or(0.0, |s| s.height),
            ],
        }
    }
}

fn to_f32(m: DMat4) -> [[f32; 4]; 4] {
    m.as_mat4().to_cols_array_2d()
}

/// The instance that draws `selected` from `source`'s textures (itself, or an ancestor standing in).
pub(super) fn instance(
    selected: &Selected,
    source: PatchId,
    data: &PatchData,
    camera: DVec3,
    radius: f64,
    n: u32,
) -> PatchInstance {
    let p = selected.patch;
    let centre = p.center();
    let rel = centre * radius - camera;
    // The patch's frame on the cube, in f64: its centre and the steps across it (docs/rendering.md, "Precision").
    let (_, a, b) = FACE_AXES[p.face as usize];
    let (uc, vc) = p.uv(0.5, 0.5);
    let cube_centre = cube_point(p.face as usize, uc, vc);
    let (axis_u, axis_v) = (a * p.size(), b * p.size());
    let with = |v: DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
    let depth = (p.level - source.level) as u32;
    let scale = 1.0 / (1u32 << depth) as f32;
    let offset_x = (p.x - (source.x << depth)) as f32 * scale * (n - 1) as f32;
    let offset_y = (p.y - (source.y << depth)) as f32 * scale * (n - 1) as f32;
    let spacing = PatchFrame::new(p, radius, n).spacing();
    PatchInstance {
        centre_rel: [rel.x as f32, rel.y as f32, rel.z as f32, p.level as f32],
        centre_dir: [
            centre.x as f32,
            centre.y as f32,
            centre.z as f32,
            spacing as f32,
        ],
        cube_centre: with(cube_centre, cube_centre.length()),
        axis_u: with(axis_u, 2.0 * cube_centre.dot(axis_u)),
        axis_v: with(axis_v, 2.0 * cube_centre.dot(axis_v)),
        tex_rect: [offset_x, offset_y, scale, 0.0],
        slots: [
            data.base.shader_index() as i32,
            data.river.map_or(-1, |place| place.shader_index() as i32),
            selected.quadrants as i32,
            -1,
        ],
        morph: NO_MORPH,
        switch_distances: [1.0; 4],
        detail: [
            detail_coordinate(centre.x * radius),
            detail_coordinate(centre.y * radius),
            detail_coordinate(centre.z * radius),
            0.0,
        ],
    }
}

/// The period in world units of the fragment shader's detail coordinates (the ground's detail and the water's
/// ripples): patch centres are reduced modulo it in f64, into [-P/2, P/2), so the coordinates stay small at any
/// planet size: precise to 4 mm at most, where the absolute positions in f32 were 0.4 m apart on an Earth-sized
/// planet (ripples a few metres across, on its narrow rivers, broke into streaks). Every lattice of the ground detail
/// (256 units, terrain.frag) divides it, so neighbouring patches agree although their centres wrap differently; the
/// ripples, whose size follows the river's width, change pattern where a coordinate wraps: planes 65.5 km apart on
/// config/earth.xml, none on a planet whose coordinates stay within the half period (the default planet's radius is
/// 1,024).
const DETAIL_PERIOD: f64 = 65536.0;

/// A patch centre's world coordinate reduced to [-DETAIL_PERIOD / 2, DETAIL_PERIOD / 2).
fn detail_coordinate(x: f64) -> f32 {
    ((x + DETAIL_PERIOD / 2.0).rem_euclid(DETAIL_PERIOD) - DETAIL_PERIOD / 2.0) as f32
}

/// Morph parameters that never morph (the level-0 patches, and the thesis's instant switching): a band of no
/// length beyond any distance.
pub(super) const NO_MORPH: [f32; 4] = [f32::MAX, 0.0, 0.0, 0.0];
