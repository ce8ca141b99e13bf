//! Shear/extension element of one edge (paper eq. 1 and the first sum of eq. 3).
//!
//! Γ = R(p)ᵀ (x_b − x_a)/Δs − e3, energy ½ Δs (Γ−Γ⁰)ᵀ C^Γ (Γ−Γ⁰), C^Γ = diag(GA₁, GA₂, EA).
//! Derivatives are taken in the coordinates (x_a, x_b, θ) with p ← p ⊗ exp(θ/2) at θ = 0;
//! the Hessian is the exact second derivative in these coordinates (symmetric).
use crate::rotation::{rotation_matrix, skew, Quat};
use nalgebra::{Matrix3, Vector3};

/// Value, gradient and Hessian of one shear element.
#[derive(Clone, Debug, Default)]
pub struct ShearEval {
    pub energy: f64,
    /// Γ − Γ⁰ in the material frame.
    pub strain: Vector3<f64>,
    /// Material-frame section force F = C^Γ (Γ − Γ⁰): F1, F2 shear, F3 tension.
    pub force: Vector3<f64>,
    /// Gradient with respect to x_a, x_b (global) and θ (body frame).
    pub grad: [Vector3<f64>; 3],
    /// Hessian blocks [i][j] for the variables (x_a, x_b, θ).
    pub hess: [[Matrix3<f64>; 3]; 3],
}

/// Γ − Γ⁰ of an edge.
#[inline]
pub fn shear_strain(
    xa: &Vector3<f64>,
    xb: &Vector3<f64>,
    p: &Quat,
    ds: f64,
    strain0: &Vector3<f64>,
) -> Vector3<f64> {
    let r = rotation_matrix(p);
    r.transpose() * ((xb - xa) / ds) - Vector3::z() - strain0
}

/// Evaluates the element; the Hessian only when `want_hess`.
#[allow(clippy::too_many_arguments)]
pub fn shear_element(
    xa: &Vector3<f64>,
    xb: &Vector3<f64>,
    p: &Quat,
    ds: f64,
    stiffness: &Vector3<f64>,
    strain0: &Vector3<f64>,
    want_hess: bool,
    out: &mut ShearEval,
) {
    let r = rotation_matrix(p);
    let u = r.transpose() * ((xb - xa) / ds); // u = Rᵀ v
    let gamma = u - Vector3::z() - strain0;
    let f = stiffness.component_mul(&gamma);
    out.energy = 0.5 * ds * gamma.dot(&f);
    out.strain = gamma;
    out.force = f;
    let rf = r * f;
    out.grad[0] = -rf;
    out.grad[1] = rf;
    out.grad[2] = ds * f.cross(&u);
    if !want_hess {
        return;
    }
    let c = Matrix3::from_diagonal(stiffness);
    let su = skew(&u);
    let kxx = r * c * r.transpose() / ds;
    let kxt = r * (c * su - skew(&f));
    let ktt = ds
        * (-su * c * su + 0.5 * (f * u.transpose() + u * f.transpose())
            - Matrix3::identity() * f.dot(&u));
    out.hess[0][0] = kxx;
    out.hess[1][1] = kxx;
    out.hess[0][1] = -kxx;
    out.hess[1][0] = -kxx;
    out.hess[1][2] = kxt;
    out.hess[0][2] = -kxt;
    out.hess[2][1] = kxt.transpose();
    out.hess[2][0] = -kxt.transpose();
    out.hess[2][2] = ktt;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp_half, rotate_body};

    fn energy(xa: &Vector3<f64>, xb: &Vector3<f64>, p: &Quat) -> f64 {
        let mut e = ShearEval::default();
        let k = Vector3::new(3.0e3, 2.0e3, 1.0e4);
        shear_element(
            xa,
            xb,
            p,
            0.1,
            &k,
            &Vector3::new(0.01, 0.0, -0.02),
            false,
            &mut e,
        );
        e.energy
    }

    /// Energy as a function of the 9 coordinates (x_a, x_b, θ) about a base state.
    fn energy_at(z: &[f64; 9]) -> f64 {
        let xa = Vector3::new(0.1, -0.2, 0.05) + Vector3::new(z[0], z[1], z[2]);
        let xb = Vector3::new(0.13, -0.17, 0.14) + Vector3::new(z[3], z[4], z[5]);
        let p0 = exp_half(&Vector3::new(0.4, -0.3, 0.9));
        let p = rotate_body(&p0, &Vector3::new(z[6], z[7], z[8]));
        energy(&xa, &xb, &p)
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let xa = Vector3::new(0.1, -0.2, 0.05);
        let xb = Vector3::new(0.13, -0.17, 0.14);
        let p = exp_half(&Vector3::new(0.4, -0.3, 0.9));
        let mut e = ShearEval::default();
        let k = Vector3::new(3.0e3, 2.0e3, 1.0e4);
        shear_element(
            &xa,
            &xb,
            &p,
            0.1,
            &k,
            &Vector3::new(0.01, 0.0, -0.02),
            true,
            &mut e,
        );
        let h = 1e-6;
        let scale = e.grad.iter().map(|g| g.amax()).fold(0.0, f64::max);
        for i in 0..9 {
            let mut zp = [0.0; 9];
            let mut zm = [0.0; 9];
            zp[i] = h;
            zm[i] = -h;
            let fd = (energy_at(&zp) - energy_at(&zm)) / (2.0 * h);
            let an = e.grad[i / 3][i % 3];
            assert!(
                (fd - an).abs() < 1e-6 * scale,
                "grad {i}: fd {fd} analytic {an}"
            );
        }
        let h = 1e-4;
        let hscale = e
            .hess
            .iter()
            .flatten()
            .map(|m| m.amax())
            .fold(0.0, f64::max);
        for i in 0..9 {
            for j in 0..9 {
                let f = |si: f64, sj: f64| {
                    let mut z = [0.0; 9];
                    z[i] += si * h;
                    z[j] += sj * h;
                    energy_at(&z)
                };
                let fd =
                    (f(1.0, 1.0) - f(1.0, -1.0) - f(-1.0, 1.0) + f(-1.0, -1.0)) / (4.0 * h * h);
                let an = e.hess[i / 3][j / 3][(i % 3, j % 3)];
                assert!(
                    (fd - an).abs() < 1e-5 * hscale,
                    "hess {i},{j}: fd {fd} analytic {an}"
                );
            }
        }
    }
}
