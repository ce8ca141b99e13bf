//! Analytic primitives: half-space (plane), box, finite cylinder, sphere. Exact signed
//! distances for points; for segments the distance to the solid (0 where the segment enters
//! it), exact for the half-space and the sphere, and for the box and the cylinder the minimum
//! of the convex function t ↦ dist(a + t (b − a), solid) by golden-section search to
//! round-off.
//!
//! One distance code for clearance and contact: the functions `*_local` give the signed
//! distance, the outward normal and the normal's gradient (the distance's Hessian, which the
//! contact Jacobian needs) of a point in a primitive's own frame; the placed primitives below
//! (clearance) and the contact obstacles of `rod::contact` (placed by their bodies' poses) both
//! call them.
use nalgebra::Matrix3;

use crate::closest::point_segment;
use crate::{PointProjection, SegmentProjection, Surface, V3};

/// Signed distance of a point to a primitive (positive outside), the outward normal (its
/// gradient) and the normal's gradient (the Hessian of the distance; zero on flat parts, and
/// when not asked for).
#[derive(Clone, Copy, Debug)]
pub struct PointDistance {
    pub distance: f64,
    pub normal: V3,
    pub hessian: Matrix3<f64>,
}

impl PointDistance {
    /// The closest point on the surface.
    pub fn closest_point(&self, p: &V3) -> V3 {
        p - self.distance * self.normal
    }
}

fn flat(distance: f64, normal: V3) -> PointDistance {
    PointDistance {
        distance,
        normal,
        hessian: Matrix3::zeros(),
    }
}

/// The half-space z ≤ 0 (normal +z).
#[inline]
pub fn half_space_local(p: &V3) -> PointDistance {
    flat(p.z, V3::z())
}

/// The ball of a radius about the origin.
#[inline]
pub fn sphere_local(radius: f64, p: &V3, hessian: bool) -> PointDistance {
    let rho = p.norm();
    if rho < 1e-12 * radius {
        return flat(-radius, V3::z());
    }
    let n = p / rho;
    PointDistance {
        distance: rho - radius,
        normal: n,
        hessian: if hessian {
            (Matrix3::identity() - n * n.transpose()) / rho
        } else {
            Matrix3::zeros()
        },
    }
}

/// The solid cylinder about the z axis, centred at the origin, with flat caps at
/// z = ±`half_length` (∞: infinite, no caps).
#[inline]
pub fn cylinder_local(radius: f64, half_length: f64, p: &V3, hessian: bool) -> PointDistance {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    let (radial, tangential) = if rho > 1e-12 * radius {
        let r = V3::new(p.x / rho, p.y / rho, 0.0);
        (r, V3::new(-r.y, r.x, 0.0))
    } else {
        (V3::x(), V3::y())
    };
    let qs = rho - radius;
    let qc = p.z.abs() - half_length;
    let axial = V3::new(0.0, 0.0, if p.z < 0.0 { -1.0 } else { 1.0 });
    let side = |d: f64| PointDistance {
        distance: d,
        normal: radial,
        // Distance to the axis: curvature 1/ρ about it.
        hessian: if hessian {
            tangential * tangential.transpose() / rho.max(1e-300)
        } else {
            Matrix3::zeros()
        },
    };
    if qs <= 0.0 && qc <= 0.0 {
        // Inside: the nearer of side and cap.
        return if qs >= qc { side(qs) } else { flat(qc, axial) };
    }
    if qc <= 0.0 {
        return side(qs);
    }
    if qs <= 0.0 {
        return flat(qc, axial);
    }
    // Outside beyond the rim circle: distance to the circle.
    let d = (qs * qs + qc * qc).sqrt();
    let n = (qs * radial + qc * axial) / d;
    PointDistance {
        distance: d,
        normal: n,
        hessian: if hessian {
            let in_plane =
                Matrix3::identity() - n * n.transpose() - tangential * tangential.transpose();
            in_plane / d + (qs / (d * rho)) * tangential * tangential.transpose()
        } else {
            Matrix3::zeros()
        },
    }
}

/// The box with half extents `half` along the axes, centred at the origin.
#[inline]
pub fn cuboid_local(half: &V3, p: &V3, hessian: bool) -> PointDistance {
    let q = p.abs() - half;
    let sign = p.map(|v| if v < 0.0 { -1.0 } else { 1.0 });
    let out = q.map(|v| v.max(0.0));
    let n_out = (0..3).filter(|&k| q[k] > 0.0).count();
    if n_out == 0 {
        // Inside: the nearest face.
        let k = q.imax();
        let mut n = V3::zeros();
        n[k] = sign[k];
        return flat(q[k], n);
    }
    let d = out.norm();
    let n = sign.component_mul(&out) / d;
    let hessian = match (hessian, n_out) {
        (false, _) | (true, 1) => Matrix3::zeros(),
        (true, 2) => {
            // Distance to an edge line along the axis that is inside.
            let k = (0..3).find(|&k| q[k] <= 0.0).unwrap();
            let mut l = V3::zeros();
            l[k] = 1.0;
            (Matrix3::identity() - n * n.transpose() - l * l.transpose()) / d
        }
        _ => (Matrix3::identity() - n * n.transpose()) / d,
    };
    PointDistance {
        distance: d,
        normal: n,
        hessian,
    }
}

/// Signed distance alone (cheaper) of the cylinder of [`cylinder_local`].
#[inline]
pub fn cylinder_local_distance(radius: f64, half_length: f64, p: &V3) -> f64 {
    let qs = (p.x * p.x + p.y * p.y).sqrt() - radius;
    let qc = p.z.abs() - half_length;
    qs.max(qc).min(0.0) + (qs.max(0.0).powi(2) + qc.max(0.0).powi(2)).sqrt()
}

/// Signed distance alone (cheaper) of the box of [`cuboid_local`].
#[inline]
pub fn cuboid_local_distance(half: &V3, p: &V3) -> f64 {
    let q = p.abs() - half;
    q.max().min(0.0) + q.map(|v| v.max(0.0)).norm()
}

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
        let q = half_space_local(&V3::new(0.0, 0.0, (p - self.point).dot(&self.normal)));
        (q.distance, p - self.normal * q.distance, self.normal)
    }
}

impl Convex for Sphere {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        let q = sphere_local(self.radius, &(p - self.center), false);
        (q.distance, q.closest_point(p), q.normal)
    }
}

impl Convex for Cuboid {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        let l = self.rotation.transpose() * (p - self.center);
        let q = cuboid_local(&self.half_extents, &l, false);
        let n = self.rotation * q.normal;
        (q.distance, p - n * q.distance, n)
    }
}

impl Convex for Cylinder {
    fn project(&self, p: &V3) -> (f64, V3, V3) {
        // In the frame (radial, ·, axis) of the point: local (ρ, 0, z).
        let r = p - self.center;
        let z = r.dot(&self.axis);
        let rho = r - self.axis * z;
        let rl = rho.norm();
        let radial = if rl > 0.0 {
            rho / rl
        } else {
            any_orthogonal(&self.axis)
        };
        let q = cylinder_local(self.radius, self.half_length, &V3::new(rl, 0.0, z), false);
        let n = radial * q.normal.x + self.axis * q.normal.z;
        (q.distance, p - n * q.distance, n)
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
