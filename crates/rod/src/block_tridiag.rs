//! Block-tridiagonal matrices with 6×6 blocks and their O(N) solve (block Thomas algorithm with
//! LU-inverted pivot blocks, so that substitutions are matrix–vector products). Storage is allocated once; factor and solve do not allocate.
use nalgebra::{Matrix3, Matrix6, Vector6, LU};

pub type Block = Matrix6<f64>;

#[derive(Clone, Debug)]
pub struct BlockTridiag {
    /// J[n][n].
    pub diag: Vec<Block>,
    /// J[n][n−1] (entry 0 unused).
    pub lower: Vec<Block>,
    /// J[n][n+1] (last entry unused).
    pub upper: Vec<Block>,
    /// D'_n⁻¹, the inverted pivot blocks (substitution is then matrix–vector products only).
    inv: Vec<Block>,
    /// D'_n⁻¹ U_n of the forward elimination.
    elim: Vec<Block>,
}

/// A pivot block of the elimination is singular: the system has a free (zero-stiffness) mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Singular {
    pub block: usize,
}

impl BlockTridiag {
    pub fn new(n_blocks: usize) -> Self {
        BlockTridiag {
            diag: vec![Block::zeros(); n_blocks],
            lower: vec![Block::zeros(); n_blocks],
            upper: vec![Block::zeros(); n_blocks],
            inv: vec![Block::zeros(); n_blocks],
            elim: vec![Block::zeros(); n_blocks],
        }
    }

    pub fn n_blocks(&self) -> usize {
        self.diag.len()
    }

    pub fn clear(&mut self) {
        for m in self
            .diag
            .iter_mut()
            .chain(self.lower.iter_mut())
            .chain(self.upper.iter_mut())
        {
            m.fill(0.0);
        }
    }

    /// Adds the 3×3 matrix `m` at rows (block bi, half hi) and columns (block bj, half hj).
    #[inline]
    pub fn add3(&mut self, bi: usize, hi: usize, bj: usize, hj: usize, m: &Matrix3<f64>) {
        let target = if bi == bj {
            &mut self.diag[bi]
        } else if bj == bi + 1 {
            &mut self.upper[bi]
        } else if bi == bj + 1 {
            &mut self.lower[bi]
        } else {
            panic!("coupling of blocks {bi} and {bj} breaks the band structure");
        };
        let mut v = target.fixed_view_mut::<3, 3>(3 * hi, 3 * hj);
        v += m;
    }

    /// Makes slot k of block b inactive: identity row and column.
    pub fn eliminate_slot(&mut self, b: usize, k: usize) {
        let n = self.n_blocks();
        for j in 0..6 {
            self.diag[b][(k, j)] = 0.0;
            self.diag[b][(j, k)] = 0.0;
            self.upper[b][(k, j)] = 0.0;
            self.lower[b][(k, j)] = 0.0;
            if b + 1 < n {
                self.lower[b + 1][(j, k)] = 0.0;
            }
            if b > 0 {
                self.upper[b - 1][(j, k)] = 0.0;
            }
        }
        self.diag[b][(k, k)] = 1.0;
    }

    /// Factors the matrix (forward elimination of the block Thomas algorithm).
    pub fn factor(&mut self) -> Result<(), Singular> {
        let n = self.n_blocks();
        for b in 0..n {
            let mut d = self.diag[b];
            if b > 0 {
                d -= self.lower[b] * self.elim[b - 1];
            }
            let lu = LU::new(d);
            let u = lu.u();
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for k in 0..6 {
                lo = lo.min(u[(k, k)].abs());
                hi = hi.max(u[(k, k)].abs());
            }
            if lo.is_nan() || lo <= 1e-14 * hi || !hi.is_finite() {
                return Err(Singular { block: b });
            }
            self.inv[b] = lu.try_inverse().ok_or(Singular { block: b })?;
            if b + 1 < n {
                self.elim[b] = self.inv[b] * self.upper[b];
            }
        }
        Ok(())
    }

    /// Solves J x = rhs in place with the current factorisation.
    pub fn solve_factored(&self, rhs: &mut [Vector6<f64>]) {
        let n = self.n_blocks();
        // Forward: y_b = D'_b⁻¹ (r_b − L_b y_{b−1}).
        for b in 0..n {
            let mut r = rhs[b];
            if b > 0 {
                r -= self.lower[b] * rhs[b - 1];
            }
            rhs[b] = self.inv[b] * r;
        }
        // Backward: x_b = y_b − (D'_b⁻¹ U_b) x_{b+1}.
        for b in (0..n.saturating_sub(1)).rev() {
            let next = rhs[b + 1];
            rhs[b] -= self.elim[b] * next;
        }
    }

    /// y = J x (for tests and residual checks).
    pub fn mul(&self, x: &[Vector6<f64>], y: &mut [Vector6<f64>]) {
        let n = self.n_blocks();
        for b in 0..n {
            let mut v = self.diag[b] * x[b];
            if b > 0 {
                v += self.lower[b] * x[b - 1];
            }
            if b + 1 < n {
                v += self.upper[b] * x[b + 1];
            }
            y[b] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_random_system() {
        let n = 7;
        let mut j = BlockTridiag::new(n);
        let mut seed = 1u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for b in 0..n {
            j.diag[b] = Block::from_fn(|_, _| rnd()) + Block::identity() * 4.0;
            j.lower[b] = Block::from_fn(|_, _| rnd());
            j.upper[b] = Block::from_fn(|_, _| rnd());
        }
        let x: Vec<Vector6<f64>> = (0..n).map(|_| Vector6::from_fn(|_, _| rnd())).collect();
        let mut rhs = vec![Vector6::zeros(); n];
        j.mul(&x, &mut rhs);
        j.factor().unwrap();
        j.solve_factored(&mut rhs);
        for b in 0..n {
            assert!((rhs[b] - x[b]).norm() < 1e-12);
        }
    }
}
