//! The command line: the arguments of every command (clap lives here and nowhere else in the program), and one
//! module per group of commands.

pub mod benchmarks;
pub mod export;
pub mod generate;
pub mod progress;
pub mod render;

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use riverplanet::{
    config::LodRule,
    export::raster::RasterFormat,
    kernel::gpu::autotune::KernelChoice,
    named::Named,
    render::{ViewMode, WaterMode},
};

#[derive(Parser)]
#[command(
    name = "riverplanet",
    version,
    about = "River networks on procedural planets, rendered with Vulkan"
)]
pub struct Cli {
    /// Use the first Vulkan device whose name contains this text.
    #[arg(long, global = true, env = "RIVERPLANET_ADAPTER")]
    pub adapter: Option<String>,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Show the Vulkan instance, every device, the chosen one and each required feature; fails if none is usable.
    Info {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Print the resolved configuration of FILE (exit code 2 if it is invalid).
    Config { file: PathBuf },
    /// Generate the planet: per-face heightmaps, statistics and (with --preview) an unfolded picture.
    Generate {
        #[command(flatten)]
        planet: PlanetArgs,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Also write DIR/preview.png, the six faces unfolded.
        #[arg(long)]
        preview: bool,
        /// Also write DIR/continents.png, land and sea as an equirectangular image (input for continents-from-file).
        #[arg(long)]
        equirect: bool,
        /// Level of detail of the face images (32 x 2^N + 1 pixels per edge with 33 vertices), made by the same
        /// on-demand refinement as the renderer's patches. Default: 6, or max-level-of-detail if lower.
        #[arg(long)]
        level: Option<u32>,
    },
    /// Export the planet for other tools (beyond the thesis).
    Export {
        #[command(subcommand)]
        what: ExportCommand,
    },
    /// Render one image headless (no display, no window system) and print per-pass GPU times.
    Render(RenderArgs),
    /// Open the interactive viewer (needs a display; see the README for keys).
    View(ViewArgs),
    /// Draw the figures of Chapter 9 (SVG and PNG) from `bench flight` JSON reports.
    Plot {
        /// Report of the normal flight.
        #[arg(long)]
        flight: PathBuf,
        /// Report of the stress flight.
        #[arg(long)]
        stress: Option<PathBuf>,
        #[arg(long)]
        out: PathBuf,
    },
    /// Write docs/results.md from the JSON reports of `bench kernel` and `bench flight` (see tools/results).
    Report {
        #[arg(long)]
        kernel: PathBuf,
        #[arg(long)]
        kernel_stress: PathBuf,
        #[arg(long)]
        flight: PathBuf,
        #[arg(long)]
        flight_stress: PathBuf,
        #[arg(long)]
        long_flight: Option<PathBuf>,
        /// The report of `bench kernel --parent-reuse`.
        #[arg(long)]
        kernel_reuse: Option<PathBuf>,
        /// Reports of `bench flight --descent` (repeat the option for several).
        #[arg(long)]
        descent: Vec<PathBuf>,
        /// Reports of `bench flight` on the default planet, one per level-of-detail rule or frames in flight
        /// (repeat the option for several).
        #[arg(long)]
        frame_flight: Vec<PathBuf>,
        /// A file with the commands that made the reports (quoted in the document).
        #[arg(long)]
        commands: PathBuf,
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure the river kernel variants side by side in one run.
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
}

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub planet: PlanetArgs,
    /// Camera position, world units with the planet centre at the origin.
    #[arg(long, value_parser = parse_vec3, default_value = "0,1200,3400", allow_hyphen_values = true)]
    pub eye: glam::DVec3,
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
    pub look_at: glam::DVec3,
    /// The screen's up [default: towards the planet's outward normal at the eye, or any direction across the view
    /// when that is straight down]; the viewer's screenshot sidecars give it, so their views keep their roll.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<glam::DVec3>,
    /// Place the camera from the planet's own features instead of --eye/--look-at: `orbit` (the first river's
    /// side of the planet), `mountains` (above the first river's source), `river` (close above the first river).
    #[arg(long, value_parser = named::<riverplanet::render::presets::Preset>(), conflicts_with_all = ["eye", "look_at", "up"])]
    pub preset: Option<riverplanet::render::presets::Preset>,
    /// Take the camera from a recorded camera path (`view --record`, or the viewer's bookmarks.json) instead of
    /// --eye/--look-at: its frame --path-frame, with the viewer's field of view.
    #[arg(long, conflicts_with_all = ["eye", "look_at", "up", "preset", "fov"])]
    pub path: Option<PathBuf>,
    /// With --path: which frame (a bookmark's number), 1 to the path's length [default: the last].
    #[arg(long, requires = "path", value_parser = clap::value_parser!(u32).range(1..))]
    pub path_frame: Option<u32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 45.0)]
    pub fov: f64,
    #[arg(long, value_parser = parse_size, default_value = "1280x720")]
    pub size: [u32; 2],
    #[arg(long, value_parser = named::<WaterMode>(), default_value = "auto")]
    pub water: WaterMode,
    #[arg(long, value_parser = named::<ViewMode>(), default_value = "shaded")]
    pub view: ViewMode,
    /// The river kernel: `simple` (7.3.1), `tiled` (7.3.2) or `auto`, the faster on this device (measured at
    /// first use and cached, with the tiled kernel's shape: docs/kernel.md).
    #[arg(long, value_parser = named::<KernelChoice>(), default_value = "auto")]
    pub kernel: KernelChoice,
    /// The thesis's level of detail: Eq. 6.1 on patch centres and instant switching, instead of nearest-point
    /// selection with morphing.
    #[arg(long)]
    pub no_morphing: bool,
    /// The level-of-detail rule instead of the configuration's `level-of-detail-rule`: `screen-space-error` or
    /// `distance` (the thesis's Eq. 6.1).
    #[arg(long, value_parser = parse_lod_rule)]
    pub lod_rule: Option<LodRule>,
    /// The atmosphere (single scattering in the shell of atmosphere-height; beyond the thesis). `off`: a
    /// constant haze and the clear colour behind the planet, for comparisons.
    #[arg(long, value_enum, default_value = "on")]
    pub atmosphere: Switch,
    /// Water that flows (beyond the thesis): ripples carried downstream, foam at banks and shores. `off`: the
    /// thesis's still water.
    #[arg(long, value_enum, default_value = "on")]
    pub flowing_water: Switch,
    /// The water drawn by the terrain pass, its vertices under water raised to the water's surface (beyond the
    /// thesis). `off`: the thesis's water pass of transparent triangles over the terrain.
    #[arg(long, value_enum, default_value = "on")]
    pub water_in_mesh: Switch,
    /// Put the sun this many degrees above the camera's horizon, straight ahead (-90 to 90; 3 is a sunset)
    /// [default: over the camera's shoulder].
    #[arg(long, value_parser = parse_elevation, allow_hyphen_values = true)]
    pub sun_elevation: Option<f64>,
    /// Seconds of animation: how far the water has flowed (a sequence of frames differs in this).
    #[arg(long, default_value_t = 0.0, value_parser = non_negative_number, allow_hyphen_values = true)]
    pub time: f64,
    /// The colour behind the planet (where no air is): red, green, blue in [0, 1].
    #[arg(long, value_parser = parse_colour, default_value = "0.02,0.03,0.06", allow_hyphen_values = true)]
    pub clear_color: glam::DVec3,
    /// Frames to run at most while patch data streams in (the image is taken when nothing is pending).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_frames: u32,
    #[arg(long)]
    pub out: PathBuf,
}

#[derive(clap::Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub planet: PlanetArgs,
    #[arg(long, value_parser = parse_size, default_value = "1280x720")]
    pub size: [u32; 2],
    /// Start position (default: the orbit preset).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<glam::DVec3>,
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
    pub look_at: glam::DVec3,
    #[arg(long, value_parser = named::<WaterMode>(), default_value = "auto")]
    pub water: WaterMode,
    /// The atmosphere (single scattering in the shell of atmosphere-height; beyond the thesis). `off`: a
    /// constant haze and the clear colour behind the planet, for comparisons.
    #[arg(long, value_enum, default_value = "on")]
    pub atmosphere: Switch,
    /// Water that flows (beyond the thesis): ripples carried downstream, foam at banks and shores. `off`: the
    /// thesis's still water.
    #[arg(long, value_enum, default_value = "on")]
    pub flowing_water: Switch,
    /// The water drawn by the terrain pass, its vertices under water raised to the water's surface (beyond the
    /// thesis). `off`: the thesis's water pass of transparent triangles over the terrain.
    #[arg(long, value_enum, default_value = "on")]
    pub water_in_mesh: Switch,
    /// Run this many frames, then exit (with --screenshot, write it first).
    #[arg(long)]
    pub frames: Option<u64>,
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Where P writes its screenshots (created when the first is taken), each with a JSON sidecar that holds the
    /// seed, the camera and the `render` command that makes the same image; and B its bookmarks.json.
    #[arg(long, default_value = "out")]
    pub screenshots: PathBuf,
    /// The on-screen overlay (settings, times, keys) at the start; U shows or hides it.
    #[arg(long, value_enum, default_value = "on")]
    pub overlay: Switch,
    /// Write every frame's camera to this JSON file when the viewer closes (a camera path that `render --path`
    /// and `bench flight --path` replay).
    #[arg(long)]
    pub record: Option<PathBuf>,
}

/// A feature that is on unless switched off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Switch {
    On,
    Off,
}

impl Switch {
    pub fn on(self) -> bool {
        self == Switch::On
    }
}

/// The planet a command makes.
#[derive(clap::Args)]
pub struct PlanetArgs {
    /// Configuration file [default: config/planet.xml if it exists, else the built-in default: Appendix A's
    /// planet with the drainage model].
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Override master-seed.
    #[arg(long, allow_hyphen_values = true)]
    pub seed: Option<u32>,
}

/// What `riverplanet export` writes.
#[derive(Subcommand)]
pub enum ExportCommand {
    /// The terrain with the rivers carved in (as the renderer draws it) at one level of detail, as six cube-face
    /// rasters face{0..5}.tif or .exr (32-bit float) or .png (16-bit) and layout.json: radius, units, sea level, how
    /// values turn into heights, and each face's orientation.
    Faces {
        #[command(flatten)]
        planet: PlanetArgs,
        /// Level of detail, 0 to 7: faces of 32 x 2^level + 1 pixels a side.
        #[arg(long, default_value_t = 4)]
        level: u32,
        /// tiff or exr (32-bit float heights) or png (16-bit grey, one height range for all faces).
        #[arg(long, value_parser = RasterFormat::parse, default_value = "tiff")]
        format: RasterFormat,
        /// The folder to write into (made if missing; its parent must exist).
        #[arg(long)]
        out: PathBuf,
    },
    /// The whole planet's terrain with the rivers carved in, as one longitude-latitude raster (GeoTIFF with its
    /// georeference, or 16-bit PNG) and its metadata beside it (the same name with .json).
    Equirect {
        #[command(flatten)]
        planet: PlanetArgs,
        /// WxH pixels.
        #[arg(long, value_parser = parse_size, default_value = "2048x1024")]
        size: [u32; 2],
        /// The level of detail the heights come from, 0 to 7 [default: the coarsest whose vertices lie no farther
        /// apart than the pixels, at most 7].
        #[arg(long)]
        level: Option<u32>,
        /// tiff (32-bit float GeoTIFF), exr (32-bit float OpenEXR) or png (16-bit grey).
        #[arg(long, value_parser = RasterFormat::parse, default_value = "tiff")]
        format: RasterFormat,
        /// The file: .tif or .tiff for tiff, .exr for exr, .png for png.
        #[arg(long)]
        out: PathBuf,
    },
    /// A longitude-latitude window at one level of detail: the terrain with the rivers carved in as a GeoTIFF or
    /// 16-bit PNG (metadata beside it, .json), or the terrain and the water surface as a binary glTF mesh with
    /// normals in a local east-up-south frame (Blender: File > Import > glTF 2.0).
    Region {
        #[command(flatten)]
        planet: PlanetArgs,
        /// WEST,SOUTH,EAST,NORTH in degrees (west below east, south below north).
        #[arg(long, value_parser = parse_bounds, allow_hyphen_values = true)]
        bounds: [f64; 4],
        /// Level of detail, 0 to 20: samples about one vertex spacing of that level apart.
        #[arg(long, default_value_t = 6)]
        level: u32,
        /// tiff (32-bit float GeoTIFF), exr (32-bit float OpenEXR), png (16-bit grey) or glb (mesh).
        #[arg(long, value_parser = RegionFormat::parse, default_value = "tiff")]
        format: RegionFormat,
        /// The file: .tif or .tiff, .exr, .png, or .glb, as --format says.
        #[arg(long)]
        out: PathBuf,
    },
    /// The rivers as RFC 7946 GeoJSON: lines cut at the antimeridian, [lon, lat] (the drainage model: [lon, lat,
    /// bed height]) rounded to 1e-6 degrees, with width, length and order (Strahler order for the drainage
    /// model); the drainage model's lakes as polygons.
    Rivers {
        #[command(flatten)]
        planet: PlanetArgs,
        /// The thesis's river model: how often its pieces are refined, 0 to 8 [default: hull-levels, what
        /// `generate` counts in stats.json]. The drainage model: the patch level whose heights the water is
        /// routed over, up to two above its base lattice's, each adding the streams that level resolves
        /// [default: the base lattice's level].
        #[arg(long)]
        level: Option<u32>,
        /// The GeoJSON file (.geojson or .json).
        #[arg(long)]
        out: PathBuf,
    },
}

/// The parser of a library's named values ([`Named`]): its names, listed in --help, to its values (the library
/// does not depend on clap).
fn named<T: Named + Clone + Send + Sync>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::ALL.iter().map(|(name, _)| *name))
        .try_map(|name: String| T::from_name(&name).ok_or(format!("'{name}' has no value")))
}

/// What `export region` writes.
#[derive(Clone, Copy, Debug)]
pub enum RegionFormat {
    Raster(RasterFormat),
    Glb,
}

impl RegionFormat {
    fn parse(text: &str) -> Result<Self, String> {
        match text {
            "glb" => Ok(Self::Glb),
            _ => RasterFormat::parse(text)
                .map(Self::Raster)
                .map_err(|_| format!("'{text}' is not a region format: tiff, exr, png or glb")),
        }
    }
}

/// The planet a benchmark runs on (seed 1 unless given, so runs compare).
#[derive(clap::Args)]
pub struct BenchPlanet {
    /// Configuration file [default: config/planet.xml if it exists, else the built-in default: Appendix A's
    /// planet with the drainage model].
    #[arg(long)]
    pub config: Option<PathBuf>,
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    pub seed: u32,
}

#[derive(Subcommand)]
pub enum BenchCommand {
    /// CPU single-thread, CPU rayon, GPU simple and GPU tiled on identical input (Tables 9.1/9.2): every river
    /// patch the scripted flight meets, as one batch.
    Kernel {
        #[command(flatten)]
        planet: BenchPlanet,
        /// The thesis's stress test: switch factor x10, camera x25.
        #[arg(long)]
        stress: bool,
        /// Frames of the flight that produces the workload.
        #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        /// Compare river data taken from the parent patch (10.2) with computing from scratch, on the patches of
        /// the descent to the ground whose parents have the rivers' final detail (use config/earth.xml).
        #[arg(long, conflicts_with = "stress")]
        parent_reuse: bool,
        /// Repetitions per variant (the median is reported).
        #[arg(long, default_value_t = 5, value_parser = positive_count)]
        repetitions: usize,
        /// Invocations per workgroup of the simple kernel [default: the measured choice of this device].
        #[arg(long)]
        simple_workgroup: Option<u32>,
        /// Vertex block per workgroup of the tiled kernel, as WxH [default: the measured choice of this device].
        #[arg(long, value_parser = parse_block)]
        tiled_block: Option<[u32; 2]>,
        /// Samples staged per tile by the tiled kernel [default: the measured choice of this device].
        #[arg(long)]
        tile_size: Option<u32>,
        /// Write the report here as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// The scripted flight from orbit to the surface, rendered headless, with per-frame statistics (Chapter 9).
    Flight {
        #[command(flatten)]
        planet: BenchPlanet,
        /// The thesis's stress test: switch factor x10, camera x25.
        #[arg(long)]
        stress: bool,
        /// Fly the descent from three radii out to two world units above the first river's water (the ground
        /// preset) instead of the thesis's path.
        #[arg(long, conflicts_with = "stress")]
        descent: bool,
        /// Replay a recorded camera path (`view --record`, or the viewer's bookmarks.json) instead of the
        /// thesis's path, one frame per recorded frame (--frames is then the path's length).
        #[arg(long, conflicts_with_all = ["stress", "descent"])]
        path: Option<PathBuf>,
        /// With --descent: write the frames whose hole check fails to DIR/holes-FRAME.png.
        #[arg(long, requires = "descent")]
        hole_images: Option<PathBuf>,
        /// With --descent: write every tenth frame (those checked for holes) to DIR/frame-FRAME.png.
        #[arg(long, requires = "descent")]
        frame_images: Option<PathBuf>,
        /// The thesis's level of detail: Eq. 6.1 on patch centres and instant switching.
        #[arg(long)]
        no_morphing: bool,
        /// Compute every patch's river data from scratch, as the thesis (no data from the parent, 10.2).
        #[arg(long)]
        no_parent_reuse: bool,
        /// The level-of-detail rule instead of the configuration's: `screen-space-error` or `distance` (Eq. 6.1).
        #[arg(long, value_parser = parse_lod_rule)]
        lod_rule: Option<LodRule>,
        /// Frames the CPU may record ahead of the GPU (1: wait for every frame before the next, as the thesis).
        #[arg(long, default_value_t = riverplanet::gpu::frames::FRAMES_IN_FLIGHT,
              value_parser = clap::builder::RangedU64ValueParser::<usize>::new()
                  .range(1..=riverplanet::gpu::frames::MAX_FRAMES_IN_FLIGHT as u64))]
        frames_in_flight: usize,
        #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        /// The atmosphere (beyond the thesis); `off`: a constant haze, as before it.
        #[arg(long, value_enum, default_value = "on")]
        atmosphere: Switch,
        /// The vertex cache (beyond the thesis): the drawn patches' vertices computed once a frame in a compute
        /// pass; `off`: in the vertex shaders of both passes, as the thesis.
        #[arg(long, value_enum, default_value = "on")]
        vertex_cache: Switch,
        /// The water drawn by the terrain pass (beyond the thesis); `off`: the thesis's water pass.
        #[arg(long, value_enum, default_value = "on")]
        water_in_mesh: Switch,
        /// Camera speed factor (the stress test uses 25).
        #[arg(long, default_value_t = 1.0, value_parser = positive_number, allow_hyphen_values = true)]
        speed: f64,
        #[arg(long, value_parser = parse_size, default_value = "1280x720")]
        size: [u32; 2],
        /// Skip rerunning each frame's kernel input through all four variants.
        #[arg(long)]
        no_kernel_comparison: bool,
        /// Skip the flights in the geometry and painted water modes.
        #[arg(long)]
        no_water_comparison: bool,
        #[arg(long)]
        json: PathBuf,
        /// Leave the per-frame records out of the JSON (for very long flights).
        #[arg(long)]
        summary_only: bool,
        #[arg(long)]
        csv: Option<PathBuf>,
    },
}

fn parse_block(text: &str) -> Result<[u32; 2], String> {
    let (w, h) = text
        .split_once('x')
        .ok_or_else(|| format!("'{text}' is not of the form WxH (e.g. 8x8)"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{text}' is not of the form WxH (e.g. 8x8)"))
    };
    Ok([parse(w)?, parse(h)?])
}

/// A whole number of at least 1.
fn positive_count(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("'{text}' is not a whole number of at least 1")),
    }
}

fn parse_lod_rule(text: &str) -> Result<LodRule, String> {
    LodRule::from_name(text).ok_or_else(|| {
        format!(
            "'{text}' is not a level-of-detail rule: screen-space-error or distance (the thesis's Eq. 6.1)"
        )
    })
}

/// An angle above the horizon in degrees, -90 to 90.
fn parse_elevation(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if (-90.0..=90.0).contains(&x) => Ok(x),
        _ => Err(format!("'{text}' is not an angle from -90 to 90 degrees")),
    }
}

/// A finite number of at least 0.
fn non_negative_number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("'{text}' is not a finite number of at least 0")),
    }
}

/// A finite number above 0.
fn positive_number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("'{text}' is not a finite number above 0")),
    }
}

fn parse_vec3(text: &str) -> Result<glam::DVec3, String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{text}' is not three comma-separated numbers (e.g. 0,1200,3400)"))?;
    match parts.as_slice() {
        [x, y, z] if parts.iter().all(|v| v.is_finite()) => Ok(glam::DVec3::new(*x, *y, *z)),
        _ => Err(format!(
            "'{text}' is not three comma-separated numbers (e.g. 0,1200,3400)"
        )),
    }
}

/// R,G,B: three numbers in [0, 1].
fn parse_colour(text: &str) -> Result<glam::DVec3, String> {
    match parse_vec3(text) {
        Ok(c) if c.min_element() >= 0.0 && c.max_element() <= 1.0 => Ok(c),
        _ => Err(format!("'{text}' is not R,G,B with each in [0, 1]")),
    }
}

/// WEST,SOUTH,EAST,NORTH: four finite numbers (their ranges are checked with the level, `Region::new`).
fn parse_bounds(text: &str) -> Result<[f64; 4], String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{text}' is not WEST,SOUTH,EAST,NORTH in degrees"))?;
    match values[..] {
        [w, s, e, n] if values.iter().all(|v| v.is_finite()) => Ok([w, s, e, n]),
        _ => Err(format!(
            "'{text}' is not WEST,SOUTH,EAST,NORTH: four finite numbers in degrees"
        )),
    }
}

fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let [w, h] = parse_block(text)?;
    if (1..=16384).contains(&w) && (1..=16384).contains(&h) {
        Ok([w, h])
    } else {
        Err(format!("size '{text}' must be WxH with both in [1, 16384]"))
    }
}
