//! Cubic Bézier and Hermite splines (Section 3.8): evaluation, first derivative, conversion both ways, and C1
//! subdivision at any t that keeps the shape.

use glam::DVec2;

/// A cubic Hermite segment: end points and tangents (3.8.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hermite {
    /// The start point and the tangent there.
    pub p0: DVec2,
    /// See `p0`.
    pub d0: DVec2,
    /// The end point and the tangent there.
    pub p1: DVec2,
    /// See `p1`.
    pub d1: DVec2,
}

/// A cubic Bézier segment: four control points (3.8.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bezier(pub [DVec2; 4]);

impl Hermite {
    /// Eq. 3.3.
    pub fn point(&self, t: f64) -> DVec2 {
        let (t2, t3) = (t * t, t * t * t);
        self.p0 * (2.0 * t3 - 3.0 * t2 + 1.0)
            + self.d0 * (t3 - 2.0 * t2 + t)
            + self.p1 * (-2.0 * t3 + 3.0 * t2)
            + self.d1 * (t3 - t2)
    }

    /// Eq. 3.4.
    pub fn derivative(&self, t: f64) -> DVec2 {
        let t2 = t * t;
        self.p0 * (6.0 * t2 - 6.0 * t)
            + self.d0 * (3.0 * t2 - 4.0 * t + 1.0)
            + self.p1 * (-6.0 * t2 + 6.0 * t)
            + self.d1 * (3.0 * t2 - 2.0 * t)
    }

    /// The same curve as a Bézier (control points a third of the tangents from the ends).
    pub fn to_bezier(&self) -> Bezier {
        Bezier([
            self.p0,
            self.p0 + self.d0 / 3.0,
            self.p1 - self.d1 / 3.0,
            self.p1,
        ])
    }

    /// The piece of this segment over [a, b], reparametrised to [0, 1]: the same curve (tangents scale by b - a).
    pub fn piece(&self, a: f64, b: f64) -> Hermite {
        let k = b - a;
        Hermite {
            p0: self.point(a),
            d0: self.derivative(a) * k,
            p1: self.point(b),
            d1: self.derivative(b) * k,
        }
    }

    /// C1 subdivision at t (3.8.1.1): two segments that together are exactly this one.
    pub fn split(&self, t: f64) -> (Hermite, Hermite) {
        (self.piece(0.0, t), self.piece(t, 1.0))
    }

    /// Length of the straight line between the ends.
    pub fn chord(&self) -> f64 {
        self.p0.distance(self.p1)
    }

    /// The Bézier control points: the curve lies in their convex hull.
    pub fn control_points(&self) -> [DVec2; 4] {
        self.to_bezier().0
    }
}

impl Bezier {
    /// Eq. 3.1.
    pub fn point(&self, t: f64) -> DVec2 {
        let [p0, p1, p2, p3] = self.0;
        let s = 1.0 - t;
        p0 * (s * s * s) + p1 * (3.0 * s * s * t) + p2 * (3.0 * s * t * t) + p3 * (t * t * t)
    }

    /// Eq. 3.2.
    pub fn derivative(&self, t: f64) -> DVec2 {
        let [p0, p1, p2, p3] = self.0;
        let s = 1.0 - t;
        (p1 - p0) * (3.0 * s * s) + (p2 - p1) * (6.0 * s * t) + (p3 - p2) * (3.0 * t * t)
    }

    /// The same curve as a Hermite segment.
    pub fn to_hermite(&self) -> Hermite {
        let [p0, p1, p2, p3] = self.0;
        Hermite {
            p0,
            d0: (p1 - p0) * 3.0,
            p1: p3,
            d1: (p3 - p2) * 3.0,
        }
    }
}

/// Rotates `v` by `angle` radians (counter-clockwise).
pub fn rotate(v: DVec2, angle: f64) -> DVec2 {
    let (s, c) = angle.sin_cos();
    DVec2::new(v.x * c - v.y * s, v.x * s + v.y * c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v() -> impl Strategy<Value = DVec2> {
        (-100.0..100.0f64, -100.0..100.0f64).prop_map(|(x, y)| DVec2::new(x, y))
    }

    proptest! {
        #[test]
        fn bezier_and_hermite_are_the_same_curve(p0 in v(), d0 in v(), p1 in v(), d1 in v(), t in 0.0..=1.0f64) {
            let h = Hermite { p0, d0, p1, d1 };
            let b = h.to_bezier();
            prop_assert!(h.point(t).distance(b.point(t)) < 1e-9);
            prop_assert!(h.derivative(t).distance(b.derivative(t)) < 1e-9);
            let back = b.to_hermite();
            prop_assert!(back.p0.distance(p0) < 1e-9 && back.d0.distance(d0) < 1e-9);
            prop_assert!(back.p1.distance(p1) < 1e-9 && back.d1.distance(d1) < 1e-9);
        }

        #[test]
        fn subdivision_keeps_the_curve_and_is_c1(p0 in v(), d0 in v(), p1 in v(), d1 in v(), at in 0.05..0.95f64, t in 0.0..=1.0f64) {
            let h = Hermite { p0, d0, p1, d1 };
            let (a, b) = h.split(at);
            // Same points: the first half covers [0, at], the second [at, 1].
            prop_assert!(a.point(t).distance(h.point(t * at)) < 1e-8);
            prop_assert!(b.point(t).distance(h.point(at + t * (1.0 - at))) < 1e-8);
            // C1 at the join: same point, same tangent (in the curve's own parameter).
            prop_assert!(a.p1.distance(b.p0) < 1e-12);
            prop_assert!((a.d1 / at).distance(b.d0 / (1.0 - at)) < 1e-8);
        }
    }
}
