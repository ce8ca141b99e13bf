//! Modal analysis of a cable at a static equilibrium: the lowest natural modes of
//! K φ = λ M φ (λ = ω²) with K the symmetric part of the tangent stiffness of the static
//! assembly (elastic and geometric stiffness of the current loads: tension, gravity, dead
//! loads) and M the lumped mass (node masses ρA δs on the displacements, ρΔs diag(I₁, I₂, I₃)
//! on the body-frame rotations of free edges; swivel twists and twists inside swivel clips are
//! massless).
//!
//! Solver: shift-invert subspace iteration on the block-tridiagonal structure (O(N) memory and
//! time per iteration): Y = (K − σM)⁻¹ M X with the symmetric block LDLᵀ of K − σM, then a
//! Rayleigh–Ritz step in the M inner product with the projected stiffness formed as
//! Yᵀ(K − σM)Y = Yᵀ M X (no product with K: no cancellation of its large shear and axial
//! terms against small bending forces, so a stiff shear or axial section costs no accuracy).
//! Massless unknowns need no condensation: (K − σM)⁻¹ M X satisfies their (static) equations
//! exactly, and rotations with a tiny rotary inertia are treated alike (their inertia only
//! weights the M inner product). Multiple eigenvalues (the two bending planes of a round
//! section) are found together by the block of vectors. Completeness is proved by the Sturm
//! count: the number of negative pivots of K − μM (`BlockTridiag::ldlt`) is the number of
//! eigenvalues below μ; a cut above the last returned mode must count exactly the modes
//! found, otherwise the subspace is enlarged and the iteration repeated.
//!
//! Stability: the inertia of K itself counts the negative eigenvalues (an unstable
//! equilibrium). A negative eigenvalue smaller in magnitude than 1e-8 of the largest returned
//! eigenvalue is round-off of a zero mode (a free rigid motion), not an instability.
use crate::assembly::Workspace;
use crate::block_tridiag::{Block, BlockTridiag};
use crate::contact::Contact;
use crate::model::{EdgeKind, NodeKind, Rod};
use crate::rotation::rotation_matrix;
use crate::sliding::SlidingClips;
use crate::state::State;
use nalgebra::{DMatrix, Vector3, Vector6};
use std::fmt;

/// The dominant deformation of a mode, from its modal (kinetic) energy shares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeKind {
    /// Bending in the d1–d3 plane: displacement along d1 (with rotation about d2).
    BendingD1,
    /// Bending in the d2–d3 plane: displacement along d2 (with rotation about d1).
    BendingD2,
    /// Rotation about the tangent d3.
    Torsion,
    /// Displacement along the tangent d3.
    Axial,
}

impl ModeKind {
    /// The kind with the largest energy share (bending d1, bending d2, torsion, axial).
    pub fn dominant(shares: &[f64; 4]) -> ModeKind {
        let kinds = [
            ModeKind::BendingD1,
            ModeKind::BendingD2,
            ModeKind::Torsion,
            ModeKind::Axial,
        ];
        let i = (0..4)
            .max_by(|&a, &b| shares[a].total_cmp(&shares[b]))
            .unwrap();
        kinds[i]
    }

    pub fn name(&self) -> &'static str {
        match self {
            ModeKind::BendingD1 => "bending d1",
            ModeKind::BendingD2 => "bending d2",
            ModeKind::Torsion => "torsion",
            ModeKind::Axial => "axial",
        }
    }
}

/// One natural mode, mass-normalised (φᵀ M φ = 1).
#[derive(Clone, Debug)]
pub struct Mode {
    /// λ = ω², 1/s² (0 for a zero mode within round-off).
    pub eigenvalue: f64,
    /// ω, rad/s.
    pub omega: f64,
    /// Per block: node displacement (slots 0–2, global) and edge rotation (slots 3–5, body
    /// frame), as the unknowns of the solver (inactive slots 0).
    pub shape: Vec<Vector6<f64>>,
    /// Shares of the modal kinetic energy: bending d1, bending d2, torsion, axial (sum 1).
    pub shares: [f64; 4],
    pub kind: ModeKind,
}

impl Mode {
    /// Node displacements (global), N+1 (zero at nodes held by clips: slot 0 of their block
    /// may hold a swivel's twist).
    pub fn displacements(&self, rod: &Rod) -> Vec<Vector3<f64>> {
        self.shape
            .iter()
            .zip(&rod.node_kind)
            .map(|(v, kind)| match kind {
                NodeKind::Free => Vector3::new(v[0], v[1], v[2]),
                NodeKind::Prescribed { .. } => Vector3::zeros(),
            })
            .collect()
    }

    /// Edge rotation vectors in the global frame, N.
    pub fn rotations(&self, st: &State) -> Vec<Vector3<f64>> {
        st.p.iter()
            .zip(&self.shape)
            .map(|(p, v)| rotation_matrix(p) * Vector3::new(v[3], v[4], v[5]))
            .collect()
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ModalError {
    /// The assembly failed: a kink at a node.
    Kink { node: usize },
    /// The equilibrium is unstable: `count` negative eigenvalues, the lowest `eigenvalue`.
    Unstable { count: usize, eigenvalue: f64 },
    /// The cable has no massive unknown (all held by clips).
    NoUnknowns,
    /// The iteration did not converge (or the Sturm count kept finding missed modes).
    NotConverged { iterations: usize },
}

impl fmt::Display for ModalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModalError::Kink { node } => write!(f, "kink at node {node}"),
            ModalError::Unstable { count, eigenvalue } => write!(
                f,
                "the equilibrium is unstable ({count} negative stiffness eigenvalue(s), the \
                 lowest λ = {eigenvalue:.4e} 1/s²); its modes are not defined"
            ),
            ModalError::NoUnknowns => write!(f, "the cable has no free unknown with mass"),
            ModalError::NotConverged { iterations } => write!(
                f,
                "the modal solver did not converge in {iterations} iterations"
            ),
        }
    }
}
impl std::error::Error for ModalError {}

/// Relative change of the Ritz values at which the iteration stops (the default accuracy of
/// the modal analysis), and the change below which it stops when the changes no longer shrink
/// (the round-off floor of the solves).
pub const TOLERANCE: f64 = 1e-11;
const FLOOR: f64 = 1e-5;
/// Tolerances from this one up take a smaller subspace (`lowest_pairs`).
const QUICK_TOLERANCE: f64 = 1e-9;
/// Steps of iterative refinement per refined solve (`ShiftInvert::apply`).
pub(crate) const REFINEMENT_STEPS: usize = 2;
/// The change of the Ritz values at which the iteration turns from plain solves to refined
/// ones: the vectors are converged but for the solves' error, which the refined iterations
/// then remove (two or three of them instead of all).
const PLAIN_TOLERANCE: f64 = 1e-8;
const MAX_ITERATIONS: usize = 300;
/// A negative eigenvalue within this fraction of the largest returned one is a zero mode.
const ZERO_MODE: f64 = 1e-8;

/// Lumped mass per block slot (0 on inactive and massless slots).
pub fn lumped_mass(rod: &Rod) -> Vec<Vector6<f64>> {
    let sec = &rod.spec.section;
    (0..rod.mask.len())
        .map(|b| {
            let node = rod.node_kind[b] == NodeKind::Free && rod.mask[b][0];
            let edge = b < rod.n_edges() && rod.edge_kind[b] == EdgeKind::Free;
            Vector6::from_fn(|k, _| match k {
                0..=2 if node => rod.node_mass[b],
                3..=5 if edge => sec.rotary_inertia[k - 3] * rod.ds_edge[b],
                _ => 0.0,
            })
        })
        .collect()
}

/// The symmetric tangent stiffness at `st` (inactive slots: identity rows and columns).
pub fn tangent_stiffness(rod: &Rod, st: &State) -> Result<BlockTridiag, ModalError> {
    tangent_stiffness_with_contact(rod, st, None)
}

/// `tangent_stiffness` with the contact term's stiffness (the barrier, and a sticking
/// friction's tangential spring, symmetrised) when the cable touches its surroundings.
pub fn tangent_stiffness_with_contact(
    rod: &Rod,
    st: &State,
    contact: Option<&mut Contact>,
) -> Result<BlockTridiag, ModalError> {
    let mut ws = Workspace::new(rod);
    let mut sliding = SlidingClips::of(rod);
    let assembled = match contact {
        Some(c) => ws.assemble_terms(rod, st, 1.0, true, &mut [&mut sliding, c]),
        None => ws.assemble_terms(rod, st, 1.0, true, &mut [&mut sliding]),
    };
    assembled.map_err(|k| ModalError::Kink { node: k.node })?;
    let mut k = ws.jac;
    let n = k.n_blocks();
    for b in 0..n {
        k.diag[b] = 0.5 * (k.diag[b] + k.diag[b].transpose());
        if b + 1 < n {
            let u = 0.5 * (k.upper[b] + k.lower[b + 1].transpose());
            k.upper[b] = u;
            k.lower[b + 1] = u.transpose();
        }
    }
    Ok(k)
}

/// A pencil (K, M) with a lumped (diagonal) M whose K − σM can be factored and solved: the
/// single cable's block-tridiagonal one here, the harness's tree (`harness_modal`).
pub(crate) trait ShiftInvert {
    /// The lumped mass per block slot of the flattened unknowns.
    fn mass(&self) -> &[Vector6<f64>];
    /// Factors K − σM; returns its inertia (the number of eigenvalues below σ), or None if a
    /// pivot is zero (σ on or next to an eigenvalue).
    fn factor(&mut self, sigma: f64) -> Option<usize>;
    /// y = (K − σM)⁻¹ M x with the current factorisation (`r`: work space), with
    /// `REFINEMENT_STEPS` steps of iterative refinement if `refine`.
    fn apply(
        &mut self,
        x: &[Vector6<f64>],
        y: &mut [Vector6<f64>],
        r: &mut [Vector6<f64>],
        refine: bool,
    );

    fn n(&self) -> usize {
        self.mass().len()
    }

    /// Factors K − σM, moving σ down by `step`, 2 `step`, 4 `step` … off an eigenvalue if it
    /// sits on one; returns the shift used and the inertia.
    fn factor_near(&mut self, sigma: f64, step: f64) -> (f64, usize) {
        let mut s = sigma;
        for k in 0..60 {
            if let Some(nu) = self.factor(s) {
                return (s, nu);
            }
            s = sigma - step * 2f64.powi(k);
        }
        (s, self.factor(s).unwrap_or(0))
    }

    fn mdot(&self, x: &[Vector6<f64>], y: &[Vector6<f64>]) -> f64 {
        x.iter()
            .zip(y)
            .zip(self.mass())
            .map(|((a, b), m)| a.component_mul(b).dot(m))
            .sum()
    }
}

/// The pencil (K, M) on the block structure, with a work copy for the factorisations.
struct Pencil {
    k: BlockTridiag,
    m: Vec<Vector6<f64>>,
    work: BlockTridiag,
}

impl ShiftInvert for Pencil {
    fn mass(&self) -> &[Vector6<f64>] {
        &self.m
    }

    fn factor(&mut self, sigma: f64) -> Option<usize> {
        let n = self.n();
        for b in 0..n {
            self.work.diag[b] = self.k.diag[b] - Block::from_diagonal(&(self.m[b] * sigma));
            self.work.lower[b] = self.k.lower[b];
            self.work.upper[b] = self.k.upper[b];
        }
        let inertia = self.work.ldlt(0..n);
        (inertia.zero == 0).then_some(inertia.negative)
    }

    /// y = (K − σM)⁻¹ M x with the current factorisation and, if `refine`, two steps of
    /// iterative refinement (`r`: work space). K − σM is ill-conditioned by design (stiff
    /// shear and axial terms against soft bending, σ near the spectrum): one solve leaves a
    /// relative error ~1e-5 in the bending directions of a section with GA/EI = 5e8 1/m²;
    /// refinement brings the Ritz values to ~1e-7.
    fn apply(
        &mut self,
        x: &[Vector6<f64>],
        y: &mut [Vector6<f64>],
        r: &mut [Vector6<f64>],
        refine: bool,
    ) {
        let n = self.n();
        for ((y, x), m) in y.iter_mut().zip(x).zip(&self.m) {
            *y = x.component_mul(m);
        }
        self.work.solve_range(0..n, y);
        for _ in 0..if refine { REFINEMENT_STEPS } else { 0 } {
            self.work.mul(y, r);
            for ((r, x), m) in r.iter_mut().zip(x).zip(&self.m) {
                *r = x.component_mul(m) - *r;
            }
            self.work.solve_range(0..n, r);
            for (y, r) in y.iter_mut().zip(r.iter()) {
                *y += r;
            }
        }
    }
}

/// A linear congruential generator of values in [−0.5, 0.5): the modal solver's start vectors
/// (deterministic runs) and the random inputs of the crate's tests.
pub(crate) struct Rng(pub(crate) u64);
impl Rng {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }
}

/// Ritz pairs of the subspace iteration: eigenvalues ascending and M-orthonormal vectors.
pub(crate) struct Ritz {
    pub values: Vec<f64>,
    pub vectors: Vec<Vec<Vector6<f64>>>,
}

/// Subspace iteration with `p` vectors from the start vectors `x` at shift σ (factored): plain
/// solves until the Ritz values change by less than `PLAIN_TOLERANCE` (or stop shrinking),
/// then refined ones until they change by less than `tolerance`; only a refined iteration
/// ends it.
fn subspace_iteration<P: ShiftInvert>(
    pencil: &mut P,
    sigma: f64,
    mut x: Vec<Vec<Vector6<f64>>>,
    count: usize,
    iterations: &mut usize,
    tolerance: f64,
) -> Option<Ritz> {
    let n = pencil.n();
    let p = x.len();
    let mut y = vec![vec![Vector6::zeros(); n]; p];
    let mut r = vec![Vector6::zeros(); n];
    let mut old: Vec<f64> = vec![f64::NAN; p];
    let (mut best, mut since_best) = (f64::INFINITY, 0);
    let mut refine = false;
    for _ in 0..MAX_ITERATIONS {
        *iterations += 1;
        for (xi, yi) in x.iter().zip(y.iter_mut()) {
            pencil.apply(xi, yi, &mut r, refine);
        }
        // Scale the columns of Y to unit M-norm (diagonal scaling of the Gram matrices).
        let mut scale = vec![1.0; p];
        for (i, yi) in y.iter_mut().enumerate() {
            let nrm = pencil.mdot(yi, yi).sqrt();
            if nrm > 0.0 && nrm.is_finite() {
                scale[i] = 1.0 / nrm;
                yi.iter_mut().for_each(|v| *v *= scale[i]);
            }
        }
        // Projected pencil: (K − σM)_r = Yᵀ M X (Y scaled), M_r = Yᵀ M Y.
        let mut kr = DMatrix::zeros(p, p);
        let mut mr = DMatrix::zeros(p, p);
        for i in 0..p {
            for j in 0..=i {
                let a = 0.5
                    * (pencil.mdot(&y[i], &x[j]) * scale[j] + pencil.mdot(&y[j], &x[i]) * scale[i]);
                kr[(i, j)] = a;
                kr[(j, i)] = a;
                let b = pencil.mdot(&y[i], &y[j]);
                mr[(i, j)] = b;
                mr[(j, i)] = b;
            }
        }
        let l = mr.cholesky()?.l();
        let li = l.clone().try_inverse()?;
        let c = &li * kr * li.transpose();
        let c = 0.5 * (&c + c.transpose());
        let eig = c.symmetric_eigen();
        let q = li.transpose() * eig.eigenvectors;
        // μ = λ − σ; order by λ ascending
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let values: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i] + sigma).collect();
        for (slot, &i) in order.iter().enumerate() {
            let xi = &mut x[slot];
            xi.iter_mut().for_each(|v| *v = Vector6::zeros());
            for (j, yj) in y.iter().enumerate() {
                let w = q[(j, i)];
                for (a, b) in xi.iter_mut().zip(yj) {
                    *a += w * b;
                }
            }
        }
        let top = values[..count].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let change = values[..count]
            .iter()
            .zip(&old)
            .map(|(v, o)| (v - o).abs() / v.abs().max(1e-3 * top))
            .fold(
                0.0f64,
                |a, c| if c.is_nan() { f64::INFINITY } else { a.max(c) },
            );
        if change < best {
            (best, since_best) = (change, 0);
        } else {
            since_best += 1;
        }
        let converged = change <= tolerance || (since_best >= 6 && best <= FLOOR);
        old = values;
        if !refine {
            if change <= PLAIN_TOLERANCE.max(tolerance) || since_best >= 3 {
                (refine, best, since_best) = (true, f64::INFINITY, 0);
            }
            continue;
        }
        if converged {
            return Some(Ritz {
                values: old,
                vectors: x,
            });
        }
    }
    None
}

/// The `count` lowest modes of the cable at the equilibrium `st`.
pub fn lowest_modes(rod: &Rod, st: &State, count: usize) -> Result<Vec<Mode>, ModalError> {
    lowest_modes_with_contact(rod, st, count, None, TOLERANCE)
}

/// `lowest_modes` about an equilibrium in contact with the surroundings: K takes the contact
/// term's stiffness (`tangent_stiffness_with_contact`), so a cable resting on a surface is an
/// equilibrium of K (without it the carried part is unsupported). `tolerance`: the relative
/// change of the eigenvalues at which the iteration stops (`TOLERANCE` for the modal analysis;
/// a looser one where fewer digits serve, as the default damping's calibration).
pub fn lowest_modes_with_contact(
    rod: &Rod,
    st: &State,
    count: usize,
    contact: Option<&mut Contact>,
    tolerance: f64,
) -> Result<Vec<Mode>, ModalError> {
    let mass = lumped_mass(rod);
    let m = mass.clone();
    let massive = m
        .iter()
        .flat_map(|v| v.iter())
        .filter(|&&x| x > 0.0)
        .count();
    if massive == 0 {
        return Err(ModalError::NoUnknowns);
    }
    let count = count.clamp(1, massive);
    let k = tangent_stiffness_with_contact(rod, st, contact)?;
    let n = m.len();
    // Eigenvalue scale for shifts off a singular point: the largest translational K_ii/M_ii.
    let mut scale = 0.0f64;
    for (mb, kb) in m.iter().zip(&k.diag) {
        for s in (0..3).filter(|&s| mb[s] > 0.0) {
            scale = scale.max(kb[(s, s)].abs() / mb[s]);
        }
    }
    // Jacobi scaling: K̃ = D K D, M̃ = D M D with D = diag(K)^(-1/2) balances translations
    // and rotations (and stiff against soft slots) in the pivot blocks; φ = D φ̃.
    let d: Vec<Vector6<f64>> = (0..n)
        .map(|b| {
            Vector6::from_fn(|i, _| {
                let kii = k.diag[b][(i, i)].abs();
                if kii > 0.0 && kii.is_finite() {
                    1.0 / kii.sqrt()
                } else {
                    1.0
                }
            })
        })
        .collect();
    let mut k = k;
    for b in 0..n {
        let db = Block::from_diagonal(&d[b]);
        k.diag[b] = db * k.diag[b] * db;
        if b + 1 < n {
            let dn = Block::from_diagonal(&d[b + 1]);
            k.upper[b] = db * k.upper[b] * dn;
            k.lower[b + 1] = dn * k.lower[b + 1] * db;
        }
    }
    let m: Vec<Vector6<f64>> = m
        .iter()
        .zip(&d)
        .map(|(m, d)| m.component_mul(d).component_mul(d))
        .collect();
    let mut pencil = Pencil {
        work: k.clone(),
        k,
        m,
    };
    let ritz = lowest_pairs(&mut pencil, count, massive, scale, tolerance)?;
    Ok((0..count)
        .map(|i| {
            let shape = ritz.vectors[i]
                .iter()
                .zip(&d)
                .map(|(v, d)| v.component_mul(d))
                .collect();
            classify(rod, st, &mass, ritz.values[i], shape)
        })
        .collect())
}

/// The `count` lowest eigenpairs of a pencil with `massive` slots of positive mass (values
/// clamped at 0 from below; `scale`: the eigenvalue scale for shifts off a singular point):
/// the stability check (inertia of K), shift-invert subspace iteration, the Sturm cut.
pub(crate) fn lowest_pairs<P: ShiftInvert>(
    pencil: &mut P,
    count: usize,
    massive: usize,
    scale: f64,
    tolerance: f64,
) -> Result<Ritz, ModalError> {
    // Stability: the inertia of K (shifted below a zero mode if K is singular).
    let (sigma, negative) = pencil.factor_near(0.0, 1e-12 * scale);
    let mut rng = Rng(0x5eed_cab1e);
    // Bathe's 2·count or count + 8 vectors; count + 4 where fewer digits are asked (the
    // damping's calibration: the slower convergence costs less than the vectors, 2.1 → 1.3
    // ms for the harness benchmark's mode 1 at 1e-9)
    let extra = if tolerance >= QUICK_TOLERANCE { 4 } else { 8 };
    let mut p = (2 * count).max(count + extra).min(massive);
    let mut iterations = 0;
    let mut start: Vec<Vec<Vector6<f64>>> = Vec::new();
    for _attempt in 0..4 {
        // Start vectors: the previous Ritz vectors, then random ones on the massive slots.
        while start.len() < p {
            let v: Vec<Vector6<f64>> = pencil
                .mass()
                .iter()
                .map(|mb| Vector6::from_fn(|k, _| if mb[k] > 0.0 { rng.next() } else { 0.0 }))
                .collect();
            start.push(v);
        }
        let ritz = subspace_iteration(pencil, sigma, start, count, &mut iterations, tolerance)
            .ok_or(ModalError::NotConverged { iterations })?;
        let top = ritz.values[..count]
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        // The Sturm cut: above the returned modes and any mode equal to the last one.
        let mut found = count;
        while found < p && ritz.values[found] - ritz.values[count - 1] <= 1e-6 * top {
            found += 1;
        }
        let cut = if found < p {
            0.5 * (ritz.values[found - 1] + ritz.values[found])
        } else {
            ritz.values[p - 1] + 1e-6 * top
        };
        let (_, below) = pencil.factor_near(cut, 1e-10 * cut.abs().max(1e-3 * top));
        if below == found {
            if negative > 0 && ritz.values[0] < -ZERO_MODE * top {
                return Err(ModalError::Unstable {
                    count: negative,
                    eigenvalue: ritz.values[0],
                });
            }
            let mut values = ritz.values;
            let mut vectors = ritz.vectors;
            values.truncate(count);
            vectors.truncate(count);
            values.iter_mut().for_each(|v| *v = v.max(0.0));
            return Ok(Ritz { values, vectors });
        }
        // a mode was missed: enlarge the subspace, keep the Ritz vectors, and factor at σ again
        let _ = pencil.factor(sigma);
        start = ritz.vectors;
        p = (p + count + 8).min(massive);
    }
    Err(ModalError::NotConverged { iterations })
}

/// The unnormalised kinetic energy of a mode shape of one cable by deformation (bending d1,
/// bending d2, torsion, axial), and its largest mass-weighted component (|value|, sign).
pub(crate) fn energy_shares(
    rod: &Rod,
    st: &State,
    m: &[Vector6<f64>],
    shape: &[Vector6<f64>],
) -> ([f64; 4], (f64, f64)) {
    let n_edges = rod.n_edges();
    let mut shares = [0.0; 4];
    let mut big = (0.0f64, 1.0f64);
    for (b, (v, mb)) in shape.iter().zip(m).enumerate() {
        let r = rotation_matrix(&st.p[b.min(n_edges - 1)]);
        let u = r.transpose() * Vector3::new(v[0], v[1], v[2]);
        shares[0] += mb[0] * u.x * u.x + mb[4] * v[4] * v[4];
        shares[1] += mb[1] * u.y * u.y + mb[3] * v[3] * v[3];
        shares[3] += mb[2] * u.z * u.z;
        shares[2] += mb[5] * v[5] * v[5];
        for k in 0..6 {
            let w = mb[k].sqrt() * v[k];
            if w.abs() > big.0 {
                big = (w.abs(), v[k].signum());
            }
        }
    }
    (shares, big)
}

/// Mode from its eigenpair: kinetic energy shares in the local frames, sign convention (the
/// largest displacement component positive).
fn classify(
    rod: &Rod,
    st: &State,
    m: &[Vector6<f64>],
    lambda: f64,
    mut shape: Vec<Vector6<f64>>,
) -> Mode {
    let (mut shares, big) = energy_shares(rod, st, m, &shape);
    let total: f64 = shares.iter().sum();
    if total > 0.0 {
        shares.iter_mut().for_each(|s| *s /= total);
        let nrm = total.sqrt() * big.1;
        shape.iter_mut().for_each(|v| *v /= nrm);
    }
    Mode {
        eigenvalue: lambda,
        omega: lambda.sqrt(),
        shape,
        shares,
        kind: ModeKind::dominant(&shares),
    }
}

/// The modal damping ratio of the Kelvin–Voigt section law for the mode `shape` (mass-
/// normalised, φᵀMφ = 1) of natural frequency `omega` at the equilibrium `st`: the Rayleigh
/// quotient ζ = φᵀCφ / (2ω φᵀMφ) with C the viscous damping matrix of the section law
/// (viscous forces τ_Γ ∘ C^Γ Γ̇, moments τ_K ∘ C^K K̇; `shear_tau`, `bend_tau` the retardation
/// times of (GA₁, GA₂, EA) and (EI₁, EI₂, GJ)). φᵀCφ is the dissipated power of the assembly
/// with the mode shape as velocities (ẋ, ω) — one assembly, no matrix. Exact for a
/// classically damped system (C diagonal in the modes: one τ on every stiffness gives
/// ζ = τω/2 on every mode of an unstressed cable); otherwise the first-order perturbation of
/// the complex eigenvalue, accurate while ζ is small and the modes well separated. It counts
/// the strain rate of every deformation the mode carries, unlike the kinetic-energy shares.
pub fn damping_ratio(
    rod: &Rod,
    st: &State,
    shape: &[Vector6<f64>],
    omega: f64,
    shear_tau: Vector3<f64>,
    bend_tau: Vector3<f64>,
) -> Result<f64, ModalError> {
    let power = dissipated_power(rod, st, shape, shear_tau, bend_tau, &[])?;
    let mass = modal_mass(rod, shape);
    if !(omega > 0.0 && mass > 0.0) {
        return Ok(0.0);
    }
    Ok(power / (2.0 * omega * mass))
}

/// φᵀMφ of one cable's part of a mode shape (lumped mass).
pub(crate) fn modal_mass(rod: &Rod, shape: &[Vector6<f64>]) -> f64 {
    lumped_mass(rod)
        .iter()
        .zip(shape)
        .map(|(m, s)| (0..6).map(|k| m[k] * s[k] * s[k]).sum::<f64>())
        .sum()
}

/// The velocity of a node held by something that moves in the mode (a harness junction): the
/// node's velocity (global) and its ghost rotation's body angular velocity.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HeldRate {
    pub node: usize,
    pub velocity: Vector3<f64>,
    pub ghost: usize,
    pub angular_velocity: Vector3<f64>,
}

/// φᵀCφ: the power the section law's viscous forces dissipate with the mode shape `shape` as
/// velocities (ẋ, ω) — one assembly, no matrix. Held nodes do not move, except those of `held`
/// (given velocities, e.g. the ends a harness junction carries).
pub(crate) fn dissipated_power(
    rod: &Rod,
    st: &State,
    shape: &[Vector6<f64>],
    shear_tau: Vector3<f64>,
    bend_tau: Vector3<f64>,
    held: &[HeldRate],
) -> Result<f64, ModalError> {
    use crate::assembly::{Elastic, Eval, Part, Rates, Term};
    let sec = &rod.spec.section;
    let mut v: Vec<Vector6<f64>> = shape.to_vec();
    // Node velocities only where the node moves; a held node's slot 0 is a free clip angle.
    for (b, vb) in v.iter_mut().enumerate() {
        let m = &rod.mask[b];
        if !(m[0] && m[1] && m[2]) {
            vb.fixed_rows_mut::<3>(0).fill(0.0);
        }
        for k in 3..6 {
            if !m[k] {
                vb[k] = 0.0;
            }
        }
    }
    let mut ghost_omega: Vec<Vector3<f64>> = rod
        .ghosts
        .iter()
        .map(|g| match g.free_axis {
            Some(axis) => shape[g.node][0] * axis,
            None => Vector3::zeros(),
        })
        .collect();
    for e in held {
        v[e.node].fixed_rows_mut::<3>(0).copy_from(&e.velocity);
        ghost_omega[e.ghost] = e.angular_velocity;
    }
    let rates = Rates {
        v,
        ghost_omega,
        shear_damping: shear_tau.component_mul(&sec.shear_stiffness),
        bend_damping: bend_tau.component_mul(&sec.bend_stiffness),
        damping_factor: 0.0,
        tangent: Vec::new(),
    };
    let mut ws = Workspace::new(rod);
    ws.clear(false);
    let ev = Eval {
        part: Part::All,
        want_jac: false,
        rates: Some(&rates),
        load_factor: 1.0,
    };
    Elastic
        .add_residual_jacobian(rod, st, &ev, &mut ws)
        .map_err(|k| ModalError::Kink { node: k.node })?;
    Ok(ws.dissipation)
}
