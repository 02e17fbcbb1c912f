//! The windowed viewer under Xvfb: 60 frames, a screenshot with its camera sidecar, a clean exit (no validation
//! error); the sidecar's `render` command makes the same picture; the overlay shows in a screenshot; synthetic
//! mouse and keyboard input move the camera, which stays above the surface.

use std::process::Command;

/// A small planet (seed 3, base lattice 65, levels to 4) in `dir`, which is made: its configuration file.
fn small_planet(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let config = dir.join("small.xml");
    std::fs::write(
        &config,
        "<planet><planet-attributes><base-resolution>65</base-resolution><master-seed>3</master-seed>\
         </planet-attributes><rendering-attributes><max-level-of-detail>4</max-level-of-detail>\
         </rendering-attributes></planet>",
    )
    .unwrap();
    config
}

#[test]
fn viewer_runs_60_frames_under_xvfb_and_its_screenshot_sidecar_renders_the_same_view() {
    let required = gpu_required();
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        assert!(
            !required,
            "RIVERPLANET_REQUIRE_GPU=1 but xvfb-run is missing (tools/setup installs xvfb)"
        );
        eprintln!("skipping: xvfb-run is not installed");
        return;
    }
    let dir = std::env::temp_dir().join(format!("riverplanet-viewer-{}", std::process::id()));
    let config = small_planet(&dir);
    let shot = dir.join("shot.png");
    let output = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24"])
        .arg(env!("CARGO_BIN_EXE_riverplanet"))
        .args([
            "view",
            "--size",
            "320x240",
            "--frames",
            "60",
            "--overlay",
            "off",
            "--config",
        ])
        .arg(&config)
        .arg("--screenshot")
        .arg(&shot)
        .env("RIVERPLANET_VALIDATION", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() && !required && stderr.contains("no usable Vulkan") {
        eprintln!("skipping: {stderr}");
        return;
    }
    assert!(output.status.success(), "viewer failed: {stderr}");
    let image = image::open(&shot).unwrap().to_rgba8();
    let first = image.get_pixel(0, 0);
    assert!(
        image.pixels().any(|p| p != first),
        "the screenshot is one flat colour"
    );
    // The sidecar: the seed, the camera (orbit mode from three radii out), and a command that renders the view.
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("shot.json")).unwrap()).unwrap();
    assert_eq!(sidecar["seed"], 3);
    assert_eq!(sidecar["camera"]["mode"], "Orbit");
    let command = sidecar["render"].as_str().unwrap();
    let mut args: Vec<String> = command
        .split_whitespace()
        .skip(1)
        .map(String::from)
        .collect();
    assert_eq!(args[0], "render", "{command}");
    let out = args.iter().position(|a| a == "--out").unwrap() + 1;
    args[out] = dir.join("again.png").display().to_string();
    let again = Command::new(env!("CARGO_BIN_EXE_riverplanet"))
        .args(&args)
        .output()
        .unwrap();
    assert!(
        again.status.success(),
        "{command}: {}",
        String::from_utf8_lossy(&again.stderr)
    );
    let rendered = image::open(dir.join("again.png")).unwrap().to_rgba8();
    assert_eq!(rendered.dimensions(), image.dimensions());
    let differing = image
        .pixels()
        .zip(rendered.pixels())
        .filter(|(p, q)| (0..3).any(|c| (p.0[c] as i32 - q.0[c] as i32).abs() > 24))
        .count();
    let share = differing as f64 / (image.width() * image.height()) as f64;
    eprintln!(
        "the sidecar's render differs in {:.2} % of the pixels",
        share * 100.0
    );
    assert!(
        share < 0.02,
        "the sidecar's command renders another view ({:.1} % of the pixels differ)",
        share * 100.0
    );
    std::fs::remove_dir_all(&dir).ok();
}

fn gpu_required() -> bool {
    std::env::var("RIVERPLANET_REQUIRE_GPU").is_ok_and(|v| v == "1")
}

/// `riverplanet view --size 320x240 ARGS` on `xvfb` with validation, and the input into its display, once its
/// window shows; `None` to skip the test (as [`shown`]).
fn start_viewer(xvfb: &Xvfb, args: &[&std::ffi::OsStr]) -> Option<(std::process::Child, Input)> {
    let viewer = Command::new(env!("CARGO_BIN_EXE_riverplanet"))
        .args(["view", "--size", "320x240"])
        .args(args)
        .env("DISPLAY", &xvfb.display)
        .env("RIVERPLANET_VALIDATION", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let input = Input::connect(&xvfb.display);
    let viewer = shown(viewer, &input)?;
    Some((viewer, input))
}

/// `viewer` once its window shows (within a minute), or `None` to skip the test: it found no usable Vulkan device
/// (only without RIVERPLANET_REQUIRE_GPU=1).
fn shown(mut viewer: std::process::Child, input: &Input) -> Option<std::process::Child> {
    let started = std::time::Instant::now();
    while input.shown_window().is_none() {
        if let Ok(Some(status)) = viewer.try_wait() {
            let output = viewer.wait_with_output().unwrap();
            let stderr = String::from_utf8_lossy(&output.stderr);
            if !gpu_required() && stderr.contains("no usable Vulkan") {
                eprintln!("skipping: {stderr}");
                return None;
            }
            panic!("the viewer ended ({status}) before showing a window: {stderr}");
        }
        assert!(started.elapsed().as_secs() < 60, "no window after a minute");
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    Some(viewer)
}

/// An X server of the test's own (Xvfb on a free display), killed when dropped.
struct Xvfb {
    display: String,
    server: std::process::Child,
}

impl Xvfb {
    /// The test's X server, or `None` to skip the test (only without RIVERPLANET_REQUIRE_GPU=1).
    fn for_test() -> Option<Self> {
        let server = Self::start();
        if server.is_none() {
            assert!(
                !gpu_required(),
                "RIVERPLANET_REQUIRE_GPU=1 but Xvfb does not start (tools/setup installs xvfb)"
            );
            eprintln!("skipping: Xvfb does not start");
        }
        server
    }

    fn start() -> Option<Self> {
        for number in 40 + std::process::id() % 200..400 {
            if std::path::Path::new(&format!("/tmp/.X11-unix/X{number}")).exists() {
                continue;
            }
            let server = Command::new("Xvfb")
                .args([
                    &format!(":{number}"),
                    "-screen",
                    "0",
                    "640x480x24",
                    "-nolisten",
                    "tcp",
                ])
                .stderr(std::process::Stdio::null())
                .spawn()
                .ok()?;
            let display = format!(":{number}");
            for _ in 0..100 {
                if std::path::Path::new(&format!("/tmp/.X11-unix/X{number}")).exists() {
                    return Some(Self { display, server });
                }
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            return None;
        }
        None
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.server.kill();
        let _ = self.server.wait();
    }
}

/// Synthetic input through the X server's XTEST extension, as a user's mouse and keyboard would send it.
struct Input {
    conn: x11rb::rust_connection::RustConnection,
    root: u32,
}

impl Input {
    fn connect(display: &str) -> Self {
        use x11rb::connection::Connection;
        let (conn, screen) =
            x11rb::rust_connection::RustConnection::connect(Some(display)).unwrap();
        let root = conn.setup().roots[screen].root;
        Self { conn, root }
    }

    fn fake(&self, kind: u8, detail: u8, (x, y): (i16, i16)) {
        use x11rb::{connection::Connection, protocol::xtest::ConnectionExt};
        self.conn
            .xtest_fake_input(kind, detail, 0, self.root, x, y, 0)
            .unwrap();
        self.conn.flush().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(30));
    }

    fn move_to(&self, x: i16, y: i16) {
        self.fake(x11rb::protocol::xproto::MOTION_NOTIFY_EVENT, 0, (x, y));
    }

    fn button(&self, button: u8, down: bool) {
        use x11rb::protocol::xproto::{BUTTON_PRESS_EVENT, BUTTON_RELEASE_EVENT};
        let kind = if down {
            BUTTON_PRESS_EVENT
        } else {
            BUTTON_RELEASE_EVENT
        };
        self.fake(kind, button, (0, 0));
    }

    /// The keycode of a keysym (X11 keysyms of letters are their lower-case ASCII codes).
    fn keycode(&self, keysym: u32) -> u8 {
        use x11rb::{connection::Connection, protocol::xproto::ConnectionExt};
        let setup = self.conn.setup();
        let (min, max) = (setup.min_keycode, setup.max_keycode);
        let map = self
            .conn
            .get_keyboard_mapping(min, max - min + 1)
            .unwrap()
            .reply()
            .unwrap();
        let per = map.keysyms_per_keycode as usize;
        let index = map.keysyms.iter().position(|&k| k == keysym).unwrap();
        min + (index / per) as u8
    }

    fn key(&self, keysym: u32, down: bool) {
        use x11rb::protocol::xproto::{KEY_PRESS_EVENT, KEY_RELEASE_EVENT};
        let kind = if down {
            KEY_PRESS_EVENT
        } else {
            KEY_RELEASE_EVENT
        };
        self.fake(kind, self.keycode(keysym), (0, 0));
    }

    /// The window mapped on the screen, if one is; it gets the keyboard focus (no window manager gives it).
    fn shown_window(&self) -> Option<u32> {
        use x11rb::{
            connection::Connection,
            protocol::xproto::{ConnectionExt, InputFocus, MapState},
        };
        let tree = self.conn.query_tree(self.root).unwrap().reply().unwrap();
        let window = tree.children.into_iter().find(|&w| {
            self.conn
                .get_window_attributes(w)
                .ok()
                .and_then(|c| c.reply().ok())
                .is_some_and(|a| a.map_state == MapState::VIEWABLE)
        })?;
        self.conn
            .set_input_focus(InputFocus::POINTER_ROOT, window, x11rb::CURRENT_TIME)
            .unwrap();
        self.conn.flush().unwrap();
        Some(window)
    }
}

const XK_Q: u32 = 0x71;
const XK_H: u32 = 0x68;
const XK_SHIFT_L: u32 = 0xffe1;
const XK_ESCAPE: u32 = 0xff1b;

/// The viewer driven by synthetic mouse and keyboard input under Xvfb: an orbit drag turns the view, ten wheel
/// lines zoom towards the ground, Shift+Q held descends until the camera meets the surface, H returns home,
/// Escape quits. The recorded camera path (`--record`) shows every frame at least 0.3 above the drawn surface
/// below the camera, recomputed here (`render::ground`), the descent reaching it, and the last frame at home.
#[test]
fn the_viewer_follows_synthetic_input_and_its_camera_stays_above_the_surface() {
    let Some(xvfb) = Xvfb::for_test() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("riverplanet-input-{}", std::process::id()));
    let config = small_planet(&dir);
    let record = dir.join("path.json");
    let args = [
        "--overlay".as_ref(),
        "off".as_ref(),
        "--config".as_ref(),
        config.as_os_str(),
    ];
    let more = [
        "--record".as_ref(),
        record.as_os_str(),
        "--screenshots".as_ref(),
        dir.as_os_str(),
    ];
    let Some((mut viewer, input)) = start_viewer(&xvfb, &[&args[..], &more[..]].concat()) else {
        return;
    };
    let pause = |ms| std::thread::sleep(std::time::Duration::from_millis(ms));
    pause(1500);
    // Focus again now that the viewer listens (no window manager gives it).
    input.shown_window();
    // Orbit drag across the window.
    input.move_to(100, 120);
    input.button(1, true);
    for step in 1..=10 {
        input.move_to(100 + 12 * step, 120);
    }
    input.button(1, false);
    pause(500);
    // Ten wheel lines towards the ground (button 4: wheel up).
    for _ in 0..10 {
        input.button(4, true);
        input.button(4, false);
    }
    pause(500);
    // Descend fast until the ground stops the camera.
    input.key(XK_SHIFT_L, true);
    input.key(XK_Q, true);
    pause(5000);
    input.key(XK_Q, false);
    input.key(XK_SHIFT_L, false);
    pause(500);
    input.key(XK_H, true);
    input.key(XK_H, false);
    pause(1000);
    input.key(XK_ESCAPE, true);
    input.key(XK_ESCAPE, false);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while viewer.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            let _ = viewer.kill();
            let output = viewer.wait_with_output().unwrap();
            panic!(
                "the viewer did not close on Escape: {}{}",
                String::from_utf8_lossy(&output.stdout),
                String::from_utf8_lossy(&output.stderr)
            );
        }
        pause(100);
    }
    let output = viewer.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "viewer failed: {stderr}");

    let path = riverplanet::runtime::camera_path::CameraPath::load(&record).unwrap();
    let frames = &path.frames;
    assert!(frames.len() > 20, "only {} frames recorded", frames.len());
    let config = riverplanet::config::Config::load(&config).unwrap();
    let world = riverplanet::world::World::build(&config, 3).unwrap();
    let mut ground = riverplanet::render::ground::Ground::new(&world);
    let radius = world.planet.radius;
    let position = |k: usize| glam::DVec3::from_array(frames[k].position);
    let mut lowest = f64::MAX;
    for (k, frame) in frames.iter().enumerate() {
        let p = position(k);
        let above = p.length() - radius - ground.height_below(p, &world);
        assert!(above >= 0.3 - 1e-6, "frame {k}: {above} above the surface");
        assert!(
            (above - frame.altitude).abs() < 1e-6,
            "frame {k}: recorded altitude"
        );
        lowest = lowest.min(above);
    }
    let turned = (0..frames.len())
        .map(|k| position(k).angle_between(position(0)))
        .fold(0.0, f64::max);
    let home = frames[0].altitude;
    eprintln!(
        "{} frames: turned by up to {turned:.3} rad, lowest {lowest:.3} above the surface (home {home:.1})",
        frames.len()
    );
    assert!(
        turned > 0.05,
        "the drag did not turn the view ({turned} rad)"
    );
    assert!(
        lowest < 1.0,
        "the descent stopped {lowest} above the surface"
    );
    let last = frames.last().unwrap();
    assert_eq!(last.position, frames[0].position, "H did not return home");
    assert_eq!(last.forward, frames[0].forward);
    std::fs::remove_dir_all(&dir).ok();
}

/// The overlay (egui) shows in a screenshot: with it the top-left corner, where its panel sits, differs from the
/// same view without it (`--overlay off`) in a good share of its pixels (measured: 36 %; its translucent dark
/// panel over dark space changes little), and the rest of the picture hardly (0.0 %); no validation error
/// in either run (the viewer fails on one).
#[test]
fn the_overlay_shows_in_a_screenshot() {
    let required = gpu_required();
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        assert!(
            !required,
            "RIVERPLANET_REQUIRE_GPU=1 but xvfb-run is missing"
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("riverplanet-overlay-{}", std::process::id()));
    let config = small_planet(&dir);
    let shoot = |overlay: &str| {
        let shot = dir.join(format!("overlay-{overlay}.png"));
        let output = Command::new("xvfb-run")
            .args(["-a", "-s", "-screen 0 800x600x24"])
            .arg(env!("CARGO_BIN_EXE_riverplanet"))
            .args([
                "view",
                "--size",
                "640x400",
                "--frames",
                "40",
                "--overlay",
                overlay,
                "--config",
            ])
            .arg(&config)
            .arg("--screenshot")
            .arg(&shot)
            .env("RIVERPLANET_VALIDATION", "1")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "viewer failed: {stderr}");
        image::open(&shot).unwrap().to_rgba8()
    };
    let (on, off) = (shoot("on"), shoot("off"));
    let differing = |x0: u32, y0: u32, x1: u32, y1: u32| {
        let mut count = 0;
        for y in y0..y1 {
            for x in x0..x1 {
                let (p, q) = (on.get_pixel(x, y), off.get_pixel(x, y));
                count += usize::from((0..3).any(|c| (p.0[c] as i32 - q.0[c] as i32).abs() > 24));
            }
        }
        count as f64 / ((x1 - x0) * (y1 - y0)) as f64
    };
    let (panel, rest) = (differing(10, 10, 200, 200), differing(400, 0, 640, 400));
    eprintln!(
        "pixels that differ: {:.1} % under the panel, {:.1} % on the right",
        panel * 100.0,
        rest * 100.0
    );
    assert!(
        panel > 0.2,
        "the overlay does not show ({:.1} % differ)",
        panel * 100.0
    );
    assert!(
        rest < 0.05,
        "the overlay changed the picture ({:.1} % differ)",
        rest * 100.0
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// SIGTERM (and SIGINT) end the viewer as Escape does: the requested screenshot and the camera path are written,
/// the device released (no leak warnings), exit code 0.
#[test]
fn sigterm_stops_the_viewer_cleanly_with_its_screenshot() {
    let Some(xvfb) = Xvfb::for_test() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("riverplanet-sigterm-{}", std::process::id()));
    let config = small_planet(&dir);
    let (shot, record) = (dir.join("stopped.png"), dir.join("path.json"));
    let args = [
        "--config".as_ref(),
        config.as_os_str(),
        "--screenshot".as_ref(),
        shot.as_os_str(),
        "--record".as_ref(),
        record.as_os_str(),
    ];
    let Some((viewer, _input)) = start_viewer(&xvfb, &args) else {
        return;
    };
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = Command::new("kill")
        .args(["-TERM", &viewer.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let output = viewer.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    assert!(
        output.status.success(),
        "viewer failed after SIGTERM: {stderr}"
    );
    assert!(stdout.contains("SIGTERM: stopping"), "{stdout}");
    assert!(!stderr.to_lowercase().contains("leak"), "{stderr}");
    let image = image::open(&shot).unwrap().to_rgba8();
    assert_eq!(image.dimensions(), (320, 240));
    assert!(shot.with_extension("json").exists(), "no camera sidecar");
    let path = riverplanet::runtime::camera_path::CameraPath::load(&record).unwrap();
    assert!(!path.frames.is_empty(), "no frame recorded");
    let _ = std::fs::remove_dir_all(&dir);
}
