//! `riverplanet export faces`, `export equirect` and `export region`: the files read back by a reader of their own (a TIFF reader
//! written here from the TIFF 6.0 and GeoTIFF 1.1 specifications, not the `tiff` crate that writes them, and an
//! OpenEXR reader from the OpenEXR file layout, not the `exr` crate; PNGs
//! through the `image` crate, glTF through the `gltf` crate's importer), their values checked against the library's carved heights, the river channels
//! found below the land at the rivers' own coordinates, and the faces agreeing across their seams.

mod common;

use std::{collections::HashMap, path::Path, process::Command};

use glam::DVec3;
use riverplanet::{
    config::Config,
    export::carved::{carved_terrain, height_towards},
    planet::direction_at,
    world::World,
};
use serde_json::Value;

fn riverplanet() -> Command {
    Command::new(env!("CARGO_BIN_EXE_riverplanet"))
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "riverplanet-heightmaps-{name}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(args: &[&str]) -> std::process::Output {
    riverplanet().args(args).output().unwrap()
}

fn succeed(args: &[&str]) {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A single-image, uncompressed TIFF of 32-bit floats, as a GIS reader sees it.
struct Tiff {
    width: u32,
    height: u32,
    values: Vec<f32>,
    /// Every tag's values as numbers (ASCII tags: their bytes).
    tags: HashMap<u16, Vec<f64>>,
    description: String,
}

/// Reads a little-endian TIFF (TIFF 6.0, section 2): the header, the first image file directory, and the strips.
fn read_tiff(path: &Path) -> Tiff {
    let bytes = std::fs::read(path).unwrap();
    let u16_at = |o: usize| u16::from_le_bytes([bytes[o], bytes[o + 1]]);
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    assert_eq!(&bytes[0..4], b"II*\0", "a little-endian classic TIFF");
    let ifd = u32_at(4) as usize;
    let mut tags = HashMap::new();
    let mut description = String::new();
    for k in 0..u16_at(ifd) as usize {
        let entry = ifd + 2 + 12 * k;
        let (tag, kind, count) = (u16_at(entry), u16_at(entry + 2), u32_at(entry + 4) as usize);
        let size = match kind {
            1 | 2 => 1,
            3 => 2,
            4 | 11 => 4,
            5 | 12 => 8,
            other => panic!("tag {tag}: unexpected field type {other}"),
        };
        let at = if size * count <= 4 {
            entry + 8
        } else {
            u32_at(entry + 8) as usize
        };
        let values: Vec<f64> = (0..count)
            .map(|i| {
                let o = at + i * size;
                match kind {
                    1 | 2 => bytes[o] as f64,
                    3 => u16_at(o) as f64,
                    4 => u32_at(o) as f64,
                    11 => f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as f64,
                    5 => u32_at(o) as f64 / u32_at(o + 4) as f64,
                    12 => f64::from_le_bytes(bytes[o..o + 8].try_into().unwrap()),
                    _ => panic!("tag {tag}: undefined bytes not expected"),
                }
            })
            .collect();
        if tag == 270 {
            description = String::from_utf8(bytes[at..at + count - 1].to_vec()).unwrap();
        }
        tags.insert(tag, values);
    }
    let one = |tag: u16| tags[&tag][0] as u32;
    assert_eq!(one(258), 32, "32 bits per sample");
    assert_eq!(one(339), 3, "IEEE floating point samples");
    assert_eq!(one(259), 1, "no compression");
    assert_eq!(one(277), 1, "one sample per pixel");
    let mut data = Vec::new();
    for (offset, count) in tags[&273].iter().zip(&tags[&279]) {
        data.extend_from_slice(&bytes[*offset as usize..(*offset + *count) as usize]);
    }
    let values: Vec<f32> = data
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let (width, height) = (one(256), one(257));
    assert_eq!(values.len(), (width * height) as usize);
    Tiff {
        width,
        height,
        values,
        tags,
        description,
    }
}

/// Reads a single-part, uncompressed scan-line OpenEXR file of one FLOAT channel (OpenEXR file layout: magic
/// number, version, header attributes up to an empty name, the line offset table, one chunk per line of y, size
/// and the line's samples): its size, its values, and the text attribute `riverplanet`.
fn read_exr(path: &Path) -> (u32, u32, Vec<f32>, String) {
    let bytes = std::fs::read(path).unwrap();
    let i32_at = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    assert_eq!(
        &bytes[0..4],
        &[0x76, 0x2f, 0x31, 0x01],
        "OpenEXR magic number"
    );
    assert_eq!(bytes[4], 2, "version 2");
    assert_eq!(bytes[5] & 0x1e, 0, "single-part scan lines");
    let mut at = 8;
    let c_string = |at: &mut usize| {
        let end = *at + bytes[*at..].iter().position(|&b| b == 0).unwrap();
        let text = String::from_utf8(bytes[*at..end].to_vec()).unwrap();
        *at = end + 1;
        text
    };
    let (mut window, mut metadata) = ([0i32; 4], String::new());
    loop {
        let name = c_string(&mut at);
        if name.is_empty() {
            break;
        }
        let kind = c_string(&mut at);
        let size = i32_at(at) as usize;
        let value = at + 4;
        match (name.as_str(), kind.as_str()) {
            ("dataWindow", "box2i") => window = [0, 4, 8, 12].map(|k| i32_at(value + k)),
            ("compression", _) => assert_eq!(bytes[value], 0, "no compression"),
            ("channels", _) => {
                let mut c = value;
                assert_eq!(c_string(&mut c), "Y");
                assert_eq!(i32_at(c), 2, "FLOAT samples");
            }
            ("riverplanet", "string") => {
                metadata = String::from_utf8(bytes[value..value + size].to_vec()).unwrap()
            }
            _ => {}
        }
        at = value + size;
    }
    let (width, height) = (
        (window[2] - window[0] + 1) as u32,
        (window[3] - window[1] + 1) as u32,
    );
    let offsets: Vec<usize> = (0..height as usize)
        .map(|k| u64::from_le_bytes(bytes[at + 8 * k..at + 8 * k + 8].try_into().unwrap()) as usize)
        .collect();
    let mut values = vec![0.0f32; (width * height) as usize];
    for offset in offsets {
        let y = (i32_at(offset) - window[1]) as usize;
        assert_eq!(i32_at(offset + 4) as u32, width * 4);
        for x in 0..width as usize {
            let o = offset + 8 + 4 * x;
            values[y * width as usize + x] =
                f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        }
    }
    (width, height, values, metadata)
}

fn default_world() -> World {
    let config = Config::load(Path::new("config/planet.xml")).unwrap();
    World::build(&config, 1).unwrap()
}

/// The equirectangular GeoTIFF: georeferenced as the GeoTIFF keys say, and every pixel the carved height at the
/// pixel's centre.
#[test]
fn the_equirectangular_geotiff_is_georeferenced_and_holds_the_carved_heights() {
    let dir = temp_dir("equirect");
    let tif = dir.join("world.tif");
    let tif_arg = tif.to_str().unwrap();
    succeed(&[
        "export", "equirect", "--seed", "1", "--size", "720x360", "--level", "4", "--out", tif_arg,
    ]);
    let image = read_tiff(&tif);
    assert_eq!((image.width, image.height), (720, 360));
    // GeoTIFF: pixel size in degrees, the top-left corner at (-180, 90), a geographic model of pixel areas on a
    // sphere of the planet's radius.
    assert_eq!(image.tags[&33550], vec![0.5, 0.5, 0.0]);
    assert_eq!(image.tags[&33922], vec![0.0, 0.0, 0.0, -180.0, 90.0, 0.0]);
    let keys = &image.tags[&34735];
    let key = |id: f64| {
        keys[4..]
            .chunks(4)
            .find(|k| k[0] == id)
            .unwrap_or_else(|| panic!("GeoKey {id} missing"))
            .to_vec()
    };
    assert_eq!(key(1024.0)[3], 2.0, "geographic model");
    assert_eq!(key(1025.0)[3], 1.0, "pixels are areas");
    assert_eq!(key(2054.0)[3], 9102.0, "degrees");
    assert_eq!(
        image.tags[&34736],
        vec![1024.0, 1024.0],
        "the sphere's axes"
    );
    let metadata: Value = serde_json::from_str(&image.description).unwrap();
    assert_eq!(metadata["radius"], 1024.0);
    assert_eq!(metadata["seed"], 1);
    assert_eq!(metadata["level"], 4);
    let sidecar: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("world.json")).unwrap()).unwrap();
    assert_eq!(sidecar["sea_level"], metadata["sea_level"]);

    let world = default_world();
    let carved = carved_terrain(&world.planet, &world.network, &world.config, 4, &|_| {});
    let lon_lat_of = |x: f64, y: f64| (-180.0 + (x + 0.5) * 0.5, 90.0 - (y + 0.5) * 0.5);
    for y in (0..360).step_by(7) {
        for x in (0..720).step_by(5) {
            let (lon, lat) = lon_lat_of(x as f64, y as f64);
            let expected = height_towards(&carved, direction_at(lon, lat));
            assert_eq!(image.values[y * 720 + x], expected, "pixel ({x}, {y})");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The six faces as TIFF, OpenEXR and PNG: the same heights in all (the PNG within one step of its scale), and the
/// lattice points that two or three faces share, found through layout.json's orientations, equal on every face
/// that holds them (the export writes the mean of the patches' values there).
#[test]
fn face_rasters_agree_with_each_other_and_across_their_seams() {
    let dir = temp_dir("faces");
    for format in ["tiff", "exr", "png"] {
        let out = dir.join(format);
        succeed(&[
            "export",
            "faces",
            "--seed",
            "1",
            "--level",
            "2",
            "--format",
            format,
            "--out",
            out.to_str().unwrap(),
        ]);
    }
    let layout: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("tiff/layout.json")).unwrap())
            .unwrap();
    let png_layout: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("png/layout.json")).unwrap())
            .unwrap();
    assert_eq!(layout["radius"], 1024.0);
    let mut shared: HashMap<[i64; 3], Vec<f32>> = HashMap::new();
    for face in 0..6 {
        let entry = &layout["faces"][face];
        let tiff = read_tiff(&dir.join("tiff").join(entry["file"].as_str().unwrap()));
        assert_eq!((tiff.width, tiff.height), (129, 129));
        let (width, height, exr, metadata) = read_exr(&dir.join(format!("exr/face{face}.exr")));
        assert_eq!((width, height), (129, 129));
        assert_eq!(exr, tiff.values, "face {face}: EXR and TIFF differ");
        let metadata: Value = serde_json::from_str(&metadata).unwrap();
        assert_eq!(metadata["radius"], 1024.0);
        let png_entry = &png_layout["faces"][face];
        let png = image::open(dir.join("png").join(png_entry["file"].as_str().unwrap()))
            .unwrap()
            .into_luma16();
        let scale = png_entry["height_scale"].as_f64().unwrap();
        let offset = png_entry["height_offset"].as_f64().unwrap();
        let vector = |key: &str| {
            let v = entry[key].as_array().unwrap();
            DVec3::new(
                v[0].as_f64().unwrap(),
                v[1].as_f64().unwrap(),
                v[2].as_f64().unwrap(),
            )
        };
        let (origin, step_x, step_y) = (vector("origin"), vector("step_x"), vector("step_y"));
        for j in 0..129u32 {
            for i in 0..129u32 {
                let h = tiff.values[(j * 129 + i) as usize];
                let from_png = offset + scale * png.get_pixel(i, j).0[0] as f64;
                assert!(
                    (from_png - h as f64).abs() <= scale,
                    "face {face} ({i}, {j}): PNG {from_png} against TIFF {h}"
                );
                if i == 0 || j == 0 || i == 128 || j == 128 {
                    let p = origin + step_x * i as f64 + step_y * j as f64;
                    let key = [p.x, p.y, p.z].map(|c| (c * 1e6).round() as i64);
                    shared.entry(key).or_default().push(h);
                }
            }
        }
    }
    let seams: Vec<&Vec<f32>> = shared.values().filter(|v| v.len() > 1).collect();
    // 12 edges of 127 inner points each, 8 corners.
    assert_eq!(seams.len(), 12 * 127 + 8);
    let spread = seams
        .iter()
        .map(|v| {
            v.iter().fold(f32::MIN, |a, &b| a.max(b)) - v.iter().fold(f32::MAX, |a, &b| a.min(b))
        })
        .fold(0.0f32, f32::max);
    assert_eq!(spread, 0.0, "the faces differ by {spread} across a seam");
    std::fs::remove_dir_all(&dir).ok();
}

/// Bad arguments are refused before any work, naming the argument and the valid range, and leave no file.
#[test]
fn height_exports_refuse_bad_arguments_before_any_work() {
    let dir = temp_dir("refusals");
    let file = dir.join("a-file");
    std::fs::write(&file, b"keep").unwrap();
    let png = dir.join("x.png");
    let glb = dir.join("x.glb");
    let cases: [(Vec<&str>, &str); 9] = [
        (
            vec![
                "export",
                "faces",
                "--level",
                "8",
                "--out",
                dir.to_str().unwrap(),
            ],
            "--level 8 must be in [0, 7]",
        ),
        (
            vec!["export", "faces", "--out", file.to_str().unwrap()],
            "is a file; give a folder",
        ),
        (
            vec![
                "export",
                "faces",
                "--format",
                "jpg",
                "--out",
                dir.to_str().unwrap(),
            ],
            "tiff or exr (32-bit float) or png",
        ),
        (
            vec!["export", "equirect", "--out", png.to_str().unwrap()],
            "--format tiff writes .tif files",
        ),
        (
            vec!["export", "equirect", "--size", "1x1", "--out", "x.tif"],
            "both must be at least 2",
        ),
        (
            vec!["export", "region", "--bounds=10,0,5,5", "--out", "x.tif"],
            "longitudes 10 and 5 must lie in [-180, 180], west below east",
        ),
        (
            vec!["export", "region", "--bounds=0,-95,5,5", "--out", "x.tif"],
            "latitudes -95 and 5 must lie in [-90, 90]",
        ),
        (
            vec![
                "export",
                "region",
                "--bounds=0,0,90,60",
                "--level",
                "12",
                "--out",
                "x.tif",
            ],
            "at most 16777216",
        ),
        (
            vec![
                "export",
                "region",
                "--bounds=0,0,5,5",
                "--format",
                "tiff",
                "--out",
                glb.to_str().unwrap(),
            ],
            "--format tiff writes .tif files",
        ),
    ];
    for (args, message) in cases {
        let out = run(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"keep");
    assert!(!png.exists() && !glb.exists());
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "files were written"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The river channels are in the faces: at the drainage rivers' own coordinates (`export rivers`) the carved bed
/// lies below its banks (4 units to either side, about two vertex spacings of level 4) at most points, by about
/// the basin depth (config/planet.xml 0.1). The eroded relief's rivers run in valleys already (uncarved, their
/// beds lie below the banks at 88 % of 5,761 points on seed 1, by 0.18); the kernel lays a floodplain of the
/// influence distance's width around each channel, so the carved banks stand nearer the bed than the valley's
/// sides (90 %, by 0.11).
#[test]
fn the_faces_hold_the_river_channels_below_their_banks() {
    let dir = temp_dir("channels");
    let faces = dir.join("faces");
    let rivers = dir.join("rivers.geojson");
    succeed(&[
        "export",
        "faces",
        "--seed",
        "1",
        "--level",
        "4",
        "--out",
        faces.to_str().unwrap(),
    ]);
    succeed(&[
        "export",
        "rivers",
        "--seed",
        "1",
        "--out",
        rivers.to_str().unwrap(),
    ]);
    let tiffs: Vec<Tiff> = (0..6)
        .map(|f| read_tiff(&faces.join(format!("face{f}.tif"))))
        .collect();
    let cells = (tiffs[0].width - 1) as f64;
    // Bilinear in a face file at a direction: pixel (i, j) is cube point u = -1 + 2 i / cells, v likewise.
    let in_file = |d: DVec3| {
        let (face, u, v) = riverplanet::planet::cube::face_of(d);
        let (x, y) = (
            ((u + 1.0) * 0.5 * cells).min(cells - 1e-9),
            ((v + 1.0) * 0.5 * cells).min(cells - 1e-9),
        );
        let (i, j) = (x.floor() as usize, y.floor() as usize);
        let (fx, fy) = ((x - i as f64) as f32, (y - j as f64) as f32);
        let side = tiffs[face].width as usize;
        let at = |i: usize, j: usize| tiffs[face].values[j * side + i];
        let top = at(i, j) + (at(i + 1, j) - at(i, j)) * fx;
        let bottom = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * fx;
        top + (bottom - top) * fy
    };
    let world = default_world();
    let base = world.planet.face_lattice(4);
    let uncarved = |d: DVec3| height_towards(&base, d);
    let geojson: Value = serde_json::from_str(&std::fs::read_to_string(&rivers).unwrap()).unwrap();
    let offset = 4.0 / world.planet.radius;
    // Per surface: points whose bed lies below the mean of its banks, and the mean of banks - bed.
    let mut measured = [(0usize, 0.0f64); 2];
    let mut points = 0;
    for feature in geojson["features"].as_array().unwrap() {
        if feature["geometry"]["type"] != "LineString" {
            continue;
        }
        let line: Vec<DVec3> = feature["geometry"]["coordinates"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| direction_at(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect();
        for pair in line.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            if uncarved(a) <= world.planet.sea_level + 0.5 {
                continue;
            }
            let across = a.cross(b - a).normalize() * offset;
            points += 1;
            let surfaces: [&dyn Fn(DVec3) -> f32; 2] = [&in_file, &uncarved];
            for (m, height) in measured.iter_mut().zip(surfaces) {
                let bed = height(a);
                let banks =
                    0.5 * (height((a + across).normalize()) + height((a - across).normalize()));
                m.0 += usize::from(bed < banks - 0.01);
                m.1 += (banks - bed) as f64;
            }
        }
    }
    assert!(points > 1000, "only {points} river points on land");
    let [(carved_below, carved_depth), (base_below, base_depth)] =
        measured.map(|(below, depth)| (below as f64 / points as f64, depth / points as f64));
    println!(
        "{points} river points: bed below its banks at {:.1} % carved ({:.1} % uncarved), by {carved_depth:.4} on \
         average ({base_depth:.4} uncarved)",
        100.0 * carved_below,
        100.0 * base_below
    );
    assert!(
        carved_below > 0.8,
        "the bed lies below its banks at {:.1} % of the points ({:.1} % uncarved)",
        100.0 * carved_below,
        100.0 * base_below
    );
    assert!(
        carved_depth > 0.05,
        "banks - bed: {carved_depth:.4} carved, {base_depth:.4} uncarved"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A region as GeoTIFF and as glTF: the raster georeferenced to its bounds; the mesh opens in the `gltf` crate's
/// importer with every accessor read, holds a terrain mesh over every sample and a water mesh, unit normals,
/// indices in range, and its terrain vertices lie at the GeoTIFF's heights in the local frame docs/exports.md
/// gives (origin on the sea-level sphere below the centre, +X east, +Y up, -Z north).
#[test]
fn a_region_exports_as_a_georeferenced_raster_and_as_a_gltf_mesh_at_the_same_heights() {
    let dir = temp_dir("region");
    let (tif, glb) = (dir.join("region.tif"), dir.join("region.glb"));
    let bounds = "--bounds=-28,3,-23,8";
    for (format, out) in [("tiff", &tif), ("glb", &glb)] {
        succeed(&[
            "export",
            "region",
            "--seed",
            "1",
            bounds,
            "--level",
            "6",
            "--format",
            format,
            "--out",
            out.to_str().unwrap(),
        ]);
    }
    let raster = read_tiff(&tif);
    let (width, height) = (raster.width as usize, raster.height as usize);
    assert!(width > 50 && height > 50, "{width} x {height}");
    let (dx, dy) = (5.0 / width as f64, 5.0 / height as f64);
    assert_eq!(raster.tags[&33922], vec![0.0, 0.0, 0.0, -28.0, 8.0, 0.0]);
    assert_eq!(raster.tags[&33550], vec![dx, dy, 0.0]);

    let (document, buffers, _) = gltf::import_slice(std::fs::read(&glb).unwrap()).unwrap();
    let meshes: Vec<gltf::Mesh> = document.meshes().collect();
    let names: Vec<&str> = meshes.iter().map(|m| m.name().unwrap()).collect();
    assert_eq!(names, ["terrain", "water"]);
    let radius = 1024.0;
    let up = direction_at(-25.5, 5.5);
    let east = DVec3::Y.cross(up).normalize();
    let north = up.cross(east);
    for mesh in &meshes {
        let primitive = mesh.primitives().next().unwrap();
        let reader = primitive.reader(|b| Some(&buffers[b.index()]));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(positions.len(), width * height, "{}", mesh.name().unwrap());
        assert_eq!(normals.len(), positions.len());
        assert!(indices.len() % 3 == 0 && !indices.is_empty());
        assert!(indices.iter().all(|&i| (i as usize) < positions.len()));
        for n in &normals {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((length - 1.0).abs() < 1e-4, "normal {n:?}");
            assert!(n[1] > 0.0, "a normal points down: {n:?}");
        }
        if mesh.name() == Some("terrain") {
            assert_eq!(indices.len(), 6 * (width - 1) * (height - 1));
            for (k, p) in positions.iter().enumerate().step_by(13) {
                let world =
                    up * radius + east * p[0] as f64 + up * p[1] as f64 - north * p[2] as f64;
                let h = world.length() - radius;
                let expected = raster.values[k] as f64;
                assert!(
                    (h - expected).abs() < 1e-3,
                    "vertex {k}: {h} above the sphere, the GeoTIFF says {expected}"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The exports' surface is the renderer's: close above the first river (the `river` preset), every grid vertex
/// the terrain pass draws unmorphed (captured from the vertex shader) lies at the height `runtime::surface` gives
/// its patch's grid point on the CPU (the exports' source), within a thousandth of a unit (f32 positions relative
/// to the camera, and the blend's rounding on two sides): the terrain, or with the water in the mesh (the default)
/// the water's surface where the vertex lies under water (`CarvedPatch::placed`).
#[test]
fn the_exported_surface_is_the_surface_the_renderer_draws() {
    let Some(ctx) = common::gpu() else { return };
    let world = default_world();
    let (eye, target) =
        riverplanet::render::presets::camera(riverplanet::render::presets::Preset::River, &world)
            .unwrap();
    let camera = riverplanet::runtime::camera::Camera::look_at(eye, target, 60.0, 16.0 / 9.0, 0.05);
    let offscreen = riverplanet::render::target::Offscreen::new(ctx, 320, 180).unwrap();
    let mut renderer = common::renderer(ctx, &world);
    // Eq. 6.1 draws this view with finer patches than the default screen-space rule: more vertices to compare.
    renderer.lod_rule = riverplanet::config::LodRule::Distance;
    let clear = offscreen.target([0.0, 0.0, 0.0, 1.0]);
    renderer
        .render_until_streamed(&camera, &clear, 200)
        .unwrap();
    renderer.capture_vertices = true;
    renderer.render_until_streamed(&camera, &clear, 1).unwrap();
    let capture = renderer.last_capture.take().unwrap();
    drop(offscreen);
    common::assert_no_validation_errors(ctx);

    let unmorphed: Vec<_> = capture.drawn().filter(|v| v.morph == 0.0).collect();
    let mut patches: Vec<_> = unmorphed.iter().map(|v| v.patch).collect();
    patches.sort_unstable();
    patches.dedup();
    let surfaces = riverplanet::runtime::surface::carve_patches(
        &patches,
        &world.planet,
        &world.network,
        &world.config,
        &|| {},
    );
    let n = world.config.rendering.vertices;
    let radius = world.planet.radius;
    let mut worst = 0.0f64;
    let mut carved = 0;
    let mut under_water = 0;
    let sea_level = world.planet.sea_level;
    for v in &unmorphed {
        let drawn = (capture.camera + v.relative).length() - radius;
        let surface = &surfaces[&v.patch];
        let index = (v.j * n + v.i) as usize;
        let exported = surface.placed(index, sea_level) as f64;
        worst = worst.max((drawn - exported).abs());
        carved += usize::from(surface.basin[index] > -world.config.river.influence_distance);
        under_water += usize::from(exported > surface.terrain[index] as f64);
    }
    println!(
        "{} unmorphed vertices of {} patches ({carved} within a river's reach, {under_water} under water): largest \
         difference {worst}",
        unmorphed.len(),
        patches.len()
    );
    assert!(unmorphed.len() > 5_000, "only {} vertices", unmorphed.len());
    assert!(carved > 1_000, "only {carved} vertices near rivers");
    assert!(under_water > 100, "only {under_water} vertices under water");
    assert!(
        worst < 1e-3,
        "the renderer draws {worst} away from the export"
    );
}
