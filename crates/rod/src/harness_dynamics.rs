//! Dynamics of a harness (docs/harness.md): the Lie-group generalized-α method of the single
//! cable (`dynamics`) on every cable, the junctions as small rigid bodies (mass and rotary
//! inertia of their own; the lumped masses of the joined end nodes move with them), one
//! Newton iteration over the whole harness whose iteration matrix S = K + γ/(βh) C +
//! (1 − α_m)/(βh²(1 − α_f)) M is solved by the tree elimination of the static solver
//! (`harness_solver`: each cable segment onto its junctions, the junction tree leaves first).
//! The Newton stop rule, the reuse of the factorisation and the step splitting are the single
//! cable's.
//!
//! Junction unknowns: the position increment (v̇ += c_m δx, exact) and the rotation increment
//! applied to the pose, Q ← Q ⊗ exp(δθ), with Δq = log(Q_nᵀQ)/h and v̇ following from it (the
//! coupling blocks of the ends are then exact; the inertia block carries J_r⁻¹(hΔq)). The
//! junction-end coupling blocks include the Kelvin–Voigt damping (`EndBlocks::
//! compute_with_rates`); the rate of a held ghost is taken as c_damp δθ (its J_r⁻¹(hΔq)
//! factor, 1 + O(hΔq), is left out).
use crate::assembly::{KinkAt, Part};
use crate::contraction::Contraction;
use crate::dynamics::{
    guard_verdict, ClipMotion, DynamicOptions, Dynamics, Energies, GenAlpha, StepStats,
    STALL_TOLERANCE,
};
use crate::harness::{Harness, HarnessError, HarnessState, HarnessStatics};
use crate::harness_solver::vec_to_junction;
use crate::model::Pose;
use crate::predictor::Extrapolation;
use crate::rotation::{log_vec, right_jacobian, rotate_body, rotation_matrix, skew};
use crate::sliding::SlidingClips;
use crate::statics::{NewtonOptions, SolveError};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

#[path = "harness_dynamics_contact.rs"]
mod contact;

fn top(v: &Vector6<f64>) -> Vector3<f64> {
    v.fixed_rows::<3>(0).into()
}
fn bottom(v: &Vector6<f64>) -> Vector3<f64> {
    v.fixed_rows::<3>(3).into()
}

/// A held junction's prescribed pose, velocity and v̇ (ω, ω̇ in its body frame).
type HeldKinematics = (Pose, Vector6<f64>, Vector6<f64>);

/// The generalized-α integrator of a harness.
#[derive(Clone)]
pub struct HarnessDynamics {
    /// One single-cable integrator per cable (its workspace, rates and kinematics).
    pub cables: Vec<Dynamics>,
    /// The tree elimination (its workspaces are swapped with the cables' around each use).
    tree: HarnessStatics,
    pub opts: DynamicOptions,
    ga: GenAlpha,
    /// Junction velocities (ẋ global, ω body), v̇, auxiliary accelerations a; at t_n too.
    jv: Vec<Vector6<f64>>,
    jvdot: Vec<Vector6<f64>>,
    ja: Vec<Vector6<f64>>,
    jv_n: Vec<Vector6<f64>>,
    jvdot_n: Vec<Vector6<f64>>,
    /// The junctions' predictor (as the cables': crate::predictor).
    jextrapolation: Extrapolation,
    ja_n: Vec<Vector6<f64>>,
    jpose_n: Vec<Pose>,
    jdq0: Vec<Vector6<f64>>,
    jv0: Vec<Vector6<f64>>,
    ja0: Vec<Vector6<f64>>,
    /// Translational mass moving with each junction: its own and the joined end nodes'.
    jmass: Vec<f64>,
    /// Scratch: each cable's clip kinematics with its held ends following the junctions.
    motions: Vec<Vec<ClipMotion>>,
    factor_valid: bool,
    factor_h: f64,
    /// The Newton iteration's contraction with the reused matrix (the stopping rule).
    contraction: Contraction,
    /// The shortest cable (junction displacements are scaled by it).
    length: f64,
    /// Harness totals (cables and junctions) after the last step or `update_outputs`.
    pub energies: Energies,
    /// Per junction held by a clip: its prescribed pose, velocity and v̇ at the step's end.
    held_kin: Vec<Option<HeldKinematics>>,
}

impl HarnessDynamics {
    /// Starts at the harness state `st` (e.g. the static equilibrium), at rest but for the
    /// clip velocities; `clips[c]` holds every clip of cable c (the held ends' entries are
    /// replaced by the junctions' kinematics). Call `start` next.
    pub fn new(
        h: &Harness,
        st: &HarnessState,
        clips: &[Vec<ClipMotion>],
        opts: DynamicOptions,
    ) -> Self {
        let nj = h.junctions.len();
        let mut jmass: Vec<f64> = h.junctions.iter().map(|j| j.mass).collect();
        for e in &h.ends {
            jmass[e.junction] += h.cables[e.cable].node_mass[e.topo.node];
        }
        let mut hd = HarnessDynamics {
            cables: Vec::with_capacity(h.cables.len()),
            tree: HarnessStatics::new(h, NewtonOptions::default()),
            ga: GenAlpha::new(opts.rho_inf),
            opts: opts.clone(),
            jv: vec![Vector6::zeros(); nj],
            jvdot: vec![Vector6::zeros(); nj],
            ja: vec![Vector6::zeros(); nj],
            jv_n: vec![Vector6::zeros(); nj],
            jvdot_n: vec![Vector6::zeros(); nj],
            jextrapolation: Extrapolation::new(nj),
            ja_n: vec![Vector6::zeros(); nj],
            jpose_n: st.junctions.clone(),
            jdq0: vec![Vector6::zeros(); nj],
            jv0: vec![Vector6::zeros(); nj],
            ja0: vec![Vector6::zeros(); nj],
            jmass,
            motions: clips.to_vec(),
            factor_valid: false,
            factor_h: 0.0,
            contraction: Contraction::new(),
            length: h
                .cables
                .iter()
                .map(|r| r.spec.length)
                .fold(f64::INFINITY, f64::min),
            energies: Energies::default(),
            held_kin: vec![None; nj],
        };
        hd.prescribe_held(h, clips);
        hd.end_motions(h, st, clips);
        for (c, rod) in h.cables.iter().enumerate() {
            hd.cables.push(Dynamics::new(
                rod,
                &st.cables[c],
                &hd.motions[c],
                opts.clone(),
            ));
            // Section outputs only in `update_outputs` (the Newton iterations assemble whole
            // cables).
            hd.cables[c].ws.section_outputs = false;
        }
        hd
    }

    /// Sets the retardation times τ of cable c's Kelvin–Voigt damping ((GA₁, GA₂, EA) and
    /// (EI₁, EI₂, GJ), s) when they differ from the options' (call before `start`).
    pub fn set_retardation_times(
        &mut self,
        h: &Harness,
        c: usize,
        tau_shear: Vector3<f64>,
        tau_bend: Vector3<f64>,
    ) {
        let sec = &h.cables[c].spec.section;
        let dy = &mut self.cables[c];
        dy.opts.tau_shear = tau_shear;
        dy.opts.tau_bend = tau_bend;
        dy.rates.shear_damping = tau_shear.component_mul(&sec.shear_stiffness);
        dy.rates.bend_damping = tau_bend.component_mul(&sec.bend_stiffness);
    }

    fn cable_err(h: &Harness, c: usize, e: SolveError) -> HarnessError {
        crate::harness_solver::cable_error(h, c, e)
    }

    fn kink(h: &Harness, c: usize, k: KinkAt) -> HarnessError {
        let s = h.cables[c].arc[k.node];
        Self::cable_err(h, c, SolveError::Kink { node: k.node, s })
    }

    /// `motions` from `clips` with the held ends at the junctions' current kinematics.
    fn end_motions(&mut self, h: &Harness, st: &HarnessState, clips: &[Vec<ClipMotion>]) {
        for (m, c) in self.motions.iter_mut().zip(clips) {
            m.clone_from(c);
        }
        for (k, e) in h.ends.iter().enumerate() {
            let j = e.junction;
            let q = rotation_matrix(&st.junctions[j].orientation);
            self.motions[e.cable][e.topo.clip] = ClipMotion {
                pose: h.end_pose(k, &st.junctions[j]),
                velocity: top(&self.jv[j]),
                angular_velocity: q * bottom(&self.jv[j]),
                acceleration: top(&self.jvdot[j]),
                angular_acceleration: q * bottom(&self.jvdot[j]),
            };
        }
    }

    /// Moves the held ends (pose, node velocity and acceleration, ghost angular velocity) with
    /// the junctions.
    fn sync_ends(&mut self, h: &Harness, st: &mut HarnessState) {
        st.sync_ends(h);
        for e in &h.ends {
            let (v, vdot) = (self.jv[e.junction], self.jvdot[e.junction]);
            let dy = &mut self.cables[e.cable];
            let n = e.topo.node;
            dy.rates.v[n].fixed_rows_mut::<3>(0).copy_from(&top(&v));
            dy.vdot[n].fixed_rows_mut::<3>(0).copy_from(&top(&vdot));
            dy.rates.ghost_omega[e.topo.ghost] = e.rel.transpose() * bottom(&v);
        }
    }

    /// (c_mass, c_damp) of the step size `dt`.
    fn coefficients(&self, dt: f64) -> (f64, f64) {
        let ga = self.ga;
        let ca = (1.0 - ga.alpha_f) / (1.0 - ga.alpha_m);
        (1.0 / (ga.beta * dt * dt * ca), ga.gamma / (ga.beta * dt))
    }

    /// Assembles every cable (inertia, internal and external forces; with `want_jac` the
    /// iteration matrix and the coupling blocks of the held ends) and the junction residuals.
    fn assemble(
        &mut self,
        h: &Harness,
        st: &HarnessState,
        c_damp: f64,
        c_mass: f64,
        want_jac: bool,
    ) -> Result<(), HarnessError> {
        for (c, rod) in h.cables.iter().enumerate() {
            let dy = &mut self.cables[c];
            dy.assemble(rod, &st.cables[c], c_damp, c_mass, want_jac, Part::All)
                .map_err(|k| Self::kink(h, c, k))?;
            if want_jac {
                for end in &mut self.tree.held[c].ends {
                    end.compute_with_rates(rod, &st.cables[c], &dy.ws, Some(&dy.rates))
                        .map_err(|k| Self::kink(h, c, k))?;
                }
            }
        }
        for (j, js) in h.junctions.iter().enumerate() {
            let mut r = Vector6::zeros();
            for &k in &h.junction_ends[j] {
                let e = &h.ends[k];
                let local =
                    self.tree.held[e.cable].ends[e.local].residual(&self.cables[e.cable].ws);
                r += vec_to_junction(&local, &e.rel);
            }
            // Own weight and inertia (the end nodes' are in their cables' residuals).
            let f = js.mass * (top(&self.jvdot[j]) - h.gravity);
            let jw = js.rotary_inertia;
            let w = bottom(&self.jv[j]);
            let m = jw.component_mul(&bottom(&self.jvdot[j])) + w.cross(&jw.component_mul(&w));
            r += Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
            self.tree.junction_residual[j] = r;
            if want_jac {
                // ∂/∂δ: v̇ += c_m δx; v̇_rot = (log(Q_nᵀQ)/h − Δq₀)/k_dq, i.e. c_m J_r⁻¹(hΔq) δθ.
                let mut block = Matrix6::zeros();
                for k in 0..3 {
                    block[(k, k)] = c_mass * self.jmass[j];
                }
                let turn = log_vec(
                    &(self.jpose_n[j].orientation.conjugate() * st.junctions[j].orientation),
                );
                let jr_inv = right_jacobian(&turn)
                    .try_inverse()
                    .unwrap_or_else(Matrix3::identity);
                let gyro = skew(&w) * Matrix3::from_diagonal(&jw) - skew(&jw.component_mul(&w));
                let rot = (c_mass * Matrix3::from_diagonal(&jw) + c_damp * gyro) * jr_inv;
                block.fixed_view_mut::<3, 3>(3, 3).copy_from(&rot);
                self.tree.junction_extra[j] = block;
            }
        }
        Ok(())
    }

    fn swap_workspaces(&mut self) {
        for (dy, ws) in self.cables.iter_mut().zip(&mut self.tree.ws) {
            std::mem::swap(&mut dy.ws, ws);
        }
    }

    /// Factors the assembled iteration matrix (tree elimination).
    fn factor(&mut self, h: &Harness) -> Result<(), HarnessError> {
        self.swap_workspaces();
        let r = self.tree.factor(h);
        self.swap_workspaces();
        r
    }

    /// The Newton correction of the assembled residuals (into `tree.delta`, `tree.dj`);
    /// returns its norm (positions relative to each cable's length, the junctions' to the
    /// shortest cable; rotations in rad).
    fn correction(&mut self, h: &Harness) -> f64 {
        self.swap_workspaces();
        self.tree.solve(h, false);
        self.swap_workspaces();
        let mut norm = 0.0f64;
        for (c, rod) in h.cables.iter().enumerate() {
            let l = rod.spec.length;
            for d in &self.tree.delta[c] {
                norm = norm.max(top(d).amax() / l).max(bottom(d).amax());
            }
        }
        for d in &self.tree.dj {
            norm = norm.max(top(d).amax() / self.length).max(bottom(d).amax());
        }
        norm
    }

    /// Junction kinematics from v̇ (positions: x = x_n + hΔq) and Δq (rotations); returns
    /// the largest increment h|Δq| (scaled as the corrections).
    fn junction_kinematics(&mut self, st: &mut HarnessState, dt: f64, from_vdot: bool) -> f64 {
        let (k_dq, k_v) = (self.cables[0].k_dq, self.cables[0].k_v);
        let mut inc = 0.0f64;
        for j in 0..self.jv.len() {
            let dq = self.jdq0[j] + k_dq * self.jvdot[j];
            let dx = dt * top(&dq);
            st.junctions[j].position = self.jpose_n[j].position + dx;
            let turn = if from_vdot {
                let t = dt * bottom(&dq);
                st.junctions[j].orientation = rotate_body(&self.jpose_n[j].orientation, &t);
                t
            } else {
                let t = log_vec(
                    &(self.jpose_n[j].orientation.conjugate() * st.junctions[j].orientation),
                );
                let vd = (t / dt - bottom(&self.jdq0[j])) / k_dq;
                self.jvdot[j].fixed_rows_mut::<3>(3).copy_from(&vd);
                t
            };
            self.jv[j] = self.jv0[j] + k_v * self.jvdot[j];
            inc = inc.max(dx.amax() / self.length).max(turn.amax());
        }
        inc
    }

    /// Estimated local time-discretisation error of the junctions (as `Dynamics`).
    fn junction_error(&self, h: &Harness, dt: f64) -> f64 {
        let mut e = 0.0f64;
        for (j, js) in h.junctions.iter().enumerate() {
            if h.held[j] {
                continue; // prescribed
            }
            let d = self.jvdot[j] - self.jvdot_n[j];
            e = e.max(top(&d).amax() / self.length);
            if js.rotary_inertia.iter().all(|&v| v > 0.0) {
                e = e.max(bottom(&d).amax());
            }
        }
        (self.ga.beta - 1.0 / 6.0).abs() * dt * dt * e
    }

    /// Consistent initial accelerations of the cables and junctions and the initial energies
    /// (call once after `new`).
    pub fn start(&mut self, h: &Harness, st: &mut HarnessState) -> Result<(), HarnessError> {
        self.sync_ends(h, st);
        for (c, rod) in h.cables.iter().enumerate() {
            self.cables[c]
                .start(rod, &st.cables[c])
                .map_err(|e| Self::cable_err(h, c, e))?;
        }
        for v in &mut self.jvdot {
            v.fill(0.0);
        }
        self.assemble(h, st, 0.0, 0.0, false)?;
        for (j, js) in h.junctions.iter().enumerate() {
            let r = self.tree.junction_residual[j];
            let mut vd = Vector6::zeros();
            for k in 0..3 {
                vd[k] = -r[k] / self.jmass[j];
                if js.rotary_inertia[k] > 0.0 {
                    vd[k + 3] = -r[k + 3] / js.rotary_inertia[k];
                }
            }
            self.jvdot[j] = vd;
        }
        self.impose_held(st);
        self.jvdot_n.clone_from(&self.jvdot);
        self.ja.clone_from(&self.jvdot);
        self.sync_ends(h, st);
        for (c, rod) in h.cables.iter().enumerate() {
            let dy = &mut self.cables[c];
            // The held end nodes accelerate with the junctions.
            dy.update_outputs(rod, &st.cables[c])
                .map_err(|e| Self::cable_err(h, c, e))?;
        }
        self.sum_energies(h, st);
        Ok(())
    }

    fn sum_energies(&mut self, h: &Harness, st: &HarnessState) {
        let mut e = Energies::default();
        for dy in &self.cables {
            e.kinetic += dy.energies.kinetic;
            e.elastic += dy.energies.elastic;
            e.load_potential += dy.energies.load_potential;
            e.dissipated += dy.energies.dissipated;
            e.contact += dy.energies.contact;
        }
        for (j, js) in h.junctions.iter().enumerate() {
            let w = bottom(&self.jv[j]);
            e.kinetic += 0.5 * js.mass * top(&self.jv[j]).norm_squared()
                + 0.5 * w.dot(&js.rotary_inertia.component_mul(&w));
            e.load_potential -= js.mass * h.gravity.dot(&st.junctions[j].position);
        }
        self.energies = e;
    }

    /// Section forces, reactions and energies at the current state (all cables).
    pub fn update_outputs(&mut self, h: &Harness, st: &HarnessState) -> Result<(), HarnessError> {
        for (c, rod) in h.cables.iter().enumerate() {
            self.cables[c]
                .update_outputs(rod, &st.cables[c])
                .map_err(|e| Self::cable_err(h, c, e))?;
        }
        self.sum_energies(h, st);
        Ok(())
    }

    /// Force and moment (about the junction point, global) that each end's cable applies to
    /// its junction, after `update_outputs`.
    pub fn branch_loads(
        &self,
        h: &Harness,
        st: &HarnessState,
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        h.ends
            .iter()
            .map(|e| {
                let (f, m) = self.cables[e.cable].ws.clip_reaction(
                    &h.cables[e.cable],
                    &st.cables[e.cable],
                    e.topo.clip,
                );
                (-f, -m)
            })
            .collect()
    }

    /// The prescribed kinematics of the junctions held by a clip at the clip motions `clips`
    /// (their first end's entry gives the clip's; ω and ω̇ in the junction's body frame); sets
    /// their velocities and v̇.
    fn prescribe_held(&mut self, h: &Harness, clips: &[Vec<ClipMotion>]) {
        for (j, &held) in h.held.iter().enumerate() {
            if !held {
                continue;
            }
            let e = &h.ends[h.junction_ends[j][0]];
            let m = &clips[e.cable][e.topo.clip];
            let pose = h.junction_pose_from_end(j, &m.pose);
            let qt = rotation_matrix(&pose.orientation).transpose();
            let (w, wdot) = (qt * m.angular_velocity, qt * m.angular_acceleration);
            let (v, a) = (m.velocity, m.acceleration);
            let vel = Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z);
            let acc = Vector6::new(a.x, a.y, a.z, wdot.x, wdot.y, wdot.z);
            self.jv[j] = vel;
            self.jvdot[j] = acc;
            self.held_kin[j] = Some((pose, vel, acc));
        }
    }

    /// Puts the held junctions back to their prescribed kinematics (after the integrator's
    /// update of all junctions).
    fn impose_held(&mut self, st: &mut HarnessState) {
        for (j, k) in self.held_kin.iter().enumerate() {
            if let Some((pose, v, a)) = k {
                st.junctions[j] = *pose;
                self.jv[j] = *v;
                self.jvdot[j] = *a;
            }
        }
    }

    /// Fails naming the cable and the clip if a sliding clip's guide reaches beyond a cable
    /// end at `st` (after a step).
    pub fn check_sliding(&mut self, h: &Harness, st: &HarnessState) -> Result<(), HarnessError> {
        let guides = self.cables.iter_mut().map(|c| &mut c.sliding);
        crate::harness_solver::check_guides(h, st, guides)
    }

    /// Force and moment (about the junction point, global) of the clip on each junction held
    /// by a clip (zero on the others), after `update_outputs`: what accelerates the junction's
    /// own mass and rotary inertia against its weight and its branch loads.
    pub fn junction_reactions(
        &self,
        h: &Harness,
        st: &HarnessState,
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut out = vec![(Vector3::zeros(), Vector3::zeros()); h.junctions.len()];
        for (e, (f, m)) in h.ends.iter().zip(self.branch_loads(h, st)) {
            if h.held[e.junction] {
                out[e.junction].0 -= f;
                out[e.junction].1 -= m;
            }
        }
        for (j, js) in h.junctions.iter().enumerate() {
            if !h.held[j] {
                continue;
            }
            let (w, wdot) = (bottom(&self.jv[j]), bottom(&self.jvdot[j]));
            let jw = js.rotary_inertia;
            let body = jw.component_mul(&wdot) + w.cross(&jw.component_mul(&w));
            out[j].0 += js.mass * (top(&self.jvdot[j]) - h.gravity);
            out[j].1 += rotation_matrix(&st.junctions[j].orientation) * body;
        }
        out
    }

    /// Junction velocities (ẋ global, ω body).
    pub fn junction_velocities(&self) -> &[Vector6<f64>] {
        &self.jv
    }

    /// Starts a step: values at t_n, clips at t_{n+1}, predictor; returns the largest
    /// increment h|Δq| and the largest local error estimate.
    fn begin_step(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
        clips: &[Vec<ClipMotion>],
    ) -> (f64, f64) {
        let ga = self.ga;
        let restarted = self.cables.iter().any(|d| d.restarted);
        self.jpose_n.clone_from(&st.junctions);
        self.jv_n.clone_from(&self.jv);
        // v̇_n into jvdot_n and the predictor (as the cables'; held junctions get their
        // prescribed kinematics after it)
        let predict = !restarted && !self.has_contact();
        self.jextrapolation.begin_step(
            &mut self.jvdot,
            &mut self.jvdot_n,
            None,
            restarted,
            dt,
            predict,
        );
        self.ja_n.clone_from(&self.ja);
        self.prescribe_held(h, clips);
        self.end_motions(h, st, clips);
        for (c, rod) in h.cables.iter().enumerate() {
            self.cables[c].begin_step(rod, &mut st.cables[c], dt, &self.motions[c]);
        }
        // The junctions' predictor after a restart and with contact: constant velocity (as
        // the cables'); their kinematics.
        if !predict {
            let c_a = ((1.0 - ga.alpha_m) * (-(0.5 - ga.beta) / ga.beta) + ga.alpha_m)
                / (1.0 - ga.alpha_f);
            let c_v = -ga.alpha_f / (1.0 - ga.alpha_f);
            for j in 0..self.jv.len() {
                self.jvdot[j] = c_a * self.ja_n[j] + c_v * self.jvdot_n[j];
            }
        }
        let (c_vn, c_an) = (
            ga.alpha_f / (1.0 - ga.alpha_m),
            -ga.alpha_m / (1.0 - ga.alpha_m),
        );
        for j in 0..self.jv.len() {
            let a0 = c_vn * self.jvdot_n[j] + c_an * self.ja_n[j];
            self.ja0[j] = a0;
            self.jdq0[j] = self.jv_n[j] + dt * (0.5 - ga.beta) * self.ja_n[j] + dt * ga.beta * a0;
            self.jv0[j] = self.jv_n[j] + dt * (1.0 - ga.gamma) * self.ja_n[j] + dt * ga.gamma * a0;
        }
        let mut inc = self.junction_kinematics(st, dt, true);
        self.impose_held(st);
        let mut err = self.junction_error(h, dt);
        for (c, rod) in h.cables.iter().enumerate() {
            let dy = &mut self.cables[c];
            let (i, e) = dy.predicted_kinematics(&mut st.cables[c], dt, 0..rod.arc.len());
            (inc, err) = (inc.max(i), err.max(e));
        }
        self.sync_ends(h, st);
        if let Some(shortened) = self.limit_predictor(h, st, dt) {
            inc = shortened; // no cable dives through its contact barrier
        }
        (inc, err)
    }

    /// Applies the Newton correction in `tree.delta`, `tree.dj`; returns the largest
    /// increment and local error estimate.
    fn apply_correction(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
        c_mass: f64,
        scale: f64,
    ) -> (f64, f64) {
        let mut inc = 0.0f64;
        let mut err = 0.0f64;
        for (c, rod) in h.cables.iter().enumerate() {
            let dy = &mut self.cables[c];
            for (d, t) in dy.delta.iter_mut().zip(&self.tree.delta[c]) {
                *d = scale * t;
            }
            // (the segments hold every unknown: their local errors are the cable's)
            for seg in &rod.segments {
                let (i, e) = dy.apply_correction(rod, &mut st.cables[c], dt, c_mass, seg);
                inc = inc.max(i);
                err = err.max(e);
            }
        }
        for j in 0..self.jv.len() {
            let d = scale * self.tree.dj[j];
            let vd = top(&self.jvdot[j]) + c_mass * top(&d);
            self.jvdot[j].fixed_rows_mut::<3>(0).copy_from(&vd);
            st.junctions[j].orientation = rotate_body(&st.junctions[j].orientation, &bottom(&d));
        }
        inc = inc.max(self.junction_kinematics(st, dt, false));
        self.impose_held(st);
        err = err.max(self.junction_error(h, dt));
        self.sync_ends(h, st);
        (inc, err)
    }

    /// Advances from t_n to t_n + dt with the clips at their kinematics at t_{n+1}
    /// (`clips[c]`: every clip of cable c; the held ends' entries are ignored). A step that
    /// fails from the constant-acceleration predictor is done again from constant velocity
    /// (as `Dynamics::step`).
    pub fn step(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
        clips: &[Vec<ClipMotion>],
    ) -> Result<StepStats, HarnessError> {
        let from_acceleration = !self.cables.iter().any(|d| d.restarted);
        match self.step_once(h, st, dt, clips) {
            Err(_) if from_acceleration => {
                self.rollback(st); // the next try predicts constant velocity
                self.sync_ends(h, st);
                self.step_once(h, st, dt, clips)
            }
            r => r,
        }
    }

    fn step_once(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
        clips: &[Vec<ClipMotion>],
    ) -> Result<StepStats, HarnessError> {
        let (c_mass, c_damp) = self.coefficients(dt);
        let (mut scale, _) = self.begin_step(h, st, dt, clips);
        let mut stats = StepStats {
            substeps: 1,
            ..Default::default()
        };
        let mut last_norm = f64::INFINITY;
        let mut last_fresh_norm = f64::INFINITY;
        let mut last_applied = f64::INFINITY;
        let mut converged = false;
        // With contact, the single cable's rules (`Dynamics::solve_segment`): iterations whose
        // correction the barrier shortened do not count (up to 4× the limit), three strikes.
        let contact = self.has_contact();
        // Frictional guides, too (`Dynamics::solve_segment`).
        let friction = self
            .cables
            .iter()
            .any(|dy| SlidingClips::frictional(&dy.sliding).is_some());
        let mut budget = self.opts.max_iterations;
        let mut strikes = 0;
        let mut next = 0;
        self.contraction.begin_step();
        while next < budget {
            let it = next;
            next += 1;
            let refactor = !self.factor_valid || self.factor_h != dt;
            self.assemble(h, st, c_damp, c_mass, refactor)?;
            if refactor {
                self.factor(h)?;
                self.factor_valid = true;
                self.factor_h = dt;
                stats.factorizations += 1;
            }
            let norm = self.correction(h);
            if !refactor && (!norm.is_finite() || norm >= last_norm) {
                // The reused matrix no longer contracts: refactor at this iterate.
                self.factor_valid = false;
                continue;
            }
            if refactor && norm >= last_fresh_norm {
                strikes += 1;
            }
            if !norm.is_finite() || strikes >= if contact || friction { 3 } else { 1 } {
                // Diverging; the iterate is kept when the correction that led to it was
                // below `STALL_TOLERANCE` of the step's increment (as `Dynamics`).
                let touching = contact && self.contact_active();
                if it > 0 && !touching && norm.is_finite() && last_applied < STALL_TOLERANCE * scale
                {
                    converged = true;
                    break;
                }
                self.factor_valid = false;
                return Err(self.not_converged(h, it + 1));
            }
            if refactor {
                last_fresh_norm = norm;
            }
            // Contact: no cable dives through its barrier (the correction is shortened); no
            // node jumps across a frictional guide's stick zone, and one stopped in it needs a
            // fresh matrix (the stick spring; a stale one from the slip side sends it back).
            let (alpha, stick) = if contact || friction {
                self.correction_alpha(h, st, dt, c_mass)
            } else {
                (1.0, false)
            };
            if stick {
                self.factor_valid = false;
            }
            if alpha < 1.0 {
                last_fresh_norm = f64::INFINITY;
                budget = (budget + 1).min(4 * self.opts.max_iterations);
            }
            let (s, error) = self.apply_correction(h, st, dt, c_mass, alpha);
            scale = s;
            last_applied = norm;
            stats.iterations = it + 1;
            let active = contact && self.contact_active();
            let mut tolerance = self.opts.step_tolerance(error, scale, active);
            // Frictional guides: a correction small against the stick width (`Dynamics`).
            for (rod, dy) in h.cables.iter().zip(&self.cables) {
                if let Some(s) = SlidingClips::frictional(&dy.sliding) {
                    tolerance = tolerance.at_most(s.newton_tolerance(rod.spec.length));
                }
            }
            if !refactor && last_norm.is_finite() {
                self.contraction.measure(norm, last_norm);
            }
            if alpha == 1.0 && self.contraction.converged(norm, tolerance) {
                converged = true;
                break;
            }
            let rate = if active {
                self.opts.contact_refactor_rate
            } else {
                self.opts.refactor_rate
            };
            // … unless expected to finish at the next iterate (`Dynamics`).
            if norm > rate * last_norm && !refactor && norm * (norm / last_norm) >= tolerance.value
            {
                self.factor_valid = false;
            }
            last_norm = norm;
        }
        if !converged {
            self.factor_valid = false;
            return Err(self.not_converged(h, stats.iterations));
        }
        stats.residual = self.residual_inf(h);
        for dy in &mut self.cables {
            dy.update_accelerations();
            // The dissipated power at the last iterate, integrated by the trapezoidal rule.
            let power = dy.ws.dissipation;
            dy.energies.dissipated += 0.5 * dt * (power + dy.power_n);
            dy.power_n = power;
        }
        let k_a = self.cables[0].k_a;
        for j in 0..self.ja.len() {
            self.ja[j] = self.ja0[j] + k_a * self.jvdot[j];
        }
        if self.opts.outputs_every_step {
            self.update_outputs(h, st)?;
        }
        Ok(stats)
    }

    fn residual_inf(&self, h: &Harness) -> f64 {
        let mut r = 0.0f64;
        for (c, rod) in h.cables.iter().enumerate() {
            let ws = &self.cables[c].ws;
            r = r.max(ws.residual_inf_range(0..ws.rhs.len(), rod.mean_ds()));
        }
        for v in &self.tree.junction_residual {
            r = r.max(top(v).amax());
        }
        r
    }

    fn not_converged(&self, h: &Harness, iterations: usize) -> HarnessError {
        HarnessError(format!(
            "{}",
            SolveError::NotConverged {
                iterations,
                residual: self.residual_inf(h),
                load_factor: 1.0,
            }
        ))
    }

    /// Returns to the values at the start of the last (failed) step.
    fn rollback(&mut self, st: &mut HarnessState) {
        for (dy, s) in self.cables.iter_mut().zip(&mut st.cables) {
            dy.rollback(s);
        }
        st.junctions.clone_from(&self.jpose_n);
        self.jv.clone_from(&self.jv_n);
        self.jvdot.clone_from(&self.jvdot_n);
        self.ja.clone_from(&self.ja_n);
        self.factor_valid = false;
    }

    /// Advances by dt from the clip kinematics `from` (at t_n) to `to` (at t_n + dt); a step
    /// whose Newton iteration fails is rolled back and done as two half steps with the clip
    /// kinematics interpolated in between, recursively up to 2^`max_depth` sub-steps.
    pub fn advance(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
        from: &[Vec<ClipMotion>],
        to: &[Vec<ClipMotion>],
        max_depth: usize,
    ) -> Result<StepStats, HarnessError> {
        // With contact near: the energy guard of the single cable (harness_dynamics_contact);
        // at the deepest split a gain is reported in the stats instead.
        let start = self.energy_start(h, st, dt)?;
        let result = match (self.step(h, st, dt, to), start) {
            (Ok(s), Some(e0)) => {
                let (gain, scale) = self.energy_gain(h, st, &e0)?;
                match guard_verdict(gain, self.opts.energy_tolerance, max_depth) {
                    Some(0.0) => Ok(s),
                    Some(g) => self.give_back(h, st, (g, scale), s),
                    None => {
                        self.restore_dissipated(&e0);
                        Err(HarnessError(format!(
                            "the step gained energy at contact ({} iterations)",
                            s.iterations
                        )))
                    }
                }
            }
            (r, _) => r,
        };
        match result {
            Ok(s) => self.check_sliding(h, st).map(|_| s),
            Err(e) if max_depth == 0 => Err(e),
            Err(_) => {
                self.rollback(st);
                self.sync_ends(h, st);
                let mid: Vec<Vec<ClipMotion>> = from
                    .iter()
                    .zip(to)
                    .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x.midpoint(y)).collect())
                    .collect();
                let s1 = self.advance(h, st, 0.5 * dt, from, &mid, max_depth - 1)?;
                let s2 = self.advance(h, st, 0.5 * dt, &mid, to, max_depth - 1)?;
                Ok(s1.then(s2))
            }
        }
    }

    /// Finite-difference check of the iteration matrix at the current iterate (call after
    /// `step`): the Newton correction δ of the assembled system solves S δ = −r, so the
    /// central difference of the residual along δ, (r(q + εδ) − r(q − εδ))/2ε, must equal −r.
    /// Returns (largest deviation, largest |r|) over the active cable slots and the junctions
    /// (forces and moments separately: [force dev, force scale, moment dev, moment scale]).
    /// For tests and diagnostics; allocates.
    pub fn newton_direction_fd(
        &mut self,
        h: &Harness,
        st: &mut HarnessState,
        dt: f64,
        eps: f64,
    ) -> Result<[f64; 4], HarnessError> {
        let (c_mass, c_damp) = self.coefficients(dt);
        self.assemble(h, st, c_damp, c_mass, true)?;
        self.factor(h)?;
        self.correction(h);
        let r0 = self.residual_vector(h);
        let saved_cables = self.cables.clone();
        let saved_st = st.clone();
        let saved_j = (self.jv.clone(), self.jvdot.clone());
        let mut sides = Vec::new();
        for sign in [1.0, -1.0] {
            self.apply_correction(h, st, dt, c_mass, sign * eps);
            self.assemble(h, st, c_damp, c_mass, false)?;
            sides.push(self.residual_vector(h));
            self.cables.clone_from(&saved_cables);
            st.clone_from(&saved_st);
            (self.jv, self.jvdot) = saved_j.clone();
        }
        let mut out = [0.0f64; 4];
        for (i, (r, kind)) in r0.iter().enumerate() {
            let fd = (sides[0][i].0 - sides[1][i].0) / (2.0 * eps);
            let k = 2 * kind;
            out[k] = out[k].max((fd + r).abs());
            out[k + 1] = out[k + 1].max(r.abs());
        }
        Ok(out)
    }

    /// The residual of the active cable slots and the junctions, with its kind (0 force,
    /// 1 moment).
    fn residual_vector(&self, h: &Harness) -> Vec<(f64, usize)> {
        let mut out = Vec::new();
        for (c, rod) in h.cables.iter().enumerate() {
            for (b, m) in rod.mask.iter().enumerate() {
                for (k, &active) in m.iter().enumerate() {
                    if active {
                        out.push((self.cables[c].ws.rhs[b][k], k / 3));
                    }
                }
            }
        }
        // A held junction's residual is its clip's reaction, not an equation.
        for (r, _) in self
            .tree
            .junction_residual
            .iter()
            .zip(&h.held)
            .filter(|(_, &held)| !held)
        {
            for k in 0..6 {
                out.push((r[k], k / 3));
            }
        }
        out
    }
}

#[cfg(test)]
#[path = "harness_dynamics_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "harness_dynamics_clip_tests.rs"]
mod clip_tests;
