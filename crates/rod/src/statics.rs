//! Static and quasistatic equilibria: Newton on the rotation group with a backtracking line
//! search on the scaled residual, load continuation when plain Newton fails, and sub-stepped
//! clip motions for sequences of equilibria.
use crate::assembly::{KinkAt, Workspace};
use crate::contact::Contact;
use crate::model::{NodeKind, Pose, Rod};
use crate::rotation::slerp;
use crate::sliding::SlidingClips;
use crate::stability::{free_rigid_motions, Inertia};
use crate::state::State;
use nalgebra::{Vector3, Vector6};
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
    /// Negative eigenvalues of the tangent stiffness at the returned state (0: stable; None:
    /// not checked — dead moments make the loads non-conservative, see `ensure_stable`).
    pub unstable: Option<usize>,
    /// Unstable equilibria met and left on the way (see `Statics::ensure_stable`).
    pub escapes: usize,
    /// The largest jump to another stable branch in a quasistatic step, if any.
    pub snap: Option<Snap>,
}

/// A snap-through: the equilibrium branch ended (or became unstable) inside a step and the
/// cable jumped to another stable equilibrium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Snap {
    /// Fraction of the step's clip motion at which it happened.
    pub fraction: f64,
    /// Largest node displacement of the jump, m, and that node.
    pub jump: f64,
    pub node: usize,
}

impl SolveStats {
    /// Keeps the larger snap of two.
    fn merge_snap(&mut self, other: Option<Snap>) {
        if let Some(o) = other {
            if self.snap.is_none_or(|s| o.jump > s.jump) {
                self.snap = Some(o);
            }
        }
    }
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
    /// The clips leave a rigid-body motion of a part of the cable free.
    RigidBody {
        /// The clips holding that part, and the free motion (translation, rotation).
        clips: String,
        translation: Vector3<f64>,
        rotation: Vector3<f64>,
    },
    NotConverged {
        iterations: usize,
        residual: f64,
        load_factor: f64,
    },
    /// A sliding clip's guide reaches beyond a cable end (the cable ran out of it).
    SlidOff {
        clip: String,
    },
    /// With contact: the equilibrium leaves the cable inside the geometry (a start deep
    /// inside that the barrier could not push out, e.g. a clip inside a solid).
    Penetration {
        node: usize,
        s: f64,
        obstacle: String,
        depth: f64,
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
                "the stiffness matrix is singular near node {node} (s = {s:.4} m), although the \
                 clips hold the cable against every rigid-body motion: a section stiffness is \
                 zero or too small to resolve against the others (check the section and \
                 material), or the state is at a bifurcation"
            ),
            SolveError::RigidBody {
                clips,
                translation,
                rotation,
            } => {
                let what = if rotation.norm() > 1e-6 {
                    let a = rotation.normalize();
                    format!(
                        "a rotation about the axis ({:.3}, {:.3}, {:.3})",
                        a.x, a.y, a.z
                    )
                } else {
                    let t = translation.normalize();
                    format!("a translation along ({:.3}, {:.3}, {:.3})", t.x, t.y, t.z)
                };
                write!(
                    f,
                    "the stiffness matrix is singular: the clips {clips} leave a rigid-body \
                     motion of the cable free ({what}); add a fixed clip or hold it otherwise"
                )
            }
            SolveError::NotConverged {
                iterations,
                residual,
                load_factor,
            } => write!(
                f,
                "Newton did not converge: {iterations} iterations, last residual {residual:.3e} N \
                 at load factor {load_factor:.4}"
            ),
            SolveError::SlidOff { clip } => write!(
                f,
                "the cable ran out of sliding clip '{clip}': its guide reaches beyond a cable end"
            ),
            SolveError::Penetration {
                node,
                s,
                obstacle,
                depth,
            } => write!(
                f,
                "the cable stays inside the geometry '{obstacle}': node {node} (s = {s:.4} m), \
                 its surface {:.2} mm deep; contact could not push it out (a clip inside the \
                 solid, or a route through it that the clips hold): route the cable outside \
                 the geometry",
                depth * 1e3
            ),
        }
    }
}
impl std::error::Error for SolveError {}

/// Initial damping of the pseudo-transient path relative to the stiffest diagonal entry.
const PTC_START: f64 = 1e-3;

/// Bisection depth of a quasistatic step from which a failed sub-step is relaxed by energy
/// descent (the branch may end in a fold there).
const SNAP_DEPTH: usize = 6;

/// A jump of a node by more than this fraction of the cable length within a sub-step of
/// 2⁻⁶ of a step is reported as a snap-through.
const SNAP_JUMP: f64 = 0.01;

/// Relative round-off of the potential energy (to |elastic| + |load potential|) within which a
/// descent step that does not pass Armijo may still be accepted by the monotonicity test.
const ENERGY_ROUND_OFF: f64 = 1e-10;

/// The damping σ of the energy descent (relative to the stiffest diagonal entry per damping)
/// below which its steps count as Newton steps for convergence (see `descend`).
const NEUTRAL_SIGMA: f64 = 1e-9;

/// The damping σ of the energy descent (relative to its floor, 1e-12 of the stiffest entry)
/// up to which a full step is followed by a line search along the nearly neutral mode that
/// holds σ up (`Statics::neutral_search`): the curvature of that mode is then below what the
/// tangent resolves next to the stiff axis.
const NEUTRAL_SEARCH: f64 = 100.0;

/// A static/quasistatic solver for one cable: the workspace and options.
pub struct Statics {
    pub ws: Workspace,
    pub opts: NewtonOptions,
    /// Contact with the surroundings (a term of the assembly when set).
    pub contact: Option<Contact>,
    /// The sliding clips' term (None without sliding clips).
    pub sliding: Option<SlidingClips>,
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
    /// The state before an escape from an unstable equilibrium.
    before: State,
    relax_start: State,
    /// The descent's state before a Newton shortcut.
    shortcut_start: State,
    /// Scratch of the projection onto the stiff axis (`projection::relax_positions`) and of
    /// the line search along a nearly neutral mode (`neutral_search`).
    proj_ws: Workspace,
    proj_delta: Vec<Vector6<f64>>,
    neutral: Vec<Vector6<f64>>,
    /// (H + σD)⁻¹ D z of the neutral mode z and zᵀDw (`neutral_search`), and whether
    /// `state_along` corrects its trials off the mode with them.
    neutral_w: Vec<Vector6<f64>>,
    neutral_zdw: f64,
    correct_off_mode: bool,
    /// The unstable modes of an escape (`ensure_stable`).
    modes: [Vec<Vector6<f64>>; 2],
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
            sliding: SlidingClips::of(rod),
            delta: vec![Vector6::zeros(); rod.n_edges() + 1],
            trial: vec![Vector6::zeros(); rod.n_edges() + 1],
            base: State::empty(),
            saved: State::empty(),
            start_poses: Vec::new(),
            last: State::empty(),
            prev: State::empty(),
            has_prev: false,
            force_scale: weight.max(loads).max(bend).max(1e-12),
            before: State::empty(),
            relax_start: State::empty(),
            shortcut_start: State::empty(),
            proj_ws: Workspace::new(rod),
            proj_delta: vec![Vector6::zeros(); rod.n_edges() + 1],
            neutral: vec![Vector6::zeros(); rod.n_edges() + 1],
            neutral_w: vec![Vector6::zeros(); rod.n_edges() + 1],
            neutral_zdw: 0.0,
            correct_off_mode: false,
            modes: [
                vec![Vector6::zeros(); rod.n_edges() + 1],
                vec![Vector6::zeros(); rod.n_edges() + 1],
            ],
        }
    }

    /// Relaxes the node positions of `st` with its rotations frozen: the projection of a
    /// finite rotation step onto the stiff axis (`projection::relax_positions`).
    fn project_positions(&mut self, rod: &Rod, st: &mut State) -> bool {
        crate::projection::relax_positions(
            &mut self.proj_ws,
            rod,
            st,
            &mut [&mut self.contact, &mut self.sliding],
            &mut self.proj_delta,
            self.opts.step_tolerance,
        )
        .unwrap_or(false)
    }

    /// The static assembly: internal forces, external loads and contact.
    pub fn assemble(
        &mut self,
        rod: &Rod,
        st: &State,
        load_factor: f64,
        want_jac: bool,
    ) -> Result<(), KinkAt> {
        self.ws.assemble_terms(
            rod,
            st,
            load_factor,
            want_jac,
            &mut [&mut self.contact, &mut self.sliding],
        )
    }

    /// Fails with `SlidOff` if a sliding clip's guide reaches beyond a cable end.
    pub fn check_sliding(&mut self, rod: &Rod, st: &State) -> Result<(), SolveError> {
        match self.sliding.as_mut().map(|s| s.check(rod, st)) {
            Some(Err(c)) => Err(SolveError::SlidOff {
                clip: rod.spec.clips[c].name.clone(),
            }),
            _ => Ok(()),
        }
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
        c.min_gap()
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
    /// The equilibrium found is checked for stability and, if unstable, left for a stable one
    /// (`ensure_stable`); a singular system is diagnosed (a rigid-body motion the clips leave
    /// free, or a zero stiffness).
    /// With contact, a start that runs through the geometry (a routed shape) is first solved
    /// without contact; the barrier's penalty continuation then pushes the cable out.
    ///
    /// With contact of automatic stiffness, the barrier is scaled to the load
    /// (`Contact::adapt_stiffness`): an equilibrium whose contact presses a sample below d̂/10
    /// is solved again from there with the stiffness that carries it at about d̂/2, and a solve
    /// that fails with a sample pressed below the barrier's continuation gap is retried from
    /// the start with the stiffness ×30 (`Contact::stiffen_after_failure`, at most 3 times).
    pub fn solve(&mut self, rod: &Rod, st: &mut State) -> Result<SolveStats, SolveError> {
        solve_load_scaled(
            self,
            st,
            |s, f| s.contact.as_mut().is_some_and(f),
            |e| matches!(e, SolveError::NotConverged { .. }),
            |s, st| s.solve_once(rod, st),
        )
    }

    fn solve_once(&mut self, rod: &Rod, st: &mut State) -> Result<SolveStats, SolveError> {
        self.has_prev = false; // a new sequence starts here
        self.check_held(rod, st)?;
        let mut pre = SolveStats::default();
        let inside = self.contact.as_ref().is_some_and(|c| c.penetrates(rod, st));
        let start_state = st.clone();
        if inside {
            let mut contact = self.contact.take();
            let start = st.clone();
            match self.solve_any(rod, st) {
                Ok(s) => pre = s,
                Err(_) => st.clone_from(&start),
            }
            // Deep inside a mesh the bounded broad phase sees nothing: exact distances there.
            if let Some(c) = &mut contact {
                c.mark_deep_edges(Some(&st.x));
            }
            self.contact = contact;
            // A shallow start is resolved by the barrier's continuation from there (its
            // Taylor part below d̂/1000 pushes out): bench_contact's draped hose in 47
            // iterations against 193 through the push-out's stages. A deep one fails or stays
            // inside: then the push-out from the equilibrium without contact.
            let shallow = st.clone();
            let direct = self.solve_any(rod, st);
            if let Ok(s) = &direct {
                pre.iterations += s.iterations;
            }
            let clear = direct.is_ok() && {
                let c = self.contact.as_mut().expect("contact");
                c.mark_deep_edges(Some(&st.x));
                c.deepest_penetration(st).is_none()
            };
            if !clear {
                st.clone_from(&shallow);
                pre.iterations += self.push_out(rod, st);
            }
        }
        // Never a silent wrong answer: a cable left inside the geometry, or a start inside it
        // that the solver could not resolve, is an error naming where.
        let inside_at = |s: &mut Self, st: &State| {
            let c = s.contact.as_mut()?;
            c.mark_deep_edges(Some(&st.x));
            let p = c.deepest_penetration(st);
            c.mark_deep_edges(None);
            p.map(|p| SolveError::Penetration {
                node: p.node,
                s: rod.arc[p.node],
                obstacle: p.name,
                depth: p.depth,
            })
        };
        let result = self.solve_any(rod, st);
        if let Some(c) = &mut self.contact {
            c.mark_deep_edges(None);
        }
        let mut stats = match result {
            Ok(s) => s,
            Err(SolveError::NotConverged { .. }) if inside => {
                return Err(
                    inside_at(self, &start_state).unwrap_or(SolveError::NotConverged {
                        iterations: 0,
                        residual: f64::NAN,
                        load_factor: 0.0,
                    }),
                );
            }
            Err(e) => return Err(e),
        };
        if inside {
            if let Some(e) = inside_at(self, st) {
                return Err(e);
            }
        }
        stats.iterations += pre.iterations;
        self.ensure_stable(rod, st, &mut stats, 0.0)?;
        stats.snap = None; // leaving an unstable first solution is no jump of the cable
        self.check_sliding(rod, st)?;
        Ok(stats)
    }

    /// A cable that lies deeper inside the geometry than the barrier reaches (the equilibrium
    /// without contact of a route through a solid): the geometry is shrunk until the cable is
    /// clear of it (every signed distance grown by the depth) and grown back to its true
    /// surface in halving stages; at each stage the free nodes it reaches are moved out along
    /// its normal (their edge frames turned with their chords) and the cable is solved from
    /// there with contact, so it ends on the side of the surface nearest to where it was.
    /// Returns the iterations spent; a cable that cannot get out (a clip inside the solid) is
    /// left for the caller's error.
    fn push_out(&mut self, rod: &Rod, st: &mut State) -> usize {
        let Some(deep) = self
            .contact
            .as_ref()
            .and_then(|c| c.deepest_penetration(st))
        else {
            return 0;
        };
        let reach = self.contact.as_ref().map_or(0.0, |c| c.opts.distance);
        let mut shrink = deep.depth + 2.0 * reach;
        let mut iterations = 0;
        let mut last = st.clone();
        let mut fraction = 0.5; // of the shrink kept at the next stage
        let mut failures = 0;
        while shrink > 0.0 && failures < 8 {
            let next = if shrink <= 4.0 * reach {
                0.0
            } else {
                fraction * shrink
            };
            let c = self.contact.as_mut().expect("contact");
            c.set_shrink(next);
            c.move_out(rod, st, 0.5 * reach, None);
            let r = self.solve_any(rod, st);
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!(
                    "push-out: shrink {next:.3e} -> {:?}",
                    r.as_ref().map(|s| s.iterations)
                );
            }
            match r {
                Ok(s) => {
                    iterations += s.iterations;
                    (shrink, fraction) = (next, 0.5);
                    last.clone_from(st);
                }
                Err(_) => {
                    // A smaller stage from the last equilibrium; the caller names a cable
                    // that still cannot get out.
                    st.clone_from(&last);
                    fraction = 0.5 + 0.5 * fraction;
                    failures += 1;
                    if next == 0.0 {
                        shrink = 8.0 * reach; // stages down to zero again
                    }
                }
            }
        }
        if let Some(c) = self.contact.as_mut() {
            c.set_shrink(0.0);
        }
        iterations
    }

    /// Fails with `RigidBody` if the clips leave a rigid-body motion of a part free.
    pub fn check_held(&self, rod: &Rod, st: &State) -> Result<(), SolveError> {
        for seg in &rod.segments {
            let fixed = seg
                .clips
                .iter()
                .any(|&c| rod.spec.clips[c].kind == crate::model::ClipKind::Fixed);
            if fixed {
                continue;
            }
            if let (n, Some((t, w))) = free_rigid_motions(rod, &seg.clips, &st.clip_pose) {
                debug_assert!(n > 0);
                let names: Vec<String> = seg
                    .clips
                    .iter()
                    .map(|&c| format!("'{}'", rod.spec.clips[c].name))
                    .collect();
                return Err(SolveError::RigidBody {
                    clips: if names.is_empty() {
                        "(none)".into()
                    } else {
                        names.join(", ")
                    },
                    translation: t,
                    rotation: w,
                });
            }
        }
        Ok(())
    }

    /// Any equilibrium: plain Newton, pseudo-transient, load continuation (see `solve`).
    fn solve_any(&mut self, rod: &Rod, st: &mut State) -> Result<SolveStats, SolveError> {
        if let Some(c) = &mut self.contact {
            c.begin_step(&st.x, None); // friction acts against the motion from the start
        }
        if let Some(s) = &mut self.sliding {
            s.begin_step(rod, st, None);
        }
        let start = st.clone();
        // Plain Newton converges in a handful of iterations from a good guess; a slow start
        // means a poor guess, for which the pseudo-transient path is the better use of time.
        let full = self.opts.max_iterations;
        self.opts.max_iterations = full.min(15);
        let plain = self.newton(rod, st, 1.0, false);
        self.opts.max_iterations = full;
        if let Err(e @ SolveError::Singular { .. }) = &plain {
            let e = e.clone();
            // Singular at the start: a zero stiffness. Met on the way (Newton passing a
            // bifurcation: an imperfect column above its Euler load, measured at N = 10): the
            // damped paths below avoid it.
            self.assemble(rod, &start, 1.0, true)
                .map_err(|k| Self::kink_err(rod, k))?;
            self.ws.factor(rod).map_err(|_| e)?;
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

    /// Inertia of the tangent stiffness at `st` (the Jacobian assembled there: after a
    /// converged solve it already is, `assemble` false).
    pub fn inertia(
        &mut self,
        rod: &Rod,
        st: &State,
        assemble: bool,
    ) -> Result<Inertia, SolveError> {
        if assemble {
            self.assemble(rod, st, 1.0, true)
                .map_err(|k| Self::kink_err(rod, k))?;
        }
        Ok(self.ws.jac.inertia(0..rod.arc.len()))
    }

    /// Checks the equilibrium `st` (just converged: the Jacobian is assembled there) for
    /// stability; an unstable one is left along a direction of negative curvature (both signs
    /// tried, the lower energy kept) and relaxed (`relax`: pseudo-transient continuation) into a stable one, with larger
    /// perturbations if that lands on an unstable state again. `stats.unstable` is the count
    /// of negative eigenvalues at the state returned (0 unless no stable state was found);
    /// `stats.snap` the jump if there was an escape (at `fraction` of a quasistatic step).
    pub fn ensure_stable(
        &mut self,
        rod: &Rod,
        st: &mut State,
        stats: &mut SolveStats,
        fraction: f64,
    ) -> Result<(), SolveError> {
        let frictional = self
            .contact
            .as_ref()
            .is_some_and(|c| c.active > 0 && c.obstacles.iter().any(|o| o.friction > 0.0))
            || self.sliding.is_some();
        if frictional || rod.edge_moment.iter().any(|m| *m != Vector3::zeros()) {
            // A dead moment is not conservative on the rotation group, and friction in contact
            // and the guides of sliding clips (sliding.rs) are not conservative at all: the symmetric part of the tangent is then no
            // stability criterion (that needs the dynamics).
            stats.unstable = None;
            return Ok(());
        }
        let mut inertia = self.inertia(rod, st, false)?;
        stats.unstable = Some(inertia.negative);
        if inertia.negative == 0 {
            return Ok(());
        }
        self.before.clone_from(st);
        let l = rod.spec.length;
        for attempt in 0..4 {
            if !self.unstable_mode(rod) {
                break;
            }
            // Scale: 0.1 rad of rotation or 2 % of the length, whichever comes first.
            let (mut dx, mut dth) = (0.0f64, 0.0f64);
            for (b, d) in self.trial.iter().enumerate() {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        if k < 3 {
                            dx = dx.max(d[k].abs());
                        } else {
                            dth = dth.max(d[k].abs());
                        }
                    }
                }
            }
            let amp = f64::from(1u32 << attempt) / (dth / 0.1).max(dx / (0.02 * l)).max(1e-300);
            let mut best = (f64::INFINITY, 0.0);
            for sign in [1.0, -1.0] {
                st.clone_from(&self.before);
                st.apply_increment(rod, &self.trial, sign * amp);
                if self.assemble(rod, st, 1.0, false).is_ok() {
                    let e = self.ws.elastic_energy + self.ws.load_potential;
                    if e < best.0 {
                        best = (e, sign);
                    }
                }
            }
            if best.1 == 0.0 {
                break;
            }
            st.clone_from(&self.before);
            st.apply_increment(rod, &self.trial, best.1 * amp);
            if attempt == 0 {
                // First along the mode as far as the energy falls, each trial projected back
                // onto the stiff axis: a fixed step along the linearised mode stretches it at
                // second order, and from a small one the descent crawls (docs/solver.md).
                // With two negative eigenvalues (a round section: one per bending plane, split
                // only by the imperfection) the directions cos ψ v₁ + sin ψ v₂ of both modes,
                // 16 values of ψ; the imperfection's plane ends lowest (escape.rs).
                self.modes[0].clone_from(&self.trial);
                st.clone_from(&self.before);
                self.inertia(rod, st, true)?;
                let [first, second] = &mut self.modes;
                let planes = inertia.negative >= 2
                    && crate::escape::second_mode(
                        &mut self.ws.jac,
                        rod,
                        first,
                        second,
                        &mut self.delta,
                    )
                    .is_some_and(|rho| rho < 0.0);
                self.base.clone_from(&self.before);
                let e0 = self.ws.elastic_energy + self.ws.load_potential;
                let count = if planes { 16 } else { 2 };
                let mut far = (f64::INFINITY, 0.0, 0);
                for i in 0..count {
                    let dth = self.escape_direction(rod, i, count, planes);
                    let (e, t) = self.minimise_along(rod, st, 1.0, 0.01 / dth, e0);
                    if t > 0.0 && e < far.0 {
                        far = (e, t, i);
                    }
                }
                if far.1 != 0.0 {
                    self.escape_direction(rod, far.2, count, planes);
                    self.state_along(rod, st, far.1);
                } else {
                    st.clone_from(&self.before);
                    st.apply_increment(rod, &self.trial, best.1 * amp);
                }
            }
            let found = self.relax(rod, st, true);
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!("escape {attempt}: amp {amp:.3e} dx {dx:.3e} dth {dth:.3e} -> {found:?}");
            }
            match found {
                Ok(s) => {
                    stats.iterations += s.iterations;
                    stats.residual = s.residual;
                    inertia = self.inertia(rod, st, false)?;
                    if inertia.negative == 0 {
                        stats.unstable = Some(0);
                        stats.escapes += 1;
                        stats.merge_snap(Some(self.jump_from_before(rod, st, fraction)));
                        return Ok(());
                    }
                }
                Err(SolveError::Singular { .. }) | Err(SolveError::NotConverged { .. }) => {}
                Err(e) => return Err(e),
            }
            // Not stable: try again from the unstable state with a larger perturbation.
            st.clone_from(&self.before);
            self.inertia(rod, st, true)?;
        }
        // No stable state found: return the unstable equilibrium, flagged.
        st.clone_from(&self.before);
        inertia = self.inertia(rod, st, true)?;
        stats.unstable = Some(inertia.negative);
        if std::env::var_os("ROD_DEBUG").is_some() {
            eprintln!("no stable state found: {inertia:?}");
        }
        Ok(())
    }

    /// The mode of the most negative eigenvalue of H φ = λ D φ (H the symmetric tangent
    /// stiffness assembled in the workspace, D the damping diagonal of `pseudo_transient`), in
    /// `self.trial`: a direction of negative curvature from the block LDLᵀ, refined by inverse
    /// iteration with H shifted below that eigenvalue (the shift raised until the shifted
    /// matrix is positive definite). The workspace Jacobian is left as it was.
    fn unstable_mode(&mut self, rod: &Rod) -> bool {
        let nb = rod.arc.len();
        if !self.ws.jac.negative_direction(0..nb, &mut self.trial) {
            return false;
        }
        let damping = |b: usize, k: usize| -> f64 {
            if k < 3 {
                rod.ds_node[b]
            } else {
                rod.ds_edge[b.min(nb - 2)].powi(3) / 12.0
            }
        };
        let d_norm = |z: &[Vector6<f64>]| -> f64 {
            let mut sum = 0.0;
            for (b, v) in z.iter().enumerate() {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        sum += damping(b, k) * v[k] * v[k];
                    }
                }
            }
            sum
        };
        // Rayleigh quotient zᵀHz / zᵀDz of z = trial (the skew part of J drops out of zᵀJz);
        // `delta` is its scratch.
        let rayleigh = |jac: &crate::block_tridiag::BlockTridiag,
                        z: &[Vector6<f64>],
                        hz: &mut [Vector6<f64>]| {
            jac.mul(z, hz);
            let zhz: f64 = z.iter().zip(hz.iter()).map(|(a, b)| a.dot(b)).sum();
            zhz / d_norm(z).max(1e-300)
        };
        let rho = rayleigh(&self.ws.jac, &self.trial, &mut self.delta);
        if !(rho < 0.0 && rho.is_finite()) {
            return true; // keep the LDLᵀ direction
        }
        let shift = |jac: &mut crate::block_tridiag::BlockTridiag, mu: f64| {
            for b in 0..nb {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        jac.diag[b][(k, k)] -= mu * damping(b, k);
                    }
                }
            }
        };
        let mut mu = 1.5 * rho;
        let mut ok = false;
        for _ in 0..30 {
            shift(&mut self.ws.jac, mu);
            let inertia = self.ws.jac.inertia(0..nb);
            if inertia.negative == 0 && inertia.zero == 0 && self.ws.jac.factor().is_ok() {
                ok = true;
                break;
            }
            shift(&mut self.ws.jac, -mu);
            mu *= 1.5;
        }
        if !ok {
            return true;
        }
        let iterate = |ws: &mut Workspace, z: &mut [Vector6<f64>], count: usize| {
            for _ in 0..count {
                for (b, v) in z.iter_mut().enumerate() {
                    for k in 0..6 {
                        v[k] *= if rod.mask[b][k] { damping(b, k) } else { 0.0 };
                    }
                }
                ws.jac.solve_factored(z);
                let n = d_norm(z).sqrt().max(1e-300);
                z.iter_mut().for_each(|v| *v /= n);
            }
        };
        iterate(&mut self.ws, &mut self.trial, 8);
        shift(&mut self.ws.jac, -mu);
        // Nearly equal negative eigenvalues (a round section: one per bending plane, split
        // only by imperfections) need a shift close to the eigenvalue to separate: shift by
        // the Rayleigh quotient less 1 % (10 % if that is not below the spectrum).
        let rho = rayleigh(&self.ws.jac, &self.trial, &mut self.delta);
        for gap in [0.01, 0.1] {
            let mu = rho * (1.0 + gap);
            shift(&mut self.ws.jac, mu);
            let inertia = self.ws.jac.inertia(0..nb);
            let pd = inertia.negative == 0 && inertia.zero == 0 && self.ws.jac.factor().is_ok();
            if pd {
                iterate(&mut self.ws, &mut self.trial, 40);
            }
            shift(&mut self.ws.jac, -mu);
            if pd {
                break;
            }
        }
        true
    }

    /// From a perturbed (or no longer equilibrated) state into a stable equilibrium: energy
    /// descent (`descend`); if that fails, pseudo-transient continuation finished by plain
    /// Newton where a nearly neutral mode (e.g. the plane of a buckled round section) makes it
    /// creep near the solution.
    fn relax(
        &mut self,
        rod: &Rod,
        st: &mut State,
        newton_shortcut: bool,
    ) -> Result<SolveStats, SolveError> {
        self.relax_start.clone_from(st);
        let found = self.descend(rod, st, 20 * self.opts.max_iterations, newton_shortcut);
        if let Ok(s) = found {
            return Ok(s);
        }
        st.clone_from(&self.relax_start);
        let found = self.pseudo_transient(rod, st, 1.0, 20 * self.opts.max_iterations);
        match found {
            Err(SolveError::NotConverged { iterations, .. }) => {
                let mut s = self.newton(rod, st, 1.0, false)?;
                s.iterations += iterations;
                Ok(s)
            }
            other => other,
        }
    }

    /// Energy descent into a stable equilibrium: steps (J + σD)Δ = −r with σ ≥ 0 the least
    /// (of a geometric sequence) that makes the symmetric part of J + σD positive definite, so
    /// Δ is a descent direction and a saddle cannot attract the iteration; backtracking on the
    /// potential energy (Armijo), or, near the minimum where the energy's round-off hides the
    /// decrease, on the natural monotonicity test. σ is lowered after each step; it ends as
    /// Newton at a minimum. Dead moments are not conservative: then only the monotonicity test.
    /// With `newton_shortcut`, plain Newton is tried wherever J is positive definite (it may
    /// jump to a farther stable state: for escapes from unstable states, not for following a
    /// branch).
    pub fn descend(
        &mut self,
        rod: &Rod,
        st: &mut State,
        max_iterations: usize,
        newton_shortcut: bool,
    ) -> Result<SolveStats, SolveError> {
        let h = rod.mean_ds();
        let l = rod.spec.length;
        let nb = rod.arc.len();
        let conservative = rod.edge_moment.iter().all(|m| *m == Vector3::zeros());
        let damping = |b: usize, k: usize| -> f64 {
            if k < 3 {
                rod.ds_node[b]
            } else {
                rod.ds_edge[b.min(nb - 2)].powi(3) / 12.0
            }
        };
        let add_damping = |jac: &mut crate::block_tridiag::BlockTridiag, sigma: f64| {
            for b in 0..nb {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        jac.diag[b][(k, k)] += sigma * damping(b, k);
                    }
                }
            }
        };
        self.assemble(rod, st, 1.0, true)
            .map_err(|k| Self::kink_err(rod, k))?;
        let mut energy = self.ws.elastic_energy + self.ws.load_potential;
        let (_, mut rinf) = self.ws.residual_norms(h);
        let mut sigma_ref = 0.0f64;
        for b in 0..nb {
            for k in 0..6 {
                if rod.mask[b][k] {
                    sigma_ref = sigma_ref.max(self.ws.jac.diag[b][(k, k)].abs() / damping(b, k));
                }
            }
        }
        let floor = 1e-12 * sigma_ref;
        let mut sigma = 0.0f64;
        let mut next_newton = 0;
        let mut stats = SolveStats::default();
        for it in 0..max_iterations {
            stats.iterations = it + 1;
            if rinf <= self.opts.residual_tolerance * self.force_scale {
                stats.iterations = it;
                stats.residual = rinf;
                return Ok(stats);
            }
            // The least σ (0, then 10× steps) that makes J + σD positive definite.
            let mut pd = false;
            for _ in 0..40 {
                add_damping(&mut self.ws.jac, sigma);
                let inertia = self.ws.jac.inertia(0..nb);
                if inertia.negative == 0 && inertia.zero == 0 && self.ws.factor(rod).is_ok() {
                    pd = true;
                    break;
                }
                add_damping(&mut self.ws.jac, -sigma);
                sigma = (sigma * 10.0).max(floor);
            }
            if !pd {
                break;
            }
            let (dx, dth) = self.ws.newton_correction(&mut self.delta);
            let step = (dx / l).max(dth);
            if !step.is_finite() {
                break;
            }
            // Directional derivative of the energy along Δ: rᵀΔ < 0.
            let slope: f64 = self
                .ws
                .rhs
                .iter()
                .zip(&self.delta)
                .map(|(r, d)| r.dot(d))
                .sum();
            let norm0 = scaled_norm(&self.delta, l);
            let mut alpha = 1.0f64.min(self.opts.max_rotation_step / dth.max(1e-300));
            self.base.clone_from(st);
            let mut accepted = false;
            for _ in 0..30 {
                st.apply_increment(rod, &self.delta, alpha);
                if self.assemble(rod, st, 1.0, false).is_ok() {
                    let e = self.ws.elastic_energy + self.ws.load_potential;
                    let armijo = conservative && e <= energy + 1e-4 * alpha * slope;
                    // The monotonicity test stands in for Armijo only where the energy change
                    // is round-off: it must not let the iteration climb back to the saddle it
                    // left (measured: a round column returned to its straight state, 1.3e-4
                    // higher, in 8 of 12 cases).
                    let round_off = ENERGY_ROUND_OFF
                        * (self.ws.elastic_energy.abs() + self.ws.load_potential.abs());
                    let level = !conservative || e <= energy + round_off;
                    for (d, r) in self.trial.iter_mut().zip(&self.ws.rhs) {
                        *d = -r;
                    }
                    self.ws.jac.solve_factored(&mut self.trial);
                    let theta = scaled_norm(&self.trial, l) / norm0.max(1e-300);
                    if e.is_finite() && (armijo || (level && theta <= 1.0 - 0.25 * alpha)) {
                        energy = e;
                        accepted = true;
                        break;
                    }
                }
                st.clone_from(&self.base);
                alpha *= 0.5;
            }
            if !accepted {
                sigma = (sigma * 10.0).max(floor);
                self.assemble(rod, st, 1.0, true)
                    .map_err(|k| Self::kink_err(rod, k))?;
                continue;
            }
            self.assemble(rod, st, 1.0, true)
                .map_err(|k| Self::kink_err(rod, k))?;
            (_, rinf) = self.ws.residual_norms(h);
            if std::env::var_os("ROD_DEBUG").is_some() {
                eprintln!("descend {it} sigma {sigma:.3e} alpha {alpha:.3e} E {energy:.9e} rinf {rinf:.3e}");
            }
            // Converged: a full step below the step tolerance with σ zero — or negligible
            // (≤ 1e-9 of the stiffest entry's), where the equilibrium is neutral: a round
            // section's buckled shape turns freely about the load line, the tangent is
            // singular there and only J + σD with σ > 0 is positive definite (measured: the
            // residual's round-off floor, ~3e-8 of the force scale, lies above its tolerance).
            if sigma <= NEUTRAL_SIGMA * sigma_ref && alpha == 1.0 && step < self.opts.step_tolerance
            {
                stats.residual = rinf;
                return Ok(stats);
            }
            if conservative && alpha == 1.0 && sigma <= NEUTRAL_SEARCH * floor {
                // σ is held up by a mode whose curvature the tangent cannot resolve against
                // a stiff axis (the plane of a buckled round column, which an imperfection
                // turns): minimise the energy along that mode (`neutral_search`); converged
                // when that gains nothing and the step is below the tolerance outside it.
                let (moved, off_mode) = self.neutral_search(rod, st, sigma, &mut energy)?;
                (_, rinf) = self.ws.residual_norms(h);
                stats.iterations += 1;
                if !moved && alpha == 1.0 && off_mode < self.opts.step_tolerance {
                    stats.residual = rinf;
                    return Ok(stats);
                }
            }
            if newton_shortcut && sigma == 0.0 && it >= next_newton {
                // Positive definite: Newton from here, which does not creep along a nearly
                // neutral direction as the backtracking does; kept if it ends stable.
                // (Not in `base`: `newton` uses it for its own steps.)
                self.shortcut_start.clone_from(st);
                if let Ok(s) = self.newton(rod, st, 1.0, false) {
                    stats.iterations += s.iterations;
                    if self.ws.jac.inertia(0..nb).negative == 0 {
                        stats.residual = s.residual;
                        return Ok(stats);
                    }
                }
                next_newton = it + 10;
                // Where Newton went (an unstable equilibrium, or where it stopped) is kept if
                // it is lower in energy: descent from there; otherwise back to the start (a
                // Newton run back up to the saddle left the descent there).
                let lower = self.assemble(rod, st, 1.0, false).is_ok() && {
                    let e = self.ws.elastic_energy + self.ws.load_potential;
                    e.is_finite() && e < energy
                };
                if lower {
                    energy = self.ws.elastic_energy + self.ws.load_potential;
                } else {
                    st.clone_from(&self.shortcut_start);
                }
                self.assemble(rod, st, 1.0, true)
                    .map_err(|k| Self::kink_err(rod, k))?;
                (_, rinf) = self.ws.residual_norms(h);
            }
            sigma = if sigma <= floor { 0.0 } else { 0.1 * sigma };
        }
        Err(SolveError::NotConverged {
            iterations: stats.iterations,
            residual: rinf,
            load_factor: 1.0,
        })
    }

    /// Direction `i` of `count` of an escape into `self.neutral`: cos ψ v₁ + sin ψ v₂ with
    /// ψ = 2π i/count (±v₁ without `planes`; the modes in `self.modes`); returns its largest
    /// rotation component.
    fn escape_direction(&mut self, rod: &Rod, i: usize, count: usize, planes: bool) -> f64 {
        let psi = 2.0 * std::f64::consts::PI * i as f64 / count as f64;
        let (c, s) = if planes {
            (psi.cos(), psi.sin())
        } else {
            (psi.cos().signum(), 0.0)
        };
        let mut dth = 0.0f64;
        for (b, t) in self.neutral.iter_mut().enumerate() {
            *t = c * self.modes[0][b] + s * self.modes[1][b];
            for k in 3..6 {
                if rod.mask[b][k] {
                    dth = dth.max(t[k].abs());
                }
            }
        }
        dth.max(1e-300)
    }

    /// `self.base` moved by t along `self.neutral` and projected onto the stiff axis; its
    /// potential energy (∞ if the assembly fails).
    fn state_along(&mut self, rod: &Rod, st: &mut State, t: f64) -> f64 {
        st.clone_from(&self.base);
        st.apply_increment(rod, &self.neutral, t);
        self.project_positions(rod, st);
        if self.correct_off_mode {
            // Back onto the curve of the mode: chord-Newton steps with (H + σD) of the start,
            // constrained to zᵀDΔ = 0 (bordered by w = (H + σD)⁻¹Dz): a straight step along
            // the mode leaves it at second order, and against the moments of a buckled state
            // that costs energy at second order too.
            let nb = rod.arc.len();
            for _ in 0..3 {
                if self.assemble(rod, st, 1.0, false).is_err() {
                    return f64::INFINITY;
                }
                for (d, r) in self.trial.iter_mut().zip(&self.ws.rhs) {
                    *d = -r;
                }
                self.ws.jac.solve_factored(&mut self.trial);
                let mut zd = 0.0;
                for b in 0..nb {
                    for k in 0..6 {
                        if rod.mask[b][k] {
                            zd += crate::escape::damping(rod, b, k)
                                * self.neutral[b][k]
                                * self.trial[b][k];
                        }
                    }
                }
                let mu = zd / self.neutral_zdw;
                for (d, w) in self.trial.iter_mut().zip(&self.neutral_w) {
                    *d -= mu * w;
                }
                st.apply_increment(rod, &self.trial, 1.0);
                self.project_positions(rod, st);
            }
        }
        match self.assemble(rod, st, 1.0, false) {
            Ok(()) => self.ws.elastic_energy + self.ws.load_potential,
            Err(_) => f64::INFINITY,
        }
    }

    /// Minimises the energy along `sign` × `self.neutral` from `self.base` (energy `e0`):
    /// steps doubled from `unit` while the energy falls (up to the largest rotation step),
    /// then 8 ternary refinements in [t/2, 2t] (or [0, unit] if the first step rose). Returns
    /// the lowest energy found and its step t (0: none lower); `st` is scratch.
    fn minimise_along(
        &mut self,
        rod: &Rod,
        st: &mut State,
        sign: f64,
        unit: f64,
        e0: f64,
    ) -> (f64, f64) {
        let dth = unit.recip() * 0.01;
        let mut best = (e0, 0.0f64);
        let mut t = unit;
        while t * dth <= self.opts.max_rotation_step {
            let e = self.state_along(rod, st, sign * t);
            if e.is_nan() || e >= best.0 {
                break;
            }
            best = (e, t);
            t *= 2.0;
        }
        let (mut a, mut b) = if best.1 == 0.0 {
            (0.0, unit)
        } else {
            (0.5 * best.1, 2.0 * best.1)
        };
        for _ in 0..8 {
            let (m1, m2) = (a + (b - a) / 3.0, b - (b - a) / 3.0);
            let e1 = self.state_along(rod, st, sign * m1);
            let e2 = self.state_along(rod, st, sign * m2);
            for (e, m) in [(e1, m1), (e2, m2)] {
                if e < best.0 {
                    best = (e, m);
                }
            }
            if e1 < e2 {
                b = m2;
            } else {
                a = m1;
            }
        }
        best
    }

    /// A line search along the nearly neutral mode of the energy descent: the lowest mode z
    /// of (H + σD) z = μ D z (inverse iteration from the last descent step in `self.delta`,
    /// which the slow mode dominates), then the energy minimised along ∓z (the sign of the
    /// energy's slope) — steps doubled from 0.01 rad while the energy falls, then 8 ternary
    /// refinements — each trial projected back onto the stiff axis (`project_positions`: a
    /// finite turn of the frames stretches it at second order). A decrease within the energy's
    /// round-off does not count. Returns whether the state moved, and the last descent step's
    /// largest component off the mode (|Δx|/L, |θ|) for the convergence test. Leaves the
    /// Jacobian assembled at the state returned.
    fn neutral_search(
        &mut self,
        rod: &Rod,
        st: &mut State,
        sigma: f64,
        energy: &mut f64,
    ) -> Result<(bool, f64), SolveError> {
        let nb = rod.arc.len();
        let l = rod.spec.length;
        let damping = |b: usize, k: usize| -> f64 {
            if k < 3 {
                rod.ds_node[b]
            } else {
                rod.ds_edge[b.min(nb - 2)].powi(3) / 12.0
            }
        };
        let d_dot = |a: &[Vector6<f64>], c: &[Vector6<f64>]| -> f64 {
            let mut sum = 0.0;
            for (b, (x, y)) in a.iter().zip(c).enumerate() {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        sum += damping(b, k) * x[k] * y[k];
                    }
                }
            }
            sum
        };
        let shift = |jac: &mut crate::block_tridiag::BlockTridiag, s: f64| {
            for b in 0..nb {
                for k in 0..6 {
                    if rod.mask[b][k] {
                        jac.diag[b][(k, k)] += s * damping(b, k);
                    }
                }
            }
        };
        self.neutral.clone_from(&self.delta);
        shift(&mut self.ws.jac, sigma);
        let factored = self.ws.jac.factor().is_ok();
        if factored {
            for _ in 0..8 {
                for (b, v) in self.neutral.iter_mut().enumerate() {
                    for k in 0..6 {
                        v[k] *= if rod.mask[b][k] { damping(b, k) } else { 0.0 };
                    }
                }
                self.ws.jac.solve_factored(&mut self.neutral);
                let n = d_dot(&self.neutral, &self.neutral).sqrt().max(1e-300);
                self.neutral.iter_mut().for_each(|v| *v /= n);
            }
            for (b, (w, z)) in self.neutral_w.iter_mut().zip(&self.neutral).enumerate() {
                for k in 0..6 {
                    w[k] = if rod.mask[b][k] {
                        damping(b, k) * z[k]
                    } else {
                        0.0
                    };
                }
            }
            self.ws.jac.solve_factored(&mut self.neutral_w);
            self.neutral_zdw = d_dot(&self.neutral, &self.neutral_w);
        }
        shift(&mut self.ws.jac, -sigma);
        // The last step off the mode.
        let c = d_dot(&self.neutral, &self.delta);
        let mut off = 0.0f64;
        for (b, (d, z)) in self.delta.iter().zip(&self.neutral).enumerate() {
            for k in 0..6 {
                if rod.mask[b][k] {
                    let v = (d[k] - c * z[k]).abs();
                    off = off.max(if k < 3 { v / l } else { v });
                }
            }
        }
        let slope: f64 = self
            .ws
            .rhs
            .iter()
            .zip(&self.neutral)
            .map(|(r, z)| r.dot(z))
            .sum();
        let mut dth = 0.0f64;
        for (b, z) in self.neutral.iter().enumerate() {
            for k in 3..6 {
                if rod.mask[b][k] {
                    dth = dth.max(z[k].abs());
                }
            }
        }
        if !factored || !slope.is_finite() || slope == 0.0 || dth == 0.0 {
            return Ok((false, off));
        }
        let dir = -slope.signum();
        self.base.clone_from(st);
        let e0 = *energy;
        let round_off =
            ENERGY_ROUND_OFF * (self.ws.elastic_energy.abs() + self.ws.load_potential.abs());
        self.correct_off_mode = self.neutral_zdw > 0.0;
        let best = self.minimise_along(rod, st, dir, 0.01 / dth, e0);
        let moved = best.1 > 0.0 && best.0 < e0 - round_off;
        if moved {
            *energy = self.state_along(rod, st, dir * best.1);
        }
        self.correct_off_mode = false;
        if !moved {
            st.clone_from(&self.base);
        }
        self.assemble(rod, st, 1.0, true)
            .map_err(|k| Self::kink_err(rod, k))?;
        if std::env::var_os("ROD_DEBUG").is_some() {
            eprintln!(
                "neutral search: t {:.3e} rad, E {:.9e} → {:.9e}, off-mode step {off:.3e}",
                best.1 * dth,
                e0,
                best.0
            );
        }
        Ok((moved, off))
    }

    /// The largest node displacement from `self.before` to `st`.
    fn jump_from_before(&self, rod: &Rod, st: &State, fraction: f64) -> Snap {
        let mut snap = Snap {
            fraction,
            jump: 0.0,
            node: 0,
        };
        for (n, (a, b)) in self.before.x.iter().zip(&st.x).enumerate() {
            let d = (a - b).norm();
            if rod.node_kind[n] == NodeKind::Free && d > snap.jump {
                snap.jump = d;
                snap.node = n;
            }
        }
        snap
    }

    fn continuation(
        &mut self,
        rod: &Rod,
        st: &mut State,
        damped: bool,
    ) -> Result<SolveStats, SolveError> {
        let total = self.newton(rod, st, 0.0, damped)?;
        let min_step = self.opts.min_load_step;
        continue_load(st, total, min_step, |st, load| {
            self.newton(rod, st, load, damped)
        })
    }

    /// One step of a sequence of equilibria: from the current (converged) state to the clip
    /// poses `target`, bisecting the clip motion when Newton fails. (The sliding clips'
    /// friction reference is set by `sequence_step`, before its predictor.)
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
            Ok(mut s) => {
                self.ensure_stable(rod, st, &mut s, 1.0)?;
                return Ok(s);
            }
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
                Ok(mut s) => {
                    self.ensure_stable(rod, st, &mut s, f)?;
                    total.iterations += s.iterations;
                    total.residual = s.residual;
                    total.substeps += 1;
                    total.unstable = s.unstable;
                    total.escapes += s.escapes;
                    total.merge_snap(s.snap);
                    done = f;
                    if depth > 1 {
                        depth -= 1;
                        df *= 2.0;
                    }
                }
                Err(e) => {
                    st.clone_from(&self.saved);
                    if depth >= SNAP_DEPTH {
                        // The branch may end here (a fold): relax into a stable equilibrium at
                        // these clip poses or, where the landscape is too flat for that next to
                        // the fold, at the step's target; a large jump is a snap-through at f.
                        for (to, poses_to) in [(f, &poses), (1.0, &target.to_vec())] {
                            st.clone_from(&self.saved);
                            st.set_clip_poses(rod, poses_to);
                            let relaxed = self.relax(rod, st, true);
                            if std::env::var_os("ROD_DEBUG").is_some() {
                                eprintln!("fold? f {f} → {to}, depth {depth}: {relaxed:?}");
                            }
                            let Ok(mut s) = relaxed else { continue };
                            self.ensure_stable(rod, st, &mut s, f)?;
                            if s.unstable.unwrap_or(0) != 0 {
                                continue;
                            }
                            total.iterations += s.iterations;
                            total.residual = s.residual;
                            total.substeps += 1;
                            total.unstable = s.unstable;
                            self.before.clone_from(&self.saved);
                            let snap = self.jump_from_before(rod, st, f);
                            if snap.jump > SNAP_JUMP * rod.spec.length {
                                total.escapes += 1;
                                total.merge_snap(Some(snap));
                            }
                            done = to;
                            break;
                        }
                        if done >= f {
                            continue;
                        }
                        st.clone_from(&self.saved);
                    }
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
        if let Some(s) = &mut self.sliding {
            s.begin_step(rod, st, None); // the guides' friction acts from the last equilibrium
        }
        if self.has_prev {
            st.extrapolate_free(rod, &self.prev, &self.last);
        }
        let first = match self.step_to(rod, st, target) {
            Ok(s) => Ok(s),
            Err(_) => {
                st.clone_from(&self.last);
                self.step_to(rod, st, target)
            }
        };
        let result = restep_load_scaled(
            self,
            first,
            |s, f| s.contact.as_mut().is_some_and(f),
            |s| s.step_to(rod, st, target),
        );
        std::mem::swap(&mut self.prev, &mut self.last);
        self.has_prev = true;
        let stats = result?;
        self.check_sliding(rod, st)?;
        Ok(stats)
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

/// A static solve with the contact barrier scaled to the load (`Contact::adapt_stiffness`,
/// `Contact::stiffen_after_failure`), shared by the single cable and the harness: `solve` once;
/// a converged state whose contacts adapt their stiffness is solved again from there (at most
/// 4 times), a failure that `retry` admits and whose contacts stiffen is retried from the
/// start (at most 3 times). `contacts(solver, f)` applies `f` to every contact term and tells
/// whether any returned true.
pub(crate) fn solve_load_scaled<T, S: Clone, E>(
    solver: &mut T,
    st: &mut S,
    contacts: impl Fn(&mut T, &mut dyn FnMut(&mut Contact) -> bool) -> bool,
    retry: impl Fn(&E) -> bool,
    mut solve: impl FnMut(&mut T, &mut S) -> Result<SolveStats, E>,
) -> Result<SolveStats, E> {
    let start = st.clone();
    let mut iterations = 0;
    let (mut adapted, mut stiffened) = (0, 0);
    loop {
        contacts(solver, &mut |c| {
            c.begin_solve();
            false
        });
        match solve(solver, st) {
            Ok(s) => {
                iterations += s.iterations;
                if adapted < 4 && contacts(solver, &mut |c| c.adapt_stiffness()) {
                    adapted += 1;
                    continue;
                }
                return Ok(SolveStats { iterations, ..s });
            }
            Err(e) => {
                if retry(&e)
                    && stiffened < 3
                    && contacts(solver, &mut |c| c.stiffen_after_failure())
                {
                    stiffened += 1;
                    st.clone_from(&start);
                    continue;
                }
                return Err(e);
            }
        }
    }
}

/// A quasistatic step with the barrier scaled to the load (as `solve_load_scaled`): after the
/// `first` solve of the step converged and a contact adapted its stiffness, the step once more
/// from that equilibrium (`restep`), the iterations summed. Shared by the single cable and the
/// harness.
pub(crate) fn restep_load_scaled<T, E>(
    solver: &mut T,
    first: Result<SolveStats, E>,
    contacts: impl Fn(&mut T, &mut dyn FnMut(&mut Contact) -> bool) -> bool,
    restep: impl FnOnce(&mut T) -> Result<SolveStats, E>,
) -> Result<SolveStats, E> {
    match first {
        Ok(s) if contacts(solver, &mut |c| c.adapt_stiffness()) => {
            restep(solver).map(|r| SolveStats {
                iterations: s.iterations + r.iterations,
                ..r
            })
        }
        r => r,
    }
}

/// Load continuation from a converged state at load factor 0 (`total`: that solve's figures)
/// to 1: Newton at growing load factors, the increment ×1.5 after a success and ×½ after a
/// failure (the state restored), until it falls below `min_step`. Shared by the single cable
/// and the harness.
pub(crate) fn continue_load<S: Clone, E>(
    st: &mut S,
    mut total: SolveStats,
    min_step: f64,
    mut newton: impl FnMut(&mut S, f64) -> Result<SolveStats, E>,
) -> Result<SolveStats, E> {
    total.substeps = 1;
    let mut lambda = 0.0;
    let mut dl = 0.25f64;
    while lambda < 1.0 {
        let trial = (lambda + dl).min(1.0);
        let saved = st.clone();
        match newton(st, trial) {
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
                if dl < min_step {
                    return Err(e);
                }
            }
        }
    }
    Ok(total)
}
