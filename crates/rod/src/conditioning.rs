//! Conditioning of the tangent stiffness: an estimate of its condition number after Jacobi
//! (diagonal) scaling, for the warning of ill-conditioned models (docs/solver.md).
//!
//! Units differ between the slots (forces per metre on positions, moments per radian on
//! rotations), so the plain condition of K is meaningless; D^{-1/2} K D^{-1/2} with D = |diag K|
//! removes the units and the slot scales. What is left is the spread of the physical
//! stiffnesses at the element scale: a slender rod has cond ~ (GA Δs²/EI)·N², and that grows
//! without bound when a section is given a shear or axial stiffness far above its bending one,
//! or when segment lengths differ by orders of magnitude. Round-off then makes the solution's
//! soft directions, and the signs of the pivots of the stability check, unreliable: a relative
//! error ~ ε · cond.
use crate::block_tridiag::{Block, BlockTridiag};
use nalgebra::Vector6;

/// The estimate: λ_max and |λ|_min of the Jacobi-scaled symmetric matrix and their ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Condition {
    pub lambda_max: f64,
    pub lambda_min: f64,
    pub condition: f64,
}

/// Power and inverse iterations of the estimate (the ratio needs its magnitude only; the
/// spectrum of a rod's tangent has no large gap at either end, so the vectors converge slowly
/// but the norms' growth ratios converge to within a few per cent in this many steps).
const ITERATIONS: usize = 40;

/// Condition estimate of the symmetric part of the block-tridiagonal `k` (all its blocks; the
/// eliminated slots are identity rows). λ_max by power iteration, |λ|_min by inverse iteration
/// with the block LDLᵀ (`BlockTridiag::ldlt`); a zero pivot gives an infinite condition.
/// Allocates (once per call: for a diagnosis, not for a loop).
pub fn condition_estimate(k: &BlockTridiag) -> Condition {
    let n = k.n_blocks();
    // Jacobi scaling s = |diag|^{-1/2} (1 where a diagonal entry is zero).
    let s: Vec<Vector6<f64>> = k
        .diag
        .iter()
        .map(|d| {
            Vector6::from_fn(|i, _| {
                let v = d[(i, i)].abs();
                if v > 0.0 && v.is_finite() {
                    1.0 / v.sqrt()
                } else {
                    1.0
                }
            })
        })
        .collect();
    let mut a = BlockTridiag::new(n);
    let scale = |m: &Block, si: &Vector6<f64>, sj: &Vector6<f64>| {
        Block::from_fn(|i, j| m[(i, j)] * si[i] * sj[j])
    };
    for b in 0..n {
        let d = 0.5 * (k.diag[b] + k.diag[b].transpose());
        a.diag[b] = scale(&d, &s[b], &s[b]);
        if b + 1 < n {
            let u = 0.5 * (k.upper[b] + k.lower[b + 1].transpose());
            a.upper[b] = scale(&u, &s[b], &s[b + 1]);
            a.lower[b + 1] = a.upper[b].transpose();
        }
    }
    // A deterministic start with components in every slot.
    let start = |x: &mut [Vector6<f64>]| {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for v in x.iter_mut() {
            for i in 0..6 {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                v[i] = ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
            }
        }
    };
    let norm = |x: &[Vector6<f64>]| x.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
    let mut x = vec![Vector6::zeros(); n];
    let mut y = vec![Vector6::zeros(); n];
    start(&mut x);
    let mut lambda_max = 0.0;
    for _ in 0..ITERATIONS {
        let nx = norm(&x).max(1e-300);
        x.iter_mut().for_each(|v| *v /= nx);
        a.mul(&x, &mut y);
        lambda_max = norm(&y);
        std::mem::swap(&mut x, &mut y);
    }
    let inertia = a.ldlt(0..n);
    if inertia.zero > 0 || !lambda_max.is_finite() {
        return Condition {
            lambda_max,
            lambda_min: 0.0,
            condition: f64::INFINITY,
        };
    }
    start(&mut x);
    let mut lambda_min = f64::INFINITY;
    for _ in 0..ITERATIONS {
        let nx = norm(&x).max(1e-300);
        x.iter_mut().for_each(|v| *v /= nx);
        a.solve_range(0..n, &mut x);
        let g = norm(&x);
        lambda_min = if g > 0.0 && g.is_finite() {
            1.0 / g
        } else {
            0.0
        };
    }
    Condition {
        lambda_max,
        lambda_min,
        condition: if lambda_min > 0.0 {
            lambda_max / lambda_min
        } else {
            f64::INFINITY
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block-tridiagonal matrix with wildly different slot scales (as positions and
    /// rotations of a rod): the estimate equals the condition of the dense Jacobi-scaled
    /// matrix within a few per cent, indefinite or not.
    #[test]
    fn the_estimate_matches_the_dense_scaled_condition() {
        let n = 8;
        let mut seed = 3u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for shift in [0.3, 1.0, -0.2] {
            let mut k = BlockTridiag::new(n);
            let slot: Vector6<f64> = Vector6::new(1e6, 1e6, 1e8, 1e-2, 1e-2, 1e-3);
            for b in 0..n {
                let r = Block::from_fn(|_, _| rnd());
                let m = r * r.transpose() * 0.2 + Block::identity() * (1.0 + shift);
                k.diag[b] = Block::from_fn(|i, j| m[(i, j)] * (slot[i] * slot[j]).sqrt());
                if b + 1 < n {
                    let u = Block::from_fn(|_, _| 0.3 * rnd());
                    k.upper[b] = Block::from_fn(|i, j| u[(i, j)] * (slot[i] * slot[j]).sqrt());
                    k.lower[b + 1] = k.upper[b].transpose();
                }
            }
            let mut dense = nalgebra::DMatrix::<f64>::zeros(6 * n, 6 * n);
            for b in 0..n {
                dense.view_mut((6 * b, 6 * b), (6, 6)).copy_from(&k.diag[b]);
                if b + 1 < n {
                    dense
                        .view_mut((6 * b, 6 * b + 6), (6, 6))
                        .copy_from(&k.upper[b]);
                    dense
                        .view_mut((6 * b + 6, 6 * b), (6, 6))
                        .copy_from(&k.lower[b + 1]);
                }
            }
            let d = nalgebra::DVector::from_fn(6 * n, |i, _| 1.0 / dense[(i, i)].abs().sqrt());
            let scaled =
                nalgebra::DMatrix::from_fn(6 * n, 6 * n, |i, j| dense[(i, j)] * d[i] * d[j]);
            let eig = scaled.symmetric_eigenvalues();
            let max = eig.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let min = eig.iter().fold(f64::INFINITY, |a, v| a.min(v.abs()));
            let c = condition_estimate(&k);
            assert!(
                (c.condition / (max / min) - 1.0).abs() < 0.05,
                "shift {shift}: {c:?} vs {}",
                max / min
            );
        }
    }
}
