//! What `generate` writes for the drainage model: every reach and lake as GeoJSON, and the preview's rivers
//! coloured by Strahler order.

use glam::{DVec2, DVec3};
use image::{Rgb, RgbImage};
use serde_json::json;

use super::{cross_pixel, geojson};
use crate::{
    config::Config,
    drainage::Drainage,
    river::{drainage::reach_width, hull},
};

/// Every reach as a LineString of [lon, lat, bed height] in flow order (RFC 7946, module `geojson`: cut at the
/// antimeridian, rounded), with `id`, `downstream` (the id it flows into, or null at a mouth), `strahler`,
/// `drainage_area` (at its lower end, world units squared), `width` (full width there) and `length` (world units
/// along the sphere of the planet's radius); every lake as a Polygon (the convex outline of its lattice points)
/// with its `level` and `area`.
pub fn drainage_geojson(drainage: &Drainage, config: &Config) -> serde_json::Value {
    let radius = config.planet.radius as f64;
    let mut features: Vec<serde_json::Value> = drainage
        .reaches
        .iter()
        .enumerate()
        .map(|(id, reach)| {
            let points: Vec<(DVec3, Option<f64>)> = reach
                .points
                .iter()
                .zip(&reach.beds)
                .map(|(p, bed)| (*p, Some(*bed as f64)))
                .collect();
            let area = reach.areas.last().copied().unwrap_or(0.0);
            json!({
                "type": "Feature",
                "geometry": geojson::line_geometry(&points),
                "properties": {
                    "id": id,
                    "downstream": reach.downstream,
                    "strahler": reach.strahler,
                    "drainage_area": area,
                    "width": reach_width(config, drainage, area),
                    "length": geojson::length(&reach.points, radius),
                },
            })
        })
        .collect();
    for (id, lake) in drainage.lakes.iter().enumerate() {
        features.push(json!({
            "type": "Feature",
            "geometry": geojson::polygon_geometry(&outline(&lake.points)),
            "properties": { "lake": id, "level": lake.level, "area": lake.area },
        }));
    }
    json!({ "type": "FeatureCollection", "features": features })
}

/// The convex outline of `points` as a closed ring of unit directions (counter-clockwise), made in the tangent
/// plane at their centre.
fn outline(points: &[DVec3]) -> Vec<DVec3> {
    let centre = points.iter().copied().sum::<DVec3>().normalize();
    let e1 = centre.any_orthonormal_vector();
    let e2 = centre.cross(e1);
    let plane: Vec<DVec2> = points
        .iter()
        .map(|p| {
            let q = *p / p.dot(centre);
            DVec2::new(q.dot(e1), q.dot(e2))
        })
        .collect();
    let mut ring: Vec<DVec3> = hull::convex_hull(&plane)
        .iter()
        .map(|q| (centre + e1 * q.x + e2 * q.y).normalize())
        .collect();
    if let Some(first) = ring.first().copied() {
        ring.push(first);
    }
    ring
}

/// Strahler order colours, from the smallest streams (pale) to the largest rivers (dark).
const ORDER_COLOURS: [[u8; 3]; 6] = [
    [170, 225, 255],
    [110, 190, 255],
    [60, 150, 240],
    [30, 100, 220],
    [20, 60, 180],
    [10, 30, 130],
];

/// Draws every reach onto a preview of `size` pixels per face, coloured by Strahler order, and lakes in the
/// colour of the largest order.
pub fn draw_drainage(image: &mut RgbImage, drainage: &Drainage, size: u32) {
    let colour =
        |order: u32| Rgb(ORDER_COLOURS[(order as usize).clamp(1, ORDER_COLOURS.len()) - 1]);
    for lake in &drainage.lakes {
        for p in &lake.points {
            super::put(
                image,
                cross_pixel(*p, size),
                Rgb(ORDER_COLOURS[ORDER_COLOURS.len() - 1]),
            );
        }
    }
    let mut reaches: Vec<_> = drainage.reaches.iter().collect();
    reaches.sort_by_key(|r| r.strahler);
    for reach in reaches {
        super::draw_polyline(image, &reach.points, size, colour(reach.strahler));
    }
}
