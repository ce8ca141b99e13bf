//! Stability of an equilibrium: its inertia (the number of negative eigenvalues of the
//! symmetric tangent stiffness) is `BlockTridiag::ldlt` — the one block-LDLᵀ inertia code —
//! applied to the Newton Jacobian; this module holds the rigid-body motions the clips leave
//! free.
//!
//! The Newton Jacobian is the energy Hessian plus ½[g]× on each free rotation (g its energy
//! gradient) and −[Rᵀm]× for dead moments: both are skew, the first vanishes at equilibrium.
//! The check therefore uses the symmetric part ½(J + Jᵀ), the Hessian at the converged state.
pub use crate::block_tridiag::Inertia;
use crate::model::{ClipKind, Pose, Rod};
use crate::rotation::{rotation_matrix, skew};
use nalgebra::{Matrix6, SymmetricEigen, Vector3};

/// A rigid-body motion: translation and rotation (about the global origin).
pub type RigidMotion = (Vector3<f64>, Vector3<f64>);

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
