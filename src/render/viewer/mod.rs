//! The native viewer (winit): a fly or orbit camera (viewer_camera.rs) whose speed scales with altitude, keys for
//! the water mode, atmosphere,
//! wireframe, level-of-detail colours, freezing the level of detail, the kernel variant and screenshots; the seed, frame and
//! per-pass GPU times in the title bar. Survives resize and minimise.
//!
//! Keys: W/S forward/back, A/D left/right, Q/E down/up, arrows or left-drag to look (orbit mode: left-drag turns the
//! planet), wheel zoom, C fly/orbit, Shift faster; M water mode,
//! T atmosphere, F wireframe, L level-of-detail colours, R painted rivers in red, Z freeze level of detail, O morphing, G
//! level-of-detail rule (screen-space error or the thesis's Eq. 6.1), K simple/tiled kernel, H back to the start
//! view, P screenshot (screenshot.rs), B bookmark the view, 1-9 back to a bookmark (viewer_paths.rs), Escape quit (SIGTERM and SIGINT too, src/interrupt.rs). The camera stays
//! above the drawn surface (ground.rs).

mod input;
mod screenshot;

use std::{collections::HashSet, path::PathBuf, time::Instant};

use glam::DVec3;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::{
    application::ApplicationHandler,
    dpi::PhysicalSize,
    event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent},
    event_loop::{ActiveEventLoop, ControlFlow, EventLoop},
    keyboard::{KeyCode, PhysicalKey},
    window::{Window, WindowId},
};

use super::{
    frame::{FrameStats, Renderer},
    ground::Ground,
    overlay::{Overlay, ViewInfo},
    target::{create_depth, DEPTH_FORMAT},
    viewer_camera::{CameraMode, ViewerCamera},
    viewer_paths::ViewerPaths,
};
use crate::{
    config::LodRule,
    gpu::{
        swapchain::{self, Surface, Swapchain, SWAPCHAIN_FORMAT},
        Access, Context, ContextOptions, GpuError, Image,
    },
    kernel::gpu::KernelVariant,
    runtime::camera::Camera,
    world::World,
};

/// Why the viewer stopped.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No window or event loop (no display).
    #[error("cannot open a window: {0} (no display? `riverplanet render` works without one)")]
    Window(String),
    /// A Vulkan call failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A screenshot could not be written.
    #[error("cannot write screenshot {path}: {message}")]
    Screenshot {
        /// The file.
        path: String,
        /// The reason.
        message: String,
    },
    /// The recorded camera path could not be written.
    #[error("cannot write the camera path: {0}")]
    Path(String),
    /// With validation on, the layer reported errors.
    #[error("the validation layer reported {count} error(s), the first: {first}")]
    Validation {
        /// How many.
        count: usize,
        /// The first one's message.
        first: String,
    },
}

/// Options of a viewer run.
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// The window's size, pixels.
    pub size: [u32; 2],
    /// Where the camera starts, and what it looks at.
    pub eye: DVec3,
    /// See `eye`.
    pub look_at: DVec3,
    /// Stop after this many frames (for tests under Xvfb).
    pub frames: Option<u64>,
    /// Written after the last frame (with `frames`).
    pub screenshot: Option<PathBuf>,
    /// Where P writes screenshots, with a JSON sidecar each, and B its bookmarks (bookmarks.json).
    pub screenshots: PathBuf,
    /// Where to write the camera of every frame when the viewer closes (a camera path).
    pub record: Option<PathBuf>,
    /// Show the on-screen overlay at the start (U toggles it).
    pub overlay: bool,
    /// The configuration file given, for the sidecar's `render` command (`None`: the default).
    pub config: Option<PathBuf>,
    /// The water mode at the start (M cycles it).
    pub water: super::WaterMode,
    /// The atmosphere at the start (T toggles it).
    pub atmosphere: bool,
    /// Flowing water (`false`: still water, as the thesis).
    pub flowing_water: bool,
    /// The water drawn by the terrain pass (`false`: the thesis's water pass).
    pub water_in_mesh: bool,
}

/// The display's event loop, or why there is none. Made before any other work, so that `view` without a display
/// says so at once instead of after generating a planet.
pub fn event_loop() -> Result<EventLoop<()>, ViewerError> {
    EventLoop::new().map_err(|e| ViewerError::Window(e.to_string()))
}

/// Opens the viewer on `event_loop` and runs until the window closes (or `frames` are done).
pub fn run(
    event_loop: EventLoop<()>,
    world: &World,
    context_options: &ContextOptions,
    options: ViewerOptions,
) -> Result<(), ViewerError> {
    let display = event_loop
        .display_handle()
        .map_err(|e| ViewerError::Window(e.to_string()))?
        .as_raw();
    let mut ctx_options = context_options.clone();
    ctx_options.instance_extensions = swapchain::surface_extensions(display)?;
    ctx_options.swapchain = true;
    ctx_options.draws = true;
    let ctx = Context::new(&ctx_options)?;
    let renderer = Renderer::new(
        &ctx,
        &world.planet,
        &world.network,
        &world.config,
        SWAPCHAIN_FORMAT,
        DEPTH_FORMAT,
    )?;
    let camera = home(&options, world.planet.radius);
    let paths = ViewerPaths::new(
        options.record.clone(),
        options.screenshots.join("bookmarks.json"),
        world.seed,
    );
    let mut app = App {
        ctx: &ctx,
        world,
        renderer: Some(renderer),
        overlay: None,
        options,
        window: None,
        surface: None,
        swapchain: None,
        depth: None,
        camera,
        ground: Ground::new(world),
        ground_height: 0.0,
        paths,
        keys: HashSet::new(),
        dragging: false,
        cursor: None,
        last: Instant::now(),
        frames: 0,
        smoothed_ms: 0.0,
        last_stats: FrameStats::default(),
        error: None,
    };
    app.keep_above_ground();
    crate::interrupt::defer();
    event_loop.set_control_flow(ControlFlow::Poll);
    let run = event_loop
        .run_app(&mut app)
        .map_err(|e| ViewerError::Window(e.to_string()));
    app.shutdown();
    run?;
    if let Some(file) = app.paths.finish().map_err(ViewerError::Path)? {
        println!("camera path: {}", file.display());
    }
    if let Some(e) = app.error {
        return Err(e);
    }
    let errors = ctx.validation_errors();
    match errors.first() {
        Some(first) => Err(ViewerError::Validation {
            count: errors.len(),
            first: first.clone(),
        }),
        None => Ok(()),
    }
}

/// The least height above the drawn surface the camera keeps.
const MIN_ALTITUDE: f64 = 0.3;

/// The start view, in orbit mode from more than half a radius up, else flying.
fn home(options: &ViewerOptions, radius: f64) -> ViewerCamera {
    let (eye, target) = (options.eye, options.look_at);
    let mode = if eye.length() > 1.5 * radius {
        CameraMode::Orbit
    } else {
        CameraMode::Fly
    };
    ViewerCamera::new(eye, target, mode)
}

struct App<'a> {
    ctx: &'a Context,
    world: &'a World,
    renderer: Option<Renderer<'a>>,
    overlay: Option<Overlay>,
    options: ViewerOptions,
    window: Option<Window>,
    surface: Option<Surface>,
    swapchain: Option<Swapchain>,
    depth: Option<Image>,
    camera: ViewerCamera,
    ground: Ground,
    /// The drawn surface's height below the camera (`keep_above_ground` updates it).
    ground_height: f64,
    paths: ViewerPaths,
    keys: HashSet<KeyCode>,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    last: Instant,
    frames: u64,
    /// Time between frames, exponentially smoothed.
    smoothed_ms: f64,
    last_stats: FrameStats,
    error: Option<ViewerError>,
}

impl App<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: ViewerError) {
        log::error!("{error}");
        self.error = Some(error);
        event_loop.exit();
    }

    fn radius(&self) -> f64 {
        self.world.planet.radius
    }

    /// Above the drawn surface below the camera.
    fn altitude(&self) -> f64 {
        self.camera.position.length() - self.radius() - self.ground_height
    }

    fn recreate_swapchain(&mut self) -> Result<(), ViewerError> {
        let (Some(window), Some(surface)) = (&self.window, &self.surface) else {
            return Ok(());
        };
        let PhysicalSize { width, height } = window.inner_size();
        if width == 0 || height == 0 {
            return Ok(());
        }
        self.ctx.wait_idle()?;
        if let Some(old) = self.swapchain.take() {
            old.destroy(self.ctx);
        }
        self.depth = None;
        let swapchain = Swapchain::new(self.ctx, surface, width, height)?;
        self.depth = Some(create_depth(self.ctx, swapchain.extent)?);
        self.swapchain = Some(swapchain);
        Ok(())
    }

    fn camera(&self, width: u32, height: u32) -> Camera {
        let altitude = self.altitude().max(0.01);
        self.camera.camera(
            width as f64 / height.max(1) as f64,
            crate::runtime::camera::near_plane(altitude),
        )
    }

    /// Keeps the camera above the drawn surface (terrain or water) below it.
    fn keep_above_ground(&mut self) {
        self.ground_height = self.ground.height_below(self.camera.position, self.world);
        let ground = self.radius() + self.ground_height;
        if self.camera.position.length() < ground + MIN_ALTITUDE {
            self.camera.position = self.camera.radial() * (ground + MIN_ALTITUDE);
        }
    }

    fn draw(&mut self) -> Result<(), ViewerError> {
        let now = Instant::now();
        let dt = (now - self.last).as_secs_f64().min(0.25);
        self.last = now;
        self.update_camera(dt);
        if self.swapchain.is_none() {
            self.recreate_swapchain()?;
        }
        let Some(extent) = self.swapchain.as_ref().map(|s| s.extent) else {
            return Ok(());
        }; // minimised
        let camera = self.camera(extent.width, extent.height);
        let info = ViewInfo {
            seed: self.world.seed,
            altitude: self.altitude(),
            mode: self.camera.mode,
            frame_ms: self.smoothed_ms,
        };
        let (Some(swapchain), Some(depth), Some(renderer)) =
            (&mut self.swapchain, &self.depth, &mut self.renderer)
        else {
            return Ok(());
        };
        renderer.time += dt as f32;
        let Some((index, acquired, rendered)) = swapchain.acquire()? else {
            return self.recreate_swapchain();
        };
        let target = swapchain.target(index, depth, crate::render::SPACE_CLEAR);
        if let (Some(overlay), Some(window)) = (&mut self.overlay, &self.window) {
            overlay.prepare(self.ctx, window, renderer, (&info, &self.last_stats))?;
        }
        let mut overlay_error = None;
        let mut draw_overlay = |rec: &mut crate::gpu::Recorder, extent| {
            if let Some(overlay) = &mut self.overlay {
                if let Err(e) = overlay.record(rec, extent) {
                    overlay_error = Some(e);
                }
            }
        };
        let stats = renderer.render_with_overlay(
            &camera,
            &target,
            Access::Present,
            (&[(acquired, Access::ColorAttachment)], &[rendered]),
            Some(&mut draw_overlay),
        )?;
        if let Some(e) = overlay_error {
            return Err(e.into());
        }
        let presented = swapchain.present(self.ctx, index)?;
        self.frames += 1;
        let altitude = self.altitude();
        self.paths.record(&self.camera, altitude);
        // Wall-clock time between frames (what the eye sees), not the CPU's share of it.
        let interval_ms = dt * 1e3;
        self.smoothed_ms = if self.frames == 1 {
            interval_ms
        } else {
            0.9 * self.smoothed_ms + 0.1 * interval_ms
        };
        self.update_title(&stats);
        self.last_stats = stats;
        if !presented {
            self.recreate_swapchain()?;
        }
        Ok(())
    }

    fn update_title(&self, stats: &FrameStats) {
        let Some(window) = &self.window else { return };
        let renderer = self.renderer.as_ref();
        let gpu = |name: &str| stats.gpu_ms.get(name).copied().unwrap_or(0.0);
        window.set_title(&format!(
            "riverplanet | seed {} | {:.1} ms ({:.0} fps) | gpu kernel {:.2} vertices {:.1} terrain {:.1} water {:.1} sky \
             {:.1} ms | {} \
             patches ({} new) | altitude {:.1} | {:?} | water {:?}{}{}{}",
            self.world.seed,
            self.smoothed_ms,
            1000.0 / self.smoothed_ms.max(1e-3),
            gpu("kernel"),
            gpu("vertices"),
            gpu("terrain"),
            gpu("water"),
            gpu("sky"),
            stats.visible_patches,
            stats.new_patches,
            self.altitude(),
            self.camera.mode,
            renderer.map(|r| r.water_mode).unwrap_or(super::WaterMode::Auto),
            if renderer.is_some_and(|r| r.freeze_lod) { " | lod frozen" } else { "" },
            if renderer.is_some_and(|r| r.variant == KernelVariant::Simple) { " | simple kernel" } else { "" },
            if renderer.is_some_and(|r| r.lod_rule == LodRule::Distance) { " | Eq. 6.1" } else { "" },
        ));
    }

    fn shutdown(&mut self) {
        let _ = self.ctx.wait_idle();
        self.renderer = None;
        if let Some(overlay) = self.overlay.take() {
            overlay.destroy(self.ctx);
        }
        if let Some(swapchain) = self.swapchain.take() {
            swapchain.destroy(self.ctx);
        }
        self.depth = None;
        if let Some(surface) = self.surface.take() {
            surface.destroy();
        }
        let _ = self.ctx.wait_idle();
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("riverplanet")
            .with_inner_size(PhysicalSize::new(
                self.options.size[0],
                self.options.size[1],
            ));
        let created = event_loop
            .create_window(attributes)
            .map_err(|e| ViewerError::Window(e.to_string()));
        let window = match created {
            Ok(w) => w,
            Err(e) => return self.fail(event_loop, e),
        };
        let handles = window
            .display_handle()
            .and_then(|d| window.window_handle().map(|w| (d.as_raw(), w.as_raw())))
            .map_err(|e| ViewerError::Window(e.to_string()));
        let surface =
            handles.and_then(|(d, w)| Surface::new(self.ctx, d, w).map_err(ViewerError::from));
        match surface {
            Ok(s) => self.surface = Some(s),
            Err(e) => return self.fail(event_loop, e),
        }
        match Overlay::new(
            self.ctx,
            &window,
            (SWAPCHAIN_FORMAT, DEPTH_FORMAT),
            self.options.overlay,
        ) {
            Ok(o) => self.overlay = Some(o),
            Err(e) => return self.fail(event_loop, e.into()),
        }
        self.window = Some(window);
        if let Some(renderer) = &mut self.renderer {
            renderer.water_mode = self.options.water;
            renderer.atmosphere_on = self.options.atmosphere;
            renderer.flowing_water = self.options.flowing_water;
            renderer.water_in_mesh = self.options.water_in_mesh;
        }
        if let Err(e) = self.recreate_swapchain() {
            self.fail(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let taken = match (&mut self.overlay, &self.window) {
            (Some(overlay), Some(window)) => overlay.on_event(window, &event),
            _ => false,
        };
        let input = matches!(
            event,
            WindowEvent::KeyboardInput { .. }
                | WindowEvent::MouseInput { .. }
                | WindowEvent::CursorMoved { .. }
                | WindowEvent::MouseWheel { .. }
        );
        if taken && input {
            // A release still reaches the camera, so no key or drag stays stuck.
            match event {
                WindowEvent::MouseInput { .. } => self.dragging = false,
                WindowEvent::KeyboardInput { event, .. } => {
                    if let PhysicalKey::Code(code) = event.physical_key {
                        self.keys.remove(&code);
                    }
                }
                _ => {}
            }
            return;
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                if let Err(e) = self.recreate_swapchain() {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    match event.state {
                        ElementState::Pressed => {
                            if !event.repeat {
                                self.key(event_loop, code);
                            }
                            self.keys.insert(code);
                        }
                        ElementState::Released => {
                            self.keys.remove(&code);
                        }
                    }
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x, y))) = (self.dragging, self.cursor) {
                    let altitude = self.altitude();
                    self.camera.drag(position.x - x, position.y - y, altitude);
                    self.keep_above_ground();
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                let altitude = self.altitude();
                self.camera.zoom(lines, altitude);
                self.keep_above_ground();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.draw() {
                    return self.fail(event_loop, e);
                }
                if self.options.frames.is_some_and(|n| self.frames >= n) {
                    if let Some(path) = self.options.screenshot.clone() {
                        if let Err(e) = self.screenshot(&path) {
                            return self.fail(event_loop, e);
                        }
                    }
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(signal) = crate::interrupt::requested() {
            println!("{signal}: stopping");
            if let Some(path) = self.options.screenshot.clone() {
                if let Err(e) = self.screenshot(&path) {
                    return self.fail(event_loop, e);
                }
            }
            return event_loop.exit();
        }
        if let Some(window) = &self.window {
            window.request_redraw();
        }
    }
}
