//! Stability of an equilibrium: the inertia (number of negative eigenvalues) of the symmetric
//! tangent stiffness by a block LDLᵀ of the block-tridiagonal matrix (Sylvester's law of
//! inertia: H = L D Lᵀ with D = diag(S_n), S_n = H_nn − H_n,n−1 S_{n−1}⁻¹ H_n−1,n, and
//! inertia(H) = Σ inertia(S_n)); a direction of negative curvature from the same factors; and
//! the rigid-body motions the clips leave free.
//!
//! The Newton Jacobian is the energy Hessian plus ½[g]× on each free rotation (g its energy
//! gradient) and −[Rᵀm]× for dead moments: both are skew, the first vanishes at equilibrium.
//! The check therefore uses the symmetric part ½(J + Jᵀ), the Hessian at the converged state.
use crate::block_tridiag::{Block, BlockTridiag};
use crate::model::{ClipKind, Pose, Rod};
use crate::rotation::{rotation_matrix, skew};
use nalgebra::{Matrix6, SymmetricEigen, Vector3, Vector6};
use std::ops::Range;

/// Inertia of a symmetric matrix (the counts of its eigenvalue signs); `zero` counts pivots
/// below the round-off of their block.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Inertia {
    pub negative: usize,
    pub zero: usize,
}

/// Workspace of the block LDLᵀ (allocated once per cable; `inertia` does not allocate).
#[derive(Clone, Debug)]
pub struct StabilityCheck {
    /// W_n = S_n⁻¹ H_{n,n+1}: the blocks of Lᵀ (above the diagonal).
    w: Vec<Block>,
    /// The block and eigenvector of the most negative pivot eigenvalue (relative to its block).
    negative_pivot: Option<(usize, Vector6<f64>)>,
}

/// Relative size below which an eigenvalue of a pivot block counts as zero.
const ZERO_PIVOT: f64 = 1e-11;

impl StabilityCheck {
    pub fn new(n_blocks: usize) -> Self {
        StabilityCheck {
            w: vec![Block::zeros(); n_blocks],
            negative_pivot: None,
        }
    }

    /// Inertia of the symmetric part of `jac` over the blocks `r` (an independent system or the
    /// whole matrix; eliminated slots are identity rows and count as positive). The matrix
    /// blocks are read, not changed.
    pub fn inertia(&mut self, jac: &BlockTridiag, r: Range<usize>) -> Inertia {
        let mut out = Inertia::default();
        self.negative_pivot = None;
        let mut worst = 0.0f64;
        // H_{b,b+1} of the previous block: H_{b+1,b} = its transpose.
        let mut prev_upper = Block::zeros();
        for b in r.clone() {
            let d = &jac.diag[b];
            let mut s = 0.5 * (d + d.transpose());
            // Scales before the Schur update: the size of its round-off, per slot and per block
            // (units differ between slots: positions and rotations).
            let tiny = s.diagonal().map(|v| ZERO_PIVOT * v.abs());
            let scale = s.diagonal().amax().max(1e-300);
            if b > r.start {
                s -= prev_upper.transpose() * self.w[b - 1];
                s = 0.5 * (s + s.transpose());
            }
            let upper = if b + 1 < r.end {
                0.5 * (jac.upper[b] + jac.lower[b + 1].transpose())
            } else {
                Block::zeros()
            };
            prev_upper = upper;
            let mut l = s;
            if cholesky_in_place(&mut l, &tiny) {
                if b + 1 < r.end {
                    self.w[b] = upper;
                    cholesky_solve(&l, &mut self.w[b]);
                }
                continue;
            }
            // Not positive definite: count the signs from the eigenvalues (rare: only where
            // the state is unstable or singular).
            let eig = SymmetricEigen::new(s);
            let mut inv = Matrix6::zeros();
            for k in 0..6 {
                let lam = eig.eigenvalues[k];
                let v = eig.eigenvectors.column(k);
                if lam.abs() <= ZERO_PIVOT * scale {
                    out.zero += 1;
                    continue; // pseudo-inverse: a zero pivot couples nothing onward
                }
                if lam < 0.0 {
                    out.negative += 1;
                    if -lam / scale > worst {
                        worst = -lam / scale;
                        self.negative_pivot = Some((b, v.into_owned()));
                    }
                }
                inv += v * v.transpose() / lam;
            }
            if b + 1 < r.end {
                self.w[b] = inv * upper;
            }
        }
        out
    }

    /// A direction z of negative curvature (zᵀHz < 0) from the last `inertia` over `r`, in the
    /// block layout of the unknowns: Lᵀz = e_n v with v the pivot block's negative eigenvector,
    /// so zᵀHz = vᵀS_n v < 0. Returns false (and leaves `z` alone) if there was none.
    pub fn negative_direction(&self, r: Range<usize>, z: &mut [Vector6<f64>]) -> bool {
        let Some((n, v)) = self.negative_pivot else {
            return false;
        };
        for b in r.clone() {
            z[b].fill(0.0);
        }
        z[n] = v;
        for b in (r.start..n).rev() {
            z[b] = -(self.w[b] * z[b + 1]);
        }
        true
    }
}

/// A rigid-body motion: translation and rotation (about the global origin).
pub type RigidMotion = (Vector3<f64>, Vector3<f64>);

/// Cholesky factor L (lower triangle, in place) of a symmetric 6×6 block; false if the pivot of
/// slot j is not above `tiny[j]` (not positive definite, or nearly singular). Hand-written: it
/// is the hot path of the check (nalgebra's generic Cholesky and solve cost 2× more here).
#[inline]
fn cholesky_in_place(a: &mut Block, tiny: &Vector6<f64>) -> bool {
    for j in 0..6 {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        if d.is_nan() || d <= tiny[j] {
            return false;
        }
        let d = d.sqrt();
        a[(j, j)] = d;
        let inv = 1.0 / d;
        for i in j + 1..6 {
            let mut v = a[(i, j)];
            for k in 0..j {
                v -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = v * inv;
        }
    }
    true
}

/// X ← (L Lᵀ)⁻¹ X with the factor of `cholesky_in_place`.
#[inline]
fn cholesky_solve(l: &Block, x: &mut Block) {
    for c in 0..6 {
        for i in 0..6 {
            let mut v = x[(i, c)];
            for k in 0..i {
                v -= l[(i, k)] * x[(k, c)];
            }
            x[(i, c)] = v / l[(i, i)];
        }
        for i in (0..6).rev() {
            let mut v = x[(i, c)];
            for k in i + 1..6 {
                v -= l[(k, i)] * x[(k, c)];
            }
            x[(i, c)] = v / l[(i, i)];
        }
    }
}

/// The rigid-body motions (translation t, rotation ω about the global origin) of an
/// independent part that the clips `clips` at `poses` leave free: the null space of their
/// constraints (a point clip stops its point's velocity t + ω × p, a fixed clip also ω, a
/// swivel clip ω across its axis). Returns the dimension and, if any, one free motion (t, ω).
pub fn free_rigid_motions(
    rod: &Rod,
    clips: &[usize],
    poses: &[Pose],
) -> (usize, Option<RigidMotion>) {
    // Normal equations AᵀA of the constraint rows (6 × 6), accumulated row block by block.
    let mut ata = Matrix6::<f64>::zeros();
    let mut add_rows = |rows: &nalgebra::Matrix3x6<f64>| ata += rows.transpose() * rows;
    let len = rod.spec.length.max(1e-300);
    for &c in clips {
        let pose = &poses[c];
        let p = pose.position / len; // dimensionless, for a well-scaled AᵀA
        let mut point = nalgebra::Matrix3x6::zeros();
        point
            .fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&nalgebra::Matrix3::identity());
        point.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(&p)));
        add_rows(&point);
        let mut rot = nalgebra::Matrix3x6::zeros();
        let kind = rod.spec.clips[c].kind;
        match (kind, kind.free_axis()) {
            (ClipKind::Fixed, _) => {
                rot.fixed_view_mut::<3, 3>(0, 3)
                    .copy_from(&nalgebra::Matrix3::identity());
                add_rows(&rot);
            }
            (_, Some(a)) => {
                // Free to turn about the axis only (ω ∥ axis).
                let axis = rotation_matrix(&pose.orientation) * a;
                rot.fixed_view_mut::<3, 3>(0, 3).copy_from(&skew(&axis));
                add_rows(&rot);
            }
            _ => {}
        }
    }
    let eig = SymmetricEigen::new(ata);
    let top = eig.eigenvalues.amax().max(1.0);
    let mut count = 0;
    let mut motion = None;
    for k in 0..6 {
        if eig.eigenvalues[k].abs() <= 1e-10 * top {
            count += 1;
            let v = eig.eigenvectors.column(k);
            motion = Some((
                Vector3::new(v[0], v[1], v[2]) * len,
                Vector3::new(v[3], v[4], v[5]),
            ));
        }
    }
    (count, motion)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rnd(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    /// A symmetric block-tridiagonal matrix with a prescribed spectrum shift: its inertia by
    /// the block LDLᵀ equals the count of negative eigenvalues of the dense matrix.
    #[test]
    fn inertia_matches_the_dense_eigenvalues() {
        let n = 9;
        let mut seed = 7u64;
        for shift in [-3.0, -1.0, 0.0, 0.5, 1.5, 4.0] {
            let mut j = BlockTridiag::new(n);
            for b in 0..n {
                let a = Block::from_fn(|_, _| rnd(&mut seed));
                j.diag[b] = a + a.transpose() + Block::identity() * shift;
                if b + 1 < n {
                    let u = Block::from_fn(|_, _| rnd(&mut seed));
                    j.upper[b] = u;
                    j.lower[b + 1] = u.transpose();
                }
            }
            // A skew part (like ½[g]×) must not change the answer.
            let k = Block::from_fn(|_, _| rnd(&mut seed));
            j.diag[3] += k - k.transpose();
            let mut dense = nalgebra::DMatrix::<f64>::zeros(6 * n, 6 * n);
            for b in 0..n {
                let d = 0.5 * (j.diag[b] + j.diag[b].transpose());
                dense.view_mut((6 * b, 6 * b), (6, 6)).copy_from(&d);
                if b + 1 < n {
                    dense
                        .view_mut((6 * b, 6 * b + 6), (6, 6))
                        .copy_from(&j.upper[b]);
                    dense
                        .view_mut((6 * b + 6, 6 * b), (6, 6))
                        .copy_from(&j.lower[b + 1]);
                }
            }
            let expected = dense
                .clone()
                .symmetric_eigenvalues()
                .iter()
                .filter(|&&l| l < 0.0)
                .count();
            let mut chk = StabilityCheck::new(n);
            let inertia = chk.inertia(&j, 0..n);
            assert_eq!(inertia.negative, expected, "shift {shift}");
            assert_eq!(inertia.zero, 0);
            let mut z = vec![Vector6::zeros(); n];
            assert_eq!(chk.negative_direction(0..n, &mut z), expected > 0);
            if expected > 0 {
                let zv = nalgebra::DVector::from_iterator(
                    6 * n,
                    z.iter().flat_map(|v| v.iter().copied()),
                );
                assert!((zv.transpose() * &dense * &zv)[0] < 0.0);
            }
        }
    }
}
