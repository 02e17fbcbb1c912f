//! Draw recording (Chapter 8): one instance per visible patch (its own data or the part of an ancestor standing
//! in), with its morph towards its parent; the terrain drawn per quadrant, then the water through the geometry
//! shader, then the sky where no surface is; optionally every terrain vertex captured as the vertex shader placed it.

use std::ops::Range;

use glam::DVec3;

use super::{
    shader_data::{instance, NO_MORPH},
    sky::Sky,
    vertex_cache::VertexCache,
    FrameStats, Renderer,
};
use crate::{
    gpu::{
        pipeline::{Attachment, RenderTarget},
        Access, Buffer, BufferDesc, GpuError, MemoryLocation, Recorder,
    },
    planet::cube::{PatchId, PatchMap, EDGES},
    runtime::{camera::Camera, lod::Selected},
    shader_types::PatchInstance,
};

/// Every drawn terrain vertex of one frame, as the vertex shader placed it.
#[derive(Clone, Debug)]
pub struct VertexCapture {
    /// The camera position the positions are relative to.
    pub camera: DVec3,
    /// Vertices per patch edge.
    pub vertices: u32,
    /// Per terrain instance: the patch drawn, and for every mesh vertex its camera-relative position and `1 +
    /// morph factor` (0 for vertices of quadrants not drawn). Grid vertex (i, j) is at `j * vertices + i`.
    pub patches: Vec<(PatchId, Vec<[f32; 4]>)>,
}

/// One vertex of a drawn quadrant in a [`VertexCapture`].
#[derive(Clone, Copy, Debug)]
pub struct DrawnVertex {
    /// The patch it belongs to.
    pub patch: PatchId,
    /// Its grid point in the patch.
    pub i: u32,
    /// See `i`.
    pub j: u32,
    /// Position relative to the capture's camera.
    pub relative: DVec3,
    /// Morph factor towards the parent, 0 to 1.
    pub morph: f64,
}

impl VertexCapture {
    /// Every grid vertex of a drawn quadrant (the captured `1 + morph` is positive), instance by instance.
    pub fn drawn(&self) -> impl Iterator<Item = DrawnVertex> + '_ {
        let n = self.vertices;
        self.patches.iter().flat_map(move |(patch, vertices)| {
            (0..n * n).filter_map(move |k| {
                let v = vertices[k as usize];
                (v[3] > 0.0).then(|| DrawnVertex {
                    patch: *patch,
                    i: k % n,
                    j: k / n,
                    relative: DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64),
                    morph: (v[3] - 1.0) as f64,
                })
            })
        })
    }
}

/// What the recorded draws leave for after the frame: the vertex capture buffer and whose vertices it holds.
pub(super) struct Drawn {
    capture: Option<Buffer>,
    /// The instances before the terrain pass's (the vertex cache's), whose capture slots stay empty.
    first_terrain_instance: usize,
    instance_patches: Vec<PatchId>,
}

impl Drawn {
    /// The captured vertices, once the frame has completed (the buffer is freed).
    pub(super) fn read_capture(self, camera: DVec3, n: u32) -> Option<VertexCapture> {
        let positions: Option<Vec<[f32; 4]>> = self
            .capture?
            .mapped()
            .map(|bytes| bytemuck::cast_slice(bytes).to_vec());
        let per = mesh_vertices(n) as usize;
        positions.map(|p| VertexCapture {
            camera,
            vertices: n,
            patches: self
                .instance_patches
                .iter()
                .zip(p.chunks(per).skip(self.first_terrain_instance))
                .map(|(patch, v)| (*patch, v.to_vec()))
                .collect(),
        })
    }
}

impl Renderer<'_> {
    /// A patch's morph parameters (std430 `morph` of the instance: where in the switch distance its vertices start
    /// morphing, one over the morph band's share, and its texel offset in its parent's river texture) and its
    /// corners' switch distances (`switch_distances`). A patch is selected only while its nearest point is within
    /// its largest switch distance, so every vertex of one that is about to appear or disappear is beyond the
    /// switch distance at its place: fully morphed, it looks like its parent.
    fn morph(&self, patch: PatchId) -> ([f32; 4], [f32; 4]) {
        if !self.morphing || patch.level == 0 {
            return (NO_MORPH, [1.0; 4]);
        }
        let half = (self.config.rendering.vertices - 1) / 2;
        (
            [
                (1.0 - MORPH_BAND) as f32,
                (1.0 / MORPH_BAND) as f32,
                ((patch.x & 1) * half) as f32,
                ((patch.y & 1) * half) as f32,
            ],
            self.lod.switch_distances(patch).map(|d| d as f32),
        )
    }

    /// Beyond the thesis: whether a vertex of `patch` can lie beyond the switch distance at its place. There it is fully
    /// morphed beside partly morphed neighbours, and the grid triangles between them have their corners on one grid
    /// line: thin walls over the step between the two morph factors' heights, which face away from the camera as
    /// often as not and must not be culled, or a pixel they alone cover shows through (docs/rendering.md, "Back
    /// faces and morphing"). Bounded by the distance to the patch's centre at the middle of its surface's heights
    /// `(lo, hi)` plus how far its vertices can lie from that point.
    fn reaches_switch_distance(&self, patch: PatchId, (lo, hi): (f32, f32), camera: DVec3) -> bool {
        if !self.morphing || patch.level == 0 {
            return false;
        }
        let (lo, hi) = (lo as f64, hi as f64);
        let outer = self.planet.radius + hi.abs().max(lo.abs());
        let centre = patch.center() * (self.planet.radius + 0.5 * (lo + hi));
        let reach = outer * patch.cap_angle() + 0.5 * (hi - lo);
        camera.distance(centre) + reach >= self.lod.nearest_switch(patch)
    }

    /// The visible patches drawn from an ancestor's data, each with how far its surface can lie from the true one:
    /// the span of that ancestor's heights (base and river beds).
    fn stand_in_spans(&self, visible: &[Selected]) -> StandIns {
        let drawn: PatchMap<f32> = visible
            .iter()
            .filter(|s| !self.cache.contains(&s.patch))
            .filter_map(|s| {
                let (_, data) = self.cache.nearest_resident(s.patch)?;
                let (lo, hi) = data.surface_range();
                Some((s.patch, hi - lo))
            })
            .collect();
        let mut below: PatchMap<f32> = PatchMap::default();
        for (patch, span) in &drawn {
            let mut p = patch.parent();
            while let Some(q) = p {
                let entry = below.entry(q).or_insert(0.0);
                *entry = entry.max(*span);
                p = q.parent();
            }
        }
        StandIns { drawn, below }
    }

    /// Records the terrain and water passes of `visible` into `target`, whose colour image is cleared and left
    /// ready for the use `after` (drawing on, reading back or presenting).
    pub(super) fn record_draw(
        &mut self,
        rec: &mut Recorder,
        camera: &Camera,
        visible: &[Selected],
        (target, after): (&RenderTarget, Access),
        stats: &mut FrameStats,
        overlay: Option<super::Overlay<'_>>,
    ) -> Result<Drawn, GpuError> {
        let ctx = self.ctx;
        let radius = self.planet.radius;
        let n = self.config.rendering.vertices;
        // Instances: every visible patch, with its own data or the part of its nearest resident ancestor. One list
        // per quadrant for the terrain (the instances that draw it), then one for the water (patches with a river
        // or below sea level), all in one buffer.
        let stand_ins = self.stand_in_spans(visible);
        let mut drawn: Vec<DrawnPatch> = Vec::with_capacity(visible.len());
        for s in visible {
            let source = if self.cache.contains(&s.patch) {
                stats.deepest_level = stats.deepest_level.max(s.patch.level as u32);
                s.patch
            } else {
                stats.fallback_patches += 1;
                match self.cache.resident_ancestor(s.patch) {
                    Some(a) => a,
                    None => continue,
                }
            };
            // Morphing towards the parent, whose river data the vertices blend into (its base heights are the
            // patch's own at the points that remain).
            let (morph, switch_distances) = self.morph(s.patch);
            let parent_river = match (source == s.patch, s.patch.parent()) {
                (true, Some(parent)) if self.morphing => self
                    .cache
                    .touch(&parent)
                    .and_then(|d| d.river)
                    .map_or(-1, |place| place.shader_index() as i32),
                _ => -1,
            };
            let Some(data) = self.cache.touch(&source) else {
                continue;
            };
            let wet = data.river.is_some() || data.height_range.0 < self.planet.sea_level;
            let mut instance = instance(s, source, data, camera.position, radius, n);
            instance.morph = morph;
            instance.switch_distances = switch_distances;
            instance.slots[3] = parent_river;
            instance.tex_rect[3] =
                SKIRT_SPACINGS * instance.centre_dir[3] + skirt_deficit(s.patch, &stand_ins);
            let range = data.surface_range();
            drawn.push(DrawnPatch {
                instance,
                wet,
                patch: s.patch,
                culled: !self.reaches_switch_distance(s.patch, range, camera.position),
                lakes: self.lake_map.as_ref().is_some_and(|m| m.has_lakes(s.patch)),
            });
        }
        // Near to far, so that depth testing rejects what nearer patches hide before it is shaded.
        drawn.sort_by(|a, b| {
            let distance = |p: &PatchId| camera.position.distance_squared(p.center() * radius);
            distance(&a.patch).total_cmp(&distance(&b.patch))
        });
        // The drawn patches first, once each: the vertex cache's entries (instance k fills entry k).
        let cached = if self.cache_vertices {
            VertexCache::patches(drawn.len(), n)
        } else {
            0
        };
        for (k, d) in drawn.iter_mut().enumerate() {
            d.instance.detail[3] = if k < cached { k as f32 } else { -1.0 };
        }
        let mut instances: Vec<PatchInstance> = Vec::with_capacity(drawn.len() * 4);
        instances.extend(drawn.iter().map(|d| d.instance));
        let first_terrain_instance = instances.len();
        let mut instance_patches: Vec<PatchId> = Vec::with_capacity(drawn.len() * 2);
        // The terrain's draws: each quadrant's cells and edge skirts for the instances that draw it, and its
        // midline skirts only for those that leave the quadrant across the midline to finer patches; each once for
        // the patches whose back faces are culled and once for those reaching their switch distance, and each of
        // those apart for the patches a lake of the lake map reaches.
        let has = |d: &DrawnPatch, q: usize| d.instance.slots[2] & (1 << q) != 0;
        let mut terrain_draws: Vec<(Range<u32>, Range<u32>, bool, bool)> = Vec::with_capacity(48);
        for (cull, lakes) in [(true, false), (false, false), (true, true), (false, true)] {
            for (q, mesh) in self.quadrants.iter().enumerate() {
                let parts = [
                    (mesh.core.clone(), None),
                    (mesh.across[0].clone(), Some(q ^ 1)),
                    (mesh.across[1].clone(), Some(q ^ 2)),
                ];
                for (indices, across) in parts {
                    let first = instances.len() as u32;
                    for d in drawn.iter().filter(|d| {
                        d.culled == cull
                            && d.lakes == lakes
                            && has(d, q)
                            && across.is_none_or(|a| !has(d, a))
                    }) {
                        instances.push(d.instance);
                        instance_patches.push(d.patch);
                    }
                    terrain_draws.push((indices, first..instances.len() as u32, cull, lakes));
                }
            }
        }
        // The thesis's water pass, unless the terrain mesh carries the water: cached patches draw their water
        // through the cache pass's indirect draws (instance k is patch k), the rest as instances of their own.
        let water_pass = !self.wireframe_on && !self.draws_water_in_mesh(camera);
        let first = instances.len() as u32;
        if water_pass {
            instances.extend(
                drawn
                    .iter()
                    .skip(cached)
                    .filter(|d| d.wet)
                    .map(|d| d.instance),
            );
        }
        let water_instances = first..instances.len() as u32;
        let instance_buffer = {
            let mut buffer = ctx.create_buffer(&BufferDesc {
                name: "patch instances",
                size: (instances.len().max(1) * std::mem::size_of::<PatchInstance>()) as u64,
                uses: &[Access::ComputeRead, Access::VertexShaderRead],
                location: MemoryLocation::CpuToGpu,
            })?;
            buffer.write(0, &instances)?;
            buffer
        };
        // Vertex capture (tests): one slot per instance and mesh vertex, zero where nothing was drawn.
        let capture = if self.capture_vertices {
            let slots = first_terrain_instance + instance_patches.len();
            let size = (slots.max(1) * mesh_vertices(n) as usize * 16) as u64;
            let buffer = ctx.create_buffer(&BufferDesc {
                name: "vertex capture",
                size,
                uses: &[
                    Access::TransferWrite,
                    Access::VertexShaderWrite,
                    Access::HostRead,
                ],
                location: MemoryLocation::GpuToCpu,
            })?;
            rec.fill_buffer(&buffer, 0);
            rec.use_buffer(&buffer, &[Access::VertexShaderWrite]);
            Some(buffer)
        } else {
            None
        };
        let vertex_cache = VertexCache::buffer(ctx, cached, n)?;
        let (water_draws, water_indices) = if water_pass {
            (
                Some(VertexCache::water_draws(ctx, cached, &self.quadrants)?),
                Some(VertexCache::water_indices(ctx, cached, n)?),
            )
        } else {
            (None, None)
        };
        let draw_sky = self.sky().is_some();
        let dome_vertices = draw_sky.then(|| Sky::dome_vertices(ctx)).transpose()?;
        let instance_set = rec.buffer_set(
            &self.instance_layout,
            &[
                &instance_buffer,
                capture.as_ref().unwrap_or(&self.placeholder),
                &vertex_cache,
                water_draws.as_ref().unwrap_or(&self.placeholder),
                &self.indices,
                water_indices.as_ref().unwrap_or(&self.placeholder),
                dome_vertices.as_ref().unwrap_or(&self.placeholder),
            ],
        )?;
        rec.free_after_completion(instance_buffer);

        // Section 8: terrain, then water.
        let push = self.frame_push(camera);
        let sets = [self.bindless.set, instance_set];
        let push = bytemuck::bytes_of(&push);
        let cache = &self.vertex_cache;
        self.frames.profiler().scope(rec, "vertices", |rec| {
            let water = water_draws.as_ref().zip(water_indices.as_ref());
            cache.record(rec, (&sets, push), &vertex_cache, cached, n, water)
        })?;
        if let (Some(sky), Some(vertices)) = (&self.sky, &dome_vertices) {
            self.frames.profiler().scope(rec, "sky dome", |rec| {
                sky.record_dome(rec, (&sets, push), vertices)
            })?;
        }
        rec.free_after_completion(vertex_cache);
        // The target is cleared, so its contents are discarded; the wait for the earlier writes to it (the frame
        // before, which may still be in flight, or the swapchain's acquire, waited for at colour output) stays.
        rec.use_attachment(target, Attachment::Color, &[Access::ColorAttachment], true);
        rec.use_attachment(target, Attachment::Depth, &[Access::DepthAttachment], true);
        rec.begin_rendering(target, true);
        self.frames.profiler().scope(rec, "terrain", |rec| {
            for (indices, instances, cull, lakes) in terrain_draws {
                if instances.is_empty() {
                    continue;
                }
                let terrain = match (self.wireframe_on, cull, &self.terrain_lakes) {
                    (true, _, _) => &self.wireframe,
                    (false, _, Some(pipelines)) if lakes => &pipelines[!cull as usize],
                    (false, true, _) => &self.terrain,
                    (false, false, _) => &self.terrain_unculled,
                };
                stats.terrain_triangles += (indices.len() / 3 * instances.len()) as u64;
                rec.draw_indexed(terrain, &sets, push, &self.indices, indices, instances);
            }
        })?;
        self.frames.profiler().scope(rec, "water", |rec| {
            if let (Some(indices), Some(draws)) = (&water_indices, &water_draws) {
                rec.draw_indexed_indirect(
                    &self.cached_water,
                    (&sets, push),
                    indices,
                    draws,
                    4 * cached as u32,
                );
                for mesh in &self.quadrants {
                    rec.draw_indexed(
                        &self.water,
                        &sets,
                        push,
                        &self.indices,
                        mesh.grid.clone(),
                        water_instances.clone(),
                    );
                }
            }
            for buffer in water_draws.into_iter().chain(water_indices) {
                rec.free_after_completion(buffer);
            }
            if let Some(vertices) = dome_vertices {
                rec.free_after_completion(vertices);
            }
        })?;
        if let (true, Some(sky)) = (draw_sky, &self.sky) {
            self.frames
                .profiler()
                .scope(rec, "sky", |rec| sky.record(rec, &sets, push))?;
        }
        if let Some(draw) = overlay {
            draw(rec, target.extent());
        }
        rec.end_rendering();
        if after != Access::ColorAttachment {
            rec.use_attachment(target, Attachment::Color, &[after], false);
        }
        Ok(Drawn {
            capture,
            first_terrain_instance,
            instance_patches,
        })
    }
}

/// Vertices of the patch mesh: the grid and six skirts (render/mesh.rs).
fn mesh_vertices(n: u32) -> u32 {
    n * n + 6 * n
}

/// Skirt length beside patches with their own data, in vertex spacings (docs/rendering.md, "No holes").
const SKIRT_SPACINGS: f32 = 2.0;

/// How much longer the skirts of `patch` must be than [`SKIRT_SPACINGS`]: where it or a neighbour is drawn from an
/// ancestor's data, the two surfaces can part by as much as that ancestor's height span, and the higher side's
/// skirt has to reach down to the lower. `spans` holds every visible stand-in and, for every patch above one, the
/// largest span below it ([`StandIns`]), so a neighbour drawn coarser (an ancestor of the same-level neighbour) or
/// finer (a descendant) is found either way.
fn skirt_deficit(patch: PatchId, spans: &StandIns) -> f32 {
    if spans.drawn.is_empty() {
        return 0.0;
    }
    let covering = |p: PatchId| {
        let mut q = Some(p);
        while let Some(r) = q {
            if let Some(span) = spans.drawn.get(&r) {
                return *span;
            }
            q = r.parent();
        }
        0.0
    };
    std::iter::once(patch)
        .chain(EDGES.map(|e| patch.neighbour(e)))
        .map(|p| covering(p).max(spans.below.get(&p).copied().unwrap_or(0.0)))
        .fold(0.0, f32::max)
}

/// A visible patch as this frame draws it.
struct DrawnPatch {
    instance: PatchInstance,
    /// Whether it has water to draw: a river or land below sea level.
    wet: bool,
    patch: PatchId,
    /// Whether its back faces are culled (not where morphing can leave walls: `reaches_switch_distance`).
    culled: bool,
    /// Whether a lake of the lake map lies in it: drawn by the terrain pipelines that read the map.
    lakes: bool,
}

/// The visible patches drawn from an ancestor's data with the span of that ancestor's heights, and for every
/// patch above one of them the largest such span below it.
struct StandIns {
    drawn: PatchMap<f32>,
    below: PatchMap<f32>,
}

/// Share of a level's switch distance over which its patches morph into their parent's shape (CDLOD's morph
/// region): from 70 % of the distance on, fully at it.
const MORPH_BAND: f64 = 0.3;
