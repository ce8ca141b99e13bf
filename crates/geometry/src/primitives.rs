//! Analytic primitives: half-space (plane), box, finite cylinder, sphere. Exact signed
//! distances for points; for segments the distance to the solid (0 where the segment enters
//! it), exact for the half-space and the sphere, and for the box and the cylinder the minimum
//! of the convex function t ↦ dist(a + t (b − a), solid) by golden-section search to
//! round-off.
use nalgebra::Matrix3;

use crate::closest::point_segment;
use crate::{PointProjection, SegmentProjection, Surface, V3};

/// A unit vector orthogonal to `n` (unit).
fn any_orthogonal(n: &V3) -> V3 {
    let e = if n.x.abs() < 0.9 { V3::x() } else { V3::y() };
    (e - n * n.dot(&e)).normalize()
}

/// The solid below the plane through `point` with outward unit `normal`.
#[derive(Clone, Debug)]
pub struct HalfSpace {
    pub point: V3,
    pub normal: V3,
}

/// A box: centre, axes (columns of `rotation`), half extents along them.
#[derive(Clone, Debug)]
pub struct Cuboid {
    pub center: V3,
    pub rotation: Matrix3<f64>,
    pub half_extents: V3,
}

/// A finite solid cylinder: centre, unit axis, radius, half length along the axis.
#[derive(Clone, Debug)]
pub struct Cylinder {
    pub center: V3,
    pub axis: V3,
    pub radius: f64,
    pub half_length: f64,
}

#[derive(Clone, Debug)]
pub struct Sphere {
    pub center: V3,
    pub radius: f64,
}

impl HalfSpace {
    pub fn new(point: V3, normal: V3) -> Self {
        HalfSpace {
            point,
            normal: normal.normalize(),
        }
    }
}

impl Cylinder {
    pub fn new(center: V3, axis: V3, radius: f64, half_length: f64) -> Self {
        Cylinder {
            center,
            axis: axis.normalize(),
            radius,
            half_length,
        }
    }
}

/// Signed distance, closest point and outward normal of a point against a convex solid.
trait Convex {
    fn project(&self, p: &V3) -> (f64, V3, V3);
}

impl Convex for HalfSpace {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        let d = (p - self.point).dot(&self.normal);
        (d, p - self.normal * d, self.normal)
    }
}

impl Convex for Sphere {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        let r = p - self.center;
        let len = r.norm();
        let n = if len > 0.0 { r / len } else { V3::z() };
        (len - self.radius, self.center + n * self.radius, n)
    }
}

impl Convex for Cuboid {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        let l = self.rotation.transpose() * (p - self.center);
        let e = &self.half_extents;
        let q = l.abs() - e;
        if q.iter().any(|&x| x > 0.0) {
            let c = V3::new(
                l.x.clamp(-e.x, e.x),
                l.y.clamp(-e.y, e.y),
                l.z.clamp(-e.z, e.z),
            );
            let d = l - c;
            let dist = d.norm();
            let point = self.center + self.rotation * c;
            (dist, point, self.rotation * (d / dist))
        } else {
            let k = q.imax();
            let mut c = l;
            let s = if l[k] < 0.0 { -1.0 } else { 1.0 };
            c[k] = s * e[k];
            let mut n = V3::zeros();
            n[k] = s;
            (q[k], self.center + self.rotation * c, self.rotation * n)
        }
    }
}

impl Convex for Cylinder {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        let r = p - self.center;
        let z = r.dot(&self.axis);
        let rho = r - self.axis * z;
        let rl = rho.norm();
        let radial = if rl > 0.0 {
            rho / rl
        } else {
            any_orthogonal(&self.axis)
        };
        let dr = rl - self.radius;
        let dz = z.abs() - self.half_length;
        let sz = if z < 0.0 { -1.0 } else { 1.0 };
        if dr > 0.0 || dz > 0.0 {
            let cr = rl.min(self.radius);
            let cz = z.clamp(-self.half_length, self.half_length);
            let point = self.center + radial * cr + self.axis * cz;
            let d = p - point;
            let dist = d.norm();
            (dist, point, d / dist)
        } else if dr > dz {
            (
                dr,
                self.center + radial * self.radius + self.axis * z,
                radial,
            )
        } else {
            let point = self.center + rho + self.axis * (sz * self.half_length);
            (dz, point, self.axis * sz)
        }
    }
}

fn point_projection<S: Convex>(s: &S, p: &V3, max_distance: f64) -> Option<PointProjection> {
    let (distance, point, normal) = s.project(p);
    (distance.abs() <= max_distance).then_some(PointProjection {
        distance,
        point,
        normal,
        feature: 0,
    })
}

fn segment_result<S: Convex>(
    s: &S,
    a: &V3,
    b: &V3,
    t: f64,
    max_distance: f64,
) -> Option<SegmentProjection> {
    let x = a + (b - a) * t;
    let (d, y, n) = s.project(&x);
    let distance = d.max(0.0);
    (distance <= max_distance).then_some(SegmentProjection {
        distance,
        t,
        on_segment: x,
        on_surface: y,
        normal: n,
        feature: 0,
    })
}

/// Minimiser over [0, 1] of the convex function t ↦ max(sd(a + t (b − a)), 0).
fn golden_section<S: Convex>(s: &S, a: &V3, b: &V3) -> f64 {
    let f = |t: f64| s.project(&(a + (b - a) * t)).0.max(0.0);
    let len = (b - a).norm();
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut x1 = hi - g * (hi - lo);
    let mut x2 = lo + g * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    // Stop when the bracket is below 1e-10 m (or round-off): outside a convex set its distance
    // is C¹ and convex along the segment, so the distance found is within ~(1e-10 m)²/d of the
    // least one (and the end points are checked exactly below).
    while (hi - lo) * len > 1e-10_f64.max(1e-15 * (1.0 + a.norm())) && hi - lo > 1e-16 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    let mut best = (0.5 * (lo + hi), f(0.5 * (lo + hi)));
    for t in [0.0, 1.0] {
        let v = f(t);
        if v < best.1 {
            best = (t, v);
        }
    }
    best.0
}

impl Surface for HalfSpace {
    fn project_point(&self, p: &V3, max_distance: f64, _hint: usize) -> Option<PointProjection> {
        point_projection(self, p, max_distance)
    }
    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        m: f64,
        _hint: usize,
    ) -> Option<SegmentProjection> {
        let da = (a - self.point).dot(&self.normal);
        let db = (b - self.point).dot(&self.normal);
        let t = if da * db <= 0.0 && da != db {
            da / (da - db)
        } else if da <= db {
            0.0
        } else {
            1.0
        };
        segment_result(self, a, b, t, m)
    }
}

impl Surface for Sphere {
    fn project_point(&self, p: &V3, max_distance: f64, _hint: usize) -> Option<PointProjection> {
        point_projection(self, p, max_distance)
    }
    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        m: f64,
        _hint: usize,
    ) -> Option<SegmentProjection> {
        let (t, _) = point_segment(&self.center, a, b);
        segment_result(self, a, b, t, m)
    }
}

impl Surface for Cuboid {
    fn project_point(&self, p: &V3, max_distance: f64, _hint: usize) -> Option<PointProjection> {
        point_projection(self, p, max_distance)
    }
    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        m: f64,
        _hint: usize,
    ) -> Option<SegmentProjection> {
        segment_result(self, a, b, golden_section(self, a, b), m)
    }
}

impl Surface for Cylinder {
    fn project_point(&self, p: &V3, max_distance: f64, _hint: usize) -> Option<PointProjection> {
        point_projection(self, p, max_distance)
    }
    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        m: f64,
        _hint: usize,
    ) -> Option<SegmentProjection> {
        segment_result(self, a, b, golden_section(self, a, b), m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_cylinder_distances() {
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.7).into_inner();
        let b = Cuboid {
            center: V3::new(1.0, 2.0, 3.0),
            rotation: rot,
            half_extents: V3::new(0.5, 0.2, 0.1),
        };
        // a point at local (0.5 + 0.3, 0.2 + 0.4, 0): distance 0.5 to the edge
        let p = b.center + rot * V3::new(0.8, 0.6, 0.0);
        let r = b.project_point(&p, 1.0, 0).unwrap();
        assert!((r.distance - 0.5).abs() < 1e-15);
        let p = b.center + rot * V3::new(0.1, 0.15, 0.0);
        assert!((b.project_point(&p, 1.0, 0).unwrap().distance + 0.05).abs() < 1e-15);
        // segment passing the edge at distance 0.1, ends far
        let e = b.center + rot * V3::new(0.5, 0.2, 0.0);
        let dir = rot * V3::new(1.0, 1.0, 0.0).normalize();
        let along = rot * V3::new(-1.0, 1.0, 0.0).normalize();
        let s = b
            .closest_to_segment(
                &(e + dir * 0.1 - along),
                &(e + dir * 0.1 + along * 0.7),
                1.0,
                0,
            )
            .unwrap();
        assert!((s.distance - 0.1).abs() < 1e-14, "{}", s.distance);

        let c = Cylinder::new(V3::zeros(), V3::new(0.0, 0.0, 2.0), 0.3, 0.5);
        let r = c.project_point(&V3::new(0.0, 0.7, 0.2), 1.0, 0).unwrap();
        assert!((r.distance - 0.4).abs() < 1e-15);
        let r = c.project_point(&V3::new(0.6, 0.0, 0.9), 1.0, 0).unwrap();
        assert!((r.distance - 0.5).abs() < 1e-15);
        let r = c.project_point(&V3::new(0.0, 0.1, 0.45), 1.0, 0).unwrap();
        assert!((r.distance + 0.05).abs() < 1e-15);
        assert!((r.normal - V3::z()).norm() < 1e-15);
    }
}
