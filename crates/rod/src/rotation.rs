//! Quaternions (scalar first, Hamilton product) and the rotation-group helpers of the solver.
//!
//! nalgebra's `Quaternion::new(w, i, j, k)` is used throughout; `R(p)` maps the material frame
//! (d1, d2, d3) to the global frame. Increments act in the body frame: p ← p ⊗ exp(θ/2).
use crate::simd::{lanes, splat};
use nalgebra::{Matrix3, Quaternion, Vector3};

pub type Quat = Quaternion<f64>;

/// The cross-product matrix [v]×, with [v]× w = v × w.
#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Coefficients of the series of `exp_half` in t² = |θ|²/4: cos t and sin t/(2t).
const EXP_COS: [f64; 5] = [1.0, -1.0 / 2.0, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0];
const EXP_SIN: [f64; 5] = [0.5, -0.5 / 6.0, 0.5 / 120.0, -0.5 / 5040.0, 0.5 / 362880.0];

/// exp(θ/2) as a unit quaternion: the rotation by |θ| about θ/|θ|.
#[inline(always)]
pub fn exp_half(theta: &Vector3<f64>) -> Quat {
    let a2 = theta.norm_squared();
    if a2 < 1e-2 {
        // Series in t² = |θ|²/4 for cos t and sin t/(2t), exact to round-off for |θ| < 0.1
        // (the next terms are below 1e-19).
        let t2 = 0.25 * a2;
        let (c, s) = (EXP_COS, EXP_SIN);
        // Estrin's scheme: short dependency chains.
        let t4 = t2 * t2;
        let w = (c[0] + c[1] * t2) + t4 * ((c[2] + c[3] * t2) + t4 * c[4]);
        let s = (s[0] + s[1] * t2) + t4 * ((s[2] + s[3] * t2) + t4 * s[4]);
        Quaternion::new(w, s * theta.x, s * theta.y, s * theta.z)
    } else {
        let angle = a2.sqrt();
        let (s, c) = (0.5 * angle).sin_cos();
        let k = s / angle;
        Quaternion::new(c, k * theta.x, k * theta.y, k * theta.z)
    }
}

/// `rotate_body` of the edges `e` with `turn[e]` (all of them, or those with `moves[e]`), four
/// at a time in f64x4 lanes where four neighbours move by less than 0.1 rad each (the series
/// of `exp_half`): each lane with `rotate_body`'s operations in its order, the same values to
/// the last bit (≈ 3× faster; a dynamic step turns every edge once or twice).
pub fn rotate_edges(
    p_n: &[Quat],
    turn: &[Vector3<f64>],
    moves: impl Fn(usize) -> bool,
    p: &mut [Quat],
) {
    let n = p.len().min(p_n.len()).min(turn.len());
    let mut e = 0;
    while e < n {
        if e + 4 <= n && (e..e + 4).all(&moves) {
            let (tx, ty, tz) = (
                lanes(|l| turn[e + l].x),
                lanes(|l| turn[e + l].y),
                lanes(|l| turn[e + l].z),
            );
            let a2 = tx * tx + ty * ty + tz * tz;
            if a2.simd_lt(splat(1e-2)).all() {
                let s = splat;
                // exp_half's series
                let t2 = s(0.25) * a2;
                let t4 = t2 * t2;
                let series = |c: [f64; 5]| {
                    (s(c[0]) + s(c[1]) * t2) + t4 * ((s(c[2]) + s(c[3]) * t2) + t4 * s(c[4]))
                };
                let (ew, k) = (series(EXP_COS), series(EXP_SIN));
                let (ei, ej, ek) = (k * tx, k * ty, k * tz);
                // p ⊗ exp (nalgebra's product)
                let (pi, pj, pk, pw) = (
                    lanes(|l| p_n[e + l].i),
                    lanes(|l| p_n[e + l].j),
                    lanes(|l| p_n[e + l].k),
                    lanes(|l| p_n[e + l].w),
                );
                let qw = pw * ew - pi * ei - pj * ej - pk * ek;
                let qi = pw * ei + pi * ew + pj * ek - pk * ej;
                let qj = pw * ej - pi * ek + pj * ew + pk * ei;
                let qk = pw * ek + pi * ej - pj * ei + pk * ew;
                // |q|² as nalgebra sums the coordinates (i, j, k, w): (i² + k²) + (j² + w²)
                let n2 = (qi * qi + qk * qk) + (qj * qj + qw * qw);
                let near = (n2 - s(1.0)).abs().simd_lt(s(1e-8));
                let scale = near.bitselect(s(1.5) - s(0.5) * n2, s(1.0) / n2.sqrt());
                let (w, i, j, k) = (
                    (qw * scale).to_array(),
                    (qi * scale).to_array(),
                    (qj * scale).to_array(),
                    (qk * scale).to_array(),
                );
                for l in 0..4 {
                    p[e + l] = Quaternion::new(w[l], i[l], j[l], k[l]);
                }
                e += 4;
                continue;
            }
        }
        if moves(e) {
            p[e] = rotate_body(&p_n[e], &turn[e]);
        }
        e += 1;
    }
}

/// p ⊗ exp(θ/2), renormalised so that |p| = 1 holds to round-off.
#[inline(always)]
pub fn rotate_body(p: &Quat, theta: &Vector3<f64>) -> Quat {
    let q = p * exp_half(theta);
    let n2 = q.norm_squared();
    // |q|² = 1 + ε: 1/√(1 + ε) = 1 − ε/2 + O(ε²), exact to round-off for |ε| < 1e-8.
    let k = if (n2 - 1.0).abs() < 1e-8 {
        1.5 - 0.5 * n2
    } else {
        1.0 / n2.sqrt()
    };
    q * k
}

/// The right Jacobian of the exponential map, exp(θ + δ) = exp(θ) exp(J_r(θ) δ + O(δ²)):
/// J_r(θ) = I − (1 − cos t)/t² [θ]× + (t − sin t)/t³ [θ]×², t = |θ|.
pub fn right_jacobian(theta: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = theta.norm_squared();
    let (a, b) = if t2 < 1e-4 {
        (
            0.5 - t2 / 24.0 + t2 * t2 / 720.0,
            1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0,
        )
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let s = skew(theta);
    Matrix3::identity() - a * s + b * (s * s)
}

/// Rotation vector (axis · angle, angle in [0, π]) of a unit quaternion.
pub fn log_vec(q: &Quat) -> Vector3<f64> {
    let q = if q.w < 0.0 { -q } else { *q };
    let v = q.imag();
    let s = v.norm();
    if s < 1e-12 {
        return 2.0 * v;
    }
    let angle = 2.0 * s.atan2(q.w);
    v * (angle / s)
}

/// The rotation matrix R(p) of a unit quaternion p.
#[inline]
pub fn rotation_matrix(p: &Quat) -> Matrix3<f64> {
    let (w, x, y, z) = (p.w, p.i, p.j, p.k);
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz) = (x * y, x * z, y * z);
    let (wx, wy, wz) = (w * x, w * y, w * z);
    Matrix3::new(
        1.0 - 2.0 * (yy + zz),
        2.0 * (xy - wz),
        2.0 * (xz + wy),
        2.0 * (xy + wz),
        1.0 - 2.0 * (xx + zz),
        2.0 * (yz - wx),
        2.0 * (xz - wy),
        2.0 * (yz + wx),
        1.0 - 2.0 * (xx + yy),
    )
}

/// The unit quaternion of a rotation matrix (Shepperd's method, stable for all angles).
pub fn from_matrix(r: &Matrix3<f64>) -> Quat {
    let tr = r.trace();
    let q = if tr > r[(0, 0)] && tr > r[(1, 1)] && tr > r[(2, 2)] {
        let s = (1.0 + tr).sqrt() * 2.0;
        Quaternion::new(
            0.25 * s,
            (r[(2, 1)] - r[(1, 2)]) / s,
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(1, 0)] - r[(0, 1)]) / s,
        )
    } else if r[(0, 0)] > r[(1, 1)] && r[(0, 0)] > r[(2, 2)] {
        let s = (1.0 + r[(0, 0)] - r[(1, 1)] - r[(2, 2)]).sqrt() * 2.0;
        Quaternion::new(
            (r[(2, 1)] - r[(1, 2)]) / s,
            0.25 * s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
        )
    } else if r[(1, 1)] > r[(2, 2)] {
        let s = (1.0 + r[(1, 1)] - r[(0, 0)] - r[(2, 2)]).sqrt() * 2.0;
        Quaternion::new(
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            0.25 * s,
            (r[(1, 2)] + r[(2, 1)]) / s,
        )
    } else {
        let s = (1.0 + r[(2, 2)] - r[(0, 0)] - r[(1, 1)]).sqrt() * 2.0;
        Quaternion::new(
            (r[(1, 0)] - r[(0, 1)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
            (r[(1, 2)] + r[(2, 1)]) / s,
            0.25 * s,
        )
    };
    let q = q / q.norm();
    if q.w < 0.0 {
        -q
    } else {
        q
    }
}

/// The material frame with tangent d3 and (the part of `normal` orthogonal to d3 as) d1.
/// Returns `None` when `normal` is parallel to `tangent` or either is zero.
pub fn frame_quaternion(tangent: &Vector3<f64>, normal: &Vector3<f64>) -> Option<Quat> {
    let d3 = tangent.try_normalize(1e-300)?;
    let d1 = (normal - d3 * normal.dot(&d3)).try_normalize(1e-9 * normal.norm().max(1e-300))?;
    let d2 = d3.cross(&d1);
    Some(from_matrix(&Matrix3::from_columns(&[d1, d2, d3])))
}

/// A normal to `t` (unit), the global axis least aligned with it projected away from it.
pub fn any_normal(t: &Vector3<f64>) -> Vector3<f64> {
    let a = if t.x.abs() <= t.y.abs() && t.x.abs() <= t.z.abs() {
        Vector3::x()
    } else if t.y.abs() <= t.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    (a - t * a.dot(t)).normalize()
}

/// The smallest rotation taking unit vector `a` to unit vector `b`, as a quaternion
/// (global frame: q ⊗ a ⊗ q̄ = b). For antiparallel vectors any half turn is returned.
pub fn min_rotation(a: &Vector3<f64>, b: &Vector3<f64>) -> Quat {
    let c = a.dot(b);
    if c < -1.0 + 1e-12 {
        let n = any_normal(a);
        return Quaternion::new(0.0, n.x, n.y, n.z);
    }
    let v = a.cross(b);
    let q = Quaternion::new(1.0 + c, v.x, v.y, v.z);
    q / q.norm()
}

/// Spherical linear interpolation between unit quaternions (shortest arc).
pub fn slerp(a: &Quat, b: &Quat, t: f64) -> Quat {
    let b = if a.coords.dot(&b.coords) < 0.0 {
        -b
    } else {
        *b
    };
    let d = a.conjugate() * b;
    let out = a * exp_half(&(log_vec(&d) * t));
    out / out.norm()
}

#[cfg(test)]
mod tests {
    /// `rotate_edges` turns each moving edge as `rotate_body`, bit for bit: blocks of four in
    /// lanes, and the edge by edge rest — a still edge, a turn of 0.1 rad or more (outside
    /// exp_half's series), the tail; rotations of unit length (the quick renormalisation)
    /// and not (1/√|q|²).
    #[test]
    fn rotate_edges_is_rotate_body_bit_for_bit() {
        let mut rng = crate::modal::Rng(23);
        let mut rnd = || rng.next();
        let n = 43;
        let p_n: Vec<Quat> = (0..n)
            .map(|e| {
                let q = exp_half(&Vector3::new(rnd(), rnd(), rnd()));
                if e % 5 == 0 {
                    q * 1.01
                } else {
                    q
                }
            })
            .collect();
        let turn: Vec<Vector3<f64>> = (0..n)
            .map(|e| {
                let size = if e == 13 { 0.3 } else { 0.05 };
                Vector3::new(rnd(), rnd(), rnd()) * size
            })
            .collect();
        let moves = |e: usize| e != 6 && e != 30;
        let mut p = vec![Quat::new(9.0, 9.0, 9.0, 9.0); n];
        rotate_edges(&p_n, &turn, moves, &mut p);
        for e in 0..n {
            let want = if moves(e) {
                rotate_body(&p_n[e], &turn[e])
            } else {
                Quat::new(9.0, 9.0, 9.0, 9.0)
            };
            let same = p[e]
                .coords
                .iter()
                .zip(want.coords.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "edge {e}: {:?} vs {:?}", p[e], want);
        }
    }

    use super::*;

    #[test]
    fn matrix_round_trip_and_exp() {
        let p = exp_half(&Vector3::new(0.3, -1.2, 2.5));
        let r = rotation_matrix(&p);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14);
        let q = from_matrix(&r);
        assert!((q.coords - p.coords).norm() < 1e-13 || (q.coords + p.coords).norm() < 1e-13);
        let theta = Vector3::new(0.2, 0.1, -0.4);
        let e = rotation_matrix(&exp_half(&theta));
        // exp([θ]×) rotates θ onto itself and is a rotation by |θ|.
        assert!((e * theta - theta).norm() < 1e-15);
        assert!(((e.trace() - 1.0) / 2.0 - theta.norm().cos()).abs() < 1e-14);
        assert!((log_vec(&exp_half(&theta)) - theta).norm() < 1e-14);
    }

    #[test]
    fn right_jacobian_of_the_exponential() {
        for theta in [
            Vector3::new(0.3, -0.8, 0.5),
            Vector3::new(1e-3, 2e-3, -4e-3),
        ] {
            let jr = right_jacobian(&theta);
            let r0 = rotation_matrix(&exp_half(&theta));
            let h = 1e-6;
            for j in 0..3 {
                let mut d = Vector3::zeros();
                d[j] = h;
                // exp(θ + δ) = exp(θ) exp(J_r δ): the body rotation vector of the difference.
                let rp = rotation_matrix(&exp_half(&(theta + d)));
                let rm = rotation_matrix(&exp_half(&(theta - d)));
                let w = (r0.transpose() * (rp - rm)) / (2.0 * h);
                let fd = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
                assert!((fd - jr.column(j)).amax() < 1e-8, "{theta} col {j}");
            }
        }
    }

    #[test]
    fn exp_half_series_matches_the_closed_form() {
        for k in 0..200 {
            let a = 0.1 * (k as f64 / 200.0);
            let theta = Vector3::new(0.3, -0.8, 0.52).normalize() * a;
            let q = exp_half(&theta);
            let (s, c) = (0.5 * a).sin_cos();
            assert!((q.w - c).abs() < 2e-16, "{a}");
            assert!(
                (q.imag() - theta.normalize() * s).amax() < 2e-16 || a == 0.0,
                "{a}"
            );
            assert!((q.norm() - 1.0).abs() < 3e-16);
        }
    }

    #[test]
    fn min_rotation_maps_vectors() {
        let a = Vector3::new(1.0, 2.0, 3.0).normalize();
        let b = Vector3::new(-2.0, 0.5, 1.0).normalize();
        let r = rotation_matrix(&min_rotation(&a, &b));
        assert!((r * a - b).norm() < 1e-14);
        let r = rotation_matrix(&min_rotation(&a, &(-a)));
        assert!((r * a + a).norm() < 1e-14);
    }
}
