//! Sliding clips (docs/scene.md, "sliding"): a guide of length ℓ that holds the cable's axis on
//! its line (the clip position P and direction t) while the cable material slides through it.
//!
//! The cable's nodes stay material (Lagrangian); the clip is a term of the assembly that pulls
//! every node x inside the guide onto the line with the force −k_n w(z) Q(x − P), with
//! z = t·(x − P) the position along the line, Q = I − t tᵀ the projector across it and w a C¹
//! window (1 over |z| ≤ ℓ/2, a cubic taper to 0 over half an edge beyond, so that nodes enter and
//! leave the guide smoothly). The force is across the line only, like a rigid frictionless
//! guide's reaction: the cable slides without axial resistance. (It is the gradient of
//! ½ k_n w |Q d|² without the window's ∂w/∂z term: that term would be an axial force
//! ½ k_n w′ |Q d|² at the guide's ends that does not vanish under mesh refinement; the force is
//! therefore not conservative and its Jacobian k_n (w Q + w′ Q d tᵀ) not symmetric.) Each node
//! couples to nothing else: the block-tridiagonal structure stays.
//!
//! Hold stiffness k_n = `HOLD_FACTOR` · EA δs_n / Δs² (δs_n the node's length, Δs the mean edge):
//! 100 times an edge's axial stiffness EA/Δs, so the axis leaves the line by F Δs / (100 EA) —
//! one hundredth of the stretch of an edge under the clip force F — far below the discretisation
//! error, and the Jacobian stays as well conditioned as the cable's own axial stiffness.
//!
//! Outputs: the material coordinate σ of the cable at the clip centre (where it crosses the plane
//! through P normal to t; linear along the crossing edge) — the slid length is σ − σ₀ — and the
//! clip's reaction force and moment (about P). A guide that reaches beyond a cable end is flagged
//! (`off_end`); the solvers then fail naming the clip.
use crate::assembly::{Eval, KinkAt, Part, Rates, Term, Workspace};
use crate::dynamics::ClipMotion;
use crate::friction::{f1_over, stick_cut};
use crate::model::{ClipKind, NodeKind, Pose, Rod};
use crate::rotation::rotation_matrix;
use crate::state::State;
use nalgebra::{Matrix3, Vector3};

/// The hold stiffness of a node relative to an edge's axial stiffness EA/Δs.
pub const HOLD_FACTOR: f64 = 100.0;

/// A dynamic step with frictional guides converges only when its Newton correction is below
/// this fraction of the stick width ε (relative to the cable length, as the corrections):
/// inside the stick zone the friction is a spring of stiffness 2μN/ε, so a correction small
/// against the step is not small against ε. Measured (a hose through a guide, μ = 0.2 and 0.5,
/// shaken 10 mm at 5 Hz, steps of 1, 0.5 and 0.25 ms; the example harness with μ = 0.2 on its
/// trunk guide): with the step's own tolerance alone the runs held by friction slipped by
/// millimetres and their kinetic energy grew 3- to 3000-fold (the guide should hold: with a
/// tolerance 30 times tighter they all agree to 1e-3 and slip by micrometres); with this rule
/// they agree with those tight runs, in 3–5 iterations per step.
pub const STICK_TOLERANCE: f64 = 0.1;

/// The sliding clips of a cable: a term of the assembly.
#[derive(Clone, Debug)]
pub struct SlidingClips {
    /// Clip indices of the sliding clips.
    pub clips: Vec<usize>,
    /// Per sliding clip: its Coulomb friction coefficient μ.
    mu: Vec<f64>,
    /// Nodes of the cable (the row length of `z_ref` and `n_ref`).
    n_nodes: usize,
    /// Per sliding clip: material coordinate σ of the cable at the clip centre (NaN: the cable
    /// does not cross the clip's plane), from the last full assembly.
    pub sigma: Vec<f64>,
    /// Per sliding clip: force and moment (about the clip centre) of the clip on the cable,
    /// global, from the last full assembly.
    pub reaction: Vec<(Vector3<f64>, Vector3<f64>)>,
    /// A sliding clip whose guide reaches beyond a cable end (last full assembly).
    pub off_end: Option<usize>,
    /// Per sliding clip: the sum of the hold's normal forces |F_n| (last full assembly), N.
    pub normal_force: Vec<f64>,
    /// Per sliding clip: the friction force along the line on the cable (last full assembly).
    pub friction_force: Vec<f64>,
    /// Per sliding clip: the sum of the normal forces the friction acts with (last full
    /// assembly): `normal_force` in statics, its value at the start of the step in dynamics.
    pub friction_normal: Vec<f64>,
    /// Stick widths of the regularised friction: static (m) and dynamic (m/s).
    pub stick_distance: f64,
    pub stick_velocity: f64,
    hold: Vec<f64>,
    reach: f64,
    /// Per node: its coordinate along each guide's line at the start of the step (friction
    /// reference), row-major (clip, node); the stick width of the step.
    z_ref: Vec<f64>,
    eps: f64,
    /// A dynamic step (`begin_step` with its clips): h, and per sliding clip the guide's
    /// velocity and angular velocity at t_{n+1} (global), against which the friction acts.
    step_h: Option<f64>,
    guide_rates: Vec<(Vector3<f64>, Vector3<f64>)>,
    /// Dynamic steps: per (clip, node) the normal force at the start of the step, on which
    /// the friction acts (lagged, as incremental potential contact does; NaN: statics, where
    /// the current one is used). With the current normal force the friction μ N(x) couples
    /// the slip to the stiff hold across the line, a non-conservative coupling that fed energy
    /// into the undamped motion: the guided Y of `harness_dynamics_clip_tests` released under
    /// gravity at ρ∞ = 1, μ = 0.3, gained kinetic energy (1.8× its frictionless peak, the
    /// energy balance off by 1.6× that peak); lagged, its energy balance closes to 3e-3 of the
    /// peak, as without friction.
    n_ref: Vec<f64>,
}

impl SlidingClips {
    /// The term of the sliding clips of `rod` (None if it has none).
    pub fn of(rod: &Rod) -> Option<SlidingClips> {
        let clips: Vec<usize> = (0..rod.spec.clips.len())
            .filter(|&c| matches!(rod.spec.clips[c].kind, ClipKind::Sliding { .. }))
            .collect();
        if clips.is_empty() {
            return None;
        }
        let h = rod.mean_ds();
        let ea = rod.spec.section.shear_stiffness.z;
        let hold = rod
            .ds_node
            .iter()
            .map(|d| HOLD_FACTOR * ea * d / (h * h))
            .collect();
        let reach = rod.ds_edge.iter().cloned().fold(0.0, f64::max);
        let stick_distance = 1e-4 * h;
        Some(SlidingClips {
            sigma: vec![f64::NAN; clips.len()],
            reaction: vec![(Vector3::zeros(), Vector3::zeros()); clips.len()],
            normal_force: vec![0.0; clips.len()],
            friction_force: vec![0.0; clips.len()],
            friction_normal: vec![0.0; clips.len()],
            mu: clips
                .iter()
                .map(|&c| match rod.spec.clips[c].kind {
                    ClipKind::Sliding { friction } => friction,
                    _ => 0.0,
                })
                .collect(),
            n_nodes: rod.arc.len(),
            z_ref: vec![f64::NAN; clips.len() * rod.arc.len()],
            step_h: None,
            n_ref: vec![f64::NAN; clips.len() * rod.arc.len()],
            guide_rates: vec![(Vector3::zeros(), Vector3::zeros()); clips.len()],
            clips,
            off_end: None,
            stick_distance,
            stick_velocity: 1e-3,
            eps: stick_distance,
            hold,
            reach,
        })
    }

    /// The Newton tolerance of a step with these frictional guides, for the corrections
    /// relative to a cable of `length` (`STICK_TOLERANCE` of the stick width ε of the step:
    /// dynamics, stick velocity × h).
    pub fn newton_tolerance(&self, length: f64) -> f64 {
        STICK_TOLERANCE * self.eps / length
    }

    /// Whether a sliding clip has friction.
    pub fn has_friction(&self) -> bool {
        self.mu.iter().any(|&mu| mu > 0.0)
    }

    /// The term if one of its guides has friction.
    pub fn frictional(guides: &Option<SlidingClips>) -> Option<&SlidingClips> {
        guides.as_ref().filter(|s| s.has_friction())
    }

    /// Starts a step from the state `st`: the friction reference (each node's coordinate along
    /// each guide's line); `dynamic` the time step and the clips' kinematics at its end for a
    /// dynamic step (None: static, quasistatic).
    pub fn begin_step(&mut self, rod: &Rod, st: &State, dynamic: Option<(f64, &[ClipMotion])>) {
        let n = self.n_nodes;
        for (k, &c) in self.clips.iter().enumerate() {
            let (pose, t, half) = guide_line(rod, st, c);
            let taper = 0.5 * rod.mean_ds();
            for (j, x) in st.x.iter().enumerate() {
                let d = x - pose.position;
                let z = t.dot(&d);
                self.z_ref[k * n + j] = z;
                // (the lagged normal force only where friction uses it)
                self.n_ref[k * n + j] = if dynamic.is_some() && self.mu[k] > 0.0 {
                    self.hold[j] * window(z, half, taper).0 * (d - z * t).norm()
                } else {
                    f64::NAN
                };
            }
            if let Some((_, clips)) = dynamic {
                self.guide_rates[k] = (clips[c].velocity, clips[c].angular_velocity);
            }
        }
        self.step_h = dynamic.map(|(h, _)| h);
        self.eps = match dynamic {
            Some((h, _)) => self.stick_velocity * h,
            None => self.stick_distance,
        };
    }

    /// The friction's slip u of node `n` in guide `k` (`d` = x − P, `t` the guide's line) and
    /// its gradient in the node's position; None before the first step. Statics: the
    /// displacement along the line since the last equilibrium, u = t·d − z_ref, ∇u = t.
    /// Dynamics: h times the node's velocity along the line relative to the guide's material
    /// point there, u = h t·(v − v_P − ω × d), ∇u = h (c t − t × ω) with c = ∂v/∂x = γ/(βh) —
    /// on the integrator's velocity, not the step's displacement: with the displacement a node
    /// the stick zone holds in place keeps an integrator velocity that only flips sign from
    /// step to step (generalised-α with the position held: v_{n+1} ≈ (1 − γ/β) v_n, −0.995 v_n
    /// at ρ∞ = 0.9). Measured on the guided Y at ρ∞ = 1 (both forms with the lagged normal
    /// force): energy balance 2.9e-3 / 5.4e-3 of the peak kinetic energy (μ = 0.3 / 1, 1 ms)
    /// against 4.2e-3 / 2.6e-2 with the displacement, and 10–20 % fewer Newton iterations on
    /// the shaken hose of tests/test_clip_types.py.
    fn slip(
        &self,
        k: usize,
        n: usize,
        t: &Vector3<f64>,
        d: &Vector3<f64>,
        rates: Option<&Rates>,
    ) -> Option<(f64, Vector3<f64>)> {
        let z_ref = self.z_ref[k * self.n_nodes + n];
        if !z_ref.is_finite() {
            return None;
        }
        match (self.step_h, rates) {
            (Some(h), Some(r)) => {
                let (v_p, omega) = self.guide_rates[k];
                let v: Vector3<f64> = r.v[n].fixed_rows::<3>(0).into();
                let u = h * t.dot(&(v - v_p - omega.cross(d)));
                Some((u, h * (r.damping_factor * t - t.cross(&omega))))
            }
            _ => Some((t.dot(d) - z_ref, *t)),
        }
    }

    /// The largest fraction α ≤ 1 of a Newton correction (node displacements `dx` over the
    /// blocks `nodes`) that carries no node in a frictional guide across its stick zone
    /// (`friction::stick_cut`; without it Newton cycled in a two-cycle of equal corrections,
    /// measured).
    pub fn step_bound(
        &self,
        rod: &Rod,
        st: &State,
        rates: Option<&Rates>,
        dx: impl Fn(usize) -> Vector3<f64>,
        nodes: std::ops::Range<usize>,
    ) -> f64 {
        let taper = 0.5 * rod.mean_ds();
        let mut alpha = 1.0f64;
        for (k, &c) in self.clips.iter().enumerate() {
            if self.mu[k] <= 0.0 {
                continue;
            }
            let (pose, t, half) = guide_line(rod, st, c);
            for n in nodes.clone() {
                if rod.node_kind[n] != NodeKind::Free {
                    continue;
                }
                let d = st.x[n] - pose.position;
                if window(t.dot(&d), half, taper).0 == 0.0 {
                    continue;
                }
                let Some((u, grad_u)) = self.slip(k, n, &t, &d, rates) else {
                    continue;
                };
                let du = grad_u.dot(&dx(n));
                alpha = stick_cut(u * u, u * du, du * du, self.eps, alpha);
            }
        }
        alpha
    }

    /// Updates σ of every sliding clip at the state `st`; the first clip whose guide reaches
    /// beyond a cable end (or that the cable no longer passes through) is the error.
    pub fn check(&mut self, rod: &Rod, st: &State) -> Result<(), usize> {
        for (k, &c) in self.clips.iter().enumerate() {
            let (pose, t, half) = guide_line(rod, st, c);
            let sigma = SlidingClips::crossing(rod, st, &pose.position, &t);
            self.sigma[k] = sigma.unwrap_or(f64::NAN);
            if sigma.is_none_or(|s| s - half < 0.0 || s + half > rod.spec.length) {
                return Err(c);
            }
        }
        Ok(())
    }

    /// The material coordinate where the cable crosses the plane through `p` normal to `t`
    /// upwards (z from ≤ 0 to > 0), nearest to `p` if it crosses more than once.
    fn crossing(rod: &Rod, st: &State, p: &Vector3<f64>, t: &Vector3<f64>) -> Option<f64> {
        let mut best: Option<(f64, f64)> = None;
        for e in 0..rod.n_edges() {
            let (za, zb) = (t.dot(&(st.x[e] - p)), t.dot(&(st.x[e + 1] - p)));
            if za <= 0.0 && zb > 0.0 {
                let xi = -za / (zb - za);
                let off = (st.x[e] + xi * (st.x[e + 1] - st.x[e]) - p).norm();
                if best.is_none_or(|(d, _)| off < d) {
                    best = Some((off, rod.arc[e] + xi * rod.ds_edge[e]));
                }
            }
        }
        best.map(|(_, s)| s)
    }
}

/// Clip c's guide at the state `st`: its pose (the centre P), the line's direction t (the
/// clip's d3) and the half length of its window along it.
#[inline]
fn guide_line<'a>(rod: &Rod, st: &'a State, c: usize) -> (&'a Pose, Vector3<f64>, f64) {
    let pose = &st.clip_pose[c];
    let t = rotation_matrix(&pose.orientation) * Vector3::z();
    (pose, t, 0.5 * rod.spec.clips[c].length)
}

/// The guide's window along the line and its derivative in z.
#[inline]
fn window(z: f64, half: f64, taper: f64) -> (f64, f64) {
    let r = z.abs();
    if r <= half {
        return (1.0, 0.0);
    }
    if r >= half + taper {
        return (0.0, 0.0);
    }
    let s = (r - half) / taper;
    let w = 1.0 - 3.0 * s * s + 2.0 * s * s * s;
    let dw = (-6.0 * s + 6.0 * s * s) / taper * z.signum();
    (w, dw)
}

impl Term for SlidingClips {
    fn add_residual_jacobian(
        &mut self,
        rod: &Rod,
        st: &State,
        ev: &Eval,
        ws: &mut Workspace,
    ) -> Result<(), KinkAt> {
        let all = matches!(ev.part, Part::All);
        let blocks = match ev.part {
            Part::All => 0..rod.arc.len(),
            Part::Segment(seg) => seg.blocks.clone(),
        };
        if all {
            self.off_end = None;
        }
        let taper = 0.5 * rod.mean_ds();
        for (k, &c) in self.clips.iter().enumerate() {
            let (pose, t, half) = guide_line(rod, st, c);
            let p = pose.position;
            let sigma = SlidingClips::crossing(rod, st, &p, &t);
            if all {
                self.sigma[k] = sigma.unwrap_or(f64::NAN);
                let off = sigma.is_none_or(|s| s - half < 0.0 || s + half > rod.spec.length);
                if off && self.off_end.is_none() {
                    self.off_end = Some(c);
                }
            }
            let Some(sigma) = sigma else { continue };
            let span = half + taper + 2.0 * self.reach;
            let q_proj = Matrix3::identity() - t * t.transpose();
            let mu = self.mu[k];
            let mut force = Vector3::zeros();
            let mut moment = Vector3::zeros();
            let (mut normal, mut axial, mut friction_normal) = (0.0, 0.0, 0.0);
            for n in blocks.clone() {
                if (rod.arc[n] - sigma).abs() > span || rod.node_kind[n] != NodeKind::Free {
                    continue;
                }
                let d = st.x[n] - p;
                let z = t.dot(&d);
                let (w, dw) = window(z, half, taper);
                if w == 0.0 {
                    continue;
                }
                let q = q_proj * d;
                let qq = q.norm_squared();
                let kn = self.hold[n];
                // The hold force k w(z) Q d: across the line only (no ∂w/∂z part, which would
                // be a spurious axial force ½ k w′ |Q d|² at the guide's ends).
                let mut grad = kn * w * q;
                let mut h = if ev.want_jac {
                    kn * (w * q_proj + dw * q * t.transpose())
                } else {
                    Matrix3::zeros()
                };
                // Regularised Coulomb friction along the line (IPC's f₁, stick width ε):
                // μ N f₁(|u|) against the slip u (`slip`: since the last equilibrium in
                // statics, h times the velocity relative to the guide in dynamics), N = k w |q|
                // the node's normal force: at the current iterate in statics, at the start of
                // the step in dynamics (`n_ref`).
                let qn = qq.sqrt();
                let nf = kn * w * qn;
                let slip = if mu > 0.0 {
                    self.slip(k, n, &t, &d, ev.rates)
                } else {
                    None
                };
                if let Some((u, grad_u)) = slip {
                    let n_ref = self.n_ref[k * self.n_nodes + n];
                    let lagged = n_ref.is_finite();
                    let n_friction = if lagged { n_ref } else { nf };
                    let a = u.abs();
                    let (phi, dphi) = f1_over(a, self.eps);
                    let f = mu * n_friction * phi * u;
                    grad += f * t;
                    if all {
                        axial -= f;
                        friction_normal += n_friction;
                        if let Some(h) = self.step_h.filter(|_| ev.rates.is_some()) {
                            ws.dissipation += f * u / h; // the friction's power, f · v_rel
                        }
                    }
                    if ev.want_jac {
                        // ∂f/∂x = μ (φ u ∂N/∂x + N (φ + φ′|u|) ∇u); ∂N/∂x = 0 when lagged.
                        let mut dn = Vector3::zeros();
                        if !lagged {
                            dn = kn * qn * dw * t;
                            if qn > 0.0 {
                                dn += kn * w * q / qn;
                            }
                        }
                        let df = phi * u * dn + n_friction * (phi + dphi * a) * grad_u;
                        h += mu * t * df.transpose();
                    }
                }
                ws.node_grad[n] += grad;
                if all {
                    ws.elastic_energy += 0.5 * kn * w * qq;
                    force -= grad;
                    moment -= d.cross(&grad);
                    normal += nf;
                }
                if ev.want_jac {
                    ws.jac.add3(n, 0, n, 0, &h);
                }
            }
            if all {
                self.reaction[k] = (force, moment);
                self.normal_force[k] = normal;
                self.friction_force[k] = axial;
                self.friction_normal[k] = friction_normal;
                ws.held_reaction[c] = Some((force, moment));
            }
        }
        Ok(())
    }
}
