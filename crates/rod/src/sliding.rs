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
use crate::assembly::{Eval, KinkAt, Part, Term, Workspace};
use crate::model::{ClipKind, NodeKind, Rod};
use crate::rotation::rotation_matrix;
use crate::state::State;
use nalgebra::{Matrix3, Vector3};

/// The hold stiffness of a node relative to an edge's axial stiffness EA/Δs.
pub const HOLD_FACTOR: f64 = 100.0;

/// The sliding clips of a cable: a term of the assembly.
#[derive(Clone, Debug)]
pub struct SlidingClips {
    /// Clip indices of the sliding clips.
    pub clips: Vec<usize>,
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
    /// Stick widths of the regularised friction: static (m) and dynamic (m/s).
    pub stick_distance: f64,
    pub stick_velocity: f64,
    hold: Vec<f64>,
    reach: f64,
    /// Per node: its coordinate along each guide's line at the start of the step (friction
    /// reference), row-major (clip, node); the stick width of the step.
    z_ref: Vec<f64>,
    eps: f64,
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
            z_ref: vec![f64::NAN; clips.len() * rod.arc.len()],
            clips,
            off_end: None,
            stick_distance,
            stick_velocity: 1e-3,
            eps: stick_distance,
            hold,
            reach,
        })
    }

    /// Whether a sliding clip has friction.
    pub fn has_friction(&self, rod: &Rod) -> bool {
        self.clips.iter().any(
            |&c| matches!(rod.spec.clips[c].kind, ClipKind::Sliding { friction } if friction > 0.0),
        )
    }

    /// Starts a step from the state `st`: the friction reference (each node's coordinate along
    /// each guide's line); `h` the time step of a dynamic step (None: static, quasistatic).
    pub fn begin_step(&mut self, rod: &Rod, st: &State, h: Option<f64>) {
        let n = rod.arc.len();
        for (k, &c) in self.clips.iter().enumerate() {
            let pose = &st.clip_pose[c];
            let t = rotation_matrix(&pose.orientation) * Vector3::z();
            for (j, x) in st.x.iter().enumerate() {
                self.z_ref[k * n + j] = t.dot(&(x - pose.position));
            }
        }
        self.eps = match h {
            Some(h) => self.stick_velocity * h,
            None => self.stick_distance,
        };
    }

    /// Updates σ of every sliding clip at the state `st`; the first clip whose guide reaches
    /// beyond a cable end (or that the cable no longer passes through) is the error.
    pub fn check(&mut self, rod: &Rod, st: &State) -> Result<(), usize> {
        for (k, &c) in self.clips.iter().enumerate() {
            let pose = &st.clip_pose[c];
            let t = rotation_matrix(&pose.orientation) * Vector3::z();
            let sigma = SlidingClips::crossing(rod, st, &pose.position, &t);
            self.sigma[k] = sigma.unwrap_or(f64::NAN);
            let half = 0.5 * rod.spec.clips[c].length;
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
            let pose = &st.clip_pose[c];
            let p = pose.position;
            let t = rotation_matrix(&pose.orientation) * Vector3::z();
            let half = 0.5 * rod.spec.clips[c].length;
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
            let mu = match rod.spec.clips[c].kind {
                ClipKind::Sliding { friction } => friction,
                _ => 0.0,
            };
            let n_nodes = rod.arc.len();
            let mut force = Vector3::zeros();
            let mut moment = Vector3::zeros();
            let (mut normal, mut axial) = (0.0, 0.0);
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
                // μ N f₁(|u|) against the slip u = z − z_ref since the start of the step,
                // N = k w |q| the node's normal force at the current iterate.
                let qn = qq.sqrt();
                let nf = kn * w * qn;
                let z_ref = self.z_ref[k * n_nodes + n];
                if mu > 0.0 && z_ref.is_finite() {
                    let u = z - z_ref;
                    let (eps, a) = (self.eps, u.abs());
                    let (phi, dphi) = if a < eps {
                        (2.0 / eps - a / (eps * eps), -1.0 / (eps * eps))
                    } else {
                        (1.0 / a, -1.0 / (a * a))
                    };
                    let f = mu * nf * phi * u;
                    grad += f * t;
                    if all {
                        axial -= f;
                    }
                    if ev.want_jac {
                        let mut dn = kn * qn * dw * t;
                        if qn > 0.0 {
                            dn += kn * w * q / qn;
                        }
                        h += mu * t * (phi * u * dn + nf * (phi + dphi * a) * t).transpose();
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
                ws.held_reaction[c] = Some((force, moment));
            }
        }
        Ok(())
    }
}
