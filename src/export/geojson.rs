//! GeoJSON as RFC 7946 asks for it: positions [longitude, latitude] or [longitude, latitude, height] in degrees,
//! rounded to a stated precision, and lines and polygons cut at the antimeridian (3.1.9), so that map tools do not
//! draw a river that crosses it across the whole map.

use glam::DVec3;
use serde_json::{json, Value};

use crate::planet::lon_lat;

/// Decimal places of longitudes and latitudes: 1e-6 degrees, 0.11 m on Earth, 0.018 world units on Appendix A's
/// planet of radius 1024.
pub const DEGREE_DECIMALS: i32 = 6;
/// Decimal places of heights (world units).
pub const HEIGHT_DECIMALS: i32 = 3;

fn round(x: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (x * scale).round() / scale
}

/// A position: [lon, lat] or [lon, lat, height], rounded.
fn position(lon: f64, lat: f64, height: Option<f64>) -> Vec<f64> {
    let mut p = vec![round(lon, DEGREE_DECIMALS), round(lat, DEGREE_DECIMALS)];
    p.extend(height.map(|h| round(h, HEIGHT_DECIMALS)));
    p
}

/// The difference of two longitudes taken the short way round, in (-180, 180].
fn wrap(delta: f64) -> f64 {
    let d = delta.rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

/// The parts of a path of unit directions (with a height each, or none) cut where it crosses the antimeridian:
/// the crossing's latitude and height interpolated linearly in longitude, the part before ending at +-180 and the
/// next starting at -+180.
pub fn split_at_antimeridian(points: &[(DVec3, Option<f64>)]) -> Vec<Vec<Vec<f64>>> {
    let mut parts: Vec<Vec<Vec<f64>>> = vec![Vec::new()];
    let mut previous: Option<(f64, f64, Option<f64>)> = None;
    for &(p, height) in points {
        let (mut lon, lat) = lon_lat(p);
        if let Some((lon0, lat0, h0)) = previous {
            let unwrapped = lon0 + wrap(lon - lon0);
            if unwrapped.abs() <= 180.0 {
                // A point on the antimeridian keeps the side of the one before it.
                lon = unwrapped;
            } else {
                let edge = 180f64.copysign(unwrapped);
                let t = (edge - lon0) / (unwrapped - lon0);
                let lat_edge = lat0 + t * (lat - lat0);
                let h_edge = h0.zip(height).map(|(a, b)| a + t * (b - a));
                let part = parts.last_mut().expect("one part at least");
                part.push(position(edge, lat_edge, h_edge));
                parts.push(vec![position(-edge, lat_edge, h_edge)]);
            }
        }
        parts
            .last_mut()
            .expect("one part at least")
            .push(position(lon, lat, height));
        previous = Some((lon, lat, height));
    }
    parts
        .into_iter()
        .flat_map(cut_jumps)
        .filter(|part| part.iter().any(|p| p != &part[0]))
        .collect()
}

/// `part` cut wherever two neighbouring positions lie more than half the world apart in longitude. Only positions on
/// the antimeridian can: a point on it whose longitude's last bits put it on one side, then the other, rounds to 180
/// and then -180 at one latitude (seed 606's rivers did). Parts of fewer than two positions are left out.
fn cut_jumps(part: Vec<Vec<f64>>) -> Vec<Vec<Vec<f64>>> {
    let mut out: Vec<Vec<Vec<f64>>> = vec![Vec::new()];
    for p in part {
        let current = out.last_mut().expect("one part at least");
        if current.last().is_some_and(|q| (p[0] - q[0]).abs() > 180.0) {
            out.push(Vec::new());
        }
        out.last_mut().expect("one part at least").push(p);
    }
    out.retain(|part| part.len() >= 2);
    out
}

/// A LineString, or a MultiLineString where the path crosses the antimeridian.
pub fn line_geometry(points: &[(DVec3, Option<f64>)]) -> Value {
    let mut parts = split_at_antimeridian(points);
    if parts.len() == 1 {
        json!({ "type": "LineString", "coordinates": parts.remove(0) })
    } else {
        json!({ "type": "MultiLineString", "coordinates": parts })
    }
}

/// A Polygon of the closed ring of unit directions `ring` (first point repeated last), or a MultiPolygon of its
/// two sides where it straddles the antimeridian (clipped there, Sutherland-Hodgman). Rings around a pole are not
/// handled: no lake is that large.
pub fn polygon_geometry(ring: &[DVec3]) -> Value {
    // Longitudes made continuous along the ring.
    let mut unwrapped: Vec<[f64; 2]> = Vec::with_capacity(ring.len());
    for p in ring {
        let (lon, lat) = lon_lat(*p);
        let lon = match unwrapped.last() {
            Some(last) => last[0] + wrap(lon - last[0]),
            None => lon,
        };
        unwrapped.push([lon, lat]);
    }
    let closed = |points: Vec<[f64; 2]>, shift: f64| -> Vec<Vec<f64>> {
        let mut out: Vec<Vec<f64>> = points
            .iter()
            .map(|q| position(q[0] + shift, q[1], None))
            .collect();
        if out.first() != out.last() {
            if let Some(first) = out.first().cloned() {
                out.push(first);
            }
        }
        out
    };
    let beyond = unwrapped.iter().find(|q| q[0].abs() > 180.0).map(|q| q[0]);
    let Some(beyond) = beyond else {
        return json!({ "type": "Polygon", "coordinates": [closed(unwrapped, 0.0)] });
    };
    let edge = 180f64.copysign(beyond);
    let inside = clip(&unwrapped, edge, |lon| lon * edge.signum() <= 180.0);
    let outside = clip(&unwrapped, edge, |lon| lon * edge.signum() >= 180.0);
    json!({
        "type": "MultiPolygon",
        "coordinates": [[closed(inside, 0.0)], [closed(outside, -2.0 * edge)]],
    })
}

/// Sutherland-Hodgman: the part of the ring `points` whose longitudes satisfy `keep`, cut at longitude `edge`.
fn clip(points: &[[f64; 2]], edge: f64, keep: impl Fn(f64) -> bool) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for (k, b) in points.iter().enumerate() {
        let a = points[(k + points.len() - 1) % points.len()];
        let crossing = || {
            let t = (edge - a[0]) / (b[0] - a[0]);
            [edge, a[1] + t * (b[1] - a[1])]
        };
        match (keep(a[0]), keep(b[0])) {
            (true, true) => out.push(*b),
            (true, false) => out.push(crossing()),
            (false, true) => {
                out.push(crossing());
                out.push(*b);
            }
            (false, false) => {}
        }
    }
    out
}

/// The length of a path of unit directions on a sphere of `radius`, along great circles.
pub fn length(points: &[DVec3], radius: f64) -> f64 {
    points
        .windows(2)
        .map(|w| w[0].angle_between(w[1]) * radius)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(lon: f64, lat: f64) -> DVec3 {
        crate::planet::direction_at(lon, lat)
    }

    #[test]
    fn a_line_across_the_antimeridian_is_cut_there_and_one_that_is_not_stays_whole() {
        let parts =
            split_at_antimeridian(&[(at(170.0, 10.0), Some(1.0)), (at(-170.0, 20.0), Some(3.0))]);
        assert_eq!(parts.len(), 2, "{parts:?}");
        assert_eq!(parts[0].last().unwrap(), &vec![180.0, 15.0, 2.0]);
        assert_eq!(parts[1].first().unwrap(), &vec![-180.0, 15.0, 2.0]);
        assert_eq!(parts[1].last().unwrap(), &vec![-170.0, 20.0, 3.0]);
        let whole = split_at_antimeridian(&[(at(-10.0, 0.0), None), (at(10.0, 1.0), None)]);
        assert_eq!(whole.len(), 1);
        assert_eq!(whole[0], vec![vec![-10.0, 0.0], vec![10.0, 1.0]]);
        assert_eq!(
            line_geometry(&[(at(-10.0, 0.0), None), (at(10.0, 1.0), None)])["type"],
            "LineString"
        );
    }

    #[test]
    fn a_polygon_across_the_antimeridian_becomes_two_that_meet_there() {
        let ring: Vec<DVec3> = [
            (170.0, 0.0),
            (-170.0, 0.0),
            (-170.0, 10.0),
            (170.0, 10.0),
            (170.0, 0.0),
        ]
        .iter()
        .map(|&(lon, lat)| at(lon, lat))
        .collect();
        let g = polygon_geometry(&ring);
        assert_eq!(g["type"], "MultiPolygon");
        for polygon in g["coordinates"].as_array().unwrap() {
            let ring = polygon[0].as_array().unwrap();
            assert_eq!(ring.first(), ring.last(), "ring not closed");
            let lons: Vec<f64> = ring.iter().map(|p| p[0].as_f64().unwrap()).collect();
            assert!(lons.iter().all(|l| l.abs() <= 180.0), "{lons:?}");
            assert!(lons.iter().any(|l| l.abs() == 180.0), "{lons:?}");
            // Each side keeps one sign of longitude: nothing spans the map.
            assert!(
                lons.iter().all(|l| *l >= 0.0) || lons.iter().all(|l| *l <= 0.0),
                "{lons:?}"
            );
        }
        let small = polygon_geometry(&[at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0), at(0.0, 0.0)]);
        assert_eq!(small["type"], "Polygon");
    }

    #[test]
    fn positions_on_both_sides_of_the_antimeridian_never_make_one_segment() {
        let part = vec![
            vec![-179.9, 10.0],
            vec![-180.0, 10.0],
            vec![180.0, 10.0],
            vec![-180.0, 10.0],
            vec![-180.0, 10.0],
            vec![179.9, 10.0],
            vec![179.8, 10.1],
        ];
        let parts = cut_jumps(part);
        assert_eq!(
            parts,
            vec![
                vec![vec![-179.9, 10.0], vec![-180.0, 10.0]],
                vec![vec![-180.0, 10.0], vec![-180.0, 10.0]],
                vec![vec![179.9, 10.0], vec![179.8, 10.1]],
            ]
        );
        // A path through a point on the antimeridian, the point repeated: every part spans a distance, none the map.
        let points = [
            (at(-179.5, 5.0), None),
            (at(180.0, 5.0), None),
            (at(-180.0, 5.0), None),
            (at(180.0, 5.0), None),
            (at(179.5, 5.0), None),
        ];
        for part in split_at_antimeridian(&points) {
            assert!(part.iter().any(|p| p != &part[0]), "{part:?}");
            for pair in part.windows(2) {
                assert!((pair[1][0] - pair[0][0]).abs() <= 180.0, "{part:?}");
            }
        }
    }

    #[test]
    fn positions_are_rounded_to_the_stated_precision() {
        let p = position(12.123_456_789, -3.000_000_4, Some(1.234_56));
        assert_eq!(p, vec![12.123457, -3.0, 1.235]);
    }
}
