//! The configuration of a cable: node positions, edge and ghost rotations, clip poses.
use crate::model::{EdgeKind, NodeKind, Pose, Rod};
use crate::rotation::{exp_half, rotate_body, Quat};
use nalgebra::{Vector3, Vector6};

#[derive(Clone, Debug)]
pub struct State {
    /// Node positions x_n (global).
    pub x: Vec<Vector3<f64>>,
    /// Edge rotations p_{n+½} (unit quaternions).
    pub p: Vec<Quat>,
    /// Ghost rotations of point clips.
    pub ghost: Vec<Quat>,
    /// The clip poses the prescribed unknowns currently follow.
    pub clip_pose: Vec<Pose>,
}

impl State {
    /// A state with no nodes (a placeholder for buffers).
    pub fn empty() -> State {
        State {
            x: vec![],
            p: vec![],
            ghost: vec![],
            clip_pose: vec![],
        }
    }

    /// Applies a Newton increment (block vector, inactive slots ignored) scaled by `alpha`.
    pub fn apply_increment(&mut self, rod: &Rod, delta: &[Vector6<f64>], alpha: f64) {
        for (n, d) in delta.iter().enumerate() {
            let m = &rod.mask[n];
            if m[0] && m[1] && m[2] {
                self.x[n] += alpha * Vector3::new(d[0], d[1], d[2]);
            }
            if n < self.p.len() && (m[3] || m[4] || m[5]) {
                let th = Vector3::new(
                    if m[3] { d[3] } else { 0.0 },
                    if m[4] { d[4] } else { 0.0 },
                    if m[5] { d[5] } else { 0.0 },
                );
                self.p[n] = rotate_body(&self.p[n], &(alpha * th));
            }
        }
        for (g, ghost) in rod.ghosts.iter().enumerate() {
            if let Some(axis) = ghost.free_axis {
                let a = alpha * delta[ghost.node][0];
                self.ghost[g] = rotate_body(&self.ghost[g], &(a * axis));
            }
        }
    }

    /// Moves the prescribed unknowns to follow new clip poses; free angles of swivel and hinge
    /// clips are kept (the clip's rotation increment is applied from the left).
    pub fn set_clip_poses(&mut self, rod: &Rod, poses: &[Pose]) {
        for (c, pose) in poses.iter().enumerate() {
            let old = self.clip_pose[c];
            let delta = pose.orientation * old.orientation.conjugate();
            for &n in &rod.clip_nodes[c] {
                if let NodeKind::Prescribed { .. } = rod.node_kind[n] {
                    self.x[n] = rod.clip_node_position(c, n, pose);
                }
            }
            for &e in &rod.clip_edges[c] {
                self.p[e] = match rod.edge_kind[e] {
                    EdgeKind::TwistFree { .. } => normalize(delta * self.p[e]),
                    _ => pose.orientation,
                };
            }
            if let Some(g) = rod.clip_ghost[c] {
                self.ghost[g] = if rod.ghosts[g].is_free() {
                    normalize(delta * self.ghost[g])
                } else {
                    pose.orientation
                };
            }
            self.clip_pose[c] = *pose;
        }
    }

    /// Linear extrapolation of the free unknowns from two earlier states (a predictor for
    /// sequences of equilibria): x ← 2x₁ − x₀, p ← p₁ ⊗ (p̄₀ ⊗ p₁).
    pub fn extrapolate_free(&mut self, rod: &Rod, s0: &State, s1: &State) {
        for n in 0..self.x.len() {
            if rod.node_kind[n] == NodeKind::Free {
                self.x[n] = 2.0 * s1.x[n] - s0.x[n];
            }
        }
        for e in 0..self.p.len() {
            if rod.edge_kind[e] == EdgeKind::Free {
                self.p[e] = normalize(s1.p[e] * (s0.p[e].conjugate() * s1.p[e]));
            }
        }
    }

    /// Largest deviation of |p| from 1 over edges and ghosts.
    pub fn max_unit_error(&self) -> f64 {
        self.p
            .iter()
            .chain(self.ghost.iter())
            .map(|q| (q.norm() - 1.0).abs())
            .fold(0.0, f64::max)
    }
}

#[inline]
fn normalize(q: Quat) -> Quat {
    q / q.norm()
}

/// Twist a quaternion about its own d3 axis.
pub fn twist(p: &Quat, angle: f64) -> Quat {
    p * exp_half(&Vector3::new(0.0, 0.0, angle))
}
