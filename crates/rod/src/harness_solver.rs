//! The static and quasistatic solver of a harness (docs/solver.md, "Harnesses"): assembly of
//! the cables with their junction couplings, block elimination on the tree (each cable
//! segment's chain onto its junctions, then the junction tree leaves first), Newton,
//! pseudo-transient and load continuation, sequences.
use crate::assembly::Workspace;
use crate::block_tridiag::{pivot_inertia, BlockTridiag, Inertia};
use crate::contact::Contact;
use crate::harness::{Harness, HarnessError, HarnessState};
use crate::junction::HeldEnds;
use crate::model::{Pose, Rod};
use crate::rotation::slerp;
use crate::sliding::SlidingClips;
use crate::statics::{
    continue_load, restep_load_scaled, solve_load_scaled, NewtonOptions, SolveError, SolveStats,
};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

#[inline]
fn rows_to_junction(m: &Matrix6<f64>, r: &Matrix3<f64>) -> Matrix6<f64> {
    let mut out = *m;
    let low = r * m.fixed_view::<3, 6>(3, 0);
    out.fixed_view_mut::<3, 6>(3, 0).copy_from(&low);
    out
}

#[inline]
fn cols_to_junction(m: &Matrix6<f64>, r: &Matrix3<f64>) -> Matrix6<f64> {
    let mut out = *m;
    let right = m.fixed_view::<6, 3>(0, 3) * r.transpose();
    out.fixed_view_mut::<6, 3>(0, 3).copy_from(&right);
    out
}

#[inline]
pub(crate) fn vec_to_junction(v: &Vector6<f64>, r: &Matrix3<f64>) -> Vector6<f64> {
    let mut out = *v;
    let low = r * v.fixed_rows::<3>(3);
    out.fixed_rows_mut::<3>(3).copy_from(&low);
    out
}

/// Largest junction displacement per Newton iteration, as a fraction of the shortest cable.
const JUNCTION_STEP: f64 = 0.1;

/// Inverse of a junction pivot, or None when it is singular to working precision.
fn invert(m: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    let inv = m.try_inverse()?;
    let cond = m.amax() * inv.amax();
    (cond.is_finite() && cond < 1e14).then_some(inv)
}

/// Static and quasistatic solver of a harness: the cables' workspaces, the coupling terms and
/// the buffers of the tree elimination (allocated once).
#[derive(Clone)]
pub struct HarnessStatics {
    pub ws: Vec<Workspace>,
    pub held: Vec<HeldEnds>,
    /// Per cable: the sliding clips' term (None without sliding clips).
    pub sliding: Vec<Option<SlidingClips>>,
    /// Per cable: contact with the surroundings (None without; `harness_contact`).
    pub contact: Vec<Option<Contact>>,
    /// Per cable: the smallest gap before a Newton trial (`contact_bound`).
    pub(crate) gap0: Vec<f64>,
    pub opts: NewtonOptions,
    pub(crate) delta: Vec<Vec<Vector6<f64>>>,
    trial: Vec<Vec<Vector6<f64>>>,
    y: Vec<Vec<Vector6<f64>>>,
    pub(crate) dj: Vec<Vector6<f64>>,
    trial_j: Vec<Vector6<f64>>,
    /// Junction residuals (∂V/∂(X, Θ)).
    pub junction_residual: Vec<Vector6<f64>>,
    held_junction: Vec<bool>,
    /// Per end: A⁻¹ B_k over its cable, one 6×6 block per cable block (its six columns side
    /// by side, so that applying a junction's correction is one pass over the cable).
    z: Vec<Vec<Matrix6<f64>>>,
    /// Per cable: one block vector for solving a column of A⁻¹ B_k.
    column: Vec<Vec<Vector6<f64>>>,
    /// Per cable segment: its junction end when it is the segment's only one (the segment is
    /// then eliminated towards that end, which takes its Schur complement from the last two
    /// blocks: no A⁻¹ B_k columns; `BlockTridiag::solve_tail`).
    tail_end: Vec<Vec<Option<usize>>>,
    /// Whether `factor` took that path (not in the symmetric factorisation); tests switch it
    /// off with `tail_path` to compare with the columns.
    tail_factored: bool,
    pub(crate) tail_path: bool,
    /// Per end on that path: A⁻¹ r at its blocks (`topo.blocks()`) in the last solve.
    tail_x: Vec<[Vector6<f64>; 2]>,
    /// Junction pivots (after the tree elimination) and their inverses.
    pivot: Vec<Matrix6<f64>>,
    pivot_inv: Vec<Matrix6<f64>>,
    /// Schur blocks of the links: rows a cols b, rows b cols a.
    link_ab: Vec<Matrix6<f64>>,
    link_ba: Vec<Matrix6<f64>>,
    b: Vec<Vector6<f64>>,
    base: HarnessState,
    saved: HarnessState,
    start_poses: Vec<Vec<Pose>>,
    poses: Vec<Vec<Pose>>,
    pose_buffer: Vec<Pose>,
    /// The last two equilibria of a sequence (the predictor of `sequence_step`).
    last: HarnessState,
    prev: HarnessState,
    has_prev: bool,
    /// Pseudo-transient damping added to the junction pivots by `factor` (position, rotation).
    junction_shift: (f64, f64),
    /// Further junction pivot blocks: the junctions' inertia in dynamics, −σ M_j in
    /// `harness_modal`; zero in statics.
    pub(crate) junction_extra: Vec<Matrix6<f64>>,
    force_scale: f64,
    /// With `symmetric`, `factor` uses the symmetric block LDLᵀ on the cables and records the
    /// inertia of the tree factorisation (Sylvester: the cables' chain pivots plus the junction
    /// pivots) in `inertia` — the stability check and the Sturm count of `harness_modal`.
    pub symmetric: bool,
    pub inertia: Inertia,
    /// The pencil of the stability check and escape (`harness_escape`), made at first use.
    pub(crate) escape_modal: Option<Box<crate::harness_modal::ModalSystem>>,
    /// Length scales: the shortest cable (steps) and the finest mean segment (moments).
    length: f64,
    h: f64,
    /// A push-out stage solve (`harness_contact`): fallbacks cut short, no load continuation.
    pub(crate) stage: bool,
}

impl HarnessStatics {
    pub fn new(h: &Harness, opts: NewtonOptions) -> Self {
        let mut force_scale = 1e-12f64;
        let mut length = f64::INFINITY;
        let mut hmin = f64::INFINITY;
        for rod in &h.cables {
            let sec = &rod.spec.section;
            let l = rod.spec.length;
            let weight = sec.mass_per_length * l * rod.spec.gravity.norm();
            let loads = rod
                .spec
                .loads
                .iter()
                .map(|ld| ld.force.norm() + ld.moment.norm() / l)
                .fold(0.0, f64::max);
            let bend = sec.bend_stiffness.max() / (l * l);
            force_scale = force_scale.max(weight).max(loads).max(bend);
            length = length.min(l);
            hmin = hmin.min(rod.mean_ds());
        }
        for j in &h.junctions {
            force_scale = force_scale.max(j.mass * h.gravity.norm());
        }
        let blocks = |c: usize| vec![Vector6::zeros(); h.cables[c].arc.len()];
        let per_cable = || (0..h.cables.len()).map(blocks).collect::<Vec<_>>();
        let nj = h.junctions.len();
        HarnessStatics {
            ws: h.cables.iter().map(Workspace::new).collect(),
            held: h.held_ends(),
            sliding: h.cables.iter().map(SlidingClips::of).collect(),
            contact: vec![None; h.cables.len()],
            gap0: vec![f64::INFINITY; h.cables.len()],
            opts,
            delta: per_cable(),
            trial: per_cable(),
            y: per_cable(),
            dj: vec![Vector6::zeros(); nj],
            trial_j: vec![Vector6::zeros(); nj],
            junction_residual: vec![Vector6::zeros(); nj],
            held_junction: h.held.clone(),
            z: h.ends
                .iter()
                .map(|e| vec![Matrix6::zeros(); h.cables[e.cable].arc.len()])
                .collect(),
            column: per_cable(),
            tail_end: tail_ends(h),
            tail_factored: false,
            tail_path: true,
            tail_x: vec![[Vector6::zeros(); 2]; h.ends.len()],
            pivot: vec![Matrix6::zeros(); nj],
            pivot_inv: vec![Matrix6::zeros(); nj],
            link_ab: vec![Matrix6::zeros(); h.links.len()],
            link_ba: vec![Matrix6::zeros(); h.links.len()],
            b: vec![Vector6::zeros(); nj],
            base: HarnessState::empty(),
            saved: HarnessState::empty(),
            start_poses: Vec::new(),
            poses: Vec::new(),
            pose_buffer: Vec::new(),
            last: HarnessState::empty(),
            prev: HarnessState::empty(),
            has_prev: false,
            junction_shift: (0.0, 0.0),
            junction_extra: vec![Matrix6::zeros(); nj],
            force_scale,
            symmetric: false,
            inertia: Inertia::default(),
            escape_modal: None,
            length,
            h: hmin,
            stage: false,
        }
    }

    fn cable_err(h: &Harness, c: usize, e: SolveError) -> HarnessError {
        cable_error(h, c, e)
    }

    /// Assembles every cable (internal forces, loads, coupling blocks of the held ends) and
    /// the junction residuals at load factor `lf`.
    pub fn assemble(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        lf: f64,
        want_jac: bool,
    ) -> Result<(), HarnessError> {
        self.held_junction.clone_from(&h.held);
        for (c, rod) in h.cables.iter().enumerate() {
            self.ws[c]
                .assemble_terms(
                    rod,
                    &st.cables[c],
                    lf,
                    want_jac,
                    // The held ends last: their blocks take the other terms' entries at the
                    // end nodes (`Workspace::end_jac`) and the complete ghost gradients.
                    &mut [
                        &mut self.sliding[c],
                        &mut self.contact[c],
                        &mut self.held[c],
                    ],
                )
                .map_err(|k| {
                    Self::cable_err(
                        h,
                        c,
                        SolveError::Kink {
                            node: k.node,
                            s: rod.arc[k.node],
                        },
                    )
                })?;
        }
        for (j, js) in h.junctions.iter().enumerate() {
            let mut r = Vector6::zeros();
            for &k in &h.junction_ends[j] {
                let e = &h.ends[k];
                let local = self.held[e.cable].ends[e.local].residual(&self.ws[e.cable]);
                r += vec_to_junction(&local, &e.rel);
            }
            let w = lf * js.mass * h.gravity;
            r[0] -= w.x;
            r[1] -= w.y;
            r[2] -= w.z;
            self.junction_residual[j] = r;
        }
        Ok(())
    }

    /// Largest scaled residual (N; moments divided by the finest mean segment length).
    pub fn residual_inf(&self) -> f64 {
        self.residual_norms().1
    }

    /// Scaled residual norms (2-norm, ∞-norm) over the cables and junctions.
    pub fn residual_norms(&self) -> (f64, f64) {
        let mut inf = 0.0f64;
        let mut two = 0.0;
        for ws in &self.ws {
            let (t, i) = ws.residual_norms(self.h);
            inf = inf.max(i);
            two += t * t;
        }
        for (r, _) in self
            .junction_residual
            .iter()
            .zip(&self.held_junction)
            .filter(|(_, &held)| !held)
        {
            for k in 0..6 {
                let v = if k < 3 { r[k] } else { r[k] / self.h };
                inf = inf.max(v.abs());
                two += v * v;
            }
        }
        (two.sqrt(), inf)
    }

    /// Factors the assembled system: each cable segment, the Schur complements onto the
    /// junctions, the junction tree (leaves first).
    pub fn factor(&mut self, h: &Harness) -> Result<(), HarnessError> {
        self.inertia = Inertia::default();
        self.tail_factored = self.tail_path && !self.symmetric;
        for (c, rod) in h.cables.iter().enumerate() {
            for (s, seg) in rod.segments.iter().enumerate() {
                if self.symmetric {
                    let i = self.ws[c].jac.ldlt(seg.blocks.clone());
                    self.inertia.negative += i.negative;
                    self.inertia.zero += i.zero;
                } else {
                    let rev = self.tail_factored
                        && self.tail_end[c][s].is_some_and(|k| h.ends[k].topo.at_start);
                    self.ws[c]
                        .factor_segment_dir(rod, seg, rev)
                        .map_err(|e| Self::cable_err(h, c, e))?;
                }
            }
        }
        for (j, list) in h.junction_ends.iter().enumerate() {
            let mut d = Matrix6::zeros();
            for &k in list {
                let e = &h.ends[k];
                let ee = &self.held[e.cable].ends[e.local].ee;
                d += cols_to_junction(&rows_to_junction(ee, &e.rel), &e.rel);
            }
            for k in 0..6 {
                d[(k, k)] += if k < 3 {
                    self.junction_shift.0
                } else {
                    self.junction_shift.1
                };
            }
            self.pivot[j] = d + self.junction_extra[j];
        }
        self.link_ab.iter_mut().for_each(|m| m.fill(0.0));
        self.link_ba.iter_mut().for_each(|m| m.fill(0.0));
        // Z_k = A⁻¹ B_k for every end (but those of the tail path).
        for (k, e) in h.ends.iter().enumerate() {
            let Some(s) = e.segment else { continue };
            if self.on_tail(h, k) {
                continue;
            }
            let rod = &h.cables[e.cable];
            let range = rod.segments[s].blocks.clone();
            let blocks = e.topo.blocks();
            let eb = &self.held[e.cable].ends[e.local];
            let column = &mut self.column[e.cable];
            for col in 0..6 {
                for v in &mut column[range.clone()] {
                    v.fill(0.0);
                }
                for (i, &b) in blocks.iter().enumerate() {
                    let bk = cols_to_junction(&eb.ce[i], &e.rel);
                    if range.contains(&b) {
                        column[b] += bk.column(col);
                    }
                }
                self.ws[e.cable].jac.solve_range(range.clone(), column);
                for (zb, v) in self.z[k][range.clone()]
                    .iter_mut()
                    .zip(&column[range.clone()])
                {
                    zb.set_column(col, v);
                }
            }
        }
        // Schur complements: S_kl = −C_k A⁻¹ B_l for the ends k, l of one cable segment.
        for (k, e) in h.ends.iter().enumerate() {
            let Some(s) = e.segment else { continue };
            let eb = &self.held[e.cable].ends[e.local];
            let ck = [
                rows_to_junction(&eb.ec[0], &e.rel),
                rows_to_junction(&eb.ec[1], &e.rel),
            ];
            let blocks = e.topo.blocks();
            if self.on_tail(h, k) {
                // The segment's only junction end, eliminated last: A⁻¹ B_k at its blocks.
                let range = &h.cables[e.cable].segments[s].blocks;
                let rev = e.topo.at_start;
                let (last, _) = BlockTridiag::tail_blocks(range, rev);
                let (b_last, b_prev) = onto_tail(blocks, last, Matrix6::zeros(), |i| {
                    cols_to_junction(&eb.ce[i], &e.rel)
                });
                let x = self.ws[e.cable]
                    .jac
                    .solve_tail(range, rev, &b_last, &b_prev);
                let [x0, x1] = from_tail(blocks, last, x);
                self.pivot[e.junction] -= ck[0] * x0 + ck[1] * x1;
                continue;
            }
            for &l in &h.cable_ends[e.cable] {
                if h.ends[l].segment != Some(s) {
                    continue;
                }
                let z = &self.z[l];
                let m = ck[0] * z[blocks[0]] + ck[1] * z[blocks[1]];
                if l == k {
                    self.pivot[e.junction] -= m;
                } else if let Some(li) = h.links.iter().position(|x| x.end_a == k && x.end_b == l) {
                    self.link_ab[li] -= m;
                } else if let Some(li) = h.links.iter().position(|x| x.end_b == k && x.end_a == l) {
                    self.link_ba[li] -= m;
                }
            }
        }
        // The junction tree, leaves first.
        for &j in h.order.iter().rev() {
            if h.held[j] {
                // A prescribed junction: no increment, no coupling to its parent.
                self.pivot_inv[j] = Matrix6::zeros();
                continue;
            }
            if self.symmetric {
                let scale = self.pivot[j].diagonal().amax();
                pivot_inertia(&self.pivot[j], scale, &mut self.inertia);
            }
            let inv = invert(&self.pivot[j]).ok_or_else(|| {
                HarnessError(format!(
                    "the stiffness matrix is singular at junction '{}': the harness is not held \
                     against a rigid-body motion there (every branch free), or a section \
                     stiffness is zero",
                    h.junctions[j].name
                ))
            })?;
            self.pivot_inv[j] = inv;
            if let Some((p, l)) = h.parent[j] {
                let (s_pj, s_jp) = self.link_blocks(h, p, l);
                self.pivot[p] -= s_pj * inv * s_jp;
            }
        }
        Ok(())
    }

    /// Whether end k is on the tail path of the last factorisation.
    pub(crate) fn on_tail(&self, h: &Harness, k: usize) -> bool {
        let e = &h.ends[k];
        self.tail_factored
            && e.segment
                .is_some_and(|s| self.tail_end[e.cable][s] == Some(k))
    }

    /// (S_pj, S_jp) of link l whose one junction is p.
    fn link_blocks(&self, h: &Harness, p: usize, l: usize) -> (Matrix6<f64>, Matrix6<f64>) {
        if h.links[l].a == p {
            (self.link_ab[l], self.link_ba[l])
        } else {
            (self.link_ba[l], self.link_ab[l])
        }
    }

    /// Solves J Δ = −r with the factorisation for the cable residuals `rc` (block vectors, as
    /// `ws.rhs`) and junction residuals `rj`; returns the largest |Δx| and |θ|.
    pub(crate) fn solve(&mut self, h: &Harness, use_trial: bool) -> (f64, f64) {
        for (c, rod) in h.cables.iter().enumerate() {
            let y = &mut self.y[c];
            y.copy_from_slice(&self.ws[c].rhs);
            for (s, seg) in rod.segments.iter().enumerate() {
                let jac = &self.ws[c].jac;
                match self.tail_end[c][s].filter(|_| self.tail_factored) {
                    Some(k) => {
                        // Towards the end only; the way back once its junction has moved.
                        let topo = &h.ends[k].topo;
                        jac.sweep_in(seg.blocks.clone(), topo.at_start, y);
                        let x = jac.tail_of(&seg.blocks, topo.at_start, y);
                        let (last, _) = BlockTridiag::tail_blocks(&seg.blocks, topo.at_start);
                        self.tail_x[k] = from_tail(topo.blocks(), last, x);
                    }
                    None => jac.solve_range(seg.blocks.clone(), y),
                }
            }
        }
        for (j, list) in h.junction_ends.iter().enumerate() {
            let mut b = self.junction_residual[j];
            for &k in list {
                let e = &h.ends[k];
                if e.segment.is_none() {
                    continue;
                }
                let eb = &self.held[e.cable].ends[e.local];
                let tail = self.on_tail(h, k);
                for (i, &blk) in e.topo.blocks().iter().enumerate() {
                    let x = if tail {
                        self.tail_x[k][i]
                    } else {
                        self.y[e.cable][blk]
                    };
                    b -= rows_to_junction(&eb.ec[i], &e.rel) * x;
                }
            }
            self.b[j] = b;
        }
        for &j in h.order.iter().rev() {
            if let Some((p, l)) = h.parent[j] {
                let (s_pj, _) = self.link_blocks(h, p, l);
                let t = s_pj * (self.pivot_inv[j] * self.b[j]);
                self.b[p] -= t;
            }
        }
        let dj = if use_trial {
            &mut self.trial_j
        } else {
            &mut self.dj
        };
        for &j in &h.order {
            let mut b = self.b[j];
            if let Some((p, l)) = h.parent[j] {
                let s_jp = if h.links[l].a == p {
                    self.link_ba[l]
                } else {
                    self.link_ab[l]
                };
                b -= s_jp * (-dj[p]);
            }
            dj[j] = -(self.pivot_inv[j] * b);
        }
        let (mut dx, mut dth) = (0.0f64, 0.0f64);
        for d in dj.iter() {
            dx = dx.max(d.fixed_rows::<3>(0).amax());
            dth = dth.max(d.fixed_rows::<3>(3).amax());
        }
        let out = if use_trial {
            &mut self.trial
        } else {
            &mut self.delta
        };
        for (oc, yc) in out.iter_mut().zip(&self.y) {
            for (o, y) in oc.iter_mut().zip(yc) {
                *o = -y;
            }
        }
        for (k, e) in h.ends.iter().enumerate() {
            let Some(s) = e.segment else { continue };
            let range = h.cables[e.cable].segments[s].blocks.clone();
            let d = dj[e.junction];
            // (`on_tail`, with `dj` borrowed from self)
            if self.tail_factored && self.tail_end[e.cable][s] == Some(k) {
                // x = A⁻¹(r + B d): B d enters the in-sweep at the tail alone, then the way back.
                let rev = e.topo.at_start;
                let (last, prev) = BlockTridiag::tail_blocks(&range, rev);
                let eb = &self.held[e.cable].ends[e.local];
                let (u_last, u_prev) = onto_tail(e.topo.blocks(), last, Vector6::zeros(), |i| {
                    cols_to_junction(&eb.ce[i], &e.rel) * d
                });
                let jac = &self.ws[e.cable].jac;
                let x = &mut out[e.cable];
                let (w_last, w_prev) = jac.sweep_in_tail(&range, rev, &u_last, &u_prev);
                // `out` holds −y here.
                x[last] -= w_last;
                x[prev] -= w_prev;
                jac.sweep_out(range, rev, x);
                continue;
            }
            if d == Vector6::zeros() {
                continue;
            }
            for (o, z) in out[e.cable][range.clone()]
                .iter_mut()
                .zip(&self.z[k][range])
            {
                *o -= z * d;
            }
        }
        for v in out.iter() {
            for d in v {
                dx = dx.max(d.fixed_rows::<3>(0).amax());
                dth = dth.max(d.fixed_rows::<3>(3).amax());
            }
        }
        (dx, dth)
    }

    /// The Newton correction of the assembled, factored system (into the solver's buffers).
    pub fn newton_correction(&mut self, h: &Harness) -> (f64, f64) {
        self.solve(h, false)
    }

    /// The last Newton correction: per cable block vectors and per junction (ΔX, Θ).
    pub fn correction(&self) -> (&[Vec<Vector6<f64>>], &[Vector6<f64>]) {
        (&self.delta, &self.dj)
    }

    /// y = J v of the assembled system (before `factor`; for checks): cable blocks and
    /// junction 6-vectors.
    pub fn jacobian_times(
        &self,
        h: &Harness,
        v: &[Vec<Vector6<f64>>],
        vj: &[Vector6<f64>],
    ) -> (Vec<Vec<Vector6<f64>>>, Vec<Vector6<f64>>) {
        let mut y: Vec<Vec<Vector6<f64>>> =
            v.iter().map(|x| vec![Vector6::zeros(); x.len()]).collect();
        for (c, rod) in h.cables.iter().enumerate() {
            self.ws[c].jac.mul(&v[c], &mut y[c]);
            for (yb, m) in y[c].iter_mut().zip(&rod.mask) {
                for (k, &active) in m.iter().enumerate() {
                    if !active {
                        yb[k] = 0.0;
                    }
                }
            }
        }
        let mut yj = vec![Vector6::zeros(); h.junctions.len()];
        for e in &h.ends {
            let eb = &self.held[e.cable].ends[e.local];
            let t_v = {
                let mut t = vj[e.junction];
                let rot = e.rel.transpose() * t.fixed_rows::<3>(3);
                t.fixed_rows_mut::<3>(3).copy_from(&rot);
                t
            };
            yj[e.junction] += vec_to_junction(&(eb.ee * t_v), &e.rel);
            for (i, &b) in e.topo.blocks().iter().enumerate() {
                yj[e.junction] += vec_to_junction(&(eb.ec[i] * v[e.cable][b]), &e.rel);
                y[e.cable][b] += eb.ce[i] * t_v;
            }
        }
        (y, yj)
    }

    fn scaled_norm(&self, delta: &[Vec<Vector6<f64>>], dj: &[Vector6<f64>]) -> f64 {
        let l = self.length;
        let mut sum = 0.0;
        for v in delta.iter().flatten().chain(dj) {
            for k in 0..6 {
                let x = if k < 3 { v[k] / l } else { v[k] };
                sum += x * x;
            }
        }
        sum.sqrt()
    }

    /// Newton iterations at load factor `lf` (the rules of `Statics::newton`: rotation steps
    /// capped, halved when a trial kinks; with `damped`, Deuflhard's natural monotonicity test).
    pub fn newton(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        lf: f64,
        damped: bool,
    ) -> Result<SolveStats, HarnessError> {
        self.assemble(h, st, lf, true)?;
        let mut rinf = self.residual_inf();
        let mut stats = SolveStats::default();
        let not_converged = |it: usize, r: f64| {
            HarnessError(format!(
                "{}",
                SolveError::NotConverged {
                    iterations: it,
                    residual: r,
                    load_factor: lf,
                }
            ))
        };
        for it in 0..self.opts.max_iterations {
            stats.iterations = it + 1;
            if rinf <= self.opts.residual_tolerance * self.force_scale {
                stats.iterations = it;
                stats.residual = rinf;
                return Ok(stats);
            }
            self.factor(h)?;
            let (dx, dth) = self.solve(h, false);
            if !(dx.is_finite() && dth.is_finite()) {
                return Err(HarnessError(
                    "the harness's stiffness matrix is singular (non-finite Newton step)".into(),
                ));
            }
            let step = (dx / self.length).max(dth);
            let norm0 = self.scaled_norm(&self.delta, &self.dj);
            let mut alpha = 1.0f64.min(self.opts.max_rotation_step / dth.max(1e-300));
            let djx = self
                .dj
                .iter()
                .map(|d| d.fixed_rows::<3>(0).amax())
                .fold(0.0, f64::max);
            alpha = alpha.min(JUNCTION_STEP * self.length / djx.max(1e-300));
            self.contact_bound(h, st, &mut alpha);
            self.base.clone_from(st);
            let mut accepted = false;
            for _ in 0..16 {
                st.apply_increment(h, &self.delta, &self.dj, alpha);
                if self.assemble(h, st, lf, false).is_ok() {
                    self.solve(h, true);
                    let theta = self.scaled_norm(&self.trial, &self.trial_j) / norm0.max(1e-300);
                    let monotone =
                        theta <= 1.0 - 0.25 * alpha || step * alpha < self.opts.step_tolerance;
                    if theta.is_finite() && (!damped || monotone) && self.contact_feasible() {
                        accepted = true;
                        break;
                    }
                }
                st.clone_from(&self.base);
                alpha *= 0.5;
            }
            if !accepted {
                return Err(not_converged(stats.iterations, rinf));
            }
            self.assemble(h, st, lf, true)?;
            rinf = self.residual_inf();
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!(
                    "harness it {it} lf {lf} alpha {alpha:.3e} step {step:.3e} rinf {rinf:.3e}"
                );
            }
            if alpha == 1.0 && step < self.opts.step_tolerance {
                stats.residual = rinf;
                return Ok(stats);
            }
        }
        Err(not_converged(stats.iterations, rinf))
    }

    /// Pseudo-transient continuation (as `Statics::pseudo_transient`): (J + σD) Δ = −r with D
    /// a viscous medium (δs for positions, Δs³/12 for rotations; the junctions with the finest
    /// mean segment), σ relaxed to zero by switched evolution relaxation.
    pub fn pseudo_transient(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        lf: f64,
        max_iterations: usize,
    ) -> Result<SolveStats, HarnessError> {
        const PTC_START: f64 = 1e-3;
        let damping = |rod: &Rod, b: usize, k: usize| -> f64 {
            if k < 3 {
                rod.ds_node[b]
            } else {
                rod.ds_edge[b.min(rod.n_edges() - 1)].powi(3) / 12.0
            }
        };
        let junction_damping = (self.h, self.h.powi(3) / 12.0);
        self.assemble(h, st, lf, true)?;
        let (mut r_old, mut rinf) = self.residual_norms();
        let mut sigma = 0.0f64;
        for (c, rod) in h.cables.iter().enumerate() {
            for (b, m) in rod.mask.iter().enumerate() {
                for (k, &active) in m.iter().enumerate() {
                    if active {
                        let d = self.ws[c].jac.diag[b][(k, k)].abs() / damping(rod, b, k);
                        sigma = sigma.max(d);
                    }
                }
            }
        }
        sigma *= PTC_START;
        let sigma0 = sigma;
        let mut stats = SolveStats::default();
        let result = (|| {
            for it in 0..max_iterations {
                stats.iterations = it + 1;
                if rinf <= self.opts.residual_tolerance * self.force_scale {
                    stats.iterations = it;
                    stats.residual = rinf;
                    return Ok(stats);
                }
                for (c, rod) in h.cables.iter().enumerate() {
                    for (b, m) in rod.mask.iter().enumerate() {
                        for (k, &active) in m.iter().enumerate() {
                            if active {
                                self.ws[c].jac.diag[b][(k, k)] += sigma * damping(rod, b, k);
                            }
                        }
                    }
                }
                self.junction_shift = (sigma * junction_damping.0, sigma * junction_damping.1);
                self.factor(h)?;
                self.junction_shift = (0.0, 0.0);
                let (dx, dth) = self.solve(h, false);
                let step = (dx / self.length).max(dth);
                let mut alpha = 1.0f64.min(self.opts.max_rotation_step / dth.max(1e-300));
                self.contact_bound(h, st, &mut alpha);
                self.base.clone_from(st);
                st.apply_increment(h, &self.delta, &self.dj, alpha);
                let ok = self.assemble(h, st, lf, true).is_ok() && self.contact_feasible();
                let (r_new, r_inf_new) = if ok {
                    self.residual_norms()
                } else {
                    (f64::INFINITY, f64::INFINITY)
                };
                if !(step.is_finite() && r_new.is_finite()) || r_new > 10.0 * r_old.max(1e-300) {
                    st.clone_from(&self.base);
                    self.assemble(h, st, lf, true)?;
                    sigma = (sigma * 10.0).max(1e-6 * sigma0);
                    continue;
                }
                if std::env::var_os("ROD_DEBUG").is_some() {
                    eprintln!(
                        "harness ptc {it} sigma {sigma:.3e} step {step:.3e} rinf {r_inf_new:.3e}"
                    );
                }
                if sigma == 0.0 && alpha == 1.0 && step < self.opts.step_tolerance {
                    stats.residual = r_inf_new;
                    return Ok(stats);
                }
                sigma *= (r_new / r_old.max(1e-300)).min(0.5);
                if sigma < 1e-10 * sigma0 {
                    sigma = 0.0;
                }
                r_old = r_new;
                rinf = r_inf_new;
            }
            Err(HarnessError(format!(
                "{}",
                SolveError::NotConverged {
                    iterations: stats.iterations,
                    residual: rinf,
                    load_factor: lf,
                }
            )))
        })();
        self.junction_shift = (0.0, 0.0);
        result
    }

    /// Static equilibrium: plain Newton; then pseudo-transient continuation; then damped
    /// Newton; then load continuation from the unloaded start (gravity and loads ramped) with
    /// damped steps.
    ///
    /// With contact of automatic stiffness the barrier is scaled to the load as in
    /// `Statics::solve` (`Contact::adapt_stiffness`, `Contact::stiffen_after_failure`).
    pub fn solve_static(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
    ) -> Result<SolveStats, HarnessError> {
        solve_load_scaled(
            self,
            st,
            |s, f| s.any_contact(f),
            |_| true,
            |s, st| s.solve_static_once(h, st),
        )
    }

    fn solve_static_once(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
    ) -> Result<SolveStats, HarnessError> {
        st.sync_ends(h);
        self.has_prev = false; // a new sequence starts here
        let result = if self.has_contact() {
            self.solve_static_with_contact(h, st, |s, h, st| {
                s.begin_step(h, st); // friction acts against the motion from the start
                s.solve_static_inner(h, st)
            })
        } else {
            self.begin_step(h, st); // friction acts against the motion from the start
            self.solve_static_inner(h, st)
        }
        .and_then(|mut s| {
            // an unstable equilibrium is left (harness_escape; frictionless contact in the
            // count, friction skips it)
            self.ensure_stable(h, st, &mut s)?;
            Ok(s)
        });
        result.and_then(|s| self.check_sliding(h, st).map(|_| s))
    }

    /// Starts a step of the sliding clips' and the contacts' friction from `st`.
    fn begin_step(&mut self, h: &Harness, st: &HarnessState) {
        for (c, rod) in h.cables.iter().enumerate() {
            if let Some(s) = &mut self.sliding[c] {
                s.begin_step(rod, &st.cables[c], None);
            }
        }
        self.begin_contact_step(st);
    }

    /// Fails naming the cable and the clip if a sliding clip's guide reaches beyond a cable
    /// end at `st`.
    pub fn check_sliding(&mut self, h: &Harness, st: &HarnessState) -> Result<(), HarnessError> {
        check_guides(h, st, &mut self.sliding)
    }

    fn solve_static_inner(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
    ) -> Result<SolveStats, HarnessError> {
        let start = st.clone();
        let full = self.opts.max_iterations;
        self.opts.max_iterations = full.min(15);
        let plain = self.newton(h, st, 1.0, false);
        self.opts.max_iterations = full;
        match plain {
            Ok(s) => return Ok(s),
            Err(e) if e.0.contains("singular") => return Err(e),
            Err(_) => {}
        }
        st.clone_from(&start);
        // A push-out stage that does not converge is cheap to replace by a smaller one: its
        // pseudo-transient fallback gets 6× the iterations instead of 20×, and no load
        // continuation (that starts from the unloaded shape, not from the stage's neighbour).
        let factor = if self.stage { 6 } else { 20 };
        match self.pseudo_transient(h, st, 1.0, factor * self.opts.max_iterations) {
            Ok(mut s) => {
                s.substeps = 1;
                return Ok(s);
            }
            Err(e) if e.0.contains("singular") => return Err(e),
            Err(_) => {}
        }
        st.clone_from(&start);
        if self.stage {
            return Err(HarnessError(
                "a push-out stage did not converge (the next stage is smaller)".into(),
            ));
        }
        let last = match self.newton(h, st, 1.0, true) {
            Ok(mut s) => {
                s.substeps = 1;
                return Ok(s);
            }
            Err(e) if e.0.contains("singular") => return Err(e),
            Err(e) => e,
        };
        st.clone_from(&start);
        let total = match self.newton(h, st, 0.0, true) {
            Ok(s) => s,
            Err(_) => {
                st.clone_from(&start);
                return Err(last);
            }
        };
        let min_step = self.opts.min_load_step;
        continue_load(st, total, min_step, |st, load| {
            self.newton(h, st, load, true)
        })
    }

    /// One step of a sequence of equilibria: from the current state to the clip poses
    /// `target[c]` (all clips of each cable; junction ends' entries ignored), bisecting the
    /// clip motion when Newton fails.
    pub fn step_to(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        target: &[Vec<Pose>],
    ) -> Result<SolveStats, HarnessError> {
        self.begin_step(h, st); // the guides' friction acts from the last equilibrium
        self.step_from_reference(h, st, target)
    }

    /// `step_to` with the friction reference already set.
    fn step_from_reference(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        target: &[Vec<Pose>],
    ) -> Result<SolveStats, HarnessError> {
        self.start_poses.resize(st.cables.len(), Vec::new());
        for (sp, c) in self.start_poses.iter_mut().zip(&st.cables) {
            sp.clone_from(&c.clip_pose);
        }
        self.saved.clone_from(st);
        let result = self.step_to_inner(h, st, target);
        result.and_then(|s| self.check_sliding(h, st).map(|_| s))
    }

    fn step_to_inner(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        target: &[Vec<Pose>],
    ) -> Result<SolveStats, HarnessError> {
        st.set_clip_poses_with(h, target, &mut self.pose_buffer);
        match self.newton(h, st, 1.0, false) {
            Ok(s) => return Ok(s),
            Err(e) if e.0.contains("singular") => return Err(e),
            Err(_) => st.clone_from(&self.saved),
        }
        let mut total = SolveStats::default();
        let mut done = 0.0f64;
        let mut df = 0.5f64;
        let mut depth = 1;
        let mut poses = std::mem::take(&mut self.poses);
        poses.resize(target.len(), Vec::new());
        for (p, t) in poses.iter_mut().zip(target) {
            p.clone_from(t);
        }
        let result = loop {
            if done >= 1.0 {
                break Ok(total);
            }
            let f = (done + df).min(1.0);
            for (c, cable) in poses.iter_mut().enumerate() {
                for (k, pose) in cable.iter_mut().enumerate() {
                    let from = self.start_poses[c][k];
                    pose.position = from.position.lerp(&target[c][k].position, f);
                    pose.orientation = slerp(&from.orientation, &target[c][k].orientation, f);
                }
            }
            self.saved.clone_from(st);
            st.set_clip_poses_with(h, &poses, &mut self.pose_buffer);
            match self.newton(h, st, 1.0, false) {
                Ok(s) => {
                    total.iterations += s.iterations;
                    total.residual = s.residual;
                    total.substeps += 1;
                    done = f;
                    if depth > 1 {
                        depth -= 1;
                        df *= 2.0;
                    }
                }
                Err(e) => {
                    st.clone_from(&self.saved);
                    depth += 1;
                    df *= 0.5;
                    if depth > self.opts.max_substep_depth {
                        break Err(e);
                    }
                }
            }
        };
        self.poses = poses;
        result
    }

    /// The next equilibrium of a sequence (after `solve_static` for the first): the free
    /// unknowns and the junction poses are extrapolated linearly from the last two equilibria
    /// (predictor), then `step_to`; if that fails, it is retried from the last equilibrium.
    pub fn sequence_step(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        target: &[Vec<Pose>],
    ) -> Result<SolveStats, HarnessError> {
        self.last.clone_from(st);
        self.begin_step(h, st); // the guides' friction acts from the last equilibrium
        if self.has_prev {
            for (c, rod) in h.cables.iter().enumerate() {
                st.cables[c].extrapolate_free(rod, &self.prev.cables[c], &self.last.cables[c]);
            }
            for (j, pose) in st.junctions.iter_mut().enumerate() {
                let (p0, p1) = (&self.prev.junctions[j], &self.last.junctions[j]);
                pose.position = 2.0 * p1.position - p0.position;
                let q = p1.orientation * (p0.orientation.conjugate() * p1.orientation);
                pose.orientation = q / q.norm();
            }
            st.sync_ends(h);
        }
        let first = match self.step_from_reference(h, st, target) {
            Ok(s) => Ok(s),
            Err(_) => {
                st.clone_from(&self.last);
                self.step_from_reference(h, st, target)
            }
        };
        let result = restep_load_scaled(
            self,
            first,
            |s, f| s.any_contact(f),
            |s| s.step_from_reference(h, st, target),
        );
        let result = result.and_then(|mut s| {
            self.ensure_stable(h, st, &mut s)?; // an unstable equilibrium is left (harness_escape)
            Ok(s)
        });
        std::mem::swap(&mut self.prev, &mut self.last);
        self.has_prev = true;
        result
    }

    /// Force and moment (about the junction point, global) of the clip on each junction held
    /// by a clip (zero on the others), after an assembly at `st`: the junction's residual
    /// (branch loads and weight) that the clip balances.
    pub fn junction_reactions(
        &self,
        h: &Harness,
        st: &HarnessState,
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        (0..h.junctions.len())
            .map(|j| {
                if !h.held[j] {
                    return (Vector3::zeros(), Vector3::zeros());
                }
                let r = self.junction_residual[j];
                let q = crate::rotation::rotation_matrix(&st.junctions[j].orientation);
                (
                    Vector3::new(r[0], r[1], r[2]),
                    q * Vector3::new(r[3], r[4], r[5]),
                )
            })
            .collect()
    }

    /// Force and moment (about the junction point, global) that each end's cable applies to
    /// its junction, after an assembly at `st`.
    pub fn branch_loads(
        &self,
        h: &Harness,
        st: &HarnessState,
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        h.ends
            .iter()
            .map(|e| {
                let (f, m) = self.ws[e.cable].clip_reaction(
                    &h.cables[e.cable],
                    &st.cables[e.cable],
                    e.topo.clip,
                );
                (-f, -m)
            })
            .collect()
    }
}

/// An end's two coupling parts `part(i)` (at its blocks `topo.blocks()`, within the tail of
/// its segment) summed onto the tail: (at the block eliminated last, at the one before).
fn onto_tail<T: Copy + std::ops::AddAssign>(
    blocks: [usize; 2],
    last: usize,
    zero: T,
    part: impl Fn(usize) -> T,
) -> (T, T) {
    let (mut at_last, mut at_prev) = (zero, zero);
    for (i, &b) in blocks.iter().enumerate() {
        if b == last {
            at_last += part(i);
        } else {
            at_prev += part(i);
        }
    }
    (at_last, at_prev)
}

/// The values at an end's two blocks `blocks` from those at the tail (at the block eliminated
/// last, at the one before): the inverse of `onto_tail`'s placement.
fn from_tail<T: Copy>(blocks: [usize; 2], last: usize, (at_last, at_prev): (T, T)) -> [T; 2] {
    blocks.map(|b| if b == last { at_last } else { at_prev })
}

/// Per cable segment: its junction end if it is the segment's only one and couples to the
/// two blocks that the segment's elimination towards it takes last (`tail_end`).
fn tail_ends(h: &Harness) -> Vec<Vec<Option<usize>>> {
    h.cables
        .iter()
        .enumerate()
        .map(|(c, rod)| {
            rod.segments
                .iter()
                .enumerate()
                .map(|(s, seg)| {
                    let mut ends = h.cable_ends[c]
                        .iter()
                        .filter(|&&k| h.ends[k].segment == Some(s));
                    let (Some(&k), None) = (ends.next(), ends.next()) else {
                        return None;
                    };
                    if seg.blocks.len() < 2 {
                        return None;
                    }
                    let (last, prev) =
                        BlockTridiag::tail_blocks(&seg.blocks, h.ends[k].topo.at_start);
                    let blocks = h.ends[k].topo.blocks();
                    blocks.iter().all(|b| *b == last || *b == prev).then_some(k)
                })
                .collect()
        })
        .collect()
}

/// `e` of cable `c` of `h`, naming the cable.
pub(crate) fn cable_error(h: &Harness, c: usize, e: SolveError) -> HarnessError {
    HarnessError(format!("cable '{}': {e}", h.names[c]))
}

/// Fails naming the cable and the clip if a sliding clip's guide (`guides`, one per cable)
/// reaches beyond a cable end at `st`; static and dynamic harness runs.
pub(crate) fn check_guides<'a>(
    h: &Harness,
    st: &HarnessState,
    guides: impl IntoIterator<Item = &'a mut Option<SlidingClips>>,
) -> Result<(), HarnessError> {
    for ((c, rod), guide) in h.cables.iter().enumerate().zip(guides) {
        if let Some(Err(k)) = guide.as_mut().map(|s| s.check(rod, &st.cables[c])) {
            let e = SolveError::SlidOff {
                clip: rod.spec.clips[k].name.clone(),
            };
            return Err(cable_error(h, c, e));
        }
    }
    Ok(())
}
