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
//! block-tridiagonal structure of the static solver. The factorisation is reused while the
//! iteration contracts fast. Prescribed unknowns follow the clips; the free twist of swivel
//! clips is massless (quasistatic within the step).
use crate::assembly::{KinkAt, Rates, Workspace};
use crate::model::{EdgeKind, NodeKind, Pose, Rod};
use crate::rotation::{rotate_body, rotation_matrix, skew, slerp, Quat};
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
    /// Converged when the Newton correction (|δx|/L, |δθ|) is below this fraction of the
    /// step's own increment (h|Δq|) …
    pub tolerance: f64,
    /// … or below this absolute value.
    pub abs_tolerance: f64,
    /// Refactor the iteration matrix when the correction shrinks by less than this factor.
    pub refactor_rate: f64,
}

impl Default for DynamicOptions {
    fn default() -> Self {
        DynamicOptions {
            rho_inf: 0.9,
            tau_shear: Vector3::zeros(),
            tau_bend: Vector3::zeros(),
            max_iterations: 25,
            tolerance: 1e-4,
            abs_tolerance: 1e-13,
            refactor_rate: 0.5,
        }
    }
}

/// What one step did.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepStats {
    pub iterations: usize,
    pub factorizations: usize,
    pub residual: f64,
}

/// Energies after a step, J.
#[derive(Clone, Copy, Debug, Default)]
pub struct Energies {
    pub kinetic: f64,
    pub elastic: f64,
    /// Potential of gravity and dead loads (−work).
    pub load_potential: f64,
    /// Dissipated by the viscous damping since the start.
    pub dissipated: f64,
}

/// The time integrator of one cable.
#[derive(Clone)]
pub struct Dynamics {
    pub ws: Workspace,
    pub opts: DynamicOptions,
    ga: GenAlpha,
    rates: Rates,
    vdot: Vec<Vector6<f64>>,
    a: Vec<Vector6<f64>>,
    // Values at t_n.
    x_n: Vec<Vector3<f64>>,
    p_n: Vec<Quat>,
    ghost_n: Vec<Quat>,
    pose_n: Vec<Pose>,
    v_n: Vec<Vector6<f64>>,
    vdot_n: Vec<Vector6<f64>>,
    a_n: Vec<Vector6<f64>>,
    delta: Vec<Vector6<f64>>,
    /// Slots with inertia (free nodes, free edges).
    inertial: Vec<[bool; 6]>,
    edge_inertia: Vec<Vector3<f64>>,
    factor_valid: bool,
    factor_h: f64,
    pub energies: Energies,
    power_n: f64,
    poses: Vec<Pose>,
    /// h|Δq| of the current step (scaled as the Newton corrections).
    increment: f64,
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
        let inertial = (0..=n)
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
        };
        let mut dynamics = Dynamics {
            ws: Workspace::new(rod),
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
            a_n: vec![Vector6::zeros(); n + 1],
            delta: vec![Vector6::zeros(); n + 1],
            inertial,
            edge_inertia,
            factor_valid: false,
            factor_h: 0.0,
            energies: Energies::default(),
            power_n: 0.0,
            poses: Vec::with_capacity(clips.len()),
            increment: 0.0,
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

    /// Assembles the residual (and the iteration matrix) at the current iterate.
    fn assemble(
        &mut self,
        rod: &Rod,
        st: &State,
        c_damp: f64,
        c_mass: f64,
        want_jac: bool,
    ) -> Result<(), KinkAt> {
        self.rates.damping_factor = c_damp;
        self.ws.clear(want_jac);
        self.ws.add_elastic(rod, st, Some(&self.rates), want_jac)?;
        // Inertia: m ẍ on nodes, J ω̇ + ω × Jω on edges (prescribed ones enter the reactions).
        for n in 0..st.x.len() {
            let acc: Vector3<f64> = self.vdot[n].fixed_rows::<3>(0).into();
            self.ws.node_grad[n] += rod.node_mass[n] * acc;
            if want_jac && self.inertial[n][0] {
                self.ws.jac.add3(
                    n,
                    0,
                    n,
                    0,
                    &(Matrix3::identity() * (c_mass * rod.node_mass[n])),
                );
            }
        }
        for e in 0..rod.n_edges() {
            let j = self.edge_inertia[e];
            let w: Vector3<f64> = self.rates.v[e].fixed_rows::<3>(3).into();
            let wdot: Vector3<f64> = self.vdot[e].fixed_rows::<3>(3).into();
            let jw = j.component_mul(&w);
            self.ws.edge_grad[e] += j.component_mul(&wdot) + w.cross(&jw);
            if want_jac && self.inertial[e][3] {
                let jm = Matrix3::from_diagonal(&j);
                let gyro = skew(&w) * jm - skew(&jw);
                self.ws.jac.add3(e, 1, e, 1, &(c_mass * jm + c_damp * gyro));
            }
        }
        self.ws.add_external(rod, st, 1.0, want_jac);
        self.ws.finalize(rod, want_jac);
        Ok(())
    }

    /// Advances from t_n to t_n + h with the clips at their kinematics at t_{n+1}.
    pub fn step(
        &mut self,
        rod: &Rod,
        st: &mut State,
        h: f64,
        clips: &[ClipMotion],
    ) -> Result<StepStats, SolveError> {
        let ga = self.ga;
        let ca = (1.0 - ga.alpha_f) / (1.0 - ga.alpha_m);
        let c_mass = 1.0 / (ga.beta * h * h * ca);
        let c_damp = ga.gamma / (ga.beta * h);
        let l = rod.spec.length;
        if self.factor_h != h {
            self.factor_valid = false;
        }
        // Values at t_n.
        self.x_n.clone_from(&st.x);
        self.p_n.clone_from(&st.p);
        self.ghost_n.clone_from(&st.ghost);
        self.pose_n.clone_from(&st.clip_pose);
        self.v_n.clone_from(&self.rates.v);
        self.vdot_n.clone_from(&self.vdot);
        self.a_n.clone_from(&self.a);
        // Prescribed motion at t_{n+1}.
        self.poses.clear();
        self.poses.extend(clips.iter().map(|m| m.pose));
        st.set_clip_poses(rod, &self.poses);
        self.prescribe_rates(rod, st, clips);
        // Predictor: constant velocity, Δq = v_n (robust where stiff modes carry large
        // accelerations; measured as good as constant acceleration on random excitation).
        for b in 0..self.vdot.len() {
            let a1 = -(0.5 - ga.beta) / ga.beta * self.a_n[b];
            let vdot = ((1.0 - ga.alpha_m) * a1 + ga.alpha_m * self.a_n[b]
                - ga.alpha_f * self.vdot_n[b])
                / (1.0 - ga.alpha_f);
            for k in 0..6 {
                if self.inertial[b][k] {
                    self.vdot[b][k] = vdot[k];
                }
            }
        }
        let mut stats = StepStats::default();
        let mut last_norm = f64::INFINITY;
        for it in 0..self.opts.max_iterations {
            self.update_kinematics(st, h);
            let refactor = !self.factor_valid;
            self.assemble(rod, st, c_damp, c_mass, refactor)
                .map_err(|k| SolveError::Kink {
                    node: k.node,
                    s: rod.arc[k.node],
                })?;
            if refactor {
                self.ws.factor(rod)?;
                self.factor_valid = true;
                self.factor_h = h;
                stats.factorizations += 1;
            }
            let (dx, dth) = self.ws.newton_correction(&mut self.delta);
            let norm = (dx / l).max(dth);
            if !refactor && (!norm.is_finite() || norm >= last_norm) {
                // The reused matrix no longer contracts: refactor at this iterate.
                self.factor_valid = false;
                continue;
            }
            if !norm.is_finite() {
                return Err(SolveError::NotConverged {
                    iterations: it + 1,
                    residual: f64::INFINITY,
                    load_factor: 1.0,
                });
            }
            // δq on inertial slots is βh²c_a δv̇; massless slots (swivel twists) move directly.
            for (b, d) in self.delta.iter().enumerate() {
                for k in 0..6 {
                    if self.inertial[b][k] {
                        self.vdot[b][k] += c_mass * d[k];
                    }
                }
            }
            self.apply_massless(rod, st);
            stats.iterations = it + 1;
            let (_, rinf) = self.ws.residual_norms(rod.mean_ds());
            stats.residual = rinf;
            if norm < (self.opts.tolerance * self.increment).max(self.opts.abs_tolerance) {
                self.update_kinematics(st, h);
                self.finish_step(rod, st, h, c_damp, c_mass)?;
                return Ok(stats);
            }
            // Slow contraction with a reused matrix: refactor at the next iterate.
            if norm > self.opts.refactor_rate * last_norm && !refactor {
                self.factor_valid = false;
            }
            last_norm = norm;
        }
        Err(SolveError::NotConverged {
            iterations: stats.iterations,
            residual: stats.residual,
            load_factor: 1.0,
        })
    }

    /// Returns to the values at the start of the last (failed) step.
    fn rollback(&mut self, st: &mut State) {
        st.x.clone_from(&self.x_n);
        st.p.clone_from(&self.p_n);
        st.ghost.clone_from(&self.ghost_n);
        st.clip_pose.clone_from(&self.pose_n);
        self.rates.v.clone_from(&self.v_n);
        self.vdot.clone_from(&self.vdot_n);
        self.a.clone_from(&self.a_n);
        self.factor_valid = false;
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
        match self.step(rod, st, h, to) {
            Ok(s) => Ok(s),
            Err(e) if max_depth == 0 => Err(e),
            Err(_) => {
                self.rollback(st);
                let mid: Vec<ClipMotion> =
                    from.iter().zip(to).map(|(a, b)| a.midpoint(b)).collect();
                let s1 = self.advance(rod, st, 0.5 * h, from, &mid, max_depth - 1)?;
                let s2 = self.advance(rod, st, 0.5 * h, &mid, to, max_depth - 1)?;
                Ok(StepStats {
                    iterations: s1.iterations + s2.iterations,
                    factorizations: s1.factorizations + s2.factorizations,
                    residual: s2.residual,
                })
            }
        }
    }

    /// a, v and q_{n+1} of the inertial unknowns from the current v̇_{n+1}.
    fn update_kinematics(&mut self, st: &mut State, h: f64) {
        let ga = self.ga;
        let mut increment = 0.0f64;
        for b in 0..self.vdot.len() {
            let m = self.inertial[b];
            if !m.iter().any(|&x| x) {
                continue;
            }
            // (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) v̇_{n+1} + α_f v̇_n
            let a = ((1.0 - ga.alpha_f) * self.vdot[b] + ga.alpha_f * self.vdot_n[b]
                - ga.alpha_m * self.a_n[b])
                / (1.0 - ga.alpha_m);
            let dq = self.v_n[b] + h * (0.5 - ga.beta) * self.a_n[b] + h * ga.beta * a;
            let v = self.v_n[b] + h * (1.0 - ga.gamma) * self.a_n[b] + h * ga.gamma * a;
            for k in 0..6 {
                if m[k] {
                    self.a[b][k] = a[k];
                    self.rates.v[b][k] = v[k];
                }
            }
            if m[0] {
                let dx = h * Vector3::new(dq[0], dq[1], dq[2]);
                st.x[b] = self.x_n[b] + dx;
                increment = increment.max(dx.amax() / self.length);
            }
            if m[3] {
                let dth = h * Vector3::new(dq[3], dq[4], dq[5]);
                st.p[b] = rotate_body(&self.p_n[b], &dth);
                increment = increment.max(dth.amax());
            }
        }
        self.increment = increment;
    }

    /// Applies the Newton increment to the massless unknowns (swivel twists).
    fn apply_massless(&self, rod: &Rod, st: &mut State) {
        for (e, kind) in rod.edge_kind.iter().enumerate() {
            if let EdgeKind::TwistFree { .. } = kind {
                st.p[e] = rotate_body(&st.p[e], &Vector3::new(0.0, 0.0, self.delta[e][5]));
            }
        }
        for (g, ghost) in rod.ghosts.iter().enumerate() {
            if ghost.twist_free {
                let twist = Vector3::new(0.0, 0.0, self.delta[ghost.node][0]);
                st.ghost[g] = rotate_body(&st.ghost[g], &twist);
            }
        }
    }

    /// Energies and the converged assembly (section forces, reactions) at t_{n+1}.
    fn finish_step(
        &mut self,
        rod: &Rod,
        st: &State,
        h: f64,
        c_damp: f64,
        c_mass: f64,
    ) -> Result<(), SolveError> {
        self.assemble(rod, st, c_damp, c_mass, false)
            .map_err(|k| SolveError::Kink {
                node: k.node,
                s: rod.arc[k.node],
            })?;
        let power = self.ws.dissipation;
        self.energies.dissipated += 0.5 * h * (power + self.power_n);
        self.power_n = power;
        self.energies.elastic = self.ws.elastic_energy;
        self.energies.load_potential = self.ws.load_potential;
        self.energies.kinetic = self.kinetic_energy(rod);
        Ok(())
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
        self.assemble(rod, st, 0.0, 0.0, false).map_err(kink)?;
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
        self.assemble(rod, st, 0.0, 0.0, false).map_err(kink)?;
        self.power_n = self.ws.dissipation;
        self.energies.elastic = self.ws.elastic_energy;
        self.energies.load_potential = self.ws.load_potential;
        self.energies.kinetic = self.kinetic_energy(rod);
        Ok(())
    }

    /// Continues with another spectral radius ρ∞ from the current step (the auxiliary
    /// accelerations restart at the true ones, as at a consistent start).
    pub fn set_spectral_radius(&mut self, rho_inf: f64) {
        self.ga = GenAlpha::new(rho_inf);
        self.opts.rho_inf = rho_inf;
        self.a.clone_from(&self.vdot);
        self.factor_valid = false;
    }

    /// Velocities (ẋ global, ω body) per block.
    pub fn velocities(&self) -> &[Vector6<f64>] {
        &self.rates.v
    }
}
