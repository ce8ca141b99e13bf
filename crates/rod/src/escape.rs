//! The second unstable mode of an equilibrium, for the escape of `Statics::ensure_stable`.
//!
//! A round section (EI₁ = EI₂) has two nearly equal negative eigenvalues at a straight column
//! above its Euler load, one per bending plane, split only by the imperfection; the stable
//! buckled state lies in the plane the imperfection prefers, which can be any combination of
//! the two modes. The escape therefore searches the plane of both modes (docs/solver.md,
//! "Escape"): the second mode is the next eigenvector of H φ = λ D φ, by inverse iteration
//! with H shifted below the first eigenvalue, D-orthogonal to the first mode.
use crate::block_tridiag::BlockTridiag;
use crate::model::Rod;
use nalgebra::Vector6;

/// The damping diagonal of the pseudo-transient path (δs for positions, Δs³/12 for rotations).
pub(crate) fn damping(rod: &Rod, b: usize, k: usize) -> f64 {
    let nb = rod.arc.len();
    if k < 3 {
        rod.ds_node[b]
    } else {
        rod.ds_edge[b.min(nb - 2)].powi(3) / 12.0
    }
}

/// zᵀ D w over the active slots.
fn d_dot(rod: &Rod, z: &[Vector6<f64>], w: &[Vector6<f64>]) -> f64 {
    let mut sum = 0.0;
    for (b, (a, c)) in z.iter().zip(w).enumerate() {
        for k in 0..6 {
            if rod.mask[b][k] {
                sum += damping(rod, b, k) * a[k] * c[k];
            }
        }
    }
    sum
}

fn shift(jac: &mut BlockTridiag, rod: &Rod, mu: f64) {
    for b in 0..rod.arc.len() {
        for k in 0..6 {
            if rod.mask[b][k] {
                jac.diag[b][(k, k)] -= mu * damping(rod, b, k);
            }
        }
    }
}

/// The mode of the second eigenvalue of H φ = λ D φ into `out` (D-normalised), given the
/// first mode `first` (H assembled in `jac`, left as it was); `scratch` is a block vector.
/// Returns its Rayleigh quotient, or None if no shift below the spectrum was found.
pub(crate) fn second_mode(
    jac: &mut BlockTridiag,
    rod: &Rod,
    first: &[Vector6<f64>],
    out: &mut [Vector6<f64>],
    scratch: &mut [Vector6<f64>],
) -> Option<f64> {
    let nb = rod.arc.len();
    let norm1 = d_dot(rod, first, first).max(1e-300);
    jac.mul(first, scratch);
    let rho1: f64 = first
        .iter()
        .zip(scratch.iter())
        .map(|(a, b)| a.dot(b))
        .sum::<f64>()
        / norm1;
    if !(rho1 < 0.0 && rho1.is_finite()) {
        return None;
    }
    // A deterministic start with components in every active slot.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for (b, v) in out.iter_mut().enumerate() {
        for k in 0..6 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let x = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            v[k] = if rod.mask[b][k] { x } else { 0.0 };
        }
    }
    let orthogonalise = |z: &mut [Vector6<f64>]| {
        let c = d_dot(rod, z, first) / norm1;
        for (v, f) in z.iter_mut().zip(first) {
            *v -= c * f;
        }
        let n = d_dot(rod, z, z).sqrt().max(1e-300);
        z.iter_mut().for_each(|v| *v /= n);
    };
    orthogonalise(out);
    for gap in [0.01, 0.1, 0.5] {
        let mu = rho1 * (1.0 + gap);
        shift(jac, rod, mu);
        let inertia = jac.inertia(0..nb);
        let pd = inertia.negative == 0 && inertia.zero == 0 && jac.factor().is_ok();
        if pd {
            for _ in 0..40 {
                for (b, v) in out.iter_mut().enumerate() {
                    for k in 0..6 {
                        v[k] *= if rod.mask[b][k] {
                            damping(rod, b, k)
                        } else {
                            0.0
                        };
                    }
                }
                jac.solve_factored(out);
                orthogonalise(out);
            }
        }
        shift(jac, rod, -mu);
        if pd {
            jac.mul(out, scratch);
            let rho2: f64 = out.iter().zip(scratch.iter()).map(|(a, b)| a.dot(b)).sum();
            return Some(rho2);
        }
    }
    None
}
