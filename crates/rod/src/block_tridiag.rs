//! Block-tridiagonal matrices with 6×6 blocks and their O(N) solve (block Thomas algorithm; the
//! pivot blocks are LU-factored in place with partial pivoting). Storage is allocated once;
//! factor and solve do not allocate.
use nalgebra::{Matrix3, Matrix6, Vector6};
use std::ops::Range;

pub type Block = Matrix6<f64>;

#[derive(Clone, Debug)]
pub struct BlockTridiag {
    /// J[n][n].
    pub diag: Vec<Block>,
    /// J[n][n−1] (entry 0 unused).
    pub lower: Vec<Block>,
    /// J[n][n+1] (last entry unused).
    pub upper: Vec<Block>,
    /// D'_n⁻¹, the inverted pivot blocks D'_n = D_n − L_n D'_{n−1}⁻¹ U_{n−1} (substitution
    /// is then matrix–vector products only).
    inv: Vec<Block>,
    /// D'_n⁻¹ U_n of the forward elimination.
    elim: Vec<Block>,
    /// D'_n⁻¹ L_n: the forward substitution y_n = D'_n⁻¹ r_n − (D'_n⁻¹ L_n) y_{n−1} has one
    /// matrix–vector product on its dependency chain.
    inv_lower: Vec<Block>,
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
            inv_lower: vec![Block::zeros(); n_blocks],
        }
    }

    pub fn n_blocks(&self) -> usize {
        self.diag.len()
    }

    pub fn clear(&mut self) {
        self.clear_range(0..self.n_blocks());
    }

    /// Zeroes the rows of blocks `r`.
    pub fn clear_range(&mut self, r: Range<usize>) {
        for b in r {
            self.diag[b].fill(0.0);
            self.lower[b].fill(0.0);
            self.upper[b].fill(0.0);
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
        self.factor_range(0..self.n_blocks())
    }

    /// Factors the diagonal part of blocks `r` (an independent system: the coupling blocks to
    /// the blocks outside are zero).
    pub fn factor_range(&mut self, r: Range<usize>) -> Result<(), Singular> {
        for b in r.clone() {
            let mut d = self.diag[b];
            if b > r.start {
                d -= self.lower[b] * self.elim[b - 1];
            }
            // Pivots are judged against their column of D_n before the elimination: a stiffness
            // small against the others of the block (EI ≪ GA Δs²) is not a singularity, a
            // pivot cancelled to round-off by the elimination (a free mode) is.
            let mut scale = [0.0; 6];
            for (k, c) in scale.iter_mut().enumerate() {
                *c = self.diag[b].column(k).amax();
            }
            let (piv, inv_diag) = lu_in_place(&mut d, &scale).map_err(|_| Singular { block: b })?;
            let mut inv = Block::identity();
            lu_solve_matrix(&d, &piv, &inv_diag, &mut inv);
            self.inv[b] = inv;
            if b > r.start {
                self.inv_lower[b] = inv * self.lower[b];
            }
            if b + 1 < r.end {
                self.elim[b] = inv * self.upper[b];
            }
        }
        Ok(())
    }

    /// Symmetric block LDLᵀ factorisation of the blocks `r` and its inertia: the number of
    /// negative eigenvalues of the (symmetric) matrix of these blocks. The matrix must be
    /// symmetric (`lower[b] = upper[b−1]ᵀ`, `diag[b]` symmetric; only `diag` and `upper` are
    /// read for the pivots' symmetry). The pivot blocks D'_b = D_b − L_b D'_{b−1}⁻¹ U_{b−1} are
    /// those of `factor_range`, and by Sylvester's law of inertia (A = L D Lᵀ with D block
    /// diagonal) the inertia of A is the sum of the inertias of the pivots, read from their
    /// symmetric eigenvalues. Afterwards `solve_range` solves with this factorisation. With
    /// A = K − σM this is the Sturm count: the number of eigenvalues of K φ = λ M φ below σ.
    /// A pivot eigenvalue below 1e-14 of the pivot's largest is `Singular` (σ on or next to an
    /// eigenvalue: shift it).
    pub fn inertia(&mut self, r: Range<usize>) -> Result<usize, Singular> {
        let mut negative = 0;
        for b in r.clone() {
            let mut d = self.diag[b];
            if b > r.start {
                d -= self.lower[b] * self.elim[b - 1];
            }
            let d = 0.5 * (d + d.transpose());
            let eig = d.symmetric_eigen();
            let top = eig.eigenvalues.amax();
            if !(top.is_finite() && top > 0.0)
                || eig.eigenvalues.iter().any(|mu| mu.abs() <= 1e-14 * top)
            {
                return Err(Singular { block: b });
            }
            negative += eig.eigenvalues.iter().filter(|&&mu| mu < 0.0).count();
            let v = &eig.eigenvectors;
            let inv = v * Block::from_diagonal(&eig.eigenvalues.map(|mu| 1.0 / mu)) * v.transpose();
            self.inv[b] = inv;
            if b > r.start {
                self.inv_lower[b] = inv * self.lower[b];
            }
            if b + 1 < r.end {
                self.elim[b] = inv * self.upper[b];
            }
        }
        Ok(negative)
    }

    /// Solves J x = rhs in place with the current factorisation.
    pub fn solve_factored(&self, rhs: &mut [Vector6<f64>]) {
        self.solve_range(0..self.n_blocks(), rhs);
    }

    /// Solves the system of blocks `r` (factored by `factor_range`) in place; `rhs` holds all
    /// blocks, only those in `r` are used and changed.
    pub fn solve_range(&self, r: Range<usize>, rhs: &mut [Vector6<f64>]) {
        if r.is_empty() {
            return;
        }
        // Forward: y_b = D'_b⁻¹ r_b − (D'_b⁻¹ L_b) y_{b−1}.
        let x = &mut rhs[r.clone()];
        let (inv, inv_lower) = (&self.inv[r.clone()], &self.inv_lower[r.clone()]);
        x[0] = mat_vec(&inv[0], &x[0]);
        for b in 1..x.len() {
            x[b] = mat_vec(&inv[b], &x[b]) - mat_vec(&inv_lower[b], &x[b - 1]);
        }
        // Backward: x_b = y_b − (D'_b⁻¹ U_b) x_{b+1}.
        let elim = &self.elim[r];
        for b in (0..x.len() - 1).rev() {
            x[b] -= mat_vec(&elim[b], &x[b + 1]);
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

/// m x with the sum split in three independent pairs of columns (the substitutions are
/// latency-bound: this halves the dependency chain of a product).
#[inline(always)]
fn mat_vec(m: &Block, x: &Vector6<f64>) -> Vector6<f64> {
    let c = m.as_slice();
    let (mut a, mut b, mut d) = ([0.0; 6], [0.0; 6], [0.0; 6]);
    for i in 0..6 {
        a[i] = c[i] * x[0] + c[6 + i] * x[1];
        b[i] = c[12 + i] * x[2] + c[18 + i] * x[3];
        d[i] = c[24 + i] * x[4] + c[30 + i] * x[5];
    }
    for i in 0..6 {
        a[i] += b[i] + d[i];
    }
    Vector6::from(a)
}

/// Relative size of a pivot against its column's scale below which the block is singular.
const SINGULAR_PIVOT: f64 = 1e-13;

/// LU factorisation of a 6×6 block in place (partial pivoting): returns the row interchanges and
/// the reciprocals of U's diagonal; a pivot below `SINGULAR_PIVOT` of its column's `scale` (or
/// not finite) is an error.
#[inline]
fn lu_in_place(a: &mut Block, scale: &[f64; 6]) -> Result<([u8; 6], [f64; 6]), ()> {
    let mut piv = [0u8; 6];
    let mut inv = [0.0; 6];
    for k in 0..6 {
        let mut p = k;
        let mut max = a[(k, k)].abs();
        for i in k + 1..6 {
            let v = a[(i, k)].abs();
            if v > max {
                max = v;
                p = i;
            }
        }
        piv[k] = p as u8;
        if p != k {
            a.swap_rows(k, p);
        }
        let d = a[(k, k)];
        if d.abs() <= SINGULAR_PIVOT * scale[k] || !d.is_finite() {
            return Err(());
        }
        let r = 1.0 / d;
        inv[k] = r;
        for i in k + 1..6 {
            a[(i, k)] *= r;
        }
        for j in k + 1..6 {
            let akj = a[(k, j)];
            for i in k + 1..6 {
                a[(i, j)] -= a[(i, k)] * akj;
            }
        }
    }
    Ok((piv, inv))
}

/// X ← A⁻¹ X (6 columns) with the factors of `lu_in_place`.
#[inline]
fn lu_solve_matrix(lu: &Block, piv: &[u8; 6], inv: &[f64; 6], x: &mut Block) {
    for (k, &p) in piv.iter().enumerate() {
        if p as usize != k {
            x.swap_rows(k, p as usize);
        }
    }
    for j in 0..6 {
        for k in 0..6 {
            let xk = x[(k, j)];
            for i in k + 1..6 {
                x[(i, j)] -= lu[(i, k)] * xk;
            }
        }
        for k in (0..6).rev() {
            let xk = x[(k, j)] * inv[k];
            x[(k, j)] = xk;
            for i in 0..k {
                x[(i, j)] -= lu[(i, k)] * xk;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inertia_counts_the_negative_eigenvalues() {
        // A symmetric block-tridiagonal matrix with known spectrum: the 1D Laplacian (2, −1)
        // of size 6n in blocks, eigenvalues 2 − 2 cos(kπ/(6n+1)), shifted by σ.
        let n = 5;
        let size = 6 * n;
        let mut j = BlockTridiag::new(n);
        for i in 0..size {
            let (b, k) = (i / 6, i % 6);
            j.diag[b][(k, k)] = 2.0;
            if i + 1 < size {
                let (c, l) = ((i + 1) / 6, (i + 1) % 6);
                if c == b {
                    j.diag[b][(k, l)] = -1.0;
                    j.diag[b][(l, k)] = -1.0;
                } else {
                    j.upper[b][(k, l)] = -1.0;
                    j.lower[c][(l, k)] = -1.0;
                }
            }
        }
        let eig: Vec<f64> = (1..=size)
            .map(|k| 2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (size as f64 + 1.0)).cos())
            .collect();
        for sigma in [-0.5, 0.005, 0.3, 1.0, 1.77, 2.5, 3.99, 4.5] {
            let mut a = j.clone();
            for b in 0..n {
                a.diag[b] -= Block::identity() * sigma;
            }
            let expected = eig.iter().filter(|&&l| l < sigma).count();
            assert_eq!(a.inertia(0..n).unwrap(), expected, "σ = {sigma}");
            // and the factorisation solves
            let x: Vec<Vector6<f64>> = (0..n)
                .map(|b| Vector6::from_fn(|k, _| (b * 6 + k) as f64))
                .collect();
            let mut rhs = vec![Vector6::zeros(); n];
            a.mul(&x, &mut rhs);
            a.solve_range(0..n, &mut rhs);
            for b in 0..n {
                assert!(
                    (rhs[b] - x[b]).norm() < 1e-9 * x[b].norm().max(1.0),
                    "σ = {sigma}"
                );
            }
        }
        // σ on an eigenvalue of a pivot: singular
        let mut a = BlockTridiag::new(1);
        a.diag[0] = Block::identity();
        a.diag[0][(2, 2)] = 0.0;
        assert_eq!(a.inertia(0..1), Err(Singular { block: 0 }));
    }

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
        // Two independent systems: decouple blocks 2 and 3, solve each part on its own.
        j.upper[2].fill(0.0);
        j.lower[3].fill(0.0);
        j.mul(&x, &mut rhs);
        j.factor_range(0..3).unwrap();
        j.factor_range(3..n).unwrap();
        j.solve_range(3..n, &mut rhs);
        j.solve_range(0..3, &mut rhs);
        for b in 0..n {
            assert!((rhs[b] - x[b]).norm() < 1e-12);
        }
    }
}
