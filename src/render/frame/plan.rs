//! The streaming plan of a frame: which patches to draw (level of detail, Section 6.2.1, and culling, 6.2.2) and
//! which get their data this frame (roots first, then coarse before fine and nearest first, each after the
//! ancestors it is refined from, within the count and GPU-time budgets; the rest draw an ancestor meanwhile).

use std::collections::BTreeMap;
use std::time::Instant;

use super::{ms_since, FrameStats, Renderer};
use crate::{
    config::{Config, LodRule},
    gpu::GpuError,
    planet::{
        cube::{PatchId, FACES},
        Planet,
    },
    refine::with_ancestors,
    river::network::RiverNetwork,
    runtime::{
        camera::Camera,
        cull::{visible_quadrants, Frustum, HeightRange},
        error_field::ErrorField,
        lod::{
            painted_bank_error, river_error, select, select_nearest, surface_bounds, LodParams,
            Selected,
        },
    },
};

/// The errors the screen-space rule projects (`ErrorField`): for a patch, the terrain's geometric error of its
/// parent over its area, what its parent level's river data can miss, or how far the parent paints the banks of
/// the rivers crossing it from where they are (to level [`PAINTED_RIVER_LEVELS`]), whichever is larger. The
/// patch frame's vertex spacing is the face's width (2 radii) over the level's vertices.
pub(super) fn error_field(planet: &Planet, network: &RiverNetwork, config: &Config) -> ErrorField {
    let r = &config.rendering;
    let widest = network.widest();
    let segments = (r.vertices - 1) as f64;
    let spacing = |level: u32| 2.0 * planet.radius / (segments * (1u64 << level) as f64);
    let rivers = |level: u32| river_error(spacing(level), network.influence_distance, widest);
    let max_level = r.max_level_of_detail;
    // The field is projected to `pixel-error` pixels; the banks' errors are scaled to be held to
    // `river-pixel-error` pixels instead.
    let bank_scale = match r.river_pixel_error {
        0.0 => 0.0,
        pixels => (r.pixel_error / pixels) as f64,
    };
    let painted = painted_errors(
        network,
        PAINTED_RIVER_LEVELS.min(max_level),
        spacing,
        bank_scale,
    );
    ErrorField::new(
        max_level,
        planet.precomputed_level.max(painted.len() as u32),
        |patch| {
            let banks = painted
                .get(patch.level as usize - 1)
                .map_or(0.0, |errors| errors[patch.index()]);
            planet
                .quadrant_error(patch)
                .max(rivers(patch.level as u32 - 1))
                .max(banks)
        },
        |level| planet.geometric_error(level - 1).max(rivers(level - 1)),
    )
}

/// The finest level whose patches are visited by the painted rivers' bank error (`lod::painted_bank_error`):
/// its parent's vertices are 2 units apart at radius 1024, so rivers wider than that are carved from it on, and
/// finer levels for the narrow ones would refine around every stream near the camera.
const PAINTED_RIVER_LEVELS: u32 = 6;

/// Per level 1..=`levels` (index level - 1), per patch (`PatchId::index`): the largest bank error of a river
/// crossing it painted at its parent's vertex `spacing` (`lod::painted_bank_error`), times `scale` (no level if
/// 0). From points along every river's initial segments a sixteenth of a finest patch apart (2 units at level 6
/// and radius 1024; lakes are drawn to their contour, not painted along a course).
fn painted_errors(
    network: &RiverNetwork,
    levels: u32,
    spacing: impl Fn(u32) -> f64,
    scale: f64,
) -> Vec<Vec<f64>> {
    if scale == 0.0 {
        return Vec::new();
    }
    // Two of the finest level's vertex spacings, a sixteenth of its patches.
    let step = 2.0 * spacing(levels);
    let mut errors: Vec<Vec<f64>> = (1..=levels)
        .map(|level| vec![0.0; FACES * (1usize << (2 * level))])
        .collect();
    for system in &network.systems {
        for segment in system.segments.iter().filter(|s| !s.lake) {
            let chord = segment.curve.point(1.0).distance(segment.curve.point(0.0));
            let steps = (chord / step).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let t = k as f64 / steps as f64;
                let direction = system.frame.to_sphere(segment.curve.point(t));
                let half_width = 0.5 * segment.width_at(t) as f64;
                for level in 1..=levels {
                    let patch = PatchId::containing(direction, level as u8);
                    let error = scale * painted_bank_error(spacing(level - 1), half_width);
                    let slot = &mut errors[level as usize - 1][patch.index()];
                    *slot = slot.max(error);
                }
            }
        }
    }
    errors
}

impl Renderer<'_> {
    /// The switch distances of this frame: Eq. 6.1, or the error field (terrain or river data, `error_field`)
    /// projected to `pixel-error` pixels of a viewport `viewport_height` pixels high seen through `camera`.
    pub(super) fn lod_params(&self, camera: &Camera, viewport_height: u32) -> LodParams {
        let r = &self.config.rendering;
        let radius = self.planet.radius;
        match self.lod_rule {
            LodRule::Distance => LodParams::distance(
                radius,
                r.level_of_detail_switch_factor as f64,
                r.max_level_of_detail,
            ),
            LodRule::ScreenSpaceError => LodParams::screen_space(
                radius,
                self.errors.clone(),
                viewport_height as f64 / (2.0 * (0.5 * camera.fov_y).tan()),
                r.pixel_error as f64,
                r.max_level_of_detail,
            ),
        }
    }

    /// The heights between which `patch`'s surface lies (base terrain, river beds and the sea), from its own data
    /// or its nearest resident ancestor's (`lod::surface_bounds`).
    fn surface_bounds(&self, patch: PatchId) -> (f64, f64) {
        let nearest = self
            .cache
            .nearest_resident(patch)
            .map(|(q, data)| (q.level, data.surface_range()));
        surface_bounds(
            self.planet,
            self.config.river.basin_depth as f64,
            patch,
            nearest,
        )
    }

    /// The patches to draw: the level of detail's selection (or the frozen one), less the quadrants beyond the
    /// horizon or outside the frustum.
    pub(super) fn visible_patches(
        &mut self,
        camera: &Camera,
        stats: &mut FrameStats,
        cpu: &mut BTreeMap<String, f64>,
    ) -> Vec<Selected> {
        let radius = self.planet.radius;
        // Section 6.2.1: level of detail (or the frozen selection).
        let t = Instant::now();
        let selected = match (&self.frozen, self.freeze_lod) {
            (Some(frozen), true) => frozen.clone(),
            _ if self.morphing => {
                select_nearest(camera.position, &self.lod, &|p| self.surface_bounds(p))
            }
            _ => select(camera.position, &self.lod),
        };
        self.frozen = Some(selected.clone());
        cpu.insert("lod".to_string(), ms_since(t));

        // Section 6.2.2: horizon and frustum culling, here per quadrant (beyond the thesis's per patch) within the
        // patch's own heights: a quadrant the camera cannot see is not drawn, a patch with none left not at all.
        let t = Instant::now();
        let frustum = Frustum::from_matrix(camera.clip());
        let visible: Vec<Selected> = selected
            .iter()
            .filter_map(|s| {
                let (min, max) = self.surface_bounds(s.patch);
                let range = HeightRange { min, max };
                visible_quadrants(s, camera.position, &frustum, radius, range)
            })
            .collect();
        cpu.insert("cull".to_string(), ms_since(t));
        stats.selected_patches = selected.len();
        stats.visible_patches = visible.len();

        visible
    }

    /// How many new patches this frame may make: `new-patches-per-frame`, and no more than the measured GPU time
    /// per patch lets fit in `generation-budget-ms` (at least one, so streaming never stops).
    fn generation_budget(&self) -> usize {
        let count = self.config.rendering.new_patches_per_frame as usize;
        match self.generation_ms_per_patch {
            Some(ms) if ms > 0.0 => {
                let fits =
                    (self.config.rendering.generation_budget_ms as f64 / ms).floor() as usize;
                count.min(fits.max(1))
            }
            _ => count,
        }
    }

    /// Folds a frame's GPU time for making patches into the average per patch (exponential, a quarter per frame).
    pub(super) fn measure_generation(
        &mut self,
        new_patches: usize,
        gpu_ms: &BTreeMap<String, f64>,
    ) {
        if new_patches == 0 {
            return;
        }
        let ms: f64 = ["heights", "kernel"]
            .iter()
            .filter_map(|scope| gpu_ms.get(*scope))
            .sum();
        let sample = ms / new_patches as f64;
        self.generation_ms_per_patch = Some(match self.generation_ms_per_patch {
            Some(average) => 0.75 * average + 0.25 * sample,
            None => sample,
        });
    }

    /// The patches that get their data this frame, parents before children; evicts what makes room for them.
    pub(super) fn plan_streaming(
        &mut self,
        camera: &Camera,
        visible: &[Selected],
        stats: &mut FrameStats,
    ) -> Result<Vec<PatchId>, GpuError> {
        let radius = self.planet.radius;
        // Patches without data: roots first (they stand in for everything), then coarse before fine and nearest
        // first, each after the ancestors it is refined from, within the per-frame budget; the rest draw an
        // ancestor until their turn.
        let roots: Vec<PatchId> = (0..6).map(PatchId::root).collect();
        let mut wanted: Vec<PatchId> = visible
            .iter()
            .map(|s| s.patch)
            .filter(|p| p.level > 0 && !self.cache.contains(p))
            .collect();
        wanted.sort_by(|a, b| {
            let distance = |p: &PatchId| camera.position.distance_squared(p.center() * radius);
            (a.level, distance(a))
                .partial_cmp(&(b.level, distance(b)))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        wanted.dedup();
        let precomputed = self.planet.precomputed_level;
        let forced = with_ancestors(&roots, precomputed, |p| self.cache.contains(p)).len();
        let mut missing = with_ancestors(
            &roots.iter().chain(&wanted).copied().collect::<Vec<_>>(),
            precomputed,
            |p| self.cache.contains(p),
        );
        // Mark what this frame draws from (its own data or a stand-in), and the resident parents that new patches
        // are refined from, so that eviction leaves them; then make room: the cache never holds more than its
        // budget, so at most that many patches get data.
        for s in visible {
            let source = if self.cache.contains(&s.patch) {
                Some(s.patch)
            } else {
                self.cache.resident_ancestor(s.patch)
            };
            if let Some(source) = source {
                self.cache.touch(&source);
            }
        }
        let budget = self.generation_budget();
        missing.truncate((forced + budget).min(self.cache.capacity));
        for p in &missing {
            if let Some(parent) = p.parent() {
                self.cache.touch(&parent);
            }
        }
        let requested = wanted.len();
        stats.evicted_patches = self.evict_patches(self.cache.capacity - missing.len());
        let room = self.cache.capacity.saturating_sub(self.cache.len());
        missing.truncate(room.max(forced));
        log::trace!(
            "plan: {} wanted, budget {budget} ({:?} ms a patch), capacity {}, room {room}, forced {forced}, making {}",
            wanted.len(),
            self.generation_ms_per_patch,
            self.cache.capacity,
            missing.len()
        );
        stats.new_patches = missing.len().saturating_sub(forced);
        stats.pending_patches =
            requested.saturating_sub(missing.iter().filter(|p| wanted.contains(p)).count());

        Ok(missing)
    }
}
