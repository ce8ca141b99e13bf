//! Dynamics: the Newton–Euler equations of the rod (paper eqs. 5–6) integrated by the Lie-group
//! generalized-α method (Brüls, Cardona & Arnold 2012), second order, with the high-frequency
//! numerical damping set by the spectral radius at infinity ρ∞ (ρ∞ = 1: no numerical damping).
//!
//! Velocities are v = (ẋ_n global, ω_{n+½} body frame); nodes carry lumped masses ρAδs, edges
//! the rotary inertia ρΔs diag(I₁, I₂, I₁+I₂), with the gyroscopic term ω × Jω. Per step:
//!   q_{n+1} = q_n ∘ exp(hΔq),  Δq = v_n + h(½ − β)a_n + hβ a_{n+1},
//!   v_{n+1} = v_n + h(1 − γ)a_n + hγ a_{n+1},
//!   (1 − α_m)a_{n+1} + α_m a_n = (1 − α_f)v̇_{n+1} + α_f v̇_n,
//!   M v̇_{n+1} + g(q_{n+1}, v_{n+1}) = f_ext(t_{n+1}),
//! solved by Newton in the increment δq with S = K + γ/(βh) C + (1 − α_m)/(βh²(1 − α_f)) M on the
//! block-tridiagonal structure of the static solver (K includes the derivative of the viscous
//! forces through the strain rates' dependence on the configuration). The system splits at
//! fixed clips into independent segments, each iterated to convergence on its own with its own
//! factorisation, which is reused across iterations and steps while the iteration contracts
//! fast. Prescribed unknowns follow the clips; the free twist of swivel clips is massless
//! (quasistatic within the step).
use crate::assembly::{Elastic, Eval, External, KinkAt, Part, Rates, Term, Workspace};
use crate::block_tridiag::BlockTridiag;
use crate::contact::Contact;
use crate::contraction::{Contraction, Tolerance};
use crate::impact::take_gain;
use crate::model::{EdgeKind, NodeKind, Pose, Rod, Segment};
use crate::predictor::Extrapolation;
use crate::rotation::{
    log_vec, right_jacobian, rotate_body, rotate_edges, rotation_matrix, skew, slerp, Quat,
};
use crate::sliding::SlidingClips;
use crate::state::State;
use crate::statics::SolveError;
use nalgebra::{Matrix3, Vector3, Vector6};

/// Generalized-α coefficients from the spectral radius at infinity ρ∞ ∈ [0, 1].
#[derive(Clone, Copy, Debug)]
pub struct GenAlpha {
    pub rho_inf: f64,
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl GenAlpha {
    pub fn new(rho_inf: f64) -> Self {
        let r = rho_inf;
        let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
        let alpha_f = r / (r + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        GenAlpha {
            rho_inf,
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }
}

/// Kinematics of a clip at one time: pose, velocity and acceleration of the clip centre, and
/// angular velocity and acceleration (global frame).
#[derive(Clone, Copy, Debug)]
pub struct ClipMotion {
    pub pose: Pose,
    pub velocity: Vector3<f64>,
    pub angular_velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
    pub angular_acceleration: Vector3<f64>,
}

impl ClipMotion {
    /// The kinematics half-way to `other` (linear, rotations by slerp).
    pub fn midpoint(&self, other: &ClipMotion) -> ClipMotion {
        ClipMotion {
            pose: Pose {
                position: 0.5 * (self.pose.position + other.pose.position),
                orientation: slerp(&self.pose.orientation, &other.pose.orientation, 0.5),
            },
            velocity: 0.5 * (self.velocity + other.velocity),
            angular_velocity: 0.5 * (self.angular_velocity + other.angular_velocity),
            acceleration: 0.5 * (self.acceleration + other.acceleration),
            angular_acceleration: 0.5 * (self.angular_acceleration + other.angular_acceleration),
        }
    }
}

#[derive(Clone, Debug)]
pub struct DynamicOptions {
    pub rho_inf: f64,
    /// Retardation times τ of the Kelvin–Voigt damping per mode: (GA₁, GA₂, EA) and
    /// (EI₁, EI₂, GJ), s.
    pub tau_shear: Vector3<f64>,
    pub tau_bend: Vector3<f64>,
    pub max_iterations: usize,
    /// Converged when the Newton correction (|δx|/L, |δθ|, max over the segment) is below this
    /// fraction of the estimated local time-discretisation error of the step,
    /// |β − 1/6| h² |v̇_{n+1} − v̇_n| (the leading term of the Newmark/generalized-α local
    /// error, Zienkiewicz & Xie 1991; max over the cable, scaled as the corrections), at most
    /// `STALL_TOLERANCE` of the step's own increment h|Δq| (max over the cable) … or below
    /// `TOLERANCE_FLOOR` of it (round-off) … (0.1: the iteration
    /// error then stays well below the time-discretisation error whatever the cable, its
    /// damping and the excitation; measured in docs/dynamics.md)
    pub tolerance: f64,
    /// … or below this absolute value.
    pub abs_tolerance: f64,
    /// Refactor the iteration matrix when the correction shrinks by less than this factor.
    pub refactor_rate: f64,
    /// Assemble the section forces, moments, reactions and energies at the end of every step;
    /// otherwise only when asked (`update_outputs`), e.g. on the steps that are saved.
    pub outputs_every_step: bool,
    /// With contact: a step (with the clips' work subtracted, obstacles at rest) whose total
    /// energy grows by more than this fraction of the energies at play is split in two (an
    /// impact on the stiff barrier), down to the sub-step depth of `advance`.
    pub energy_tolerance: f64,
    /// With contact, while samples are inside the barrier: the Newton tolerance is at most this
    /// fraction of the step's increment h|Δq| (`step_tolerance`; the barrier turns small position
    /// errors into large energy errors). 1e-4 since session 8; measured against 3e-4 and 1e-3 in
    /// session 15 (docs/contact.md, "The Newton stopping rule with contact").
    pub contact_tolerance: f64,
    /// `refactor_rate` while samples are inside the contact barrier: the tight
    /// `contact_tolerance` is reached in fewer iterations with a fresh matrix than by the slow
    /// contraction of a reused one (bench_contact: 7.8 → 6.3 iterations per step, 30 % faster).
    pub contact_refactor_rate: f64,
    /// With contact: shorten a Newton correction by a line search on a model of the
    /// barrier-augmented merit (`Contact::line_search`) instead of the fixed rule "close at
    /// most 90 % of a gap" (`Contact::step_bound`, still the feasible bound), and refactor
    /// after a shortened correction. On by default since the contact's normal damping
    /// (session 8: bench_contact 5 s, 6.32 → 5.13 iterations per step; before the damping the
    /// drop test gained energy with it, docs/contact.md).
    pub contact_line_search: bool,
}

impl Default for DynamicOptions {
    fn default() -> Self {
        DynamicOptions {
            rho_inf: 0.9,
            tau_shear: Vector3::zeros(),
            tau_bend: Vector3::zeros(),
            max_iterations: 25,
            tolerance: DEFAULT_TOLERANCE,
            abs_tolerance: 1e-13,
            refactor_rate: 0.5,
            outputs_every_step: true,
            energy_tolerance: 1e-3,
            contact_tolerance: 1e-4,
            contact_refactor_rate: 0.2,
            contact_line_search: true,
        }
    }
}

impl DynamicOptions {
    /// The Newton tolerance of a step, in the units of its corrections: `tolerance` times the
    /// estimated local time-discretisation error `error`, at most `STALL_TOLERANCE` of the
    /// step's increment `scale` (`contact_tolerance` of it while samples are inside a contact
    /// barrier: `touching`), at least `TOLERANCE_FLOOR` of it and `abs_tolerance`. With and
    /// without contact alike (before session 15 a contact run held the fixed fractions alone,
    /// whatever the scene's `newton_tolerance`). Only where the error rule binds does the
    /// iteration stop on its estimated remaining error (`Contraction::converged`); the caps and
    /// floors bound the correction itself.
    pub fn step_tolerance(&self, error: f64, scale: f64, touching: bool) -> Tolerance {
        let cap = if touching {
            self.contact_tolerance
        } else {
            STALL_TOLERANCE
        };
        let of_error = self.tolerance * error;
        let value = of_error
            .min(cap * scale)
            .max(TOLERANCE_FLOOR * scale)
            .max(self.abs_tolerance);
        Tolerance {
            value,
            of_error: value == of_error,
        }
    }
}

/// The default `DynamicOptions::tolerance`: the Newton iteration's estimated remaining error
/// (`contraction::Contraction`) below 0.02 of the estimated local time-discretisation error
/// (0.1 of it on the correction itself before session 17: the same iteration errors on
/// `bench_newton_tolerance.py`'s cases, docs/dynamics.md "Stopping rule").
pub const DEFAULT_TOLERANCE: f64 = 0.02;

/// The Newton iteration of a step stops at the latest when its correction is below this
/// fraction of the step's own increment h|Δq| (far below any time-discretisation error, above
/// round-off).
pub const TOLERANCE_FLOOR: f64 = 1e-8;

/// The Newton tolerance is at most this fraction of the step's increment (the former fixed
/// tolerance: in a shock — a clip starting with a velocity — the error estimate exceeds the
/// increment and alone would accept a poor iterate). A Newton iteration that stops contracting
/// (a correction with a fresh matrix no smaller than the last) keeps its iterate when the
/// correction that led there was below it too; otherwise the step is split.
pub const STALL_TOLERANCE: f64 = 5e-3;

/// What one step did.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepStats {
    /// Newton iterations (the largest number over the independent segments).
    pub iterations: usize,
    /// Factorisations of segment iteration matrices.
    pub factorizations: usize,
    pub residual: f64,
    /// Steps actually taken (more than 1 when the step was split after a failed iteration).
    pub substeps: usize,
    /// The largest energy gain, relative to the energies at play, of a sub-step near the
    /// geometry that the step guard had to accept at its deepest split (an impact the time
    /// step does not resolve) and could not give back (`impact::take_gain`: the motion held
    /// less than the gain); 0 if none.
    pub unresolved_gain: f64,
    /// The largest energy gain, relative to the energies at play, of such a sub-step that was
    /// given back from the motion near the contact (counted as dissipated); 0 if none.
    pub impact_dissipation: f64,
}

impl StepStats {
    /// These stats with an impact sub-step's energy `gain` recorded: given back from the
    /// motion near the contact (`impact_dissipation`) or, where that motion held less,
    /// unresolved.
    pub(crate) fn with_impact(self, gain: f64, given_back: bool) -> StepStats {
        if given_back {
            StepStats {
                impact_dissipation: gain,
                ..self
            }
        } else {
            StepStats {
                unresolved_gain: gain,
                ..self
            }
        }
    }

    /// The stats of this step followed by `next` (sub-steps of one step).
    pub fn then(self, next: StepStats) -> StepStats {
        StepStats {
            iterations: self.iterations + next.iterations,
            factorizations: self.factorizations + next.factorizations,
            residual: next.residual,
            substeps: self.substeps + next.substeps,
            unresolved_gain: self.unresolved_gain.max(next.unresolved_gain),
            impact_dissipation: self.impact_dissipation.max(next.impact_dissipation),
        }
    }
}

/// The step guard's verdict on a step near the geometry that gained `gain` of the energies at
/// play: None to split it (a gain above `tolerance` with splits left), else the gain to report
/// as unresolved (0 within the tolerance or for NaN, nothing at play).
pub(crate) fn guard_verdict(gain: f64, tolerance: f64, max_depth: usize) -> Option<f64> {
    match (gain > tolerance, max_depth) {
        (false, _) => Some(0.0),
        (true, 0) => Some(gain),
        (true, _) => None,
    }
}

/// Energies after a step, J.
#[derive(Clone, Copy, Debug, Default)]
pub struct Energies {
    pub kinetic: f64,
    pub elastic: f64,
    /// Potential of gravity and dead loads (−work).
    pub load_potential: f64,
    /// Dissipated by the viscous damping and friction since the start.
    pub dissipated: f64,
    /// Energy of the contact barrier.
    pub contact: f64,
}

impl Energies {
    /// The step guard's measure from these energies to `after`: the gain of the energy in
    /// motion (kinetic, elastic, gravity, barrier) beyond the clips' `work`, relative to the
    /// energies at play, and that scale (J).
    pub(crate) fn gain_to(&self, after: &Energies, work: f64) -> (f64, f64) {
        let total = |e: &Energies| e.kinetic + e.elastic + e.load_potential + e.contact;
        let scale = self.kinetic + after.kinetic + self.elastic.abs() + self.contact + work.abs();
        ((total(after) - total(self) - work) / scale, scale)
    }
}

/// The work of a clip's reaction (force, moment) over a step from pose `p0` (reaction `r0`)
/// to pose `p1` (reaction `r1`), by the trapezoidal rule.
pub(crate) fn reaction_work(
    (f0, m0): (&Vector3<f64>, &Vector3<f64>),
    (f1, m1): (&Vector3<f64>, &Vector3<f64>),
    p0: &Pose,
    p1: &Pose,
) -> f64 {
    let turn = log_vec(&(p1.orientation * p0.orientation.conjugate()));
    0.5 * (f0 + f1).dot(&(p1.position - p0.position)) + 0.5 * (m0 + m1).dot(&turn)
}

/// The factorisation state of one segment's iteration matrix.
#[derive(Clone, Copy, Debug)]
struct SegmentFactor {
    valid: bool,
    h: f64,
}

/// The time integrator of one cable.
#[derive(Clone)]
pub struct Dynamics {
    pub ws: Workspace,
    pub opts: DynamicOptions,
    /// Contact with the surroundings (a term of the assembly when set); the obstacles are
    /// placed at their poses at t_{n+1} before each step.
    pub contact: Option<Contact>,
    /// The sliding clips' term (None without sliding clips).
    pub sliding: Option<SlidingClips>,
    pub(crate) ga: GenAlpha,
    pub(crate) rates: Rates,
    pub(crate) vdot: Vec<Vector6<f64>>,
    pub(crate) a: Vec<Vector6<f64>>,
    // Values at t_n.
    x_n: Vec<Vector3<f64>>,
    p_n: Vec<Quat>,
    ghost_n: Vec<Quat>,
    pose_n: Vec<Pose>,
    v_n: Vec<Vector6<f64>>,
    vdot_n: Vec<Vector6<f64>>,
    /// The predictor of v̇ (a recursion fitted to the accepted steps: crate::predictor).
    extrapolation: Extrapolation,
    a_n: Vec<Vector6<f64>>,
    pub(crate) delta: Vec<Vector6<f64>>,
    /// Slots with inertia (free nodes, free edges).
    pub(crate) inertial: Vec<[bool; 6]>,
    /// Per block: whether the node and the edge have inertia.
    inertial_half: Vec<[bool; 2]>,
    /// Per edge: its rotation's turn h Δθ in the step (scratch of `apply_correction` and
    /// `predicted_kinematics`, which then turn the edges four at a time: `rotate_edges`).
    turn: Vec<Vector3<f64>>,
    /// Δq = dq0 + k_dq v̇, v = v0 + k_v v̇, a = a0 + k_a v̇ during a step.
    dq0: Vec<Vector6<f64>>,
    v0: Vec<Vector6<f64>>,
    a0: Vec<Vector6<f64>>,
    pub(crate) k_dq: f64,
    pub(crate) k_v: f64,
    pub(crate) k_a: f64,
    /// The step size of the current step.
    h: f64,
    pub(crate) edge_inertia: Vec<Vector3<f64>>,
    factors: Vec<SegmentFactor>,
    /// Each segment's Newton contraction with its reused matrix (the stopping rule).
    contractions: Vec<Contraction>,
    /// h|Δq| of each segment in the current step (scaled as the Newton corrections).
    increments: Vec<f64>,
    /// Estimated local time-discretisation error of each segment in the current step (scaled
    /// as the Newton corrections).
    local_errors: Vec<f64>,
    /// Dissipated power of each segment at its last iterate.
    powers: Vec<f64>,
    /// Segments at rest in equilibrium (skipped while their clips stay at rest).
    resting: Vec<bool>,
    /// The next step is the first after a (re)start: constant-velocity predictor.
    pub(crate) restarted: bool,
    /// Per clip: at the same pose as in the last step, with zero rates.
    clip_still: Vec<bool>,
    pub energies: Energies,
    /// The outputs (energies, reactions) are those of the current state.
    outputs_current: bool,
    /// Whether `update_outputs` takes the outputs pass (`Workspace::outputs_only`); tests
    /// switch it off to compare with the full assembly.
    pub(crate) outputs_pass: bool,
    /// An obstacle moved in the last step (its work is not accounted: no energy check).
    obstacles_moved: bool,
    pub(crate) power_n: f64,
    poses: Vec<Pose>,
    length: f64,
}

impl Dynamics {
    /// Starts at the state `st` (the static equilibrium) at rest but for the clip velocities.
    pub fn new(rod: &Rod, st: &State, clips: &[ClipMotion], opts: DynamicOptions) -> Self {
        let n = rod.n_edges();
        let sec = &rod.spec.section;
        let edge_inertia = rod
            .ds_edge
            .iter()
            .map(|d| sec.rotary_inertia * *d)
            .collect();
        let inertial: Vec<[bool; 6]> = (0..=n)
            .map(|b| {
                let node = rod.node_kind[b] == NodeKind::Free;
                let edge = b < n && rod.edge_kind[b] == EdgeKind::Free;
                [node, node, node, edge, edge, edge]
            })
            .collect();
        let rates = Rates {
            v: vec![Vector6::zeros(); n + 1],
            ghost_omega: vec![Vector3::zeros(); rod.ghosts.len()],
            shear_damping: opts.tau_shear.component_mul(&sec.shear_stiffness),
            bend_damping: opts.tau_bend.component_mul(&sec.bend_stiffness),
            damping_factor: 0.0,
            tangent: vec![Matrix3::identity(); n],
        };
        let n_seg = rod.segments.len();
        let mut dynamics = Dynamics {
            ws: Workspace::new(rod),
            contact: None,
            sliding: SlidingClips::of(rod),
            ga: GenAlpha::new(opts.rho_inf),
            opts,
            rates,
            vdot: vec![Vector6::zeros(); n + 1],
            a: vec![Vector6::zeros(); n + 1],
            x_n: st.x.clone(),
            p_n: st.p.clone(),
            ghost_n: st.ghost.clone(),
            pose_n: st.clip_pose.clone(),
            v_n: vec![Vector6::zeros(); n + 1],
            vdot_n: vec![Vector6::zeros(); n + 1],
            extrapolation: Extrapolation::new(n + 1),
            a_n: vec![Vector6::zeros(); n + 1],
            delta: vec![Vector6::zeros(); n + 1],
            inertial_half: inertial.iter().map(|m| [m[0], m[3]]).collect(),
            turn: vec![Vector3::zeros(); n],
            inertial,
            dq0: vec![Vector6::zeros(); n + 1],
            v0: vec![Vector6::zeros(); n + 1],
            a0: vec![Vector6::zeros(); n + 1],
            k_dq: 0.0,
            k_v: 0.0,
            k_a: 0.0,
            h: 0.0,
            edge_inertia,
            factors: vec![
                SegmentFactor {
                    valid: false,
                    h: 0.0
                };
                n_seg
            ],
            contractions: vec![Contraction::new(); n_seg],
            increments: vec![0.0; n_seg],
            local_errors: vec![0.0; n_seg],
            powers: vec![0.0; n_seg],
            resting: vec![false; n_seg],
            restarted: true,
            clip_still: Vec::with_capacity(clips.len()),
            energies: Energies::default(),
            outputs_current: false,
            outputs_pass: true,
            obstacles_moved: false,
            power_n: 0.0,
            poses: Vec::with_capacity(clips.len()),
            length: rod.spec.length,
        };
        dynamics.prescribe_rates(rod, st, clips);
        dynamics.v_n.clone_from(&dynamics.rates.v);
        dynamics.vdot_n.clone_from(&dynamics.vdot);
        dynamics.a_n.clone_from(&dynamics.vdot);
        dynamics
    }

    /// Velocities and accelerations of the prescribed unknowns and ghosts from the clips.
    fn prescribe_rates(&mut self, rod: &Rod, st: &State, clips: &[ClipMotion]) {
        for (c, m) in clips.iter().enumerate() {
            let centre = m.pose.position;
            for &n in &rod.clip_nodes[c] {
                if rod.node_kind[n] == NodeKind::Free {
                    continue;
                }
                let r = st.x[n] - centre;
                let v = m.velocity + m.angular_velocity.cross(&r);
                let acc = m.acceleration
                    + m.angular_acceleration.cross(&r)
                    + m.angular_velocity.cross(&m.angular_velocity.cross(&r));
                self.rates.v[n].fixed_rows_mut::<3>(0).copy_from(&v);
                self.vdot[n].fixed_rows_mut::<3>(0).copy_from(&acc);
            }
            for &e in &rod.clip_edges[c] {
                let rt = rotation_matrix(&st.p[e]).transpose();
                self.rates.v[e]
                    .fixed_rows_mut::<3>(3)
                    .copy_from(&(rt * m.angular_velocity));
                self.vdot[e]
                    .fixed_rows_mut::<3>(3)
                    .copy_from(&(rt * m.angular_acceleration));
            }
            if let Some(g) = rod.clip_ghost[c] {
                self.rates.ghost_omega[g] =
                    rotation_matrix(&st.ghost[g]).transpose() * m.angular_velocity;
            }
        }
    }

    /// Assembles the residual (and the iteration matrix) of a part at the current iterate.
    pub(crate) fn assemble(
        &mut self,
        rod: &Rod,
        st: &State,
        c_damp: f64,
        c_mass: f64,
        want_jac: bool,
        part: Part,
    ) -> Result<(), KinkAt> {
        self.rates.damping_factor = c_damp;
        let blocks = match part {
            Part::All => 0..st.x.len(),
            Part::Segment(seg) => seg.blocks.clone(),
        };
        if want_jac {
            for b in blocks.clone() {
                if self.inertial_half[b][1] {
                    let dq: Vector3<f64> = self.dq0[b].fixed_rows::<3>(3)
                        + self.k_dq * self.vdot[b].fixed_rows::<3>(3);
                    self.rates.tangent[b] = right_jacobian(&(self.h * dq));
                }
            }
        }
        self.ws.clear_part(part, want_jac);
        let ev = Eval {
            part,
            want_jac,
            rates: Some(&self.rates),
            load_factor: 1.0,
        };
        Elastic.add_residual_jacobian(rod, st, &ev, &mut self.ws)?;
        // Inertia: m ẍ on nodes, J ω̇ + ω × Jω on edges (prescribed ones enter the reactions;
        // in the outputs pass only they: `Workspace::outputs_only`).
        let n_edges = rod.n_edges();
        let only = self.ws.outputs_only;
        for b in blocks {
            let [at_node, at_edge] = self.ws.reaction_block[b];
            if only && !at_node && !at_edge {
                continue;
            }
            let acc: Vector3<f64> = self.vdot[b].fixed_rows::<3>(0).into();
            if !only || at_node {
                self.ws.node_grad[b] += rod.node_mass[b] * acc;
            }
            let [node, edge] = self.inertial_half[b];
            if want_jac && node {
                let m = c_mass * rod.node_mass[b];
                let d = &mut self.ws.jac.diag[b];
                for k in 0..3 {
                    d[(k, k)] += m;
                }
            }
            if b >= n_edges || (only && !at_edge) {
                continue;
            }
            let j = self.edge_inertia[b];
            let w: Vector3<f64> = self.rates.v[b].fixed_rows::<3>(3).into();
            let wdot: Vector3<f64> = self.vdot[b].fixed_rows::<3>(3).into();
            let jw = j.component_mul(&w);
            self.ws.edge_grad[b] += j.component_mul(&wdot) + w.cross(&jw);
            if want_jac && edge {
                let gyro = skew(&w) * Matrix3::from_diagonal(&j) - skew(&jw);
                let mut block = c_damp * gyro;
                for k in 0..3 {
                    block[(k, k)] += c_mass * j[k];
                }
                self.ws.jac.add3(b, 1, b, 1, &block);
            }
        }
        External.add_residual_jacobian(rod, st, &ev, &mut self.ws)?;
        self.contact
            .add_residual_jacobian(rod, st, &ev, &mut self.ws)?;
        self.sliding
            .add_residual_jacobian(rod, st, &ev, &mut self.ws)?;
        if !only {
            self.ws.finalize_part(rod, want_jac, part);
        }
        Ok(())
    }

    /// The start of a step from t_n to t_n + h (shared with the harness integrator): saves the
    /// values at t_n, sets the clips to their kinematics at t_{n+1}, the predictor and the
    /// fixed parts of the kinematics.
    pub(crate) fn begin_step(&mut self, rod: &Rod, st: &mut State, h: f64, clips: &[ClipMotion]) {
        // Values at t_n.
        self.x_n.clone_from(&st.x);
        self.p_n.clone_from(&st.p);
        self.ghost_n.clone_from(&st.ghost);
        self.pose_n.clone_from(&st.clip_pose);
        self.v_n.clone_from(&self.rates.v);
        // v̇_n into vdot_n, and the predictor (below): v̇_{n+1} from a linear recursion on the
        // past accelerations of the inertial slots, fitted to the accepted steps
        // (crate::predictor)
        let restarted = self.restarted;
        self.extrapolation.begin_step(
            &mut self.vdot,
            &mut self.vdot_n,
            Some(&self.inertial),
            restarted,
            h,
            !restarted && self.contact.is_none(),
        );
        self.a_n.clone_from(&self.a);
        self.outputs_current = false;
        self.obstacles_moved = false;
        if let Some(s) = &mut self.sliding {
            s.begin_step(rod, st, Some((h, clips)));
        }
        if let Some(c) = &mut self.contact {
            c.begin_step(&st.x, Some(h));
            if c.take_moved() {
                self.resting.fill(false); // moving geometry wakes the cable
                self.obstacles_moved = true;
            }
        }
        // Clips that stay exactly where they are, at rest.
        self.clip_still.clear();
        self.clip_still
            .extend(clips.iter().zip(&st.clip_pose).map(|(m, old)| {
                m.pose == *old
                    && m.velocity == Vector3::zeros()
                    && m.angular_velocity == Vector3::zeros()
                    && m.acceleration == Vector3::zeros()
                    && m.angular_acceleration == Vector3::zeros()
            }));
        // Prescribed motion at t_{n+1}.
        self.poses.clear();
        self.poses.extend(clips.iter().map(|m| m.pose));
        st.set_clip_poses(rod, &self.poses);
        self.prescribe_rates(rod, st, clips);
        // Predictor: the recursion fitted to the run (crate::predictor, above; all coefficients
        // zero is constant acceleration). docs/dynamics.md, "Predictor": constant acceleration took
        // 2.70 → 2.04 iterations per step on bench_harness.py's cable, 4.45 → 4.32 on
        // bench_dynamic.py, against the former constant-velocity predictor Δq = v_n; the
        // fitted recursion 2.36 → 2.00 on bench_harness.py's harness. The first step after a (re)start takes
        // constant velocity: v̇ may hold the response to a jump of the clip velocities (a
        // shock), which constant acceleration would carry through the whole step; so does
        // every step with contact (an impact is a shock; the contact term's energy behaviour
        // was verified with constant velocity: with constant acceleration the drop test of
        // tests/contact.rs gains energy at an impact).
        if std::mem::take(&mut self.restarted) || self.contact.is_some() {
            // Δq = v_n, i.e. a_{n+1} = −(½ − β)/β a_n; v̇ from (1 − α_m) a_{n+1} + α_m a_n =
            // (1 − α_f) v̇_{n+1} + α_f v̇_n.
            let ga = self.ga;
            let c_a = ((1.0 - ga.alpha_m) * (-(0.5 - ga.beta) / ga.beta) + ga.alpha_m)
                / (1.0 - ga.alpha_f);
            let c_v = -ga.alpha_f / (1.0 - ga.alpha_f);
            for b in 0..self.vdot.len() {
                let vdot = c_a * self.a_n[b] + c_v * self.vdot_n[b];
                for k in 0..6 {
                    if self.inertial[b][k] {
                        self.vdot[b][k] = vdot[k];
                    }
                }
            }
        }
        self.begin_kinematics(h);
    }

    /// Advances from t_n to t_n + h with the clips at their kinematics at t_{n+1}. A step
    /// whose Newton iteration fails from the accelerations' predictor (constant or
    /// extrapolated) is done again from constant velocity (a shock: v̇_n far from v̇_{n+1}).
    pub fn step(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        clips: &[ClipMotion],
    ) -> Result<StepStats, SolveError> {
        let from_acceleration = !self.restarted && self.contact.is_none();
        match self.step_once(rod, st, h, clips) {
            Err(e) if from_acceleration && !matches!(e, SolveError::SlidOff { .. }) => {
                self.rollback(st); // the next try predicts constant velocity
                self.step_once(rod, st, h, clips)
            }
            r => r,
        }
    }

    fn step_once(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        clips: &[ClipMotion],
    ) -> Result<StepStats, SolveError> {
        self.begin_step(rod, st, h, clips);
        for (k, seg) in rod.segments.iter().enumerate() {
            let clips_still = seg.clips.iter().all(|&c| self.clip_still[c]);
            self.resting[k] &= clips_still;
            (self.increments[k], self.local_errors[k]) = if self.resting[k] {
                (0.0, 0.0) // unchanged: Δq = 0
            } else {
                let (inc, error) = self.predicted_kinematics(st, h, seg.blocks.clone());
                match self.limit_predictor(st, h, seg) {
                    // shortened against the contact barrier: v̇ changed
                    Some(inc) => (inc, self.local_error(seg.blocks.clone())),
                    None => (inc, error),
                }
            };
        }
        let mut stats = StepStats {
            substeps: 1,
            ..Default::default()
        };
        for (k, seg) in rod.segments.iter().enumerate() {
            if self.resting[k] {
                // A segment in equilibrium with its clips at rest stays so (the loads are
                // dead): its state is the one of the last step (v = v̇ = a = 0, Δq = 0).
                self.powers[k] = 0.0;
                continue;
            }
            let s = self.solve_segment(rod, st, h, k, seg)?;
            // At rest only with its clips at rest in this step too.
            self.resting[k] &= seg.clips.iter().all(|&c| self.clip_still[c]);
            stats.iterations = stats.iterations.max(s.iterations);
            stats.factorizations += s.factorizations;
            stats.residual = stats.residual.max(s.residual);
        }
        self.update_accelerations();
        for (k, seg) in rod.segments.iter().enumerate() {
            if self.resting[k] {
                // At rest to round-off: exactly at rest from now on.
                for b in seg.blocks.clone() {
                    for i in 0..6 {
                        if self.inertial[b][i] {
                            self.vdot[b][i] = 0.0;
                            self.a[b][i] = 0.0;
                            self.rates.v[b][i] = 0.0;
                        }
                    }
                }
            }
        }
        let power: f64 = self.powers.iter().sum();
        self.energies.dissipated += 0.5 * h * (power + self.power_n);
        self.power_n = power;
        if self.opts.outputs_every_step {
            self.update_outputs(rod, st)?;
        }
        if let Some(Err(c)) = self.sliding.as_mut().map(|s| s.check(rod, st)) {
            return Err(SolveError::SlidOff {
                clip: rod.spec.clips[c].name.clone(),
            });
        }
        Ok(stats)
    }

    /// Newton iteration of segment k (independent of the others) to convergence.
    fn solve_segment(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        k: usize,
        seg: &Segment,
    ) -> Result<StepStats, SolveError> {
        let ga = self.ga;
        let ca = (1.0 - ga.alpha_f) / (1.0 - ga.alpha_m);
        let c_mass = 1.0 / (ga.beta * h * h * ca);
        let c_damp = ga.gamma / (ga.beta * h);
        let l = rod.spec.length;
        let kink = |k: KinkAt| SolveError::Kink {
            node: k.node,
            s: rod.arc[k.node],
        };
        let mut stats = StepStats::default();
        let mut last_norm = f64::INFINITY;
        let mut last_fresh_norm = f64::INFINITY;
        let mut last_applied = f64::INFINITY;
        // Iterations whose correction the contact shortened do not count (up to 4× the limit).
        let mut budget = self.opts.max_iterations;
        let mut next = 0;
        let mut strikes = 0;
        let friction = SlidingClips::frictional(&self.sliding).is_some();
        self.contractions[k].begin_step();
        while next < budget {
            let it = next;
            next += 1;
            let f = self.factors[k];
            let refactor = !f.valid || f.h != h;
            self.assemble(rod, st, c_damp, c_mass, refactor, Part::Segment(seg))
                .map_err(kink)?;
            if refactor {
                self.ws.factor_segment(rod, seg)?;
                self.factors[k] = SegmentFactor { valid: true, h };
                stats.factorizations += 1;
            }
            let (dx, dth) = self
                .ws
                .newton_correction_range(seg.blocks.clone(), &mut self.delta);
            let norm = (dx / l).max(dth);
            if !refactor && (!norm.is_finite() || norm >= last_norm) {
                // The reused matrix no longer contracts: refactor at this iterate.
                self.factors[k].valid = false;
                continue;
            }
            // Diverging: not finite, or a correction with a fresh matrix no smaller than the
            // last one with a fresh matrix (Newton does not contract: give up early, the step
            // is split).
            // With contact the barrier's Newton path is not monotone: three strikes.
            if refactor && norm >= last_fresh_norm {
                strikes += 1;
            }
            // So is the path through a frictional guide's stick zone (a fresh matrix at an
            // iterate inside it sees the stick spring: a larger correction, then convergence).
            let allowed = if self.contact.is_some() || friction {
                3
            } else {
                1
            };
            if !norm.is_finite() || strikes >= allowed {
                // … unless the correction that led to the current iterate was already below
                // `STALL_TOLERANCE` of the step's increment (the former fixed tolerance): the
                // iteration has reached what it can (round-off, or the strongly non-linear
                // viscous forces of a large retardation time) and that iterate is kept.
                let scale = self.increments.iter().cloned().fold(0.0, f64::max);
                let touching = self.contact.as_ref().is_some_and(|c| c.active > 0);
                if it > 0 && !touching && last_applied < STALL_TOLERANCE * scale {
                    stats.residual = self
                        .ws
                        .residual_inf_range(seg.blocks.clone(), rod.mean_ds());
                    self.powers[k] = self.ws.dissipation;
                    self.resting[k] = false;
                    return Ok(stats);
                }
                return Err(SolveError::NotConverged {
                    iterations: it + 1,
                    residual: self
                        .ws
                        .residual_inf_range(seg.blocks.clone(), rod.mean_ds()),
                    load_factor: 1.0,
                });
            }
            if refactor {
                last_fresh_norm = norm;
            }
            // The correction's node displacements (v̇ += c_mass δ, x = x_n + h(dq0 + k_dq v̇)).
            let kx = h * self.k_dq * c_mass;
            let (delta, half) = (&self.delta, &self.inertial_half);
            let dx = |n: usize| {
                if half[n][0] {
                    kx * delta[n].fixed_rows::<3>(0).into_owned()
                } else {
                    Vector3::zeros()
                }
            };
            // Contact: no dive through the barrier (the correction is shortened).
            let alpha = match &mut self.contact {
                Some(c) => {
                    if self.opts.contact_line_search {
                        // The Newton decrement −Δxᵀ r in the position unit (J δ = −r, Δx = kx δ).
                        let rhs = &self.ws.rhs;
                        let decrement = -kx
                            * seg
                                .blocks
                                .clone()
                                .map(|b| rhs[b].dot(&delta[b]))
                                .sum::<f64>();
                        c.line_search(
                            &st.x,
                            dx,
                            seg.edges.iter().cloned(),
                            &rod.ds_edge,
                            decrement,
                            strikes > 0,
                        )
                    } else {
                        c.step_bound(&st.x, dx, seg.edges.iter().cloned())
                    }
                }
                None => 1.0,
            };
            // Frictional guides: no node jumps across the friction's stick zone, and one stopped
            // in it needs a fresh matrix (the stick spring; a stale one from the slip side sends
            // it back: a cycle, measured).
            let alpha = match SlidingClips::frictional(&self.sliding) {
                Some(s) => {
                    let bound = s.step_bound(rod, st, Some(&self.rates), dx, seg.blocks.clone());
                    if bound < 1.0 {
                        self.factors[k].valid = false;
                    }
                    alpha.min(bound)
                }
                None => alpha,
            };
            if alpha < 1.0 {
                for d in &mut self.delta[seg.blocks.clone()] {
                    *d *= alpha;
                }
                last_fresh_norm = f64::INFINITY;
                budget = (budget + 1).min(4 * self.opts.max_iterations);
            }
            (self.increments[k], self.local_errors[k]) =
                self.apply_correction(rod, st, h, c_mass, seg);
            last_applied = norm;
            stats.iterations = it + 1;
            let scale = self.increments.iter().cloned().fold(0.0, f64::max);
            let error = self.local_errors.iter().cloned().fold(0.0, f64::max);
            // The error rule, capped tighter while samples are inside a contact barrier.
            let touching = self.contact.as_ref().is_some_and(|c| c.active > 0);
            let mut tolerance = self.opts.step_tolerance(error, scale, touching);
            // Frictional guides: a correction small against the stick width.
            if let Some(s) = SlidingClips::frictional(&self.sliding) {
                tolerance = tolerance.at_most(s.newton_tolerance(l));
            }
            if !refactor && last_norm.is_finite() {
                self.contractions[k].measure(norm, last_norm);
            }
            if alpha == 1.0 && self.contractions[k].converged(norm, tolerance) {
                stats.residual = self
                    .ws
                    .residual_inf_range(seg.blocks.clone(), rod.mean_ds());
                self.powers[k] = self.ws.dissipation;
                // Nothing moved and nothing was corrected: at rest (kept while its clips are).
                self.resting[k] = it == 0
                    && norm <= self.opts.abs_tolerance
                    && self.increments[k] <= self.opts.abs_tolerance;
                return Ok(stats);
            }
            // Slow contraction with a reused matrix: refactor at the next iterate.
            let rate = if self.contact.as_ref().is_some_and(|c| c.active > 0) {
                self.opts.contact_refactor_rate
            } else {
                self.opts.refactor_rate
            };
            // With the line search: a correction the contact shortened has the barrier far
            // from its linearisation; the next iterate gets a fresh matrix.
            if alpha < 1.0 && self.opts.contact_line_search {
                self.factors[k].valid = false;
            }
            // Slow contraction (`rate`), unless the reused matrix is expected to finish at the
            // next iterate (the contraction so far carrying this correction below the
            // tolerance): a fresh matrix costs more than that iteration.
            if norm > rate * last_norm && !refactor && norm * (norm / last_norm) >= tolerance.value
            {
                self.factors[k].valid = false;
            }
            last_norm = norm;
        }
        Err(SolveError::NotConverged {
            iterations: stats.iterations,
            residual: self
                .ws
                .residual_inf_range(seg.blocks.clone(), rod.mean_ds()),
            load_factor: 1.0,
        })
    }

    /// Shortens the predictor of a segment (from the state at t_n) so that it does not dive
    /// through the contact barrier: Δq ← α Δq; returns the new increment if it was shortened.
    fn limit_predictor(&mut self, st: &mut State, h: f64, seg: &Segment) -> Option<f64> {
        let c = self.contact.as_ref()?;
        let (x, x_n) = (&st.x, &self.x_n);
        let alpha = c.step_bound(x_n, |n| x[n] - x_n[n], seg.edges.iter().cloned());
        if alpha >= 1.0 {
            return None;
        }
        Some(self.scale_predictor(st, h, alpha, seg.blocks.clone()))
    }

    /// The predictor's step Δq = dq0 + k_dq v̇ of `blocks` shortened to α Δq (the kinematics
    /// updated; returns the new increment): `limit_predictor`, and the harness's with the
    /// bound over every cable.
    pub(crate) fn scale_predictor(
        &mut self,
        st: &mut State,
        h: f64,
        alpha: f64,
        blocks: std::ops::Range<usize>,
    ) -> f64 {
        for b in blocks.clone() {
            let dq = self.dq0[b] + self.k_dq * self.vdot[b];
            let target = (alpha * dq - self.dq0[b]) / self.k_dq;
            for i in 0..6 {
                if self.inertial[b][i] {
                    self.vdot[b][i] = target[i];
                }
            }
        }
        self.update_kinematics(st, h, blocks)
    }

    /// Whether the contact obstacles moved at the start of this step (their work is not
    /// counted: the energy guard is off for the step).
    pub(crate) fn obstacles_moved(&self) -> bool {
        self.obstacles_moved
    }

    /// The node positions at the start of the step (t_n).
    pub(crate) fn start_positions(&self) -> &[Vector3<f64>] {
        &self.x_n
    }

    /// Returns to the values at the start of the last (failed) step.
    pub(crate) fn rollback(&mut self, st: &mut State) {
        st.x.clone_from(&self.x_n);
        st.p.clone_from(&self.p_n);
        st.ghost.clone_from(&self.ghost_n);
        st.clip_pose.clone_from(&self.pose_n);
        self.rates.v.clone_from(&self.v_n);
        self.vdot.clone_from(&self.vdot_n);
        self.a.clone_from(&self.a_n);
        self.invalidate_factors();
        self.outputs_current = false;
        self.restarted = true;
        if let Some(c) = &mut self.contact {
            c.rollback_step();
        }
    }

    fn invalidate_factors(&mut self) {
        for f in &mut self.factors {
            f.valid = false;
        }
        self.resting.iter_mut().for_each(|r| *r = false);
    }

    /// Advances by h from the clip kinematics `from` (at t_n) to `to` (at t_n + h); a step whose
    /// Newton iteration fails is rolled back and done as two half steps with the clip
    /// kinematics interpolated in between, recursively up to 2^`max_depth` sub-steps.
    pub fn advance(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        from: &[ClipMotion],
        to: &[ClipMotion],
        max_depth: usize,
    ) -> Result<StepStats, SolveError> {
        // With contact, the energy at t_n and the clip reactions (for the energy check).
        // Only near the geometry: within d̂ plus twice the step's travel at the current speed.
        let travel = 2.0
            * h
            * self
                .rates
                .v
                .iter()
                .map(|v| v.fixed_rows::<3>(0).norm())
                .fold(0.0, f64::max);
        // At the deepest split the check no longer splits: a gain is reported in the stats.
        let guard = self.contact.as_ref().is_some_and(|c| c.near(&st.x, travel));
        if guard && !self.outputs_current {
            self.update_outputs(rod, st)?;
        }
        let before = guard.then(|| {
            let reactions: Vec<_> = (0..rod.spec.clips.len())
                .map(|c| self.ws.clip_reaction(rod, st, c))
                .collect();
            (self.energies, reactions, st.clip_pose.clone())
        });
        let dissipated = (self.energies.dissipated, self.power_n);
        let result = self.step(rod, st, h, to);
        let result = match (result, before) {
            (Ok(s), Some((e0, r0, poses0))) if !self.obstacles_moved => {
                self.update_outputs(rod, st)?;
                let mut work = 0.0;
                for (c, (f0, m0)) in r0.iter().enumerate() {
                    let (f1, m1) = self.ws.clip_reaction(rod, st, c);
                    work += reaction_work((f0, m0), (&f1, &m1), &poses0[c], &st.clip_pose[c]);
                }
                let (gain, scale) = e0.gain_to(&self.energies, work);
                match guard_verdict(gain, self.opts.energy_tolerance, max_depth) {
                    Some(0.0) => Ok(s),
                    Some(g) => self.give_back(rod, st, (g, scale), s),
                    None => {
                        (self.energies.dissipated, self.power_n) = dissipated;
                        Err(SolveError::NotConverged {
                            iterations: s.iterations,
                            residual: s.residual,
                            load_factor: 1.0,
                        })
                    }
                }
            }
            (r, _) => r,
        };
        match result {
            Ok(s) => Ok(s),
            Err(e) if max_depth == 0 => Err(e),
            Err(_) => {
                self.rollback(st);
                let mid: Vec<ClipMotion> =
                    from.iter().zip(to).map(|(a, b)| a.midpoint(b)).collect();
                let s1 = self.advance(rod, st, 0.5 * h, from, &mid, max_depth - 1)?;
                let s2 = self.advance(rod, st, 0.5 * h, &mid, to, max_depth - 1)?;
                Ok(s1.then(s2))
            }
        }
    }

    /// A sub-step at the deepest split that gained `gain` (relative to `scale`, J): the motion
    /// near the contact gives it back (`impact::take_gain`) and the step reports it as impact
    /// dissipation, or, where the motion holds less, as unresolved.
    fn give_back(
        &mut self,
        rod: &Rod,
        st: &State,
        (gain, scale): (f64, f64),
        s: StepStats,
    ) -> Result<StepStats, SolveError> {
        let given_back = take_gain(&mut [&mut *self], &[rod], &[st], gain * scale) != 0.0;
        if given_back {
            self.update_outputs(rod, st)?;
            self.power_n = self.ws.dissipation;
        }
        Ok(s.with_impact(gain, given_back))
    }

    /// The parts of Δq, v_{n+1} and a_{n+1} fixed during a step (from the values at t_n): all
    /// three are then affine in v̇_{n+1}. Call once the values at t_n are set.
    pub(crate) fn begin_kinematics(&mut self, h: f64) {
        let ga = self.ga;
        let ka = (1.0 - ga.alpha_f) / (1.0 - ga.alpha_m);
        let (c_vn, c_an) = (
            ga.alpha_f / (1.0 - ga.alpha_m),
            -ga.alpha_m / (1.0 - ga.alpha_m),
        );
        for b in 0..self.vdot.len() {
            // (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) v̇_{n+1} + α_f v̇_n
            let a0 = c_vn * self.vdot_n[b] + c_an * self.a_n[b];
            self.a0[b] = a0;
            self.dq0[b] = self.v_n[b] + h * (0.5 - ga.beta) * self.a_n[b] + h * ga.beta * a0;
            self.v0[b] = self.v_n[b] + h * (1.0 - ga.gamma) * self.a_n[b] + h * ga.gamma * a0;
        }
        self.k_a = ka;
        self.h = h;
        self.k_dq = h * ga.beta * ka;
        self.k_v = h * ga.gamma * ka;
    }

    /// v and q_{n+1} of the inertial unknowns of blocks `r` from the current v̇_{n+1}; returns
    /// their largest increment h|Δq| (positions relative to the cable length).
    pub(crate) fn update_kinematics(
        &mut self,
        st: &mut State,
        h: f64,
        r: std::ops::Range<usize>,
    ) -> f64 {
        self.predicted_kinematics(st, h, r).0
    }

    /// `update_kinematics` and `local_error` of blocks `r` in one pass (the predicted state
    /// at the start of a step): (largest increment h|Δq|, local error estimate at v̇).
    pub(crate) fn predicted_kinematics(
        &mut self,
        st: &mut State,
        h: f64,
        r: std::ops::Range<usize>,
    ) -> (f64, f64) {
        let (mut dx_max, mut dth_max) = (0.0f64, 0.0f64);
        let (mut ex, mut eth) = (0.0f64, 0.0f64);
        let (k_dq, k_v) = (self.k_dq, self.k_v);
        let re = r.start..r.end.min(st.p.len());
        let blocks = self.inertial_half[r.clone()]
            .iter()
            .zip(&self.vdot[r.clone()])
            .zip(&self.vdot_n[r.clone()])
            .zip(&self.dq0[r.clone()])
            .zip(&self.v0[r.clone()])
            .zip(&mut self.rates.v[r.clone()])
            .zip(&mut st.x[r.clone()])
            .zip(&self.x_n[r.clone()]);
        let mut edges = self.turn[re.clone()].iter_mut();
        for (((((((half, vdot), vd_n), dq0), v0), v), x), x_n) in blocks {
            let dq = dq0 + k_dq * vdot;
            let vel = v0 + k_v * vdot;
            let d = vdot - vd_n;
            if half[0] {
                v.fixed_rows_mut::<3>(0).copy_from(&vel.fixed_rows::<3>(0));
                let dx: Vector3<f64> = h * dq.fixed_rows::<3>(0);
                *x = x_n + dx;
                dx_max = dx_max.max(dx.amax());
                ex = ex.max(d.fixed_rows::<3>(0).amax());
            }
            let Some(turn) = edges.next() else {
                break;
            };
            if half[1] {
                v.fixed_rows_mut::<3>(3).copy_from(&vel.fixed_rows::<3>(3));
                let dth: Vector3<f64> = h * dq.fixed_rows::<3>(3);
                *turn = dth;
                dth_max = dth_max.max(dth.amax());
                eth = eth.max(d.fixed_rows::<3>(3).amax());
            }
        }
        self.turn_edges(st, re);
        let error = self.error_estimate(ex, eth);
        ((dx_max / self.length).max(dth_max), error)
    }

    /// p = p_n ⊗ exp(turn/2) for the inertial edges of `re` (their turns just stored).
    fn turn_edges(&self, st: &mut State, re: std::ops::Range<usize>) {
        let half = &self.inertial_half[re.clone()];
        let (p_n, turn) = (&self.p_n[re.clone()], &self.turn[re.clone()]);
        rotate_edges(p_n, turn, |e| half[e][1], &mut st.p[re]);
    }

    /// Applies the Newton correction `delta` of a segment (v̇ += c_m δq on inertial slots, the
    /// swivel twists directly) and updates v and q_{n+1} there; returns the segment's largest
    /// increment h|Δq| (as `update_kinematics`) and its local error estimate at the new v̇
    /// (as `local_error` over the segment's blocks, in the same pass).
    pub(crate) fn apply_correction(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        c_mass: f64,
        seg: &Segment,
    ) -> (f64, f64) {
        let mut dx_max = 0.0f64;
        let mut dth_max = 0.0f64;
        let (mut ex, mut eth) = (0.0f64, 0.0f64);
        let (k_dq, k_v) = (self.k_dq, self.k_v);
        let r = seg.blocks.clone();
        // Nodes, then edges (zipped slices: no bounds checks in the loops).
        for ((((((((half, d), vdot), dq0), v0), v), x), x_n), vd_n) in self.inertial_half[r.clone()]
            .iter()
            .zip(&self.delta[r.clone()])
            .zip(&mut self.vdot[r.clone()])
            .zip(&self.dq0[r.clone()])
            .zip(&self.v0[r.clone()])
            .zip(&mut self.rates.v[r.clone()])
            .zip(&mut st.x[r.clone()])
            .zip(&self.x_n[r.clone()])
            .zip(&self.vdot_n[r.clone()])
        {
            if half[0] {
                let (dq, e) = correct_slots(0, (c_mass, k_dq, k_v), d, vdot, dq0, v0, v, vd_n);
                ex = ex.max(e);
                let dx = h * dq;
                *x = x_n + dx;
                dx_max = dx_max.max(dx.amax());
            }
        }
        let re = r.start..r.end.min(st.p.len());
        for (((((((half, d), vdot), dq0), v0), v), turn), vd_n) in self.inertial_half[re.clone()]
            .iter()
            .zip(&self.delta[re.clone()])
            .zip(&mut self.vdot[re.clone()])
            .zip(&self.dq0[re.clone()])
            .zip(&self.v0[re.clone()])
            .zip(&mut self.rates.v[re.clone()])
            .zip(&mut self.turn[re.clone()])
            .zip(&self.vdot_n[re.clone()])
        {
            if half[1] {
                let (dq, e) = correct_slots(3, (c_mass, k_dq, k_v), d, vdot, dq0, v0, v, vd_n);
                eth = eth.max(e);
                let dth = h * dq;
                *turn = dth;
                dth_max = dth_max.max(dth.amax());
            }
        }
        self.turn_edges(st, re);
        self.apply_massless(rod, st, seg);
        let error = self.error_estimate(ex, eth);
        ((dx_max / self.length).max(dth_max), error)
    }

    /// The estimated local time-discretisation error of blocks `r` at the current v̇_{n+1}:
    /// |β − 1/6| h² |v̇_{n+1} − v̇_n| (max over the inertial slots; positions relative to the
    /// cable length, as the Newton corrections).
    pub(crate) fn local_error(&self, r: std::ops::Range<usize>) -> f64 {
        let (mut dx, mut dth) = (0.0f64, 0.0f64);
        for ((half, vd), vd_n) in self.inertial_half[r.clone()]
            .iter()
            .zip(&self.vdot[r.clone()])
            .zip(&self.vdot_n[r])
        {
            let d = vd - vd_n;
            if half[0] {
                dx = dx.max(d.fixed_rows::<3>(0).amax());
            }
            if half[1] {
                dth = dth.max(d.fixed_rows::<3>(3).amax());
            }
        }
        self.error_estimate(dx, dth)
    }

    /// |β − 1/6| h² |Δv̇| from the largest change of v̇ over the translations (`dx`, m/s²) and
    /// the rotations (`dth`), positions relative to the cable length as the corrections.
    fn error_estimate(&self, dx: f64, dth: f64) -> f64 {
        (self.ga.beta - 1.0 / 6.0).abs() * self.h * self.h * (dx / self.length).max(dth)
    }

    /// a_{n+1} of the inertial unknowns from the current v̇_{n+1}.
    pub(crate) fn update_accelerations(&mut self) {
        for b in 0..self.vdot.len() {
            let a = self.a0[b] + self.k_a * self.vdot[b];
            for k in 0..6 {
                if self.inertial[b][k] {
                    self.a[b][k] = a[k];
                }
            }
        }
    }

    /// Applies the Newton increment to the massless unknowns (swivel twists) of a segment.
    fn apply_massless(&self, rod: &Rod, st: &mut State, seg: &Segment) {
        for e in seg.blocks.start..seg.blocks.end.min(rod.n_edges()) {
            if let EdgeKind::TwistFree { .. } = rod.edge_kind[e] {
                st.p[e] = rotate_body(&st.p[e], &Vector3::new(0.0, 0.0, self.delta[e][5]));
            }
        }
        for &g in &seg.ghosts {
            if let Some(axis) = rod.ghosts[g].free_axis {
                let turn = self.delta[rod.ghosts[g].node][0] * axis;
                st.ghost[g] = rotate_body(&st.ghost[g], &turn);
            }
        }
    }

    /// Assembles the outputs at the current state: section forces and moments, clip reactions
    /// (in `ws`) and the energies (the dissipated energy is integrated by `step` itself, with
    /// the power at the last Newton iterate).
    pub fn update_outputs(&mut self, rod: &Rod, st: &State) -> Result<(), SolveError> {
        let keep = std::mem::replace(&mut self.ws.section_outputs, true);
        self.ws.outputs_only = self.outputs_pass;
        let assembled = self.assemble(rod, st, 0.0, 0.0, false, Part::All);
        self.ws.outputs_only = false;
        self.ws.section_outputs = keep;
        assembled.map_err(|k| SolveError::Kink {
            node: k.node,
            s: rod.arc[k.node],
        })?;
        self.energies.elastic = self.ws.elastic_energy;
        self.energies.load_potential = self.ws.load_potential;
        self.energies.contact = self.ws.contact_energy;
        self.energies.kinetic = self.kinetic_energy(rod);
        self.outputs_current = true;
        Ok(())
    }

    /// `update_outputs` with the full assembly: also the residual of the step's equations at
    /// `st` (`ws.rhs`, e.g. `ws.residual_norms`), which the outputs pass leaves out.
    pub fn assemble_residual(&mut self, rod: &Rod, st: &State) -> Result<(), SolveError> {
        let pass = std::mem::replace(&mut self.outputs_pass, false);
        let assembled = self.update_outputs(rod, st);
        self.outputs_pass = pass;
        assembled
    }

    pub fn kinetic_energy(&self, rod: &Rod) -> f64 {
        let mut t = 0.0;
        for (n, v) in self.rates.v.iter().enumerate() {
            t += 0.5 * rod.node_mass[n] * v.fixed_rows::<3>(0).norm_squared();
            if n < rod.n_edges() {
                let w: Vector3<f64> = v.fixed_rows::<3>(3).into();
                t += 0.5 * w.dot(&self.edge_inertia[n].component_mul(&w));
            }
        }
        t
    }

    /// Consistent initial accelerations M v̇₀ = f_ext − g(q₀, v₀) and the initial energies (call
    /// once after `new`; generalized-α is second order only from consistent accelerations).
    pub fn start(&mut self, rod: &Rod, st: &State) -> Result<(), SolveError> {
        let kink = |k: KinkAt| SolveError::Kink {
            node: k.node,
            s: rod.arc[k.node],
        };
        for b in 0..self.vdot.len() {
            for k in 0..6 {
                if self.inertial[b][k] {
                    self.vdot[b][k] = 0.0;
                }
            }
        }
        self.assemble(rod, st, 0.0, 0.0, false, Part::All)
            .map_err(kink)?;
        for b in 0..self.vdot.len() {
            for k in 0..3 {
                if self.inertial[b][k] {
                    self.vdot[b][k] = -self.ws.rhs[b][k] / rod.node_mass[b];
                }
                if self.inertial[b][k + 3] {
                    // J ω̇ = −(g + ω × Jω) with J diagonal (the residual holds ω × Jω).
                    self.vdot[b][k + 3] = -self.ws.rhs[b][k + 3] / self.edge_inertia[b][k];
                }
            }
        }
        self.vdot_n.clone_from(&self.vdot);
        self.a_n.clone_from(&self.vdot);
        self.a.clone_from(&self.vdot);
        self.update_outputs(rod, st)?;
        self.power_n = self.ws.dissipation;
        self.restarted = true;
        Ok(())
    }

    /// Continues with another spectral radius ρ∞ from the current step (the auxiliary
    /// accelerations restart at the true ones, as at a consistent start).
    pub fn set_spectral_radius(&mut self, rho_inf: f64) {
        self.ga = GenAlpha::new(rho_inf);
        self.opts.rho_inf = rho_inf;
        self.a.clone_from(&self.vdot);
        self.invalidate_factors();
        self.restarted = true;
    }

    /// The iteration matrix at the current iterate of the last step (call after `step`) and its
    /// central finite-difference counterpart: the derivative of the dynamic residual with
    /// respect to the Newton unknowns (δq with v̇ ← v̇ + c_m δq on inertial slots, the swivel
    /// twists directly), for the whole cable. For tests and diagnostics; allocates.
    pub fn iteration_matrix_fd(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        eps: f64,
    ) -> Result<(BlockTridiag, BlockTridiag), KinkAt> {
        let ga = self.ga;
        let ca = (1.0 - ga.alpha_f) / (1.0 - ga.alpha_m);
        let c_mass = 1.0 / (ga.beta * h * h * ca);
        let c_damp = ga.gamma / (ga.beta * h);
        let all = 0..self.vdot.len();
        self.update_kinematics(st, h, all.clone());
        self.assemble(rod, st, c_damp, c_mass, true, Part::All)?;
        let analytic = self.ws.jac.clone();
        let mut fd = BlockTridiag::new(analytic.n_blocks());
        let n = self.vdot.len();
        for b in 0..n {
            for k in 0..6 {
                if !rod.mask[b][k] {
                    fd.diag[b][(k, k)] = 1.0;
                    continue;
                }
                let mut r = [Vec::new(), Vec::new()];
                for (side, sign) in [(0, 1.0), (1, -1.0)] {
                    self.shift_unknown(rod, st, b, k, sign * eps, c_mass);
                    self.update_kinematics(st, h, all.clone());
                    self.assemble(rod, st, c_damp, c_mass, false, Part::All)?;
                    r[side] = self.ws.rhs.clone();
                    self.shift_unknown(rod, st, b, k, -sign * eps, c_mass);
                }
                let (rp, rm) = (&r[0], &r[1]);
                for bi in b.saturating_sub(1)..(b + 2).min(n) {
                    let col = (rp[bi] - rm[bi]) / (2.0 * eps);
                    let target = if bi == b {
                        &mut fd.diag[bi]
                    } else if bi + 1 == b {
                        &mut fd.upper[bi]
                    } else {
                        &mut fd.lower[bi]
                    };
                    target.set_column(k, &col);
                }
            }
        }
        self.update_kinematics(st, h, all);
        self.assemble(rod, st, c_damp, c_mass, false, Part::All)?;
        Ok((analytic, fd))
    }

    /// Assembles the residual (with `want_jac` also the iteration matrix) of the whole cable
    /// at the current iterate for the step size h (for benchmarks and diagnostics).
    pub fn assemble_iterate(
        &mut self,
        rod: &Rod,
        st: &State,
        h: f64,
        want_jac: bool,
    ) -> Result<(), KinkAt> {
        let ga = self.ga;
        let ca = (1.0 - ga.alpha_f) / (1.0 - ga.alpha_m);
        let c_mass = 1.0 / (ga.beta * h * h * ca);
        let c_damp = ga.gamma / (ga.beta * h);
        self.assemble(rod, st, c_damp, c_mass, want_jac, Part::All)
    }

    /// Moves one Newton unknown by `d` (inertial: v̇ += c_m d; massless twist: rotated).
    fn shift_unknown(
        &mut self,
        rod: &Rod,
        st: &mut State,
        b: usize,
        k: usize,
        d: f64,
        c_mass: f64,
    ) {
        if self.inertial[b][k] {
            self.vdot[b][k] += c_mass * d;
        } else if k == 5 {
            st.p[b] = rotate_body(&st.p[b], &Vector3::new(0.0, 0.0, d));
        } else if let Some(g) = rod.ghosts.iter().position(|g| g.is_free() && g.node == b) {
            let axis = rod.ghosts[g].free_axis.unwrap_or_else(Vector3::z);
            st.ghost[g] = rotate_body(&st.ghost[g], &(d * axis));
        }
    }

    /// Velocities (ẋ global, ω body) per block.
    pub fn velocities(&self) -> &[Vector6<f64>] {
        &self.rates.v
    }
}

/// The Newton correction of three inertial slots of a block (from `k`: 0 the node's position,
/// 3 the edge's rotation): v̇ += c_m δ, then v = v₀ + k_v v̇; returns the new Δq = Δq₀ + k_dq v̇
/// there and max |v̇ − v̇_n| (the local error estimate's part).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn correct_slots(
    k: usize,
    (c_mass, k_dq, k_v): (f64, f64, f64),
    d: &Vector6<f64>,
    vdot: &mut Vector6<f64>,
    dq0: &Vector6<f64>,
    v0: &Vector6<f64>,
    v: &mut Vector6<f64>,
    vd_n: &Vector6<f64>,
) -> (Vector3<f64>, f64) {
    let mut vd: Vector3<f64> = vdot.fixed_rows::<3>(k).into();
    vd += c_mass * d.fixed_rows::<3>(k);
    vdot.fixed_rows_mut::<3>(k).copy_from(&vd);
    v.fixed_rows_mut::<3>(k)
        .copy_from(&(v0.fixed_rows::<3>(k) + k_v * vd));
    let error = (vd - vd_n.fixed_rows::<3>(k)).amax();
    (dq0.fixed_rows::<3>(k) + k_dq * vd, error)
}
