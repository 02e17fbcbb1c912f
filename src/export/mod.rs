//! The planet for other tools and for people (beyond the thesis): heightmaps (`heightmaps`, `raster`, with the
//! rivers carved in by `carved`), rivers as GeoJSON (`geojson`, `drainage`), and here the unfolded colour
//! preview and the land mask that `generate` writes.

use image::{Rgb, RgbImage};
use serde_json::json;

pub mod carved;
pub mod drainage;
pub mod files;
pub mod geojson;
pub mod heightmaps;
pub mod mesh;
pub mod raster;
pub mod region;

use crate::planet::{
    cube::{cube_point, FACES, FACE_AXES},
    Planet,
};

/// Why an export could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// Writing a file failed (nothing half-written is left).
    #[error("cannot write {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// Terrain colour for a height (sea by depth, then sand, grass, rock, snow).
pub fn terrain_colour(h: f32, sea_level: f32, max_height: f32) -> [u8; 3] {
    if h <= sea_level {
        let depth = ((sea_level - h) / 6.0).clamp(0.0, 1.0);
        let lerp = |a: f32, b: f32| (a + (b - a) * depth) as u8;
        return [lerp(40.0, 8.0), lerp(110.0, 30.0), lerp(180.0, 90.0)];
    }
    let t = ((h - sea_level) / (max_height - sea_level).max(1e-3)).clamp(0.0, 1.0);
    let stops: [(f32, [f32; 3]); 5] = [
        (0.0, [194.0, 178.0, 128.0]),
        (0.05, [86.0, 140.0, 60.0]),
        (0.35, [60.0, 100.0, 45.0]),
        (0.6, [120.0, 110.0, 100.0]),
        (1.0, [245.0, 245.0, 250.0]),
    ];
    for w in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (w[0], w[1]);
        if t <= t1 {
            let f = (t - t0) / (t1 - t0);
            return [0, 1, 2].map(|k| (c0[k] + (c1[k] - c0[k]) * f) as u8);
        }
    }
    [245, 245, 250]
}

/// Where each face sits in the unfolded cross (in face-size units), and how its (u, v) map to the cross's
/// (right, down): the cross is +Y on top, then -X, +Z, +X, -Z in a row, -Y below (a view from outside).
const CROSS: [(u32, u32); FACES] = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];

/// An unfolded colour picture of the six faces at `size` pixels per face (layout in docs/planet.md).
pub fn preview(planet: &Planet, size: u32) -> RgbImage {
    let mut image = RgbImage::from_pixel(4 * size, 3 * size, Rgb([20, 20, 24]));
    let max = planet.stats.max_height;
    for (face, &(cx, cy)) in CROSS.iter().enumerate() {
        for py in 0..size {
            for px in 0..size {
                let (u, v) = cross_uv(face, px, py, size);
                let p = cross_direction(face, u, v);
                let c = terrain_colour(planet.height_at(p), planet.sea_level, max);
                image.put_pixel(cx * size + px, cy * size + py, Rgb(c));
            }
        }
    }
    image
}

/// The (u, v) on `face` seen at pixel (px, py) of its square in the cross: the cross shows each face from
/// outside with +Y up where possible.
fn cross_uv(face: usize, px: u32, py: u32, size: u32) -> (f64, f64) {
    let s = (px as f64 + 0.5) / size as f64 * 2.0 - 1.0;
    let t = 1.0 - (py as f64 + 0.5) / size as f64 * 2.0;
    // Screen right/up in terms of 3D directions for each square of the cross.
    let (right, up) = cross_axes(face);
    let (_, a, b) = FACE_AXES[face];
    let dir = right * s + up * t;
    (dir.dot(a), dir.dot(b))
}

fn cross_direction(face: usize, u: f64, v: f64) -> glam::DVec3 {
    cube_point(face, u, v).normalize()
}

/// Screen right and up (3D) of each face in the cross, seen from outside: the equatorial faces with +Y up, +Y with
/// -Z up and -Y with +Z up, so that neighbouring squares continue each other.
fn cross_axes(face: usize) -> (glam::DVec3, glam::DVec3) {
    use glam::DVec3 as V;
    match face {
        0 => (V::NEG_Z, V::Y), // +X
        1 => (V::Z, V::Y),     // -X
        2 => (V::X, V::NEG_Z), // +Y (above +Z)
        3 => (V::X, V::Z),     // -Y (below +Z)
        4 => (V::X, V::Y),     // +Z
        _ => (V::NEG_X, V::Y), // -Z
    }
}

/// Maps a unit direction to its pixel in the cross, for drawing overlays.
pub fn cross_pixel(p: glam::DVec3, size: u32) -> (f64, f64) {
    let (face, _, _) = crate::planet::cube::face_of(p);
    let (n, _, _) = FACE_AXES[face];
    let q = p / p.dot(n);
    let (right, up) = cross_axes(face);
    let (s, t) = (q.dot(right), q.dot(up));
    let (cx, cy) = CROSS[face];
    (
        cx as f64 * size as f64 + (s + 1.0) * 0.5 * size as f64,
        cy as f64 * size as f64 + (1.0 - t) * 0.5 * size as f64,
    )
}

/// The planet's land (white) and sea (black) as an equirectangular image `width x width/2`: the format that
/// `continents-from-file` reads back.
pub fn equirectangular_land(planet: &Planet, width: u32) -> image::GrayImage {
    let height = width / 2;
    image::GrayImage::from_fn(width, height, |x, y| {
        let lon = ((x as f64 + 0.5) / width as f64 * 360.0 - 180.0).to_radians();
        let lat = (90.0 - (y as f64 + 0.5) / height as f64 * 180.0).to_radians();
        // Inverse of planet::lon_lat: lon from +X towards -Z, latitude towards +Y.
        let p = glam::DVec3::new(lat.cos() * lon.cos(), lat.sin(), -lat.cos() * lon.sin());
        image::Luma([if planet.is_land(p) { 255 } else { 0 }])
    })
}

/// Every river and tributary of the thesis's network at `depth` (Section 5.3's pieces refined `depth` times), as
/// RFC 7946 GeoJSON (module `geojson`: cut at the antimeridian, rounded): one feature per branch with `id`,
/// `parent` (the id it flows into, null for a main river), `order` (0 for a main river, its parent's plus one for a
/// tributary), `width_start` and `width_end` (full widths, world units), `length` (world units along the sphere
/// of `radius`) and `level` (`depth`). As many tributaries as `RiverNetwork::count(depth)` counts.
pub fn rivers_geojson(
    network: &crate::river::network::RiverNetwork,
    depth: u32,
    radius: f64,
) -> serde_json::Value {
    let mut features = Vec::new();
    for system in &network.systems {
        let lines = crate::river::samples::polylines(network, system, depth);
        let name = |branch: u64| {
            if lines.first().is_some_and(|l| l.key == branch) {
                format!("{}", system.id)
            } else {
                format!("{}-{:08x}", system.id, branch as u32)
            }
        };
        let order = |line: &crate::river::samples::Branch| {
            let mut order = 0;
            let mut parent = line.parent;
            while let Some(key) = parent {
                order += 1;
                parent = lines.iter().find(|l| l.key == key).and_then(|l| l.parent);
            }
            order
        };
        for line in &lines {
            let points: Vec<(glam::DVec3, Option<f64>)> =
                line.points.iter().map(|p| (*p, None)).collect();
            features.push(json!({
                "type": "Feature",
                "geometry": geojson::line_geometry(&points),
                "properties": {
                    "id": name(line.key),
                    "parent": line.parent.map(name),
                    "order": order(line),
                    "width_start": line.widths.0,
                    "width_end": line.widths.1,
                    "length": geojson::length(&line.points, radius),
                    "level": depth,
                },
            }));
        }
    }
    json!({ "type": "FeatureCollection", "features": features })
}

/// Draws every river of `network` at `depth` onto a [`preview`] of `size` pixels per face.
pub fn draw_rivers(
    image: &mut RgbImage,
    network: &crate::river::network::RiverNetwork,
    depth: u32,
    size: u32,
) {
    for system in &network.systems {
        for line in crate::river::samples::polylines(network, system, depth) {
            let colour = if line.parent.is_none() {
                Rgb([120, 200, 255])
            } else {
                Rgb([60, 160, 240])
            };
            draw_polyline(image, &line.points, size, colour);
        }
    }
}

/// Draws a polyline of unit-sphere points onto a [`preview`] of `size` pixels per face.
pub fn draw_polyline(image: &mut RgbImage, points: &[glam::DVec3], size: u32, colour: Rgb<u8>) {
    for pair in points.windows(2) {
        let (a, b) = (cross_pixel(pair[0], size), cross_pixel(pair[1], size));
        // Skip segments that jump across the cross's gaps.
        if (a.0 - b.0).abs() + (a.1 - b.1).abs() > size as f64 / 4.0 {
            continue;
        }
        let steps = ((a.0 - b.0).abs().max((a.1 - b.1).abs()).ceil() as u32).max(1);
        for k in 0..=steps {
            let f = k as f64 / steps as f64;
            put(
                image,
                (a.0 + (b.0 - a.0) * f, a.1 + (b.1 - a.1) * f),
                colour,
            );
        }
    }
}

/// Sets the pixel at (x, y) if it is inside the image.
fn put(image: &mut RgbImage, (x, y): (f64, f64), colour: Rgb<u8>) {
    if x >= 0.0 && y >= 0.0 && (x as u32) < image.width() && (y as u32) < image.height() {
        image.put_pixel(x as u32, y as u32, colour);
    }
}
