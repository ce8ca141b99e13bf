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

/// Strain Γ − Γ⁰ of an edge and its derivatives: the pieces from which forces, stiffness
/// and viscous damping are assembled (static and dynamic alike).
#[derive(Clone, Copy, Debug)]
pub struct ShearKinematics {
    pub ds: f64,
    /// R(p).
    pub r: Matrix3<f64>,
    /// u = Rᵀ (x_b − x_a)/Δs.
    pub u: Vector3<f64>,
    /// Γ − Γ⁰.
    pub strain: Vector3<f64>,
}

impl ShearKinematics {
    pub fn new(
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        p: &Quat,
        ds: f64,
        strain0: &Vector3<f64>,
    ) -> Self {
        let r = rotation_matrix(p);
        let u = r.transpose() * ((xb - xa) / ds);
        ShearKinematics {
            ds,
            r,
            u,
            strain: u - Vector3::z() - strain0,
        }
    }

    /// Γ̇ for the velocities ẋ_a, ẋ_b (global) and ω (body frame): dΓ = Rᵀ(dx_b − dx_a)/Δs + [u]× θ.
    pub fn rate(&self, va: &Vector3<f64>, vb: &Vector3<f64>, omega: &Vector3<f64>) -> Vector3<f64> {
        self.r.transpose() * ((vb - va) / self.ds) + self.u.cross(omega)
    }

    /// Generalised forces Δs Jᵀ f of the section force f (material frame) on (x_a, x_b, θ).
    pub fn forces(&self, f: &Vector3<f64>) -> [Vector3<f64>; 3] {
        let rf = self.r * f;
        [-rf, rf, self.ds * f.cross(&self.u)]
    }

    /// Δs Jᵀ C J for a diagonal C: the stiffness (C = C^Γ) or viscous damping (C = τC^Γ) blocks.
    pub fn gauss_newton(&self, c: &Vector3<f64>) -> [[Matrix3<f64>; 3]; 3] {
        let c = Matrix3::from_diagonal(c);
        let su = skew(&self.u);
        let kxx = self.r * c * self.r.transpose() / self.ds;
        let kxt = self.r * c * su;
        let ktt = -self.ds * su * c * su;
        [
            [kxx, -kxx, -kxt],
            [-kxx, kxx, kxt],
            [-kxt.transpose(), kxt.transpose(), ktt],
        ]
    }

    /// Σ_k f_k Δs ∇²Γ_k: the geometric stiffness of the section force f.
    pub fn geometric(&self, f: &Vector3<f64>) -> [[Matrix3<f64>; 3]; 3] {
        let z = Matrix3::zeros();
        let kxt = -self.r * skew(f);
        let ktt = self.ds
            * (0.5 * (f * self.u.transpose() + self.u * f.transpose())
                - Matrix3::identity() * f.dot(&self.u));
        [
            [z, z, -kxt],
            [z, z, kxt],
            [-kxt.transpose(), kxt.transpose(), ktt],
        ]
    }
}

/// Evaluates the element (static: f = C^Γ(Γ − Γ⁰)); the Hessian only when `want_hess`.
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
    let kin = ShearKinematics::new(xa, xb, p, ds, strain0);
    let f = stiffness.component_mul(&kin.strain);
    out.energy = 0.5 * ds * kin.strain.dot(&f);
    out.strain = kin.strain;
    out.force = f;
    out.grad = kin.forces(&f);
    if want_hess {
        let gn = kin.gauss_newton(stiffness);
        let geo = kin.geometric(&f);
        for i in 0..3 {
            for j in 0..3 {
                out.hess[i][j] = gn[i][j] + geo[i][j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp_half, rotate_body};

    /// The element about a fixed base state, moved by z = (x_a, x_b, θ).
    fn eval_at(z: &[f64; 9], want_hess: bool) -> ShearEval {
        let xa = Vector3::new(0.1, -0.2, 0.05) + Vector3::new(z[0], z[1], z[2]);
        let xb = Vector3::new(0.13, -0.17, 0.14) + Vector3::new(z[3], z[4], z[5]);
        let p = rotate_body(
            &exp_half(&Vector3::new(0.4, -0.3, 0.9)),
            &Vector3::new(z[6], z[7], z[8]),
        );
        let (k, strain0) = (
            Vector3::new(3.0e3, 2.0e3, 1.0e4),
            Vector3::new(0.01, 0.0, -0.02),
        );
        let mut e = ShearEval::default();
        shear_element(&xa, &xb, &p, 0.1, &k, &strain0, want_hess, &mut e);
        e
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let e = eval_at(&[0.0; 9], true);
        crate::fd_check::check_derivatives::<9>(
            |z| eval_at(z, false).energy,
            |i| e.grad[i / 3][i % 3],
            |i, j| e.hess[i / 3][j / 3][(i % 3, j % 3)],
        );
    }
}
