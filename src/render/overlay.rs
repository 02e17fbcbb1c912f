//! The viewer's on-screen overlay (beyond the thesis; egui, drawn by gpu::overlay into the frame after the sky):
//! the seed, altitude, camera mode, frame time and GPU time per pass, and the settings that can change while the
//! planet is shown (water mode, level-of-detail rule with its pixel error or switch factor, kernel variant,
//! wireframe, level-of-detail colours, morphing, atmosphere, flowing water), and the keys. U shows or hides it.
//! Pointer and keyboard input over it go to it, not to the camera.

use egui::{ClippedPrimitive, ComboBox, Slider};
use winit::{event::WindowEvent, window::Window};

use super::{
    frame::{FrameStats, Renderer, ViewMode, WaterMode},
    viewer_camera::CameraMode,
};
use crate::{
    config::LodRule,
    gpu::{overlay::OverlayRenderer, Context, Extent2D, Format, GpuError, Recorder},
    kernel::gpu::KernelVariant,
    named::Named,
};

/// What the overlay shows that the renderer does not hold.
pub struct ViewInfo {
    /// The planet's seed.
    pub seed: u32,
    /// The camera's height above the drawn surface.
    pub altitude: f64,
    /// Flying or orbiting.
    pub mode: CameraMode,
    /// The last frame's time, milliseconds.
    pub frame_ms: f64,
}

/// The viewer's egui panel: what is drawn and how fast, the switches, the keys.
pub struct Overlay {
    /// Shown (U toggles it).
    pub visible: bool,
    egui: egui::Context,
    input: egui_winit::State,
    renderer: OverlayRenderer,
    primitives: Vec<ClippedPrimitive>,
    pixels_per_point: f32,
}

const KEYS: &str = "W/S A/D Q/E move, arrows or drag look (orbit: drag turns the planet), wheel zoom, C fly/orbit, \
                    Shift faster, H home, B bookmark, 1-9 bookmarks, P screenshot, U overlay, M water, T air, \
                    F wireframe, L LoD colours, R painted rivers red, Z freeze LoD, O morphing, G LoD rule, \
                    K kernel, Esc quit";

impl Overlay {
    /// The panel for `window`, drawn into targets of `color` and `depth`.
    pub fn new(
        ctx: &Context,
        window: &Window,
        (color, depth): (Format, Format),
        visible: bool,
    ) -> Result<Self, GpuError> {
        let egui = egui::Context::default();
        let input = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        Ok(Self {
            visible,
            egui,
            input,
            renderer: OverlayRenderer::new(ctx, color, depth)?,
            primitives: Vec::new(),
            pixels_per_point: 1.0,
        })
    }

    /// Hands a window event to egui; true when the overlay takes it (the pointer is over it, or it has the
    /// keyboard), so that the camera leaves it alone.
    pub fn on_event(&mut self, window: &Window, event: &WindowEvent) -> bool {
        let response = self.input.on_window_event(window, event);
        self.visible && response.consumed
    }

    /// This frame's overlay: runs the panel, applies what it changed to `renderer`, uploads new textures.
    pub fn prepare(
        &mut self,
        ctx: &Context,
        window: &Window,
        renderer: &mut Renderer,
        (info, stats): (&ViewInfo, &FrameStats),
    ) -> Result<(), GpuError> {
        let raw = self.input.take_egui_input(window);
        let visible = self.visible;
        let output = self.egui.run(raw, |egui| {
            if visible {
                panel(egui, renderer, info, stats);
            }
        });
        self.input
            .handle_platform_output(window, output.platform_output);
        self.pixels_per_point = output.pixels_per_point;
        self.primitives = self.egui.tessellate(output.shapes, output.pixels_per_point);
        self.renderer
            .set_textures(ctx, &output.textures_delta.set)?;
        self.renderer
            .free_textures(ctx, &output.textures_delta.free)
    }

    /// Records the prepared overlay into the frame's rendering.
    pub fn record(&mut self, rec: &mut Recorder, extent: Extent2D) -> Result<(), GpuError> {
        if !self.visible {
            return Ok(());
        }
        self.renderer
            .record(rec, extent, self.pixels_per_point, &self.primitives)
    }

    /// After the device is idle.
    pub fn destroy(self, ctx: &Context) {
        self.renderer.destroy(ctx);
    }
}

fn panel(egui: &egui::Context, renderer: &mut Renderer, info: &ViewInfo, stats: &FrameStats) {
    egui::Window::new("riverplanet")
        .default_pos([8.0, 8.0])
        .default_width(250.0)
        .show(egui, |ui| {
            ui.label(format!(
                "seed {} | altitude {:.2} | {:?}",
                info.seed, info.altitude, info.mode
            ));
            ui.label(format!(
                "{:.1} ms ({:.0} fps), {} patches ({} new), {} triangles",
                info.frame_ms,
                1000.0 / info.frame_ms.max(1e-3),
                stats.visible_patches,
                stats.new_patches,
                stats.terrain_triangles
            ));
            let gpu = |name: &str| stats.gpu_ms.get(name).copied().unwrap_or(0.0);
            ui.label(format!(
                "GPU ms: kernel {:.2}, vertices {:.1}, terrain {:.1}, water {:.1}, sky {:.1}",
                gpu("kernel"),
                gpu("vertices"),
                gpu("terrain"),
                gpu("water"),
                gpu("sky")
            ));
            ui.separator();
            ComboBox::from_label("water")
                .selected_text(renderer.water_mode.name())
                .show_ui(ui, |ui| {
                    for &(name, mode) in WaterMode::ALL {
                        ui.selectable_value(&mut renderer.water_mode, mode, name);
                    }
                });
            ui.horizontal(|ui| {
                ui.radio_value(
                    &mut renderer.lod_rule,
                    LodRule::ScreenSpaceError,
                    "screen-space error",
                );
                ui.radio_value(&mut renderer.lod_rule, LodRule::Distance, "Eq. 6.1");
            });
            let rule = renderer.lod_rule;
            let (pixel_error, switch_factor) = renderer.level_of_detail_settings();
            match rule {
                LodRule::ScreenSpaceError => {
                    ui.add(Slider::new(pixel_error, 0.5..=16.0).text("pixel error"))
                }
                LodRule::Distance => {
                    ui.add(Slider::new(switch_factor, 1.0..=32.0).text("switch factor"))
                }
            };
            ui.horizontal(|ui| {
                ui.radio_value(&mut renderer.variant, KernelVariant::Tiled, "tiled kernel");
                ui.radio_value(
                    &mut renderer.variant,
                    KernelVariant::Simple,
                    "simple kernel",
                );
            });
            ui.checkbox(&mut renderer.atmosphere_on, "atmosphere");
            ui.checkbox(&mut renderer.flowing_water, "flowing water");
            ui.checkbox(&mut renderer.water_in_mesh, "water in the terrain mesh");
            ui.checkbox(&mut renderer.morphing, "morphing");
            ui.checkbox(&mut renderer.wireframe_on, "wireframe");
            let mut lod_colours = renderer.view_mode == ViewMode::Lod;
            if ui
                .checkbox(&mut lod_colours, "level-of-detail colours")
                .changed()
            {
                renderer.view_mode = if lod_colours {
                    ViewMode::Lod
                } else {
                    ViewMode::Shaded
                };
            }
            egui::CollapsingHeader::new("keys").show(ui, |ui| ui.label(KEYS));
        });
}
