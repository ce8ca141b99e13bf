//! Bending/torsion element between two rotations (paper eq. 2 and the second sum of eq. 3).
//!
//! K = (2/δs) Im(p̄_a p_b) / Re(p̄_a p_b), energy ½ δs (K−K⁰)ᵀ C^K (K−K⁰), C^K = diag(EI₁, EI₂, GJ).
//! K is the relative rotation's axis times (2/δs) tan(φ/2); the axis has the same components
//! in the frames of a and b, so K and M are "the" material-frame values at the node.
//! Derivatives in θ_a, θ_b with p ← p ⊗ exp(θ/2) at θ = 0 (exact, symmetric Hessian).
use crate::rotation::Quat;
use nalgebra::{Matrix3, Matrix3x4, Matrix4, Matrix4x3, Quaternion, Vector3, Vector4};

/// Value, gradient and Hessian of one bending element.
#[derive(Clone, Debug, Default)]
pub struct BendEval {
    pub energy: f64,
    /// Curvature K (material frame): κ₁, κ₂ bending, κ₃ twist, 1/m.
    pub curvature: Vector3<f64>,
    /// Material-frame moment M = C^K (K − K⁰): M1, M2 bending, M3 torsion.
    pub moment: Vector3<f64>,
    pub grad: [Vector3<f64>; 2],
    pub hess: [[Matrix3<f64>; 2]; 2],
}

/// The relative rotation p̄_a p_b reached a half turn: the curvature is singular.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kink {
    /// Re(p̄_a p_b) / |p̄_a p_b|.
    pub cos_half_angle: f64,
}

/// Smallest |cos(φ/2)| accepted, φ the rotation between neighbouring edges (φ < 179.9°).
pub const MIN_COS_HALF: f64 = 1e-3;

#[inline]
fn pure(i: usize) -> Quat {
    let mut v = Vector3::zeros();
    v[i] = 1.0;
    Quaternion::from_imag(v)
}

/// Curvature of two rotations over the cell length `w`.
#[inline]
pub fn curvature(pa: &Quat, pb: &Quat, w: f64) -> Result<Vector3<f64>, Kink> {
    let q = pa.conjugate() * pb;
    if q.w.abs() < MIN_COS_HALF * q.norm() {
        return Err(Kink {
            cos_half_angle: q.w / q.norm(),
        });
    }
    Ok(q.imag() * (2.0 / (w * q.w)))
}

/// Curvature K of a bending cell and its derivatives with respect to θ_a, θ_b.
#[derive(Clone, Copy, Debug)]
pub struct BendKinematics {
    pub w: f64,
    /// q = p̄_a p_b.
    q: Quat,
    /// K (not reduced by K⁰).
    pub curvature: Vector3<f64>,
    dkdq: Matrix3x4<f64>,
    qa: Matrix4x3<f64>,
    qb: Matrix4x3<f64>,
    /// ∂K/∂θ_a, ∂K/∂θ_b.
    pub ja: Matrix3<f64>,
    pub jb: Matrix3<f64>,
}

impl BendKinematics {
    pub fn new(pa: &Quat, pb: &Quat, w: f64) -> Result<Self, Kink> {
        let q = pa.conjugate() * pb;
        let s = q.w;
        if s.abs() < MIN_COS_HALF * q.norm() {
            return Err(Kink {
                cos_half_angle: s / q.norm(),
            });
        }
        let v = q.imag();
        let c2 = 2.0 / w;
        // ∂K/∂q, columns (s, v1, v2, v3).
        let mut dkdq = Matrix3x4::zeros();
        dkdq.set_column(0, &(-v * (c2 / (s * s))));
        for i in 0..3 {
            dkdq[(i, i + 1)] = c2 / s;
        }
        // ∂q/∂θ_a = −½ ε_j ⊗ q, ∂q/∂θ_b = ½ q ⊗ ε_j (columns j).
        let mut qa = Matrix4x3::zeros();
        let mut qb = Matrix4x3::zeros();
        for j in 0..3 {
            let a = pure(j) * q * -0.5;
            let b = q * pure(j) * 0.5;
            qa.set_column(j, &Vector4::new(a.w, a.i, a.j, a.k));
            qb.set_column(j, &Vector4::new(b.w, b.i, b.j, b.k));
        }
        Ok(BendKinematics {
            w,
            q,
            curvature: v * (c2 / s),
            dkdq,
            qa,
            qb,
            ja: dkdq * qa,
            jb: dkdq * qb,
        })
    }

    /// K̇ for the body angular velocities ω_a, ω_b.
    pub fn rate(&self, omega_a: &Vector3<f64>, omega_b: &Vector3<f64>) -> Vector3<f64> {
        self.ja * omega_a + self.jb * omega_b
    }

    /// Generalised moments w Jᵀ m of the section moment m on (θ_a, θ_b).
    pub fn forces(&self, m: &Vector3<f64>) -> [Vector3<f64>; 2] {
        [
            self.w * self.ja.transpose() * m,
            self.w * self.jb.transpose() * m,
        ]
    }

    /// w Jᵀ C J for a diagonal C (stiffness or viscous damping).
    pub fn gauss_newton(&self, c: &Vector3<f64>) -> [[Matrix3<f64>; 2]; 2] {
        let c = Matrix3::from_diagonal(c);
        let (ja, jb) = (self.ja, self.jb);
        let ab = self.w * ja.transpose() * c * jb;
        [
            [self.w * ja.transpose() * c * ja, ab],
            [ab.transpose(), self.w * jb.transpose() * c * jb],
        ]
    }

    /// Σ_k m_k w ∇²K_k: the geometric stiffness of the section moment m.
    pub fn geometric(&self, m: &Vector3<f64>) -> [[Matrix3<f64>; 2]; 2] {
        let (s, v) = (self.q.w, self.q.imag());
        let c2 = 2.0 / self.w;
        // Σ_k m_k ∂²K_k/∂q² (K = (2/w) v/s: only the s-s and s-v entries are non-zero).
        let mut sqq = Matrix4::zeros();
        sqq[(0, 0)] = c2 * 2.0 * m.dot(&v) / (s * s * s);
        for j in 0..3 {
            sqq[(0, j + 1)] = -c2 * m[j] / (s * s);
            sqq[(j + 1, 0)] = sqq[(0, j + 1)];
        }
        // λ = (∂K/∂q)ᵀ m with the second derivatives of q: aa and bb are −q/4 δij, which
        // contract with λ to zero (K is homogeneous of degree 0 in q); ab is −¼ ε_i ⊗ q ⊗ ε_j.
        let lambda = self.dkdq.transpose() * m;
        let mut tab = Matrix3::zeros();
        for i in 0..3 {
            let left = pure(i) * self.q;
            for j in 0..3 {
                let d = left * pure(j);
                tab[(i, j)] = -0.25 * lambda.dot(&Vector4::new(d.w, d.i, d.j, d.k));
            }
        }
        let (qa, qb, w) = (self.qa, self.qb, self.w);
        let ab = w * (qa.transpose() * sqq * qb + tab);
        [
            [w * qa.transpose() * sqq * qa, ab],
            [ab.transpose(), w * qb.transpose() * sqq * qb],
        ]
    }
}

/// Evaluates the element (static: m = C^K(K − K⁰)); the Hessian only when `want_hess`.
#[allow(clippy::too_many_arguments)]
pub fn bend_element(
    pa: &Quat,
    pb: &Quat,
    w: f64,
    stiffness: &Vector3<f64>,
    curvature0: &Vector3<f64>,
    want_hess: bool,
    out: &mut BendEval,
) -> Result<(), Kink> {
    let kin = BendKinematics::new(pa, pb, w)?;
    let dk = kin.curvature - curvature0;
    let m = stiffness.component_mul(&dk);
    out.energy = 0.5 * w * dk.dot(&m);
    out.curvature = kin.curvature;
    out.moment = m;
    out.grad = kin.forces(&m);
    if want_hess {
        let gn = kin.gauss_newton(stiffness);
        let geo = kin.geometric(&m);
        for i in 0..2 {
            for j in 0..2 {
                out.hess[i][j] = gn[i][j] + geo[i][j];
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp_half, rotate_body};

    const K: [f64; 3] = [0.02, 0.03, 0.015];

    /// The element about a fixed base state, rotated by z = (θ_a, θ_b).
    fn eval_at(z: &[f64; 6], want_hess: bool) -> BendEval {
        let pa = rotate_body(
            &exp_half(&Vector3::new(0.3, 0.2, -0.5)),
            &Vector3::new(z[0], z[1], z[2]),
        );
        let pb = rotate_body(
            &exp_half(&Vector3::new(0.45, 0.1, -0.3)),
            &Vector3::new(z[3], z[4], z[5]),
        );
        let mut e = BendEval::default();
        let k0 = Vector3::new(1.0, 0.0, 0.5);
        bend_element(&pa, &pb, 0.05, &Vector3::from(K), &k0, want_hess, &mut e).unwrap();
        e
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let e = eval_at(&[0.0; 6], true);
        crate::fd_check::check_derivatives::<6>(
            |z| eval_at(z, false).energy,
            |i| e.grad[i / 3][i % 3],
            |i, j| e.hess[i / 3][j / 3][(i % 3, j % 3)],
        );
    }

    #[test]
    fn curvature_of_a_uniform_bend_and_kink_error() {
        // Two edges rotated by φ about d1 over a cell w: K = (2/w) tan(φ/2) e1.
        let phi: f64 = 0.2;
        let w = 0.1;
        let pb = exp_half(&Vector3::new(phi, 0.0, 0.0));
        let k = curvature(&Quat::identity(), &pb, w).unwrap();
        assert!((k - Vector3::new(2.0 / w * (phi / 2.0).tan(), 0.0, 0.0)).norm() < 1e-13);
        // Invariant under the sign of p_b.
        assert!((curvature(&Quat::identity(), &(-pb), w).unwrap() - k).norm() < 1e-13);
        let half_turn = exp_half(&Vector3::new(std::f64::consts::PI, 0.0, 0.0));
        assert!(curvature(&Quat::identity(), &half_turn, w).is_err());
    }
}
