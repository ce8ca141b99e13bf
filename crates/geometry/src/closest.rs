//! Closest-point kernels: point–triangle (with the feature reached), segment–segment and
//! segment–triangle (Ericson, "Real-Time Collision Detection", 5.1.5 and 5.1.9).
use crate::V3;

/// Feature of a triangle a closest point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    Vertex(u8),
    /// Edge i joins vertex i and vertex (i + 1) % 3.
    Edge(u8),
    Face,
}

/// Closest point of triangle (a, b, c) to p, and the feature it lies on.
#[inline]
pub fn point_triangle(p: &V3, a: &V3, b: &V3, c: &V3) -> (V3, Feature) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, Feature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, Feature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (a + ab * v + ac * w, Feature::Face)
}

/// Closest point of segment [a, b] to p: (parameter t, point).
#[inline]
pub fn point_segment(p: &V3, a: &V3, b: &V3) -> (f64, V3) {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, a + ab * t)
}

/// Closest points of segments [p1, q1] and [p2, q2]: (s, t, c1, c2) with c1 = p1 + s (q1 − p1).
#[inline]
pub fn segment_segment(p1: &V3, q1: &V3, p2: &V3, q2: &V3) -> (f64, f64, V3, V3) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let eps = 1e-300;
    let (s, t);
    if a <= eps && e <= eps {
        return (0.0, 0.0, *p1, *p2);
    }
    if a <= eps {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= eps {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-14 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    (s, t, p1 + d1 * s, p2 + d2 * t)
}

/// Closest points of segment [p, q] and triangle (a, b, c): (t on the segment, point on the
/// segment, point on the triangle). Distance 0 where the segment crosses the triangle.
pub fn segment_triangle(p: &V3, q: &V3, a: &V3, b: &V3, c: &V3) -> (f64, V3, V3) {
    let ab = b - a;
    let ac = c - a;
    let n = ab.cross(&ac);
    let dp = (p - a).dot(&n);
    let dq = (q - a).dot(&n);
    if (dp <= 0.0 && dq >= 0.0) || (dp >= 0.0 && dq <= 0.0) {
        let den = dp - dq;
        if den != 0.0 {
            let t = dp / den;
            let x = p + (q - p) * t;
            // barycentric test of the crossing point
            let (cx, f) = point_triangle(&x, a, b, c);
            if f == Feature::Face || (cx - x).norm_squared() == 0.0 {
                return (t, x, cx);
            }
        }
    }
    let mut best = {
        let (cp, _) = point_triangle(p, a, b, c);
        (0.0, *p, cp, (cp - p).norm_squared())
    };
    let (cq, _) = point_triangle(q, a, b, c);
    let dq2 = (cq - q).norm_squared();
    if dq2 < best.3 {
        best = (1.0, *q, cq, dq2);
    }
    for (e0, e1) in [(a, b), (b, c), (c, a)] {
        let (s, _, c1, c2) = segment_segment(p, q, e0, e1);
        let d2 = (c1 - c2).norm_squared();
        if d2 < best.3 {
            best = (s, c1, c2, d2);
        }
    }
    (best.0, best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> V3 {
        V3::new(x, y, z)
    }

    #[test]
    fn point_triangle_regions() {
        let (a, b, c) = (v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.));
        let (x, f) = point_triangle(&v(0.2, 0.2, 1.), &a, &b, &c);
        assert!((x - v(0.2, 0.2, 0.)).norm() < 1e-16 && f == Feature::Face);
        assert_eq!(
            point_triangle(&v(-1., -1., 0.), &a, &b, &c),
            (a, Feature::Vertex(0))
        );
        assert_eq!(
            point_triangle(&v(2., -0.5, 0.), &a, &b, &c),
            (b, Feature::Vertex(1))
        );
        assert_eq!(
            point_triangle(&v(0.5, -1., 3.), &a, &b, &c),
            (v(0.5, 0., 0.), Feature::Edge(0))
        );
        assert_eq!(
            point_triangle(&v(1., 1., 0.), &a, &b, &c),
            (v(0.5, 0.5, 0.), Feature::Edge(1))
        );
        assert_eq!(
            point_triangle(&v(-1., 0.5, 0.), &a, &b, &c),
            (v(0., 0.5, 0.), Feature::Edge(2))
        );
    }

    #[test]
    fn segment_triangle_matches_dense_sampling() {
        let (a, b, c) = (v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.));
        let cases = [
            (v(0.2, 0.2, -1.), v(0.2, 0.2, 1.)),  // crosses: 0
            (v(-1., 2., 0.5), v(2., -1., 0.3)),   // passes over edge bc
            (v(1.5, 0.5, 0.2), v(1.5, 0.5, 2.0)), // beside
            (v(-0.5, -0.5, 0.1), v(-0.2, -0.3, 0.4)),
        ];
        for (p, q) in cases {
            let (_, x, y) = segment_triangle(&p, &q, &a, &b, &c);
            let d = (x - y).norm();
            let mut brute = f64::INFINITY;
            let n = 2000;
            for i in 0..=n {
                let s = p + (q - p) * (i as f64 / n as f64);
                let (cp, _) = point_triangle(&s, &a, &b, &c);
                brute = brute.min((cp - s).norm());
            }
            assert!(d <= brute + 1e-12, "{d} > {brute}");
            assert!(brute - d < 2e-3 * (q - p).norm(), "{d} vs {brute}");
        }
    }
}
