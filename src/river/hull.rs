//! Convex hulls and extended hulls (Sections 3.7 and 6.3), and the convex-polygon tests that decide which
//! patches a river influences.

use glam::DVec2;

/// 2D cross product of (a - o) and (b - o): positive when o, a, b turn counter-clockwise.
fn cross(o: DVec2, a: DVec2, b: DVec2) -> f64 {
    (a - o).perp_dot(b - o)
}

/// The convex hull of `points`, counter-clockwise, without collinear or duplicate points (Andrew's monotone chain:
/// same result as the gift wrapping of Procedure 1, with collinear and duplicate points handled). Fewer than three
/// distinct points give a degenerate hull of one or two points.
pub fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = points.iter().copied().filter(|p| p.is_finite()).collect();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(pts.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Whether `p` lies inside or on the counter-clockwise convex polygon `poly` (with tolerance `eps`).
pub fn contains(poly: &[DVec2], p: DVec2, eps: f64) -> bool {
    match poly.len() {
        0 => false,
        1 => poly[0].distance(p) <= eps,
        2 => segment_distance(poly[0], poly[1], p) <= eps,
        n => (0..n).all(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            (b - a).perp_dot(p - a) >= -eps * (b - a).length()
        }),
    }
}

fn segment_distance(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// The distance from `p` to a convex polygon (0 inside).
pub fn distance(poly: &[DVec2], p: DVec2) -> f64 {
    if poly.len() >= 3 && contains(poly, p, 0.0) {
        return 0.0;
    }
    (0..poly.len())
        .map(|i| segment_distance(poly[i], poly[(i + 1) % poly.len()], p))
        .fold(f64::MAX, f64::min)
}

/// The extended hull (6.3): `hull` grown by `offset` in every direction, as a convex polygon that contains every
/// point within `offset` of the hull. Each vertex is split into points along the normals of its two edges (the
/// "split points" of Fig. 6.2) and, where they turn by more than 30 degrees, more points in between; all lie at
/// `offset / cos(half the step)`, so the chords between them stay outside the true offset curve.
pub fn extend(hull: &[DVec2], offset: f64) -> Vec<DVec2> {
    let n = hull.len();
    if n == 0 {
        return Vec::new();
    }
    let mut out = Vec::new();
    let step_max = std::f64::consts::PI / 6.0;
    let normal = |a: DVec2, b: DVec2| {
        let e = b - a;
        DVec2::new(e.y, -e.x).normalize_or_zero()
    };
    for i in 0..n {
        let p = hull[i];
        // Outward normals of the edges before and after p (a point or segment hull gets a full circle).
        let (a0, a1) = if n >= 3 {
            let before = normal(hull[(i + n - 1) % n], p);
            let after = normal(p, hull[(i + 1) % n]);
            let a0 = before.y.atan2(before.x);
            let mut a1 = after.y.atan2(after.x);
            while a1 < a0 {
                a1 += std::f64::consts::TAU;
            }
            (a0, a1)
        } else if n == 2 {
            let nrm = normal(hull[0], hull[1]) * if i == 0 { -1.0 } else { 1.0 };
            let a = nrm.y.atan2(nrm.x);
            (a, a + std::f64::consts::PI)
        } else {
            (0.0, std::f64::consts::TAU)
        };
        let steps = ((a1 - a0) / step_max).ceil().max(1.0) as usize;
        let step = (a1 - a0) / steps as f64;
        let radius = offset / (step * 0.5).cos();
        for k in 0..=steps {
            let a = a0 + step * k as f64;
            out.push(p + DVec2::new(a.cos(), a.sin()) * radius);
        }
    }
    convex_hull(&out)
}

/// Whether two convex polygons overlap (separating axis test; touching counts as overlapping).
pub fn intersects(a: &[DVec2], b: &[DVec2]) -> bool {
    if a.is_empty() || b.is_empty() {
        return false;
    }
    let separated_by_edges_of = |p: &[DVec2], q: &[DVec2]| {
        let n = p.len();
        if n < 2 {
            return false;
        }
        (0..n).any(|i| {
            let (s, e) = (p[i], p[(i + 1) % n]);
            let axis = DVec2::new(e.y - s.y, s.x - e.x);
            if axis.length_squared() == 0.0 {
                return false;
            }
            let proj = |poly: &[DVec2]| {
                poly.iter()
                    .map(|v| v.dot(axis))
                    .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)))
            };
            let (pa, pb) = (proj(p), proj(q));
            pa.1 < pb.0 || pb.1 < pa.0
        })
    };
    if a.len() == 1 && b.len() == 1 {
        return a[0] == b[0];
    }
    if a.len() == 1 {
        return contains(b, a[0], 1e-12);
    }
    if b.len() == 1 {
        return contains(a, b[0], 1e-12);
    }
    !(separated_by_edges_of(a, b) || separated_by_edges_of(b, a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn points() -> impl Strategy<Value = Vec<DVec2>> {
        prop::collection::vec(
            (-50.0..50.0f64, -50.0..50.0f64).prop_map(|(x, y)| DVec2::new(x, y)),
            1..40,
        )
    }

    #[test]
    fn collinear_and_duplicate_points() {
        let line: Vec<DVec2> = (0..5)
            .map(|i| DVec2::new(i as f64, 2.0 * i as f64))
            .collect();
        assert_eq!(convex_hull(&line).len(), 2);
        let square = [
            DVec2::ZERO,
            DVec2::X,
            DVec2::ONE,
            DVec2::Y,
            DVec2::ZERO,
            DVec2::new(0.5, 0.0),
        ];
        assert_eq!(convex_hull(&square).len(), 4);
        assert_eq!(convex_hull(&[DVec2::ONE, DVec2::ONE]).len(), 1);
    }

    proptest! {
        #[test]
        fn hull_contains_all_points(pts in points()) {
            let hull = convex_hull(&pts);
            for p in &pts {
                prop_assert!(contains(&hull, *p, 1e-9));
            }
        }

        #[test]
        fn extended_hull_contains_everything_within_the_offset(pts in points(), offset in 0.1..30.0f64, angle in 0.0..6.3f64, frac in 0.0..=1.0f64, which in 0usize..40) {
            let hull = convex_hull(&pts);
            let ext = extend(&hull, offset);
            let p = pts[which % pts.len()] + DVec2::new(angle.cos(), angle.sin()) * offset * frac;
            prop_assert!(contains(&ext, p, 1e-9), "{p} not in extended hull");
        }

        #[test]
        fn intersection_agrees_with_containment(a in points(), b in points()) {
            let (ha, hb) = (convex_hull(&a), convex_hull(&b));
            if b.iter().any(|p| contains(&ha, *p, 0.0)) {
                prop_assert!(intersects(&ha, &hb));
            }
        }
    }
}
