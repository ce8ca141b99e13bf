//! Static and quasistatic equilibria: Newton on the rotation group with a backtracking line
//! search on the scaled residual, load continuation when plain Newton fails, and sub-stepped
//! clip motions for sequences of equilibria.
use crate::assembly::{KinkAt, Workspace};
use crate::contact::Contact;
use crate::model::{Pose, Rod};
use crate::rotation::slerp;
use crate::state::State;
use nalgebra::Vector6;
use std::fmt;

#[derive(Clone, Debug)]
pub struct NewtonOptions {
    pub max_iterations: usize,
    /// Converged when the full Newton step is below this (|Δx|/L and |θ| in rad).
    pub step_tolerance: f64,
    /// … or when the scaled residual is below this times the reference force.
    pub residual_tolerance: f64,
    /// Largest rotation increment per iteration, rad.
    pub max_rotation_step: f64,
    /// Smallest load-factor increment of the continuation before giving up.
    pub min_load_step: f64,
    /// Deepest bisection of a quasistatic step before giving up.
    pub max_substep_depth: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            max_iterations: 40,
            step_tolerance: 1e-9,
            residual_tolerance: 1e-10,
            max_rotation_step: 1.0,
            min_load_step: 1e-4,
            max_substep_depth: 12,
        }
    }
}

/// What a solve did.
#[derive(Clone, Copy, Debug, Default)]
pub struct SolveStats {
    pub iterations: usize,
    /// Scaled residual (∞-norm, N) at the end.
    pub residual: f64,
    /// Number of continuation or sub-steps used (0: plain Newton worked).
    pub substeps: usize,
}

#[derive(Clone, Debug)]
pub enum SolveError {
    Kink {
        node: usize,
        s: f64,
    },
    Singular {
        node: usize,
        s: f64,
    },
    NotConverged {
        iterations: usize,
        residual: f64,
        load_factor: f64,
    },
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveError::Kink { node, s } => write!(
                f,
                "the cable folds back on itself at node {node} (s = {s:.4} m): neighbouring \
                 segments turned by almost 180°; refine the mesh or check the clip poses"
            ),
            SolveError::Singular { node, s } => write!(
                f,
                "the stiffness matrix is singular near node {node} (s = {s:.4} m): the clips \
                 leave a rigid-body motion of the cable free (add a fixed clip or a constraint)"
            ),
            SolveError::NotConverged {
                iterations,
                residual,
                load_factor,
            } => write!(
                f,
                "Newton did not converge: {iterations} iterations, last residual {residual:.3e} N \
                 at load factor {load_factor:.4}"
            ),
        }
    }
}
impl std::error::Error for SolveError {}

/// Initial damping of the pseudo-transient path relative to the stiffest diagonal entry.
const PTC_START: f64 = 1e-3;

/// A static/quasistatic solver for one cable: the workspace and options.
pub struct Statics {
    pub ws: Workspace,
    pub opts: NewtonOptions,
    /// Contact with the surroundings (a term of the assembly when set).
    pub contact: Option<Contact>,
    delta: Vec<Vector6<f64>>,
    trial: Vec<Vector6<f64>>,
    base: State,
    /// Buffers of a sequence of equilibria (reused: no allocation per step).
    saved: State,
    start_poses: Vec<Pose>,
    last: State,
    prev: State,
    has_prev: bool,
    force_scale: f64,
}

impl Statics {
    pub fn new(rod: &Rod, opts: NewtonOptions) -> Self {
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
        Statics {
            ws: Workspace::new(rod),
            opts,
            contact: None,
            delta: vec![Vector6::zeros(); rod.n_edges() + 1],
            trial: vec![Vector6::zeros(); rod.n_edges() + 1],
            base: State::empty(),
            saved: State::empty(),
            start_poses: Vec::new(),
            last: State::empty(),
            prev: State::empty(),
            has_prev: false,
            force_scale: weight.max(loads).max(bend).max(1e-12),
        }
    }

    /// The static assembly: internal forces, external loads and contact.
    pub fn assemble(
        &mut self,
        rod: &Rod,
        st: &State,
        load_factor: f64,
        want_jac: bool,
    ) -> Result<(), KinkAt> {
        self.ws
            .assemble_terms(rod, st, load_factor, want_jac, &mut [&mut self.contact])
    }

    /// Limits the step fraction `alpha` of the Newton correction so that the cable does not
    /// dive through the contact barrier; returns the smallest gap at the current state (from
    /// its assembly), for the acceptance test of the trial.
    fn contact_bound(&self, rod: &Rod, st: &State, alpha: &mut f64) -> f64 {
        let Some(c) = &self.contact else {
            return f64::INFINITY;
        };
        let a = *alpha;
        let dx = |n: usize| {
            if rod.mask[n][0] {
                a * self.delta[n].fixed_rows::<3>(0).into_owned()
            } else {
                nalgebra::Vector3::zeros()
            }
        };
        *alpha *= c.step_bound(&st.x, dx, 0..rod.n_edges());
        c.min_gap
    }

    fn kink_err(rod: &Rod, k: KinkAt) -> SolveError {
        SolveError::Kink {
            node: k.node,
            s: rod.arc[k.node],
        }
    }

    /// Newton iterations at a fixed load factor. Plain steps (rotation increments capped, halved
    /// only when a trial kinks or is not finite) or, with `damped`, steps that must pass the
    /// natural monotonicity test. On failure the state is left where it got.
    pub fn newton(
        &mut self,
        rod: &Rod,
        st: &mut State,
        load_factor: f64,
        damped: bool,
    ) -> Result<SolveStats, SolveError> {
        let h = rod.mean_ds();
        let l = rod.spec.length;
        self.assemble(rod, st, load_factor, true)
            .map_err(|k| Self::kink_err(rod, k))?;
        let (_, mut rinf) = self.ws.residual_norms(h);
        let mut stats = SolveStats::default();
        for it in 0..self.opts.max_iterations {
            stats.iterations = it + 1;
            if rinf <= self.opts.residual_tolerance * self.force_scale {
                stats.iterations = it;
                stats.residual = rinf;
                return Ok(stats);
            }
            self.ws.factor(rod)?;
            let (dx, dth) = self.ws.newton_correction(&mut self.delta);
            if !(dx.is_finite() && dth.is_finite()) {
                return Err(SolveError::Singular { node: 0, s: 0.0 });
            }
            let step = (dx / l).max(dth);
            let norm0 = scaled_norm(&self.delta, l);
            let mut alpha = 1.0f64.min(self.opts.max_rotation_step / dth.max(1e-300));
            let gap0 = self.contact_bound(rod, st, &mut alpha);
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!("  bound alpha {alpha:.3e} gap {gap0:.3e}");
            }
            // Damped: Deuflhard's natural monotonicity test, the simplified Newton correction
            // J⁻¹ r(x ⊕ αΔ) with the factorisation at hand must shrink. It is invariant to the
            // scaling of the equations, so a stiff EA does not distort it. (Residual-norm line
            // searches stall here: a rotation step stretches the stiff axis quadratically.)
            self.base.clone_from(st);
            let mut accepted = false;
            for _ in 0..16 {
                st.apply_increment(rod, &self.delta, alpha);
                if self.assemble(rod, st, load_factor, false).is_ok() {
                    for (d, r) in self.trial.iter_mut().zip(&self.ws.rhs) {
                        *d = -r;
                    }
                    self.ws.jac.solve_factored(&mut self.trial);
                    let theta = scaled_norm(&self.trial, l) / norm0.max(1e-300);
                    let monotone =
                        theta <= 1.0 - 0.25 * alpha || step * alpha < self.opts.step_tolerance;
                    let feasible = self.contact.as_ref().is_none_or(|c| c.gap_acceptable(gap0));
                    if theta.is_finite() && (!damped || monotone) && feasible {
                        accepted = true;
                        break;
                    }
                }
                st.clone_from(&self.base);
                alpha *= 0.5;
            }
            if !accepted {
                return Err(SolveError::NotConverged {
                    iterations: stats.iterations,
                    residual: rinf,
                    load_factor,
                });
            }
            self.assemble(rod, st, load_factor, true)
                .map_err(|k| Self::kink_err(rod, k))?;
            (_, rinf) = self.ws.residual_norms(h);
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!(
                    "it {it} lf {load_factor} alpha {alpha:.3e} step {step:.3e} rinf {rinf:.3e}"
                );
            }
            if alpha == 1.0 && step < self.opts.step_tolerance {
                stats.residual = rinf;
                return Ok(stats);
            }
        }
        Err(SolveError::NotConverged {
            iterations: stats.iterations,
            residual: rinf,
            load_factor,
        })
    }

    /// Pseudo-transient continuation: (J + σD) Δ = −r with D a damping diagonal (δs for
    /// positions, Δs³/12 for rotations: a viscous medium) and σ driven to zero by switched
    /// evolution relaxation (σ ← σ·min(‖r_k‖/‖r_{k−1}‖, ½), ×10 after a rejected step). It follows a damped motion into a stable
    /// equilibrium, where plain Newton from a poor guess (slack spans, buckled loops) may not
    /// find one, and turns into Newton near convergence.
    pub fn pseudo_transient(
        &mut self,
        rod: &Rod,
        st: &mut State,
        load_factor: f64,
        max_iterations: usize,
    ) -> Result<SolveStats, SolveError> {
        let h = rod.mean_ds();
        let l = rod.spec.length;
        let nb = rod.n_edges() + 1;
        let damping = |b: usize, k: usize| -> f64 {
            if k < 3 {
                rod.ds_node[b]
            } else {
                rod.ds_edge[b.min(nb - 2)].powi(3) / 12.0
            }
        };
        self.assemble(rod, st, load_factor, true)
            .map_err(|k| Self::kink_err(rod, k))?;
        let (mut r_old, mut rinf) = self.ws.residual_norms(h);
        // Start where the damping term matches the largest stiffness on the diagonal.
        let mut sigma = 0.0f64;
        for b in 0..nb {
            for k in 0..6 {
                if rod.mask[b][k] {
                    sigma = sigma.max(self.ws.jac.diag[b][(k, k)].abs() / damping(b, k));
                }
            }
        }
        sigma *= PTC_START;
        let sigma0 = sigma;
        let mut stats = SolveStats::default();
        for it in 0..max_iterations {
            stats.iterations = it + 1;
            if rinf <= self.opts.residual_tolerance * self.force_scale {
                stats.iterations = it;
                stats.residual = rinf;
                return Ok(stats);
            }
            for b in 0..nb {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        self.ws.jac.diag[b][(k, k)] += sigma * damping(b, k);
                    }
                }
            }
            self.ws.factor(rod)?;
            let (dx, dth) = self.ws.newton_correction(&mut self.delta);
            let step = (dx / l).max(dth);
            let mut alpha = 1.0f64.min(self.opts.max_rotation_step / dth.max(1e-300));
            let gap0 = self.contact_bound(rod, st, &mut alpha);
            self.base.clone_from(st);
            st.apply_increment(rod, &self.delta, alpha);
            let ok = self.assemble(rod, st, load_factor, true).is_ok()
                && self.contact.as_ref().is_none_or(|c| c.gap_acceptable(gap0));
            let (r_new, r_inf_new) = if ok {
                self.ws.residual_norms(h)
            } else {
                (f64::INFINITY, f64::INFINITY)
            };
            if !(step.is_finite() && r_new.is_finite()) || r_new > 10.0 * r_old.max(1e-300) {
                // Too bold: back off and damp more.
                st.clone_from(&self.base);
                self.assemble(rod, st, load_factor, true)
                    .map_err(|k| Self::kink_err(rod, k))?;
                sigma = (sigma * 10.0).max(1e-6 * sigma0);
                continue;
            }
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!("ptc {it} sigma {sigma:.3e} step {step:.3e} rinf {r_inf_new:.3e}");
            }
            if sigma == 0.0 && alpha == 1.0 && step < self.opts.step_tolerance {
                stats.residual = r_inf_new;
                return Ok(stats);
            }
            // At least halve σ per accepted step: soft (slack, near-mechanism) cables creep
            // with small residuals, so residual ratios alone would relax σ far too slowly.
            sigma *= (r_new / r_old.max(1e-300)).min(0.5);
            if sigma < 1e-10 * sigma0 {
                sigma = 0.0;
            }
            r_old = r_new;
            rinf = r_inf_new;
        }
        Err(SolveError::NotConverged {
            iterations: stats.iterations,
            residual: rinf,
            load_factor,
        })
    }

    /// Static equilibrium: plain Newton; then pseudo-transient continuation; then load
    /// continuation from the unloaded routed shape (gravity and loads ramped), with plain and
    /// then damped Newton steps.
    ///
    /// With contact, a start that runs through the geometry (a routed shape) is first solved
    /// without contact; the barrier's penalty continuation then pushes the cable out.
    pub fn solve(&mut self, rod: &Rod, st: &mut State) -> Result<SolveStats, SolveError> {
        self.has_prev = false; // a new sequence starts here
        let mut pre = SolveStats::default();
        if self.contact.as_ref().is_some_and(|c| c.penetrates(rod, st)) {
            let contact = self.contact.take();
            let start = st.clone();
            match self.solve_from(rod, st) {
                Ok(s) => pre = s,
                Err(_) => st.clone_from(&start),
            }
            self.contact = contact;
        }
        let mut stats = self.solve_from(rod, st)?;
        stats.iterations += pre.iterations;
        Ok(stats)
    }

    fn solve_from(&mut self, rod: &Rod, st: &mut State) -> Result<SolveStats, SolveError> {
        if let Some(c) = &mut self.contact {
            c.begin_step(&st.x, None); // friction acts against the motion from the start
        }
        let start = st.clone();
        // Plain Newton converges in a handful of iterations from a good guess; a slow start
        // means a poor guess, for which the pseudo-transient path is the better use of time.
        let full = self.opts.max_iterations;
        self.opts.max_iterations = full.min(15);
        let plain = self.newton(rod, st, 1.0, false);
        self.opts.max_iterations = full;
        if let Err(e @ SolveError::Singular { .. }) = plain {
            return Err(e);
        }
        if let Ok(s) = plain {
            return Ok(s);
        }
        let mut last;
        st.clone_from(&start);
        match self.pseudo_transient(rod, st, 1.0, 20 * self.opts.max_iterations) {
            Ok(mut s) => {
                s.substeps = 1;
                return Ok(s);
            }
            Err(e @ SolveError::Singular { .. }) => return Err(e),
            Err(e) => last = e,
        }
        for damped in [false, true] {
            st.clone_from(&start);
            match self.continuation(rod, st, damped) {
                Ok(s) => return Ok(s),
                Err(e @ SolveError::Singular { .. }) => return Err(e),
                Err(e) => last = e,
            }
        }
        Err(last)
    }

    fn continuation(
        &mut self,
        rod: &Rod,
        st: &mut State,
        damped: bool,
    ) -> Result<SolveStats, SolveError> {
        let mut total = self.newton(rod, st, 0.0, damped)?;
        total.substeps = 1;
        let mut lambda = 0.0;
        let mut dl = 0.25f64;
        while lambda < 1.0 {
            let trial = (lambda + dl).min(1.0);
            let saved = st.clone();
            match self.newton(rod, st, trial, damped) {
                Ok(s) => {
                    total.iterations += s.iterations;
                    total.residual = s.residual;
                    total.substeps += 1;
                    lambda = trial;
                    dl *= 1.5;
                }
                Err(e) => {
                    st.clone_from(&saved);
                    dl *= 0.5;
                    if dl < self.opts.min_load_step {
                        return Err(e);
                    }
                }
            }
        }
        Ok(total)
    }

    /// One step of a sequence of equilibria: from the current (converged) state to the clip
    /// poses `target`, bisecting the clip motion when Newton fails.
    pub fn step_to(
        &mut self,
        rod: &Rod,
        st: &mut State,
        target: &[Pose],
    ) -> Result<SolveStats, SolveError> {
        self.start_poses.clone_from(&st.clip_pose);
        self.saved.clone_from(st);
        if let Some(c) = &mut self.contact {
            c.begin_step(&st.x, None); // friction against the motion since the last equilibrium
        }
        st.set_clip_poses(rod, target);
        match self.newton(rod, st, 1.0, false) {
            Ok(s) => return Ok(s),
            Err(e @ SolveError::Singular { .. }) => return Err(e),
            Err(_) => st.clone_from(&self.saved),
        }
        // Bisect the motion: fractions of the way from start to target.
        let mut total = SolveStats::default();
        let mut done = 0.0f64;
        let mut df = 0.5f64;
        let mut depth = 1;
        let mut poses = target.to_vec();
        while done < 1.0 {
            let f = (done + df).min(1.0);
            for (c, pose) in poses.iter_mut().enumerate() {
                let from = self.start_poses[c];
                pose.position = from.position.lerp(&target[c].position, f);
                pose.orientation = slerp(&from.orientation, &target[c].orientation, f);
            }
            self.saved.clone_from(st);
            st.set_clip_poses(rod, &poses);
            match self.newton(rod, st, 1.0, false) {
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
                    df *= 0.5;
                    depth += 1;
                    if depth > self.opts.max_substep_depth {
                        return Err(e);
                    }
                }
            }
        }
        Ok(total)
    }

    /// The next equilibrium of a sequence (after a `solve` for the first): the free unknowns
    /// are extrapolated linearly from the last two equilibria (predictor), then `step_to`;
    /// if that fails, it is retried from the last equilibrium without the predictor.
    pub fn sequence_step(
        &mut self,
        rod: &Rod,
        st: &mut State,
        target: &[Pose],
    ) -> Result<SolveStats, SolveError> {
        self.last.clone_from(st);
        if self.has_prev {
            st.extrapolate_free(rod, &self.prev, &self.last);
        }
        let result = match self.step_to(rod, st, target) {
            Ok(s) => Ok(s),
            Err(_) => {
                st.clone_from(&self.last);
                self.step_to(rod, st, target)
            }
        };
        std::mem::swap(&mut self.prev, &mut self.last);
        self.has_prev = true;
        result
    }
}

/// ‖Δ‖ with positions relative to the cable length and rotations in rad.
fn scaled_norm(d: &[Vector6<f64>], length: f64) -> f64 {
    let mut sum = 0.0;
    for v in d {
        for k in 0..6 {
            let x = if k < 3 { v[k] / length } else { v[k] };
            sum += x * x;
        }
    }
    sum.sqrt()
}
