//! Analytic primitives: half-space (plane), box, finite cylinder, sphere. Exact signed
//! distances for points; for segments the distance to the solid (0 where the segment enters
//! it), exact for the half-space and the sphere, and for the box and the cylinder the minimum
//! of the convex function t ↦ dist(a + t (b − a), solid): at an end where the slope there
//! points away, else at the root of the slope (regula falsi to 1e-10 m along the segment).
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

/// Minimiser over [0, 1] of the convex function t ↦ max(sd(a + t (b − a)), 0), sd the signed
/// distance to a convex solid ([`minimise_along_segment`] with the stop inside the solid).
fn convex_segment_minimiser<S: Convex>(s: &S, a: &V3, b: &V3) -> f64 {
    let d = b - a;
    let slope = |t: f64| {
        let (sd, _, n) = s.project(&(a + d * t));
        (sd, n.dot(&d))
    };
    minimise_along_segment(slope, d.norm(), a.norm(), true)
}

/// Minimiser over [0, 1] of a convex distance f(t) along a segment of length `len` (a the
/// start's distance from the origin, for the round-off floor), given `slope(t)` = (f(t),
/// f′(t)); the distance to a convex solid is convex and, outside it, C¹ with f′ = n·(b − a)
/// (n the outward normal at the closest point). The minimum lies at an end when the slope
/// there points away (one or two evaluations: most segments), else at the root of the
/// non-decreasing slope, bracketed and found by regula falsi (Illinois) to 1e-10 m along the
/// segment (as the golden-section search it replaces, which took ~40 evaluations for every
/// segment). `stop_inside`: f ≤ 0 ends the search (a distance clamped at 0: any point inside
/// will do); else the signed minimum (the deepest point) is sought.
pub fn minimise_along_segment(
    slope: impl Fn(f64) -> (f64, f64),
    len: f64,
    a: f64,
    stop_inside: bool,
) -> f64 {
    let (f0, g0) = slope(0.0);
    if (stop_inside && f0 <= 0.0) || g0 >= 0.0 {
        return 0.0;
    }
    let (f1, g1) = slope(1.0);
    if (stop_inside && f1 <= 0.0) || g1 <= 0.0 {
        return 1.0;
    }
    let tol = 1e-10_f64.max(1e-15 * (1.0 + a)) / len;
    let (mut lo, mut hi, mut glo, mut ghi) = (0.0, 1.0, g0, g1);
    let mut side = 0i8; // which end stayed last time (Illinois: halve its slope)
    for _ in 0..100 {
        if hi - lo <= tol.max(1e-16) {
            break;
        }
        let mut t = lo - glo * (hi - lo) / (ghi - glo);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let (f, g) = slope(t);
        if (stop_inside && f <= 0.0) || g == 0.0 {
            return t;
        }
        if g < 0.0 {
            (lo, glo) = (t, g);
            if side == -1 {
                ghi *= 0.5;
            }
            side = -1;
        } else {
            (hi, ghi) = (t, g);
            if side == 1 {
                glo *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (lo + hi)
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
        segment_result(self, a, b, convex_segment_minimiser(self, a, b), m)
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
        segment_result(self, a, b, convex_segment_minimiser(self, a, b), m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: the least of max(sd, 0) over 4001 samples of the segment, refined by a
    /// ternary search between the best sample's neighbours (sd is convex along the segment).
    fn brute_force<S: Convex>(s: &S, a: &V3, b: &V3) -> f64 {
        brute_force_of(|t| s.project(&(a + (b - a) * t)).0.max(0.0))
    }

    /// The same search for any function of t ∈ [0, 1].
    fn brute_force_of(f: impl Fn(f64) -> f64) -> f64 {
        let n = 4000;
        let k = (0..=n)
            .min_by(|&i, &j| f(i as f64 / n as f64).total_cmp(&f(j as f64 / n as f64)))
            .unwrap();
        let (mut lo, mut hi) = (
            (k.max(1) - 1) as f64 / n as f64,
            ((k + 1).min(n)) as f64 / n as f64,
        );
        for _ in 0..200 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if f(m1) <= f(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
    }

    #[test]
    fn segment_distances_to_box_and_cylinder_equal_a_brute_force_search() {
        // Segments of random position, direction and length (1 mm – 0.3 m) around a box and a
        // cylinder: clear of them, grazing edges and rims, and through them (distance 0). The
        // minimiser's distance equals the dense search's to 1e-12 m, and the number of
        // segments that needed the interior search is reported (the rest stop at an end).
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.7).into_inner();
        let bx = Cuboid {
            center: V3::new(0.1, -0.05, 0.02),
            rotation: rot,
            half_extents: V3::new(0.05, 0.02, 0.03),
        };
        let cy = Cylinder::new(
            V3::new(0.0, 0.02, -0.01),
            V3::new(0.2, 1.0, 0.3),
            0.02,
            0.06,
        );
        let mut rnd = crate::test_random(12345);
        let (mut inside, mut interior) = (0, 0);
        for k in 0..1500 {
            let a = V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.3;
            let dir = V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
            let len = 1e-3 + 0.3 * rnd().powi(2);
            let b = a + dir * len;
            for (name, got, want) in [
                (
                    "box",
                    bx.closest_to_segment(&a, &b, 1.0, 0),
                    brute_force(&bx, &a, &b),
                ),
                (
                    "cylinder",
                    cy.closest_to_segment(&a, &b, 1.0, 0),
                    brute_force(&cy, &a, &b),
                ),
            ] {
                let got = got.unwrap();
                assert!(
                    (got.distance - want).abs() < 1e-12,
                    "{name} segment {k}: {} vs {want}",
                    got.distance
                );
                inside += (want == 0.0) as usize;
                interior += (got.t > 0.0 && got.t < 1.0) as usize;
            }
            // The signed minimum (the deepest point of a segment through the solid), as the
            // contact's segment query asks for it. Inside, the signed distance has kinks (where
            // the nearest face changes) and the minimum sits on one: the slope changes sign
            // there without a root, and the search's 1e-10 m bracket bounds the error by
            // 1e-10 m (|slope| ≤ 1).
            for (name, s) in [
                ("box", &bx as &dyn Convex),
                ("cylinder", &cy as &dyn Convex),
            ] {
                let d = b - a;
                let slope = |t: f64| {
                    let (sd, _, n) = s.project(&(a + d * t));
                    (sd, n.dot(&d))
                };
                let t = minimise_along_segment(slope, d.norm(), a.norm(), false);
                let got = s.project(&(a + d * t)).0;
                let want = brute_force_of(|t| s.project(&(a + d * t)).0);
                assert!(
                    (got - want).abs() < 1e-10,
                    "{name} signed {k}: {got} vs {want}"
                );
            }
        }
        assert!(
            inside > 20 && interior > 100,
            "through {inside}, interior minima {interior}"
        );
    }

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
