//! Shear/extension element of one edge (paper eq. 1 and the first sum of eq. 3).
//!
//! Γ = R(p)ᵀ (x_b − x_a)/Δs − e3, energy ½ Δs (Γ−Γ⁰)ᵀ C^Γ (Γ−Γ⁰), C^Γ = diag(GA₁, GA₂, EA).
//! Derivatives are taken in the coordinates (x_a, x_b, θ) with p ← p ⊗ exp(θ/2) at θ = 0;
//! the Hessian is the exact second derivative in these coordinates (symmetric).
use crate::rotation::{rotation_matrix, skew, Quat};
use crate::simd::{lanes, splat};
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

/// Γ = Rᵀ (x_b − x_a)/Δs − e3 of a saved state: the edge's rotation given by a quaternion
/// (w, u) of any length, Rᵀ v = v + k (u × (u × v) − w u × v) with k = 2/|p|² (the rotation
/// matrix is never formed). The validity scan of results (axial and shear strains).
#[inline]
pub fn saved_strain(
    xa: &Vector3<f64>,
    xb: &Vector3<f64>,
    w: f64,
    u: &Vector3<f64>,
    inv_ds: f64,
) -> Vector3<f64> {
    let k = 2.0 / (w * w + u.norm_squared());
    let v = (xb - xa) * inv_ds;
    let c = u.cross(&v);
    v + k * (u.cross(&c) - w * c) - Vector3::z()
}

/// The largest value of a scan and where it is (saved step, edge).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extreme {
    pub value: f64,
    pub step: usize,
    pub edge: usize,
}

impl Extreme {
    /// Takes (value, step, edge) if it is the scan's new largest: the first of equal values,
    /// and the first NaN over any number (numpy's `argmax`, so a NaN in a result is reported).
    #[inline]
    fn offer(slot: &mut Option<Extreme>, value: f64, step: usize, edge: usize) {
        let take = match slot {
            None => true,
            Some(e) => !e.value.is_nan() && (value.is_nan() || value > e.value),
        };
        if take {
            *slot = Some(Extreme { value, step, edge });
        }
    }

    /// `offer` of a saved step's values by edge, scanned only where one of them could be
    /// taken: none yet, or one above the largest so far, or a NaN (unless that is a NaN
    /// already). The test pass has no early exit, so that it vectorises.
    fn offer_step(
        slot: &mut Option<Extreme>,
        values: impl Iterator<Item = f64> + Clone,
        step: usize,
    ) {
        if let Some(b) = slot {
            let above = |any: bool, v: f64| any | (v > b.value || v.is_nan());
            if b.value.is_nan() || !values.clone().fold(false, above) {
                return;
            }
        }
        for (edge, value) in values.enumerate() {
            Extreme::offer(slot, value, step, edge);
        }
    }
}

/// Axial strain Γ₃ and shear strain |(Γ₁, Γ₂)| of every edge at one saved step: positions
/// `x` (N + 1, 3) and quaternions `p` (N, 4, scalar first, any length) row-major, `inv_ds`
/// 1/Δs per edge (N), into `axial` and `shear` (N).
///
/// Four edges at a time in f64x4 lanes (`wide`), each lane with the operations of
/// `saved_strain` in its order: the same values to the last bit.
pub fn saved_step_strains(
    x: &[f64],
    p: &[f64],
    inv_ds: &[f64],
    axial: &mut [f64],
    shear: &mut [f64],
) {
    let n = inv_ds.len();
    let full = n - n % 4;
    for e0 in (0..full).step_by(4) {
        let w = lanes(|l| p[4 * (e0 + l)]);
        let (ux, uy, uz) = (
            lanes(|l| p[4 * (e0 + l) + 1]),
            lanes(|l| p[4 * (e0 + l) + 2]),
            lanes(|l| p[4 * (e0 + l) + 3]),
        );
        let inv = lanes(|l| inv_ds[e0 + l]);
        let k = splat(2.0) / (w * w + (ux * ux + uy * uy + uz * uz));
        let d =
            |i: usize| (lanes(|l| x[3 * (e0 + l + 1) + i]) - lanes(|l| x[3 * (e0 + l) + i])) * inv;
        let (vx, vy, vz) = (d(0), d(1), d(2));
        // c = u × v, then u × c
        let (cx, cy, cz) = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx);
        let (ex, ey, ez) = (uy * cz - uz * cy, uz * cx - ux * cz, ux * cy - uy * cx);
        // v + k (u × c − w c) − e₃ (x − 0 is x to the last bit)
        let gx = vx + k * (ex - w * cx);
        let gy = vy + k * (ey - w * cy);
        let gz = vz + k * (ez - w * cz) - splat(1.0);
        axial[e0..e0 + 4].copy_from_slice(&gz.to_array());
        shear[e0..e0 + 4].copy_from_slice(&(gx * gx + gy * gy).sqrt().to_array());
    }
    let tail = inv_ds.iter().zip(axial.iter_mut().zip(shear)).enumerate();
    for (e, (inv, (ax, sh))) in tail.skip(full) {
        let at = |i: usize| Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        let q = &p[4 * e..4 * e + 4];
        let g = saved_strain(
            &at(e),
            &at(e + 1),
            q[0],
            &Vector3::new(q[1], q[2], q[3]),
            *inv,
        );
        *ax = g.z;
        *sh = (g.x * g.x + g.y * g.y).sqrt();
    }
}

/// The validity scan of a saved run in one pass, without the strain arrays: the largest
/// axial strain Γ₃, the largest compression (−Γ₃) and the largest shear strain |(Γ₁, Γ₂)|
/// over the steps and edges, each with where it is (the first of equal values; a NaN
/// counts as largest). `positions`: (T, N + 1, 3) and `quaternions` (T, N, 4, scalar first,
/// any length) row-major; `inv_ds`: 1/Δs per edge (N). None for no steps or no edges.
pub fn saved_strain_extremes(
    positions: &[f64],
    quaternions: &[f64],
    inv_ds: &[f64],
) -> Option<[Extreme; 3]> {
    let n = inv_ds.len();
    if n == 0 {
        return None;
    }
    let steps = quaternions.len() / (4 * n);
    assert_eq!(
        positions.len(),
        steps * 3 * (n + 1),
        "positions (T, N + 1, 3)"
    );
    assert_eq!(quaternions.len(), steps * 4 * n, "quaternions (T, N, 4)");
    let mut best = [None; 3];
    // per step the strains of all edges first (a loop free of branches), then the scans
    let (mut axial, mut shear) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..steps {
        let x = &positions[k * 3 * (n + 1)..(k + 1) * 3 * (n + 1)];
        let p = &quaternions[k * 4 * n..(k + 1) * 4 * n];
        saved_step_strains(x, p, inv_ds, &mut axial, &mut shear);
        Extreme::offer_step(&mut best[0], axial.iter().copied(), k);
        Extreme::offer_step(&mut best[1], axial.iter().map(|a| -a), k);
        Extreme::offer_step(&mut best[2], shear.iter().copied(), k);
    }
    match best {
        [Some(a), Some(c), Some(s)] => Some([a, c, s]),
        _ => None,
    }
}

/// Strain Γ − Γ⁰ of an edge and its derivatives: the pieces from which forces, stiffness
/// and viscous damping are assembled (static and dynamic alike).
#[derive(Clone, Copy, Debug)]
pub struct ShearKinematics {
    pub ds: f64,
    /// 1/Δs.
    pub inv_ds: f64,
    /// R(p).
    pub r: Matrix3<f64>,
    /// u = Rᵀ (x_b − x_a)/Δs.
    pub u: Vector3<f64>,
    /// Γ − Γ⁰.
    pub strain: Vector3<f64>,
}

impl ShearKinematics {
    #[inline]
    pub fn new(
        xa: &Vector3<f64>,
        xb: &Vector3<f64>,
        p: &Quat,
        ds: f64,
        strain0: &Vector3<f64>,
    ) -> Self {
        let r = rotation_matrix(p);
        let inv_ds = 1.0 / ds;
        let u = r.transpose() * ((xb - xa) * inv_ds);
        ShearKinematics {
            ds,
            inv_ds,
            r,
            u,
            strain: u - Vector3::z() - strain0,
        }
    }

    /// Γ̇ for the velocities ẋ_a, ẋ_b (global) and ω (body frame): dΓ = Rᵀ(dx_b − dx_a)/Δs + [u]× θ.
    #[inline]
    pub fn rate(&self, va: &Vector3<f64>, vb: &Vector3<f64>, omega: &Vector3<f64>) -> Vector3<f64> {
        self.r.transpose() * ((vb - va) * self.inv_ds) + self.u.cross(omega)
    }

    /// ∂Γ̇/∂(x_a, x_b, θ) at fixed velocities: the strain rate J v depends on the configuration
    /// through R and u (Γ̇ = Rᵀ(v_b − v_a)/Δs + u × ω).
    pub fn rate_derivative(
        &self,
        va: &Vector3<f64>,
        vb: &Vector3<f64>,
        omega: &Vector3<f64>,
    ) -> [Matrix3<f64>; 3] {
        let wx = skew(omega);
        let g = wx * self.r.transpose() * self.inv_ds;
        let w = self.r.transpose() * ((vb - va) * self.inv_ds);
        [g, -g, skew(&w) - wx * skew(&self.u)]
    }

    /// Generalised forces Δs Jᵀ f of the section force f (material frame) on (x_a, x_b, θ).
    pub fn forces(&self, f: &Vector3<f64>) -> [Vector3<f64>; 3] {
        let rf = self.r * f;
        [-rf, rf, self.ds * f.cross(&self.u)]
    }
}

/// Kelvin–Voigt damping of an element in a dynamic Jacobian: the viscous coefficients τ∘C,
/// the factor of the velocity derivative (γ/(βh) in generalized-α) and the velocities.
#[derive(Clone, Copy, Debug)]
pub struct ShearViscous {
    pub coeff: Vector3<f64>,
    pub factor: f64,
    /// Whether the edge rotation has a tracked rate (a free edge; not a swivel's twist).
    pub rate_theta: bool,
    pub va: Vector3<f64>,
    pub vb: Vector3<f64>,
    pub omega: Vector3<f64>,
    /// J_r(hΔθ) of the edge rotation's increment in the step: the Newton update changes the
    /// increment, so the configuration derivatives along θ are multiplied by it.
    pub tangent: Option<Matrix3<f64>>,
}

/// The 3×3 blocks of an element's force Jacobian over (x_a, x_b, θ), which have the pattern
/// [[−X, X, −Y], [X, −X, Y], [W, −W, T]].
#[derive(Clone, Copy, Debug)]
pub struct ShearBlocks {
    pub x: Matrix3<f64>,
    pub y: Matrix3<f64>,
    pub w: Matrix3<f64>,
    pub t: Matrix3<f64>,
}

impl ShearBlocks {
    pub fn block(&self, i: usize, j: usize) -> Matrix3<f64> {
        match (i, j) {
            (0, 0) | (1, 1) => -self.x,
            (0, 1) | (1, 0) => self.x,
            (0, 2) => -self.y,
            (1, 2) => self.y,
            (2, 0) => self.w,
            (2, 1) => -self.w,
            _ => self.t,
        }
    }
}

/// diag(c) m.
#[inline]
pub(crate) fn scale_rows(c: &Vector3<f64>, m: &Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| c[i] * m[(i, j)])
}

impl ShearKinematics {
    /// The derivative of the generalised forces Δs Jᵀ f, f = C(Γ − Γ⁰) (+ τ∘C Γ̇), along the
    /// Newton update: the stiffness Δs Jᵀ C J, the geometric part of the section force f, and
    /// with `viscous` the damping matrix (factor × Δs Jᵀ τ∘C J, on the rate unknowns) and the
    /// derivative through the strain rate's dependence on the configuration (Δs Jᵀ τ∘C G,
    /// G = ∂Γ̇/∂q). The whole element: Δs Jᵀ P + geometric(f) with P = C J + τ∘C (c J + G),
    /// the configuration part of the θ column times the tangent J_r of the step.
    pub fn jacobian(
        &self,
        f: &Vector3<f64>,
        c: &Vector3<f64>,
        viscous: Option<&ShearViscous>,
    ) -> ShearBlocks {
        let rt = self.r.transpose();
        let su = skew(&self.u);
        let inv_ds = self.inv_ds;
        let mut ca = -c * inv_ds;
        // θ column: configuration part (C J + τ∘C G, × J_r of the step) and rate part.
        let mut pth = scale_rows(c, &su);
        let mut pth_rate = None;
        let mut pa_extra = Matrix3::zeros();
        let mut tangent = None;
        if let Some(v) = viscous {
            ca -= v.coeff * (v.factor * inv_ds);
            let [ga, _, gth] = self.rate_derivative(&v.va, &v.vb, &v.omega);
            pa_extra = scale_rows(&v.coeff, &ga);
            pth += scale_rows(&v.coeff, &gth);
            if v.rate_theta {
                pth_rate = Some(scale_rows(&(v.coeff * v.factor), &su));
            }
            tangent = v.tangent;
        }
        let pa = scale_rows(&ca, &rt) + pa_extra;
        let sf = skew(f);
        let ktt = self.ds
            * (0.5 * (f * self.u.transpose() + self.u * f.transpose())
                - Matrix3::identity() * f.dot(&self.u));
        let mut y = pth - sf;
        let mut t = ktt - self.ds * su * pth;
        if let Some(jr) = tangent {
            y *= jr;
            t *= jr;
        }
        if let Some(pr) = pth_rate {
            y += pr;
            t -= self.ds * su * pr;
        }
        ShearBlocks {
            x: self.r * pa,
            y: self.r * y,
            w: -self.ds * su * pa - sf * rt,
            t,
        }
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
        let jac = kin.jacobian(&f, stiffness, None);
        for i in 0..3 {
            for j in 0..3 {
                out.hess[i][j] = jac.block(i, j);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp_half, rotate_body};

    #[test]
    fn strain_extremes_are_the_first_largest_and_report_nan() {
        // three steps of a straight cable of 4 edges along z (Δs = 0.1): step 1 stretches
        // edge 2 by 3 %, step 2 compresses edge 0 by 2 % and shears edge 3 by 0.05 twice
        // (edges 3 at steps 1 and 2 equal: the first is reported)
        let (n, ds) = (4, 0.1);
        let mut x = vec![];
        let mut q = vec![];
        let stretch = [[0.0; 4], [0.0, 0.0, 0.03, 0.0], [-0.02, 0.0, 0.0, 0.0]];
        let shear = [[0.0; 4], [0.0, 0.0, 0.0, 0.05], [0.0, 0.0, 0.0, 0.05]];
        for k in 0..3 {
            let mut p = Vector3::zeros();
            x.extend_from_slice(p.as_slice());
            for e in 0..n {
                p += Vector3::new(shear[k][e], 0.0, 1.0 + stretch[k][e]) * ds;
                x.extend_from_slice(p.as_slice());
                q.extend_from_slice(&[2.0, 0.0, 0.0, 0.0]); // identity, not unit
            }
        }
        let inv = vec![1.0 / ds; n];
        let [a, c, s] = saved_strain_extremes(&x, &q, &inv).unwrap();
        assert!(
            (a.value - 0.03).abs() < 1e-12 && (a.step, a.edge) == (1, 2),
            "{a:?}"
        );
        assert!(
            (c.value - 0.02).abs() < 1e-12 && (c.step, c.edge) == (2, 0),
            "{c:?}"
        );
        assert!(
            (s.value - 0.05).abs() < 1e-12 && (s.step, s.edge) == (1, 3),
            "{s:?}"
        );
        // a NaN position at step 2, node 3: edges 2 and 3 are NaN, the first is reported
        x[2 * 3 * (n + 1) + 3 * 3] = f64::NAN;
        for e in saved_strain_extremes(&x, &q, &inv).unwrap() {
            assert!(e.value.is_nan() && (e.step, e.edge) == (2, 2), "{e:?}");
        }
        assert_eq!(saved_strain_extremes(&[], &[], &inv), None);
        assert_eq!(saved_strain_extremes(&[0.0; 3], &[], &[]), None);
    }

    /// Random saved steps: positions (T, N + 1, 3) along z with noise, quaternions of any
    /// length; the stretch grows with the step (the extremes move).
    fn random_steps(steps: usize, n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut rng = crate::modal::Rng(seed);
        let mut rnd = || rng.next();
        let (mut x, mut q) = (vec![], vec![]);
        for k in 0..steps {
            let mut p = Vector3::zeros();
            x.extend_from_slice(p.as_slice());
            for _ in 0..n {
                let stretch = 1.0 + 0.01 * k as f64 * rnd();
                p += Vector3::new(0.01 * rnd(), 0.01 * rnd(), 0.1 * stretch);
                x.extend_from_slice(p.as_slice());
                q.extend_from_slice(&[1.0 + 0.01 * rnd(), 0.01 * rnd(), 0.01 * rnd(), rnd()]);
            }
        }
        (x, q)
    }

    /// The lanes of four edges give `saved_strain`'s values to the last bit (41 edges: ten
    /// blocks and a tail).
    #[test]
    fn step_strains_in_lanes_are_saved_strain_bit_for_bit() {
        let n = 41;
        let (x, q) = random_steps(1, n, 5);
        let inv: Vec<f64> = (0..n).map(|e| 10.0 + 0.1 * e as f64).collect();
        let (mut axial, mut shear) = (vec![0.0; n], vec![0.0; n]);
        saved_step_strains(&x, &q, &inv, &mut axial, &mut shear);
        for e in 0..n {
            let at = |i: usize| Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
            let u = Vector3::new(q[4 * e + 1], q[4 * e + 2], q[4 * e + 3]);
            let g = saved_strain(&at(e), &at(e + 1), q[4 * e], &u, inv[e]);
            assert_eq!(axial[e].to_bits(), g.z.to_bits(), "edge {e}");
            let s = (g.x * g.x + g.y * g.y).sqrt();
            assert_eq!(shear[e].to_bits(), s.to_bits(), "edge {e}");
        }
    }

    /// The scan skips a step's offers only where none could be taken: the extremes of every
    /// value offered, with and without a NaN late in the run.
    #[test]
    fn strain_extremes_equal_offering_every_value() {
        let (steps, n) = (30, 13);
        let (mut x, q) = random_steps(steps, n, 9);
        let inv = vec![10.0; n];
        for nan in [false, true] {
            if nan {
                x[(25 * (n + 1) + 7) * 3 + 2] = f64::NAN;
            }
            let mut all = [None; 3];
            let (mut axial, mut shear) = (vec![0.0; n], vec![0.0; n]);
            for k in 0..steps {
                let xs = &x[k * 3 * (n + 1)..(k + 1) * 3 * (n + 1)];
                saved_step_strains(
                    xs,
                    &q[k * 4 * n..(k + 1) * 4 * n],
                    &inv,
                    &mut axial,
                    &mut shear,
                );
                for e in 0..n {
                    Extreme::offer(&mut all[0], axial[e], k, e);
                    Extreme::offer(&mut all[1], -axial[e], k, e);
                    Extreme::offer(&mut all[2], shear[e], k, e);
                }
            }
            let got = saved_strain_extremes(&x, &q, &inv).unwrap();
            for (g, a) in got.iter().zip(all) {
                let a = a.unwrap();
                assert_eq!((g.step, g.edge), (a.step, a.edge));
                assert_eq!(g.value.to_bits(), a.value.to_bits());
            }
            assert!(
                got[0].step > 0 && got[2].step > 0,
                "the extremes moved: {got:?}"
            );
            assert_eq!(got[0].value.is_nan(), nan);
        }
    }

    #[test]
    fn saved_strain_is_the_element_strain_for_any_quaternion_length() {
        let p = crate::rotation::exp_half(&Vector3::new(0.3, -0.7, 1.1));
        let (xa, xb) = (
            Vector3::new(0.1, 0.2, -0.3),
            Vector3::new(0.12, 0.25, -0.28),
        );
        let ds = 0.05;
        let exact = shear_strain(&xa, &xb, &p, ds, &Vector3::zeros());
        for scale in [1.0, 3.0, 0.01] {
            let q = p.coords * scale; // (i, j, k, w)
            let u = Vector3::new(q[0], q[1], q[2]);
            let got = saved_strain(&xa, &xb, q[3], &u, 1.0 / ds);
            assert!((got - exact).amax() < 1e-14, "{scale}: {got} vs {exact}");
        }
    }

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

    #[test]
    fn strain_rate_and_its_configuration_derivative_match_finite_differences() {
        let (va, vb, omega) = (
            Vector3::new(0.3, -0.8, 0.2),
            Vector3::new(-0.5, 0.1, 0.9),
            Vector3::new(1.2, -0.4, 0.7),
        );
        let kin_at = |z: &[f64; 9]| {
            let xa = Vector3::new(0.1, -0.2, 0.05) + Vector3::new(z[0], z[1], z[2]);
            let xb = Vector3::new(0.13, -0.17, 0.14) + Vector3::new(z[3], z[4], z[5]);
            let p = rotate_body(
                &exp_half(&Vector3::new(0.4, -0.3, 0.9)),
                &Vector3::new(z[6], z[7], z[8]),
            );
            ShearKinematics::new(&xa, &xb, &p, 0.1, &Vector3::new(0.01, 0.0, -0.02))
        };
        let kin = kin_at(&[0.0; 9]);
        let g = kin.rate_derivative(&va, &vb, &omega);
        let scale = g.iter().map(|m| m.amax()).fold(0.0, f64::max);
        let h = 1e-6;
        for i in 0..9 {
            let mut zp = [0.0; 9];
            let mut zm = [0.0; 9];
            zp[i] = h;
            zm[i] = -h;
            let fd = (kin_at(&zp).rate(&va, &vb, &omega) - kin_at(&zm).rate(&va, &vb, &omega))
                / (2.0 * h);
            let an = g[i / 3].column(i % 3);
            assert!(
                (fd - an).amax() < 1e-6 * scale,
                "∂Γ̇/∂q col {i}: fd {fd} analytic {an}"
            );
        }
    }
}
