//! Modal analysis and stability of a harness at a static equilibrium (docs/harness.md,
//! "Modal analysis and stability"): the pencil (K, M) of the whole tree — the cables' symmetric
//! tangent stiffness with their junction couplings, the cables' lumped masses, and per junction
//! its mass plus the node masses of the cable ends it holds (translations) and its rotary
//! inertia (body-frame rotations) — solved by the shift-invert subspace iteration of
//! `modal` with K − σM factored by the harness's tree elimination (`HarnessStatics::factor`
//! in its symmetric mode: block LDLᵀ on the cable chains, then the junction tree, leaves
//! first; O(N)).
//!
//! Stability and the Sturm count: by Sylvester's law of inertia the number of negative
//! eigenvalues of K − σM is the number of negative pivots of the tree LDLᵀ — the cables' chain
//! pivots plus the junction pivots (the Schur complements of the tree elimination).
use crate::block_tridiag::Block;
use crate::contact::Contact;
use crate::harness::{Harness, HarnessError, HarnessState};
use crate::harness_solver::HarnessStatics;
use crate::modal::{
    dissipated_power, energy_shares, lowest_pairs, lumped_mass, modal_mass, HeldRate, ModalError,
    ModeKind, ShiftInvert, REFINEMENT_STEPS,
};
use crate::statics::NewtonOptions;
use nalgebra::{Matrix6, Vector3, Vector6};

/// One natural mode of a harness, mass-normalised over the whole harness (φᵀ M φ = 1).
#[derive(Clone, Debug)]
pub struct HarnessMode {
    /// λ = ω², 1/s².
    pub eigenvalue: f64,
    /// ω, rad/s.
    pub omega: f64,
    /// Per cable, per block: node displacement (global) and edge rotation (body frame), as
    /// `modal::Mode::shape` (zero at the nodes held by clips and junctions).
    pub cables: Vec<Vec<Vector6<f64>>>,
    /// Per junction: displacement (global) and rotation (junction body frame).
    pub junctions: Vec<Vector6<f64>>,
    /// Shares of the cables' modal kinetic energy: bending d1, bending d2, torsion, axial.
    pub shares: [f64; 4],
    pub kind: ModeKind,
}

/// The buffers of a harness's pencil, allocated once (`HarnessStability` keeps them across the
/// steps of a sequence): `k` the assembled symmetric stiffness (kept for products), `work` its
/// shifted copy factored by the tree elimination.
#[derive(Clone)]
pub struct ModalSystem {
    k: HarnessStatics,
    work: HarnessStatics,
    /// Lumped mass on the flattened unknowns: the cables' blocks in order, then the junctions.
    m: Vec<Vector6<f64>>,
    offsets: Vec<usize>,
    sigma: f64,
    xc: Vec<Vec<Vector6<f64>>>,
    xj: Vec<Vector6<f64>>,
    /// M x and a refinement's correction in `HarnessPencil::apply` (flattened unknowns).
    mx: Vec<Vector6<f64>>,
    dy: Vec<Vector6<f64>>,
}

/// The lumped mass of junction `j` on its unknowns: its own mass plus the node masses of the
/// cable ends it holds (translations), its rotary inertia (body-frame rotations).
fn junction_mass(h: &Harness, j: usize) -> Vector6<f64> {
    let js = &h.junctions[j];
    let ends: f64 = h.junction_ends[j]
        .iter()
        .map(|&e| h.cables[h.ends[e].cable].node_mass[h.ends[e].topo.node])
        .sum();
    let mt = js.mass + ends;
    let r = js.rotary_inertia;
    Vector6::new(mt, mt, mt, r.x, r.y, r.z)
}

/// The pencil (K, M) of a harness on its buffers.
struct HarnessPencil<'a> {
    h: &'a Harness,
    s: &'a mut ModalSystem,
}

impl ModalSystem {
    pub fn new(h: &Harness) -> Self {
        let k = HarnessStatics::new(h, NewtonOptions::default());
        let mut work = HarnessStatics::new(h, NewtonOptions::default());
        work.symmetric = true;
        let mut m = Vec::new();
        let mut offsets = Vec::with_capacity(h.cables.len() + 1);
        for rod in &h.cables {
            offsets.push(m.len());
            m.extend(lumped_mass(rod));
        }
        offsets.push(m.len());
        m.extend((0..h.junctions.len()).map(|j| junction_mass(h, j)));
        let xc = h
            .cables
            .iter()
            .map(|r| vec![Vector6::zeros(); r.arc.len()])
            .collect();
        let xj = vec![Vector6::zeros(); h.junctions.len()];
        let n = m.len();
        ModalSystem {
            k,
            work,
            m,
            offsets,
            sigma: 0.0,
            xc,
            xj,
            mx: vec![Vector6::zeros(); n],
            dy: vec![Vector6::zeros(); n],
        }
    }

    /// `load` with each cable's contact term in K (`contact`: the solver's, per cable; swapped
    /// in for the assembly and back, nothing copied). Only frictionless contact is
    /// conservative: with friction the symmetric part is no stability criterion (callers skip).
    pub fn load_with_contact(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        contact: &mut Vec<Option<Contact>>,
    ) -> Result<(), HarnessError> {
        std::mem::swap(&mut self.k.contact, contact);
        let result = self.load(h, st);
        std::mem::swap(&mut self.k.contact, contact);
        result
    }

    /// Assembles the symmetric tangent stiffness of `h` at `st`.
    pub fn load(&mut self, h: &Harness, st: &HarnessState) -> Result<(), HarnessError> {
        let k = &mut self.k;
        k.assemble(h, st, 1.0, true)?;
        // The symmetric part: the Hessian at the equilibrium (see `stability`).
        for ws in &mut k.ws {
            let jac = &mut ws.jac;
            let n = jac.n_blocks();
            for b in 0..n {
                jac.diag[b] = 0.5 * (jac.diag[b] + jac.diag[b].transpose());
                if b + 1 < n {
                    let u = 0.5 * (jac.upper[b] + jac.lower[b + 1].transpose());
                    jac.upper[b] = u;
                    jac.lower[b + 1] = u.transpose();
                }
            }
        }
        for held in &mut k.held {
            for end in &mut held.ends {
                end.ee = 0.5 * (end.ee + end.ee.transpose());
                for i in 0..2 {
                    let s = 0.5 * (end.ec[i] + end.ce[i].transpose());
                    end.ec[i] = s;
                    end.ce[i] = s.transpose();
                }
            }
        }
        for (w, k) in self.work.held.iter_mut().zip(&self.k.held) {
            w.ends.clone_from(&k.ends);
        }
        Ok(())
    }
}

impl HarnessPencil<'_> {
    fn split(&mut self, x: &[Vector6<f64>]) {
        for (c, xc) in self.s.xc.iter_mut().enumerate() {
            xc.copy_from_slice(&x[self.s.offsets[c]..self.s.offsets[c + 1]]);
        }
        let nc = self.s.offsets[self.s.xc.len()];
        self.s.xj.copy_from_slice(&x[nc..]);
    }

    /// y = (K − σM)⁻¹ r for the flattened r (one tree solve).
    fn solve(&mut self, r: &[Vector6<f64>], y: &mut [Vector6<f64>]) {
        let nc = self.s.offsets[self.s.xc.len()];
        for (c, ws) in self.s.work.ws.iter_mut().enumerate() {
            for (o, v) in ws.rhs.iter_mut().zip(&r[self.s.offsets[c]..]) {
                *o = -v;
            }
        }
        for (o, v) in self.s.work.junction_residual.iter_mut().zip(&r[nc..]) {
            *o = -v;
        }
        self.s.work.newton_correction(self.h);
        let (dc, dj) = self.s.work.correction();
        for (c, d) in dc.iter().enumerate() {
            y[self.s.offsets[c]..self.s.offsets[c + 1]].copy_from_slice(d);
        }
        y[nc..].copy_from_slice(dj);
    }

    /// r ← b − (K − σM) y.
    fn residual(&mut self, b: &[Vector6<f64>], y: &[Vector6<f64>], r: &mut [Vector6<f64>]) {
        self.split(y);
        let (kc, kj) = self.s.k.jacobian_times(self.h, &self.s.xc, &self.s.xj);
        let nc = self.s.offsets[self.s.xc.len()];
        for (c, kv) in kc.iter().enumerate() {
            r[self.s.offsets[c]..self.s.offsets[c + 1]].copy_from_slice(kv);
        }
        r[nc..].copy_from_slice(&kj);
        for (((r, b), y), m) in r.iter_mut().zip(b).zip(y).zip(&self.s.m) {
            *r = b - (*r - self.s.sigma * y.component_mul(m));
        }
    }
}

impl ShiftInvert for HarnessPencil<'_> {
    fn mass(&self) -> &[Vector6<f64>] {
        &self.s.m
    }

    fn factor(&mut self, sigma: f64) -> Option<usize> {
        self.s.sigma = sigma;
        for (c, ws) in self.s.work.ws.iter_mut().enumerate() {
            ws.jac.clone_from(&self.s.k.ws[c].jac);
            for (b, d) in ws.jac.diag.iter_mut().enumerate() {
                *d -= Block::from_diagonal(&(self.s.m[self.s.offsets[c] + b] * sigma));
            }
        }
        let nc = self.s.offsets[self.s.xc.len()];
        for (d, m) in self.s.work.junction_extra.iter_mut().zip(&self.s.m[nc..]) {
            *d = Matrix6::from_diagonal(&(-sigma * m));
        }
        self.s.work.factor(self.h).ok()?;
        (self.s.work.inertia.zero == 0).then_some(self.s.work.inertia.negative)
    }

    /// y = (K − σM)⁻¹ M x by the tree solve with, if `refine`, two steps of iterative
    /// refinement (as the single cable's `apply`).
    fn apply(
        &mut self,
        x: &[Vector6<f64>],
        y: &mut [Vector6<f64>],
        r: &mut [Vector6<f64>],
        refine: bool,
    ) {
        // the system's buffers, taken out for the calls that borrow it
        let (mut b, mut dy) = (
            std::mem::take(&mut self.s.mx),
            std::mem::take(&mut self.s.dy),
        );
        for ((b, x), m) in b.iter_mut().zip(x).zip(&self.s.m) {
            *b = x.component_mul(m);
        }
        self.solve(&b, y);
        for _ in 0..if refine { REFINEMENT_STEPS } else { 0 } {
            self.residual(&b, y, r);
            self.solve(r, &mut dy);
            for (y, d) in y.iter_mut().zip(&dy) {
                *y += d;
            }
        }
        (self.s.mx, self.s.dy) = (b, dy);
    }
}

/// Eigenvalue scale for shifts off a singular point: the largest translational K_ii/M_ii.
fn eigen_scale(p: &ModalSystem) -> f64 {
    let mut scale = 0.0f64;
    for (c, ws) in p.k.ws.iter().enumerate() {
        for (b, kb) in ws.jac.diag.iter().enumerate() {
            let mb = p.m[p.offsets[c] + b];
            for s in (0..3).filter(|&s| mb[s] > 0.0) {
                scale = scale.max(kb[(s, s)].abs() / mb[s]);
            }
        }
    }
    scale.max(1e-300)
}

/// The number of negative eigenvalues of the harness's symmetric tangent stiffness at `st`
/// (0: a stable equilibrium), from the pivots of its tree LDLᵀ. A singular K (a free rigid
/// motion) is shifted by a round-off amount below its zero eigenvalues.
pub fn harness_negative_count(h: &Harness, st: &HarnessState) -> Result<usize, HarnessError> {
    ModalSystem::new(h).negative_count(h, st)
}

impl ModalSystem {
    /// `harness_negative_count` on these buffers (no allocation after the first call).
    pub fn negative_count(
        &mut self,
        h: &Harness,
        st: &HarnessState,
    ) -> Result<usize, HarnessError> {
        self.load(h, st)?;
        Ok(self.loaded_negative_count(h))
    }

    /// `negative_count` with each cable's (frictionless) contact in K (`load_with_contact`).
    pub fn negative_count_with_contact(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        contact: &mut Vec<Option<Contact>>,
    ) -> Result<usize, HarnessError> {
        self.load_with_contact(h, st, contact)?;
        Ok(self.loaded_negative_count(h))
    }

    fn loaded_negative_count(&mut self, h: &Harness) -> usize {
        let scale = eigen_scale(self);
        HarnessPencil { h, s: self }
            .factor_near(0.0, 1e-12 * scale)
            .1
    }
}

/// An unstable mode of a harness: λ < 0, per cable block vectors, per junction 6-vectors.
pub(crate) type UnstableMode = (f64, Vec<Vec<Vector6<f64>>>, Vec<Vector6<f64>>);

impl ModalSystem {
    /// The mode of the most negative eigenvalue of K φ = λ M φ at `st` (per cable block
    /// vectors, per junction 6-vectors; M-normalised) and λ, for the escape from an unstable
    /// equilibrium (`harness_escape`); None if K has no negative eigenvalue (or no shift below
    /// it was found). Inverse iteration with K − μM, μ below the spectrum (the tree LDLᵀ has no
    /// negative pivot there), then shifted 1 % below the Rayleigh quotient: the two bending
    /// planes of a round section give two nearly equal eigenvalues.
    pub(crate) fn unstable_mode(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        contact: &mut Vec<Option<Contact>>,
    ) -> Result<Option<UnstableMode>, HarnessError> {
        self.load_with_contact(h, st, contact)?;
        let scale = eigen_scale(self);
        let n = self.m.len();
        let mut p = HarnessPencil { h, s: self };
        if p.factor_near(0.0, 1e-12 * scale).1 == 0 {
            return Ok(None);
        }
        let mut x: Vec<Vector6<f64>> = vec![Vector6::zeros(); n];
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for (v, m) in x.iter_mut().zip(&p.s.m) {
            for k in 0..6 {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                let r = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                v[k] = if m[k] > 0.0 { r } else { 0.0 };
            }
        }
        let (mut y, mut r) = (vec![Vector6::zeros(); n], vec![Vector6::zeros(); n]);
        let m_dot = |a: &[Vector6<f64>], b: &[Vector6<f64>], m: &[Vector6<f64>]| -> f64 {
            a.iter()
                .zip(b)
                .zip(m)
                .map(|((a, b), m)| a.component_mul(b).dot(m))
                .sum()
        };
        let mut mu = -1e-8 * scale;
        let mut rho = f64::NAN;
        for pass in 0..2 {
            let mut found = false;
            for _ in 0..40 {
                if p.factor(mu) == Some(0) {
                    found = true;
                    break;
                }
                mu *= if pass == 0 { 10.0 } else { 1.1 };
            }
            if !found {
                return Ok(None);
            }
            for _ in 0..(if pass == 0 { 30 } else { 40 }) {
                p.apply(&x, &mut y, &mut r, true);
                let xmy = m_dot(&x, &y, &p.s.m);
                let xmx = m_dot(&x, &x, &p.s.m);
                rho = mu + xmx / xmy;
                let nrm = m_dot(&y, &y, &p.s.m).sqrt().max(1e-300);
                for (a, b) in x.iter_mut().zip(&y) {
                    *a = b / nrm;
                }
            }
            if rho.is_nan() || rho >= 0.0 {
                return Ok(None);
            }
            mu = 1.01 * rho;
        }
        let sys = &*p.s;
        let nc = sys.offsets[h.cables.len()];
        let cables = (0..h.cables.len())
            .map(|c| x[sys.offsets[c]..sys.offsets[c + 1]].to_vec())
            .collect();
        Ok(Some((rho, cables, x[nc..].to_vec())))
    }
}

/// The `count` lowest natural modes of the harness at the equilibrium `st`.
pub fn harness_lowest_modes(
    h: &Harness,
    st: &HarnessState,
    count: usize,
) -> Result<Vec<HarnessMode>, HarnessError> {
    harness_lowest_modes_with_contact(h, st, count, None, crate::modal::TOLERANCE)
}

/// `harness_lowest_modes` with each cable's contact stiffness in K (`contact`: the solver's
/// terms, `ModalSystem::load_with_contact`): the modes of a harness resting on the geometry
/// (without it, the part the contact carries is no equilibrium of K alone and shows as
/// unstable).
pub fn harness_lowest_modes_with_contact(
    h: &Harness,
    st: &HarnessState,
    count: usize,
    contact: Option<&mut Vec<Option<Contact>>>,
    tolerance: f64,
) -> Result<Vec<HarnessMode>, HarnessError> {
    let describe = |e: ModalError| HarnessError(format!("modal analysis of the harness: {e}"));
    let mut sys = ModalSystem::new(h);
    match contact {
        Some(c) => sys.load_with_contact(h, st, c)?,
        None => sys.load(h, st)?,
    }
    let p = &sys;
    let massive =
        p.m.iter()
            .flat_map(|v| v.iter())
            .filter(|&&x| x > 0.0)
            .count();
    if massive == 0 {
        return Err(describe(ModalError::NoUnknowns));
    }
    let count = count.clamp(1, massive);
    let scale = eigen_scale(p);
    let ritz = lowest_pairs(
        &mut HarnessPencil { h, s: &mut sys },
        count,
        massive,
        scale,
        tolerance,
    )
    .map_err(describe)?;
    let p = &sys;
    let nc = p.offsets[h.cables.len()];
    Ok(ritz
        .values
        .iter()
        .zip(&ritz.vectors)
        .map(|(&lambda, v)| {
            let mut shares = [0.0; 4];
            let mut big = (0.0f64, 1.0f64);
            let mut total = 0.0;
            for (c, rod) in h.cables.iter().enumerate() {
                let range = p.offsets[c]..p.offsets[c + 1];
                let (s, b) = energy_shares(rod, &st.cables[c], &p.m[range.clone()], &v[range]);
                for k in 0..4 {
                    shares[k] += s[k];
                }
                if b.0 > big.0 {
                    big = b;
                }
            }
            for (x, m) in v[nc..].iter().zip(&p.m[nc..]) {
                total += x.component_mul(x).dot(m);
            }
            total += shares.iter().sum::<f64>();
            let cable_total: f64 = shares.iter().sum();
            if cable_total > 0.0 {
                shares.iter_mut().for_each(|s| *s /= cable_total);
            }
            let nrm = total.sqrt().max(1e-300) * big.1;
            let scaled: Vec<Vector6<f64>> = v.iter().map(|x| x / nrm).collect();
            HarnessMode {
                eigenvalue: lambda,
                omega: lambda.sqrt(),
                cables: (0..h.cables.len())
                    .map(|c| scaled[p.offsets[c]..p.offsets[c + 1]].to_vec())
                    .collect(),
                junctions: scaled[nc..].to_vec(),
                shares,
                kind: ModeKind::dominant(&shares),
            }
        })
        .collect())
}

/// The modal damping ratio of a harness mode with the Kelvin–Voigt section law of each cable
/// (`shear_tau[c]`, `bend_tau[c]` the retardation times of cable c's (GA₁, GA₂, EA) and
/// (EI₁, EI₂, GJ)): the Rayleigh quotient ζ = φᵀCφ / (2ω φᵀMφ) over the whole tree, as
/// `modal::damping_ratio` for one cable. The ends a junction holds move with it in the mode
/// (node velocity = the junction's displacement, ghost angular velocity = its rotation in the
/// end's frame), so the half cells and edges next to a junction dissipate as in a continuous
/// cable; the junction itself carries no damping.
pub fn harness_damping_ratio(
    h: &Harness,
    st: &HarnessState,
    mode: &HarnessMode,
    shear_tau: &[Vector3<f64>],
    bend_tau: &[Vector3<f64>],
) -> Result<f64, HarnessError> {
    let nc = h.cables.len();
    if shear_tau.len() != nc || bend_tau.len() != nc {
        return Err(HarnessError(format!(
            "damping ratios: {} shear and {} bending retardation time triples for {nc} cables",
            shear_tau.len(),
            bend_tau.len()
        )));
    }
    let mut power = 0.0;
    let mut mass = 0.0;
    let mut held = Vec::new();
    for (c, rod) in h.cables.iter().enumerate() {
        held.clear();
        held.extend(h.ends.iter().filter(|e| e.cable == c).map(|e| {
            let x = mode.junctions[e.junction];
            HeldRate {
                node: e.topo.node,
                velocity: x.fixed_rows::<3>(0).into_owned(),
                ghost: e.topo.ghost,
                angular_velocity: e.rel.transpose() * x.fixed_rows::<3>(3),
            }
        }));
        let shape = &mode.cables[c];
        power += dissipated_power(rod, &st.cables[c], shape, shear_tau[c], bend_tau[c], &held)
            .map_err(|e| HarnessError(format!("damping ratio of cable '{}': {e}", h.names[c])))?;
        mass += modal_mass(rod, shape);
    }
    for (j, x) in mode.junctions.iter().enumerate() {
        mass += x.component_mul(x).dot(&junction_mass(h, j));
    }
    if !(mode.omega > 0.0 && mass > 0.0) {
        return Ok(0.0);
    }
    Ok(power / (2.0 * mode.omega * mass))
}

#[cfg(test)]
#[path = "harness_modal_tests.rs"]
mod tests;
