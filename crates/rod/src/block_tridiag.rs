//! Block-tridiagonal matrices with 6×6 blocks and their O(N) solve (block Thomas algorithm; the
//! pivot blocks are LU-factored in place with partial pivoting). Storage is allocated once;
//! factor and solve do not allocate.
use nalgebra::{Matrix3, Matrix6, SymmetricEigen, Vector6};
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
    /// The block and eigenvector of the most negative pivot eigenvalue of the last `ldlt`.
    negative_pivot: Option<(usize, Vector6<f64>)>,
}

/// Inertia of a symmetric matrix (the counts of its eigenvalue signs); `zero` counts pivots
/// below the round-off of their block (`ZERO_PIVOT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Inertia {
    pub negative: usize,
    pub zero: usize,
}

/// Relative size (to the largest diagonal entry of its block before the elimination) below
/// which an eigenvalue of a pivot block counts as zero.
pub const ZERO_PIVOT: f64 = 1e-11;

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
            negative_pivot: None,
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
        self.factor_range_dir(r, false)
    }

    /// `factor_range` eliminating from the first block to the last (`rev` false: block LU) or
    /// from the last to the first (`rev` true: block UL, so that the first block's pivot
    /// carries the whole range and a coupling at the range's start reaches a Schur complement
    /// through the first two blocks alone, `solve_tail`). `inv_lower` holds D'⁻¹ times the
    /// coupling to the block eliminated before (the in-sweep), `elim` D'⁻¹ times the coupling
    /// to the one eliminated after (the out-sweep).
    pub fn factor_range_dir(&mut self, r: Range<usize>, rev: bool) -> Result<(), Singular> {
        let n = r.len();
        for k in 0..n {
            let b = if rev { r.end - 1 - k } else { r.start + k };
            // Couplings to the blocks eliminated before and after b.
            let (before, after) = if rev {
                (&self.upper[b], &self.lower[b])
            } else {
                (&self.lower[b], &self.upper[b])
            };
            let mut d = self.diag[b];
            if k > 0 {
                let prev = if rev { b + 1 } else { b - 1 };
                d -= mul6(before, &self.elim[prev]);
            }
            let inv = self.pivot_inverse(b, d)?;
            self.inv[b] = inv;
            if k > 0 {
                self.inv_lower[b] = mul6(&inv, before);
            }
            if k + 1 < n {
                self.elim[b] = mul6(&inv, after);
            }
        }
        Ok(())
    }

    /// The inverse of pivot block `d` (block b after the elimination). Pivots are judged
    /// against their column of D_b before the elimination: a stiffness small against the others
    /// of the block (EI ≪ GA Δs²) is not a singularity, a pivot cancelled to round-off by the
    /// elimination (a free mode) is.
    fn pivot_inverse(&self, b: usize, mut d: Block) -> Result<Block, Singular> {
        let mut scale = [0.0; 6];
        for (k, c) in scale.iter_mut().enumerate() {
            *c = self.diag[b].column(k).amax();
        }
        let (piv, inv_diag) = lu_in_place(&mut d, &scale).map_err(|_| Singular { block: b })?;
        let mut inv = Block::identity();
        lu_solve_matrix(&d, &piv, &inv_diag, &mut inv);
        Ok(inv)
    }

    /// Symmetric block LDLᵀ factorisation of the symmetric part ½(J + Jᵀ) of the blocks `r`
    /// and its inertia — the one inertia code of the crate (stability of an equilibrium, Sturm
    /// counts of the modal solver; a tree solver counts the negative pivots of its own
    /// elimination the same way, with `pivot_inertia`).
    ///
    /// H = L D Lᵀ with D = diag(S_b), S_b = H_bb − H_b,b−1 S_{b−1}⁻¹ H_b−1,b, and by
    /// Sylvester's law of inertia inertia(H) = Σ inertia(S_b). With H = K − σM it is the Sturm
    /// count: the number of eigenvalues of K φ = λ M φ below σ. A pivot block is first
    /// Cholesky-factored (hand-written 6×6 kernel: the hot path of the stability check); only
    /// if that fails are its eigenvalues computed. A pivot eigenvalue below `ZERO_PIVOT` of the
    /// largest diagonal entry of its block before the elimination counts as zero (and its
    /// direction is dropped: pseudo-inverse). Afterwards `solve_range` solves with the
    /// symmetric part (meaningful when `zero` is 0), and `negative_direction` gives a direction
    /// of negative curvature. The matrix blocks are read, not changed. No allocation.
    pub fn ldlt(&mut self, r: Range<usize>) -> Inertia {
        self.symmetric_factor(r, true)
    }

    /// The inertia of `ldlt` without keeping what `solve_range` needs (the pivot inverses):
    /// the stability check, 1.6× cheaper (`examples/bench_assembly`). `negative_direction`
    /// works after it; a solve needs `ldlt` or `factor_range`.
    pub fn inertia(&mut self, r: Range<usize>) -> Inertia {
        self.symmetric_factor(r, false)
    }

    fn symmetric_factor(&mut self, r: Range<usize>, for_solve: bool) -> Inertia {
        let mut out = Inertia::default();
        self.negative_pivot = None;
        let mut worst = 0.0f64;
        // H_{b−1,b} (symmetric part) of the previous block: H_{b,b−1} is its transpose.
        let mut prev_upper = Block::zeros();
        for b in r.clone() {
            let d = &self.diag[b];
            let mut s = 0.5 * (d + d.transpose());
            // Scales before the Schur update: the size of its round-off, per slot and per block
            // (units differ between slots: positions and rotations).
            let tiny = s.diagonal().map(|v| ZERO_PIVOT * v.abs());
            let scale = s.diagonal().amax().max(1e-300);
            if b > r.start {
                s -= mul6(&prev_upper.transpose(), &self.elim[b - 1]);
                s = 0.5 * (s + s.transpose());
            }
            let upper = if b + 1 < r.end {
                0.5 * (self.upper[b] + self.lower[b + 1].transpose())
            } else {
                Block::zeros()
            };
            let mut l = s;
            let inv = if cholesky_in_place(&mut l, &tiny) {
                // S⁻¹H_{b,b+1} by substitution, not by the product with S⁻¹: the Schur
                // complements of a stiff rod cancel to the soft eigenvalues (1e-10 of their
                // block), and the product's round-off, ε·cond(S) larger, would hide them.
                if b + 1 < r.end {
                    self.elim[b] = upper;
                    cholesky_solve(&l, &mut self.elim[b]);
                }
                if !for_solve {
                    prev_upper = upper;
                    continue;
                }
                let mut inv = Block::identity();
                cholesky_solve(&l, &mut inv);
                inv
            } else {
                let (inv, pivot) = pivot_inertia(&s, scale, &mut out);
                if let Some((lam, v)) = pivot {
                    if -lam / scale > worst {
                        worst = -lam / scale;
                        self.negative_pivot = Some((b, v));
                    }
                }
                if b + 1 < r.end {
                    self.elim[b] = mul6(&inv, &upper);
                }
                inv
            };
            if for_solve {
                self.inv[b] = inv;
                if b > r.start {
                    self.inv_lower[b] = mul6(&inv, &prev_upper.transpose());
                }
            }
            prev_upper = upper;
        }
        out
    }

    /// A direction z of negative curvature (zᵀHz < 0) from the last `ldlt` over `r`, in the
    /// block layout of the unknowns: Lᵀz = e_n v with v the eigenvector of the most negative
    /// pivot eigenvalue (relative to its block), so zᵀHz = vᵀS_n v < 0. Returns false (and
    /// leaves `z` alone) if there was none.
    pub fn negative_direction(&self, r: Range<usize>, z: &mut [Vector6<f64>]) -> bool {
        let Some((n, v)) = self.negative_pivot else {
            return false;
        };
        for b in r.clone() {
            z[b].fill(0.0);
        }
        z[n] = v;
        for b in (r.start..n).rev() {
            z[b] = -(self.elim[b] * z[b + 1]);
        }
        true
    }

    /// Solves J x = rhs in place with the current factorisation.
    pub fn solve_factored(&self, rhs: &mut [Vector6<f64>]) {
        self.solve_range(0..self.n_blocks(), rhs);
    }

    /// Solves the system of blocks `r` (factored by `factor_range`) in place; `rhs` holds all
    /// blocks, only those in `r` are used and changed.
    pub fn solve_range(&self, r: Range<usize>, rhs: &mut [Vector6<f64>]) {
        self.solve_range_dir(r, false, rhs);
    }

    /// `solve_range` with the factors of `factor_range_dir`.
    pub fn solve_range_dir(&self, r: Range<usize>, rev: bool, rhs: &mut [Vector6<f64>]) {
        self.sweep_in(r.clone(), rev, rhs);
        self.sweep_out(r, rev, rhs);
    }

    /// The first half of a solve with the factors of `factor_range_dir`, towards the block
    /// eliminated last:
    /// y_b = D'_b⁻¹ r_b − (D'_b⁻¹ L_b) y_{b−1} (reversed: U_b and y_{b+1}).
    pub fn sweep_in(&self, r: Range<usize>, rev: bool, rhs: &mut [Vector6<f64>]) {
        if r.is_empty() {
            return;
        }
        let x = &mut rhs[r.clone()];
        let (inv, inv_lower) = (&self.inv[r.clone()], &self.inv_lower[r]);
        let n = x.len();
        if rev {
            x[n - 1] = mat_vec(&inv[n - 1], &x[n - 1]);
            for b in (0..n - 1).rev() {
                x[b] = mat_vec(&inv[b], &x[b]) - mat_vec(&inv_lower[b], &x[b + 1]);
            }
        } else {
            x[0] = mat_vec(&inv[0], &x[0]);
            for b in 1..n {
                x[b] = mat_vec(&inv[b], &x[b]) - mat_vec(&inv_lower[b], &x[b - 1]);
            }
        }
    }

    /// The second half, from the block eliminated last back: x_b = y_b − (D'_b⁻¹ U_b) x_{b+1}
    /// (reversed: L_b and x_{b−1}).
    pub fn sweep_out(&self, r: Range<usize>, rev: bool, rhs: &mut [Vector6<f64>]) {
        if r.is_empty() {
            return;
        }
        let x = &mut rhs[r.clone()];
        let elim = &self.elim[r];
        if rev {
            for b in 1..x.len() {
                x[b] -= mat_vec(&elim[b], &x[b - 1]);
            }
        } else {
            for b in (0..x.len() - 1).rev() {
                x[b] -= mat_vec(&elim[b], &x[b + 1]);
            }
        }
    }

    /// The block eliminated last in `r` and the one before it (`r` of at least two blocks).
    pub fn tail_blocks(r: &Range<usize>, rev: bool) -> (usize, usize) {
        if rev {
            (r.start, r.start + 1)
        } else {
            (r.end - 1, r.end - 2)
        }
    }

    /// The solution at the tail (`tail_blocks`) from the in-sweep `y` there: x_last = y_last,
    /// x_prev = y_prev − E_prev x_last.
    pub fn tail_of(
        &self,
        r: &Range<usize>,
        rev: bool,
        y: &[Vector6<f64>],
    ) -> (Vector6<f64>, Vector6<f64>) {
        let (last, prev) = Self::tail_blocks(r, rev);
        (y[last], y[prev] - mat_vec(&self.elim[prev], &y[last]))
    }

    /// The in-sweep of a right-hand side that is zero outside the tail (`u_last`, `u_prev`
    /// there): its values at the tail, O(1).
    pub fn sweep_in_tail(
        &self,
        r: &Range<usize>,
        rev: bool,
        u_last: &Vector6<f64>,
        u_prev: &Vector6<f64>,
    ) -> (Vector6<f64>, Vector6<f64>) {
        let (last, prev) = Self::tail_blocks(r, rev);
        let w_prev = mat_vec(&self.inv[prev], u_prev);
        let w_last = mat_vec(&self.inv[last], u_last) - mat_vec(&self.inv_lower[last], &w_prev);
        (w_last, w_prev)
    }

    /// X = A⁻¹ B at the tail for a block column B that is zero outside it (`b_last`,
    /// `b_prev` there): the Schur complement of a coupling at the tail, O(1).
    pub fn solve_tail(
        &self,
        r: &Range<usize>,
        rev: bool,
        b_last: &Block,
        b_prev: &Block,
    ) -> (Block, Block) {
        let (last, prev) = Self::tail_blocks(r, rev);
        let y_prev = mul6(&self.inv[prev], b_prev);
        let x_last = mul6(&self.inv[last], b_last) - mul6(&self.inv_lower[last], &y_prev);
        (x_last, y_prev - mul6(&self.elim[prev], &x_last))
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

/// A B of two blocks on column-major arrays (nalgebra's generic product took twice the
/// instructions in the factorisation); the sums in nalgebra's order (k = 0, 1, …), so the
/// result is the same to the last bit.
#[inline(always)]
fn mul6(a: &Block, b: &Block) -> Block {
    let (a, b) = (a.as_slice(), b.as_slice());
    let mut c = [0.0; 36];
    for j in 0..6 {
        let bj = &b[6 * j..6 * j + 6];
        let cj = &mut c[6 * j..6 * j + 6];
        for i in 0..6 {
            cj[i] = a[i] * bj[0];
        }
        for k in 1..6 {
            let ak = &a[6 * k..6 * k + 6];
            for i in 0..6 {
                cj[i] += ak[i] * bj[k];
            }
        }
    }
    Block::from_column_slice(&c)
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

/// Inertia of one symmetric pivot block `s` of a block elimination, added to `out`, from its
/// eigenvalues (an eigenvalue within `ZERO_PIVOT · scale` of zero counts as zero); returns the
/// pseudo-inverse of `s` (zero directions dropped: they couple nothing onward) and the most
/// negative eigenvalue with its eigenvector, if any. For a block LDLᵀ of any structure (a
/// chain here, a tree elsewhere): the inertia of the matrix is the sum over its pivots.
pub fn pivot_inertia(
    s: &Block,
    scale: f64,
    out: &mut Inertia,
) -> (Block, Option<(f64, Vector6<f64>)>) {
    let eig = SymmetricEigen::new(*s);
    let mut inv = Block::zeros();
    let mut most_negative: Option<(f64, Vector6<f64>)> = None;
    for k in 0..6 {
        let lam = eig.eigenvalues[k];
        let v = eig.eigenvectors.column(k);
        if lam.is_nan() || lam.abs() <= ZERO_PIVOT * scale {
            out.zero += 1;
            continue;
        }
        if lam < 0.0 {
            out.negative += 1;
            if most_negative.is_none_or(|(l, _)| lam < l) {
                most_negative = Some((lam, v.into_owned()));
            }
        }
        inv += v * v.transpose() / lam;
    }
    (inv, most_negative)
}

/// Cholesky factor L (lower triangle, in place) of a symmetric 6×6 block; false if the pivot of
/// slot j is not above `tiny[j]` (not positive definite, or nearly singular). Hand-written: it
/// is the hot path of the stability check (nalgebra's generic Cholesky and solve cost 2× more
/// here).
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
            assert_eq!(
                a.ldlt(0..n),
                Inertia {
                    negative: expected,
                    zero: 0
                },
                "σ = {sigma}"
            );
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
        // σ on an eigenvalue of a pivot: a zero pivot
        let mut a = BlockTridiag::new(1);
        a.diag[0] = Block::identity();
        a.diag[0][(2, 2)] = 0.0;
        assert_eq!(
            a.ldlt(0..1),
            Inertia {
                negative: 0,
                zero: 1
            }
        );
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

    /// Both directions of the elimination solve a random system; the tail operations equal
    /// a full solve there (a right-hand side zero outside the tail, as a junction's coupling).
    #[test]
    fn reversed_elimination_and_tail_solves_match_full_solves() {
        let n = 8;
        let mut seed = 11u64;
        let mut j = BlockTridiag::new(n);
        for b in 0..n {
            j.diag[b] = Block::from_fn(|_, _| rnd(&mut seed)) + Block::identity() * 4.0;
            j.lower[b] = Block::from_fn(|_, _| rnd(&mut seed));
            j.upper[b] = Block::from_fn(|_, _| rnd(&mut seed));
        }
        let x: Vec<Vector6<f64>> = (0..n)
            .map(|_| Vector6::from_fn(|_, _| rnd(&mut seed)))
            .collect();
        let mut rhs = vec![Vector6::zeros(); n];
        j.mul(&x, &mut rhs);
        let r = 1..n - 1; // a range inside: its coupling blocks to the rest are ignored
        let mut sub = j.clone();
        sub.lower[r.start].fill(0.0);
        sub.upper[r.end - 1].fill(0.0);
        let mut b = vec![Vector6::zeros(); n];
        sub.mul(&x, &mut b);
        for rev in [false, true] {
            j.factor_range_dir(r.clone(), rev).unwrap();
            let mut y = b.clone();
            j.sweep_in(r.clone(), rev, &mut y);
            let (t_last, t_prev) = j.tail_of(&r, rev, &y);
            j.sweep_out(r.clone(), rev, &mut y);
            for k in r.clone() {
                assert!((y[k] - x[k]).norm() < 1e-12, "rev {rev} block {k}");
            }
            let (last, prev) = BlockTridiag::tail_blocks(&r, rev);
            assert!((t_last - x[last]).norm() < 1e-12 && (t_prev - x[prev]).norm() < 1e-12);
            // A right-hand side (and a block column) zero outside the tail.
            let (u_last, u_prev) = (
                Vector6::from_fn(|_, _| rnd(&mut seed)),
                Vector6::from_fn(|_, _| rnd(&mut seed)),
            );
            let mut u = vec![Vector6::zeros(); n];
            u[last] = u_last;
            u[prev] = u_prev;
            let mut full = u.clone();
            j.sweep_in(r.clone(), rev, &mut full);
            let (w_last, w_prev) = j.sweep_in_tail(&r, rev, &u_last, &u_prev);
            assert!((w_last - full[last]).norm() < 1e-13 && (w_prev - full[prev]).norm() < 1e-13);
            j.sweep_out(r.clone(), rev, &mut full);
            let (bl, bp) = (
                Block::from_fn(|_, _| rnd(&mut seed)),
                Block::from_fn(|_, _| rnd(&mut seed)),
            );
            let (xl, xp) = j.solve_tail(&r, rev, &bl, &bp);
            for c in 0..6 {
                let mut col = vec![Vector6::zeros(); n];
                col[last] = bl.column(c).into();
                col[prev] = bp.column(c).into();
                j.solve_range_dir(r.clone(), rev, &mut col);
                assert!(
                    (xl.column(c) - col[last]).norm() < 1e-12,
                    "rev {rev} column {c}"
                );
                assert!((xp.column(c) - col[prev]).norm() < 1e-12);
            }
        }
    }

    #[test]
    fn block_product_equals_nalgebras_to_the_last_bit() {
        let mut seed = 3u64;
        for _ in 0..50 {
            let a = Block::from_fn(|_, _| rnd(&mut seed) * 1e3);
            let b = Block::from_fn(|_, _| rnd(&mut seed) * 1e-4);
            assert_eq!(mul6(&a, &b), a * b);
        }
    }

    fn rnd(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    /// A symmetric block-tridiagonal matrix with a prescribed spectrum shift: its inertia by
    /// the block LDLᵀ equals the count of negative eigenvalues of the dense matrix.
    #[test]
    fn ldlt_inertia_matches_the_dense_eigenvalues_of_the_symmetric_part() {
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
            let inertia = j.ldlt(0..n);
            assert_eq!(j.inertia(0..n), inertia, "the same factorisation");
            assert_eq!(inertia.negative, expected, "shift {shift}");
            assert_eq!(inertia.zero, 0);
            let mut z = vec![Vector6::zeros(); n];
            assert_eq!(j.negative_direction(0..n, &mut z), expected > 0);
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
