//! Issue "Your own terrain, your own program": a planet from a height raster (`<relief-model>file</relief-model>`,
//! `<terrain-file>`), as a user makes one: a planet exported with `export equirect` and read back, in each of the
//! formats `export` writes, and files that cannot be a planet refused before any work.

mod common;

use std::{
    collections::HashMap,
    path::{Path, PathBuf},
    process::Command,
};

use glam::DVec3;
use riverplanet::{
    config::Config,
    planet::{direction_at, lon_lat, terrain_file::TerrainFile, Planet},
};

fn riverplanet(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_riverplanet"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

fn succeeds(args: &[&str]) -> String {
    let out = riverplanet(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).to_string()
}

/// A fresh folder of this test run for `name`'s files.
fn temp_dir(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("riverplanet-terrain-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Seed 1 of config/planet.xml as `export equirect --size SIZE --format FORMAT` writes it, to `dir/world.EXT`.
fn export_world(dir: &Path, size: &str, format: &str, extension: &str) -> PathBuf {
    let path = dir.join(format!("world.{extension}"));
    succeeds(&[
        "export",
        "equirect",
        "--seed",
        "1",
        "--size",
        size,
        "--format",
        format,
        "--out",
        path.to_str().unwrap(),
    ]);
    path
}

/// config/planet.xml with its relief from `terrain` (relative to the configuration's folder) and `extra` elements.
fn file_config(dir: &Path, terrain: &str, extra: &str) -> PathBuf {
    let default =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("config/planet.xml"))
            .unwrap();
    let text = default.replace(
        "<continents-from-file>>false</continents-from-file>",
        &format!("<relief-model>file</relief-model><terrain-file>{terrain}</terrain-file>{extra}"),
    );
    assert_ne!(text, default);
    let path = dir.join(format!("{}.xml", terrain.replace('.', "-")));
    std::fs::write(&path, text).unwrap();
    path
}

fn planet(config: &Path) -> Planet {
    let config = Config::load(config).unwrap();
    Planet::generate(&config, 1, |_| {}).unwrap()
}

/// River course points bucketed by whole degrees of longitude and latitude, for "is a river near" questions.
struct RiverPoints(HashMap<(i32, i32), Vec<DVec3>>);

impl RiverPoints {
    fn new(planet: &Planet, lowest_order: u32) -> Self {
        let mut buckets: HashMap<(i32, i32), Vec<DVec3>> = HashMap::new();
        let drainage = planet.drainage.as_ref().unwrap();
        for reach in drainage
            .reaches
            .iter()
            .filter(|r| r.strahler >= lowest_order)
        {
            for &p in &reach.points {
                buckets.entry(Self::bucket(p)).or_default().push(p);
            }
        }
        Self(buckets)
    }

    fn bucket(p: DVec3) -> (i32, i32) {
        let (lon, lat) = lon_lat(p);
        (lon.floor() as i32, lat.floor() as i32)
    }

    /// Whether a river point lies within `angle` radians of `p` (angle at most a degree).
    fn near(&self, p: DVec3, angle: f64) -> bool {
        let (x, y) = Self::bucket(p);
        (-2..=2).any(|dx| {
            (-1..=1).any(|dy| {
                let x = (x + dx + 180).rem_euclid(360) - 180;
                self.0
                    .get(&(x, y + dy))
                    .is_some_and(|points| points.iter().any(|q| q.angle_between(p) <= angle))
            })
        })
    }
}

/// `export equirect` at 1024x512 (two pixels per base cell) read back as the relief: the same land, the same
/// heights away from the rivers (whose beds the export carves in), the same rivers, drained as before.
#[test]
fn a_planet_exported_and_read_back_is_the_same_planet() {
    let dir = temp_dir("round-trip");
    export_world(&dir, "1024x512", "tiff", "tif");
    let original = planet(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/planet.xml"));
    let read_back = planet(&file_config(&dir, "world.tif", ""));

    let (a, b) = (
        original.stats.landmass_percent,
        read_back.stats.landmass_percent,
    );
    println!("land {a:.2} % -> {b:.2} %");
    assert!((a - b).abs() < 0.5, "land {a:.2} % became {b:.2} %");

    // Heights at points a base cell and more from every river and lake of the original.
    let default =
        Config::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/planet.xml")).unwrap();
    let cell = std::f64::consts::FRAC_PI_2 / (default.planet.base_resolution - 1) as f64;
    let rivers = RiverPoints::new(&original, 1);
    let relief = (original.stats.max_height - original.stats.min_height) as f64;
    let mut differences = Vec::new();
    for y in 0..180 {
        for x in 0..360 {
            let p = direction_at(x as f64 - 179.5, 89.5 - y as f64);
            if rivers.near(p, 2.0 * cell) {
                continue;
            }
            differences
                .push((original.height_at(p) - read_back.height_at(p)).abs() as f64 / relief);
        }
    }
    differences.sort_by(f64::total_cmp);
    let at = |q: f64| differences[((differences.len() - 1) as f64 * q) as usize];
    println!(
        "{} points away from rivers: |height difference| / relief median {:.4}, 95 % {:.4}, 99 % {:.4}",
        differences.len(),
        at(0.5),
        at(0.95),
        at(0.99)
    );
    // Measured: 0.0007 and 0.0036 (the file's pixels between the base lattice's points, bilinear).
    assert!(
        at(0.5) < 0.002 && at(0.99) < 0.01,
        "heights moved by {:.4} (median) and {:.4} (99 %) of the relief",
        at(0.5),
        at(0.99)
    );

    // The rivers: the original's of order 2 and more, found again within a base cell.
    let again = RiverPoints::new(&read_back, 1);
    let drainage = original.drainage.as_ref().unwrap();
    let points: Vec<DVec3> = drainage
        .reaches
        .iter()
        .filter(|r| r.strahler >= 2)
        .flat_map(|r| r.points.iter().copied())
        .collect();
    let found = points.iter().filter(|&&p| again.near(p, cell)).count();
    println!("{found} of {} river points found again", points.len());
    assert!(
        found as f64 >= 0.98 * points.len() as f64,
        "only {found} of {} river points of order 2 and more found again within a base cell",
        points.len()
    );
    let measures = &read_back.drainage.as_ref().unwrap().measures;
    assert_eq!(
        (measures.uphill_steps, measures.crossings),
        (0, 0),
        "uphill steps and crossings"
    );
}

/// The same planet as 16-bit PNG (its height scale and offset in the JSON beside it) and OpenEXR reads as the TIFF
/// does: the EXR's heights equal, the PNG's within half its height step; and the TIFF written again with Deflate
/// compression (as GIS tools often write DEMs) equal.
#[test]
fn every_format_export_writes_reads_back_alike() {
    let dir = temp_dir("formats");
    let read = |format: &str, extension: &str| {
        let path = export_world(&dir, "256x128", format, extension);
        TerrainFile::load(&path, (1.0, 0.0), 0.4).unwrap()
    };
    let (tiff, exr, png) = (read("tiff", "tif"), read("exr", "exr"), read("png", "png"));
    let deflated = dir.join("deflated.tif");
    {
        let file = std::fs::File::open(dir.join("world.tif")).unwrap();
        let mut decoder = tiff::decoder::Decoder::new(std::io::BufReader::new(file)).unwrap();
        let tiff::decoder::DecodingResult::F32(heights) = decoder.read_image().unwrap() else {
            panic!("the export is 32-bit float");
        };
        let out = std::fs::File::create(&deflated).unwrap();
        tiff::encoder::TiffEncoder::new(out)
            .unwrap()
            .with_compression(tiff::encoder::Compression::Deflate(
                tiff::encoder::DeflateLevel::Balanced,
            ))
            .write_image::<tiff::encoder::colortype::Gray32Float>(256, 128, &heights)
            .unwrap();
    }
    let deflated = TerrainFile::load(&deflated, (1.0, 0.0), 0.4).unwrap();
    let metadata: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("world.json")).unwrap()).unwrap();
    let step = metadata["height_scale"].as_f64().unwrap();
    let mut largest: f64 = 0.0;
    for y in 0..128 {
        for x in 0..256 {
            let p = direction_at(
                (x as f64 + 0.5) * 360.0 / 256.0 - 180.0,
                90.0 - (y as f64 + 0.5) * 180.0 / 128.0,
            );
            assert_eq!(
                tiff.height_towards(p),
                exr.height_towards(p),
                "pixel ({x}, {y})"
            );
            assert_eq!(
                tiff.height_towards(p),
                deflated.height_towards(p),
                "pixel ({x}, {y}) of the Deflate TIFF"
            );
            largest = largest.max((tiff.height_towards(p) - png.height_towards(p)).abs());
        }
    }
    println!("PNG against TIFF: {largest:.6} at most, height step {step:.6}");
    assert!(
        largest <= 0.5 * step * 1.001 + 1e-5,
        "PNG heights {largest} from the TIFF's, step {step}"
    );
}

/// Files that cannot be a planet are refused before any work, with the file and what a usable one needs named,
/// and nothing written.
#[test]
fn files_that_cannot_be_a_planet_are_refused_first() {
    let dir = temp_dir("refused");
    // Values 0, 1, 2, ... along each row, times `slope`.
    let gray16 = |name: &str, (w, h): (u32, u32), slope: u16| {
        let image = image::ImageBuffer::<image::Luma<u16>, _>::from_fn(w, h, |x, _| {
            image::Luma([slope * x as u16])
        });
        image.save(dir.join(name)).unwrap();
    };
    gray16("square.png", (64, 64), 1);
    gray16("sea.png", (64, 32), 0);
    gray16("low.png", (64, 32), 1);
    image::GrayImage::from_pixel(64, 32, image::Luma([200]))
        .save(dir.join("eight-bit.png"))
        .unwrap();
    let mut nan = vec![1.0f32; 64 * 32];
    nan[3 * 64 + 5] = f32::NAN;
    {
        let file = std::fs::File::create(dir.join("nan.tif")).unwrap();
        let mut encoder = tiff::encoder::TiffEncoder::new(file).unwrap();
        encoder
            .write_image::<tiff::encoder::colortype::Gray32Float>(64, 32, &nan)
            .unwrap();
    }
    std::fs::write(dir.join("heights.txt"), "1 2 3").unwrap();
    let cases = [
        ("missing.tif", "", "cannot read terrain-file"),
        (
            "square.png",
            "",
            "is 64x64; a whole planet's equirectangular raster must be twice as wide as high",
        ),
        (
            "sea.png",
            "",
            "is all sea at sea-level-height 0.4 (heights 0 to 0)",
        ),
        // The configuration's scale where no JSON lies beside the PNG.
        (
            "low.png",
            "<terrain-height-scale>0.001</terrain-height-scale>",
            "is all sea at sea-level-height 0.4 (heights 0 to 0.063)",
        ),
        ("eight-bit.png", "", "a PNG terrain must be 16-bit grey"),
        (
            "nan.tif",
            "",
            "has no height at pixel (5, 3) (the value is NaN)",
        ),
        (
            "heights.txt",
            "",
            "the name must end in .tif, .tiff, .exr or .png",
        ),
    ];
    for (file, extra, expected) in cases {
        let config = file_config(&dir, file, extra);
        let out = dir.join(format!("out-{file}"));
        let result = riverplanet(&[
            "generate",
            "--config",
            config.to_str().unwrap(),
            "--seed",
            "1",
            "--out",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(!result.status.success(), "{file} was accepted");
        assert!(
            stderr.contains(expected) && stderr.contains(file),
            "{file}: expected \"{expected}\" naming the file, got: {stderr}"
        );
        assert!(!out.exists(), "{file}: {} was written", out.display());
    }
    // The relief model and the file name each other.
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("config/planet.xml"))
            .unwrap();
    for (replacement, expected) in [
        ("<relief-model>file</relief-model>", "terrain-file"),
        ("<terrain-file>sea.png</terrain-file>", "relief-model"),
    ] {
        let path = dir.join("half.xml");
        std::fs::write(
            &path,
            text.replace(
                "<continents-from-file>>false</continents-from-file>",
                replacement,
            ),
        )
        .unwrap();
        let message = Config::load(&path).unwrap_err().to_string();
        assert!(message.contains(expected), "{replacement}: {message}");
    }
}

/// A planet from a file renders and descends to the ground with no hole pixel and no validation error.
#[test]
fn a_planet_from_a_file_renders_and_descends() {
    // Skips (or fails, where a GPU is required) as every GPU test does.
    if common::gpu().is_none() {
        return;
    }
    let dir = temp_dir("descent");
    export_world(&dir, "512x256", "tiff", "tif");
    let config = file_config(&dir, "world.tif", "");
    let json = dir.join("flight.json");
    let out = Command::new(env!("CARGO_BIN_EXE_riverplanet"))
        .args([
            "bench",
            "flight",
            "--descent",
            "--config",
            config.to_str().unwrap(),
            "--frames",
            "60",
            "--size",
            "160x90",
            "--no-kernel-comparison",
            "--no-water-comparison",
            "--json",
            json.to_str().unwrap(),
        ])
        .env("RIVERPLANET_VALIDATION", "1")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("Validation Error"), "{stderr}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let summary = &report["summary"];
    println!("{summary}");
    assert_eq!(
        summary["deepest_level"], 6,
        "the descent reaches config/planet.xml's deepest level"
    );
    assert!(summary["hole_checked_frames"].as_u64().unwrap() >= 5);
    assert_eq!(summary["hole_pixels"], 0, "hole pixels in the descent");
}
