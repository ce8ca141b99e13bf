//! Bending/torsion element between two rotations (paper eq. 2 and the second sum of eq. 3).
//!
//! K = (2/δs) Im(p̄_a p_b) / Re(p̄_a p_b), energy ½ δs (K−K⁰)ᵀ C^K (K−K⁰), C^K = diag(EI₁, EI₂, GJ).
//! K is the relative rotation's axis times (2/δs) tan(φ/2); the axis has the same components
//! in the frames of a and b, so K and M are "the" material-frame values at the node.
//! Derivatives in θ_a, θ_b with p ← p ⊗ exp(θ/2) at θ = 0 (exact, symmetric Hessian).
use crate::rotation::{skew, Quat};
use crate::shear::scale_rows;
use nalgebra::{Matrix3, Vector3};

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

/// Curvature K of a bending cell and its derivatives with respect to θ_a, θ_b, in closed form
/// through the Gibbs vector g = Im(q)/Re(q) of q = p̄_a p_b (K = (2/w) g):
/// ∂K/∂θ_a = A/w, ∂K/∂θ_b = B/w with A = −I + [g]× − g gᵀ and B = −Aᵀ = I + [g]× + g gᵀ.
#[derive(Clone, Copy, Debug)]
pub struct BendKinematics {
    pub w: f64,
    /// 1/w.
    pub inv_w: f64,
    /// Gibbs vector g = tan(φ/2)·axis of the relative rotation.
    pub g: Vector3<f64>,
    /// K (not reduced by K⁰).
    pub curvature: Vector3<f64>,
}

impl BendKinematics {
    #[inline]
    pub fn new(pa: &Quat, pb: &Quat, w: f64) -> Result<Self, Kink> {
        let q = pa.conjugate() * pb;
        let s = q.w;
        let nv = q.imag().norm_squared();
        if s * s < MIN_COS_HALF * MIN_COS_HALF * (s * s + nv) {
            return Err(Kink {
                cos_half_angle: s / (s * s + nv).sqrt(),
            });
        }
        let g = q.imag() * (1.0 / s);
        let inv_w = 1.0 / w;
        Ok(BendKinematics {
            w,
            inv_w,
            g,
            curvature: g * (2.0 * inv_w),
        })
    }

    /// A = w ∂K/∂θ_a.
    #[inline]
    pub fn a(&self) -> Matrix3<f64> {
        let g = &self.g;
        skew(g) - Matrix3::identity() - g * g.transpose()
    }

    /// B = w ∂K/∂θ_b = −Aᵀ.
    #[inline]
    pub fn b(&self) -> Matrix3<f64> {
        let g = &self.g;
        skew(g) + Matrix3::identity() + g * g.transpose()
    }

    /// ∂K/∂θ_a, ∂K/∂θ_b.
    pub fn jacobians(&self) -> (Matrix3<f64>, Matrix3<f64>) {
        (self.a() * self.inv_w, self.b() * self.inv_w)
    }

    /// K̇ for the body angular velocities ω_a, ω_b.
    #[inline]
    pub fn rate(&self, omega_a: &Vector3<f64>, omega_b: &Vector3<f64>) -> Vector3<f64> {
        let d = omega_b - omega_a;
        (d + self.g.cross(&(omega_a + omega_b)) + self.g * self.g.dot(&d)) * self.inv_w
    }

    /// Generalised moments w Jᵀ m of the section moment m on (θ_a, θ_b).
    #[inline]
    pub fn forces(&self, m: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let gm = self.g.cross(m);
        let proj = self.g * self.g.dot(m);
        [-m - gm - proj, m - gm + proj]
    }

    /// Σ_k m_k w ∇²K_k: the geometric stiffness of the section moment m (the symmetric
    /// second derivative in θ_a, θ_b, from the composition of Gibbs vectors).
    pub fn geometric(&self, m: &Vector3<f64>) -> [[Matrix3<f64>; 2]; 2] {
        let g = &self.g;
        let mg = m.dot(g);
        let ggt = g * g.transpose();
        let sym = |x: Matrix3<f64>| 0.5 * (x + x.transpose());
        let haa = sym((m + g.cross(m)) * g.transpose()) + mg * ggt;
        let hbb = sym((m + m.cross(g)) * g.transpose()) + mg * ggt;
        let xab = (g * m.transpose() - skew(m) + Matrix3::identity() * mg) * self.b();
        let ab = -0.5 * xab;
        [[haa, ab], [ab.transpose(), hbb]]
    }

    /// ∂K̇/∂θ_a, ∂K̇/∂θ_b at fixed angular velocities (K̇ depends on the configuration
    /// through g).
    pub fn rate_derivative(
        &self,
        omega_a: &Vector3<f64>,
        omega_b: &Vector3<f64>,
    ) -> [Matrix3<f64>; 2] {
        let d = omega_b - omega_a;
        let g = &self.g;
        let e = (Matrix3::identity() * g.dot(&d) + g * d.transpose() - skew(&(omega_a + omega_b)))
            * (0.5 * self.inv_w);
        [e * self.a(), e * self.b()]
    }
}

/// Kelvin–Voigt damping of a bending cell in a dynamic Jacobian (see `ShearViscous`).
#[derive(Clone, Copy, Debug)]
pub struct BendViscous {
    pub coeff: Vector3<f64>,
    pub factor: f64,
    /// Whether rotation a (b) has a tracked rate (a free edge).
    pub rate_a: bool,
    pub rate_b: bool,
    pub omega_a: Vector3<f64>,
    pub omega_b: Vector3<f64>,
    /// J_r of the rotations' increments in the step (see `ShearViscous::tangent`).
    pub tangent_a: Option<Matrix3<f64>>,
    pub tangent_b: Option<Matrix3<f64>>,
}

impl BendKinematics {
    /// The derivative of the generalised moments w Jᵀ m, m = C(K − K⁰) (+ τ∘C K̇), along the
    /// Newton update (without the rotation-group correction ½[g]×): w Jᵀ P + geometric(m) with
    /// P = C J + τ∘C (c J + G) on the rate unknowns, G = ∂K̇/∂θ, the configuration part of each
    /// column times the tangent J_r of its rotation's step. Blocks [[aa, ab], [ba, bb]].
    pub fn jacobian(
        &self,
        m: &Vector3<f64>,
        c: &Vector3<f64>,
        viscous: Option<&BendViscous>,
    ) -> [[Matrix3<f64>; 2]; 2] {
        let (a, b) = (self.a(), self.b());
        let inv_w = self.inv_w;
        let geo = self.geometric(m);
        let (at, bt) = (a.transpose(), b.transpose());
        let mut pa = scale_rows(&(c * inv_w), &a);
        let mut pb = scale_rows(&(c * inv_w), &b);
        let Some(v) = viscous else {
            return [
                [at * pa + geo[0][0], at * pb + geo[0][1]],
                [bt * pa + geo[1][0], bt * pb + geo[1][1]],
            ];
        };
        let g = self.rate_derivative(&v.omega_a, &v.omega_b);
        pa += scale_rows(&v.coeff, &g[0]);
        pb += scale_rows(&v.coeff, &g[1]);
        // Configuration part (× J_r of the rotation's step), then the rate part.
        let mut col_a = [at * pa + geo[0][0], bt * pa + geo[1][0]];
        let mut col_b = [at * pb + geo[0][1], bt * pb + geo[1][1]];
        for (col, jr) in [(&mut col_a, v.tangent_a), (&mut col_b, v.tangent_b)] {
            if let Some(jr) = jr {
                col[0] *= jr;
                col[1] *= jr;
            }
        }
        let rate = v.coeff * (v.factor * inv_w);
        if v.rate_a {
            let ra = scale_rows(&rate, &a);
            col_a[0] += at * ra;
            col_a[1] += bt * ra;
        }
        if v.rate_b {
            let rb = scale_rows(&rate, &b);
            col_b[0] += at * rb;
            col_b[1] += bt * rb;
        }
        [[col_a[0], col_b[0]], [col_a[1], col_b[1]]]
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
        out.hess = kin.jacobian(&m, stiffness, None);
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
    fn curvature_rate_and_its_configuration_derivative_match_finite_differences() {
        let base_a = exp_half(&Vector3::new(0.3, 0.2, -0.5));
        let base_b = exp_half(&Vector3::new(0.45, 0.1, -0.3));
        let (wa, wb) = (Vector3::new(0.7, -1.1, 0.4), Vector3::new(-0.2, 0.9, 1.3));
        let w = 0.05;
        let kin_at = |z: &[f64; 6]| {
            let pa = rotate_body(&base_a, &Vector3::new(z[0], z[1], z[2]));
            let pb = rotate_body(&base_b, &Vector3::new(z[3], z[4], z[5]));
            BendKinematics::new(&pa, &pb, w).unwrap()
        };
        let kin = kin_at(&[0.0; 6]);
        let (ja, jb) = kin.jacobians();
        let g = kin.rate_derivative(&wa, &wb);
        let h = 1e-6;
        let scale_j = ja.amax().max(jb.amax());
        let scale_g = g[0].amax().max(g[1].amax());
        for i in 0..6 {
            let mut zp = [0.0; 6];
            let mut zm = [0.0; 6];
            zp[i] = h;
            zm[i] = -h;
            let (kp, km) = (kin_at(&zp), kin_at(&zm));
            // K along the coordinate: the columns of ∂K/∂θ.
            let dk = (kp.curvature - km.curvature) / (2.0 * h);
            let an_j = if i < 3 {
                ja.column(i)
            } else {
                jb.column(i - 3)
            };
            assert!((dk - an_j).amax() < 1e-6 * scale_j, "∂K/∂θ col {i}");
            // K̇ at fixed ω along the coordinate.
            let dr = (kp.rate(&wa, &wb) - km.rate(&wa, &wb)) / (2.0 * h);
            let an = if i < 3 {
                g[0].column(i)
            } else {
                g[1].column(i - 3)
            };
            assert!(
                (dr - an).amax() < 1e-6 * scale_g,
                "∂K̇/∂θ col {i}: fd {dr} analytic {an}"
            );
        }
        // K̇ is ∂K/∂θ ω.
        assert!((kin.rate(&wa, &wb) - (ja * wa + jb * wb)).amax() < 1e-12 * scale_j);
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
