//! The signed distance of a union of capsules sampled on a voxel grid, narrow-band truncated.
//!
//! The grid is cut into bricks of at most 4 × 4 × 4 voxels. For each brick one exact distance
//! query at its centre bounds the field over the whole brick (the field is 1-Lipschitz):
//! bricks wholly outside the band are filled with +band, bricks wholly deeper than the band
//! with −band, and only the capsules that can come within the band (or below the brick's upper
//! bound) are gathered — sorted by their lower bound, so each voxel stops at the first capsule
//! that cannot beat its current minimum. Cost grows with the surface, not voxels × capsules.
//! Slabs of bricks run in parallel (rayon); buffers are per slab, never per voxel.

use rayon::prelude::*;

use super::capsules::{Aabb, Capsules, InputError, Vec3};

/// A regular grid: voxel (i, j, k) is the point origin + spacing · (i, j, k); values are
/// stored in C order (k fastest).
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    pub origin: Vec3,
    pub spacing: f64,
    pub shape: [usize; 3],
}

/// The most voxels one grid may have (4 GiB of f32).
pub const MAX_VOXELS: usize = 1 << 30;

const BRICK: usize = 4;

impl Grid {
    /// Checks the grid and returns the number of voxels.
    pub fn validate(&self) -> Result<usize, InputError> {
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(InputError(format!(
                "spacing = {}: must be a finite number > 0",
                self.spacing
            )));
        }
        if self.origin.iter().any(|x| !x.is_finite()) {
            return Err(InputError(format!(
                "origin = {:?}: must be 3 finite numbers",
                self.origin
            )));
        }
        let n = self
            .shape
            .iter()
            .try_fold(1usize, |acc, &s| acc.checked_mul(s))
            .filter(|&n| n <= MAX_VOXELS);
        match n {
            Some(n) if self.shape.iter().all(|&s| s > 0) => Ok(n),
            _ => Err(InputError(format!(
                "shape = {:?}: every size must be > 0 and the product at most {MAX_VOXELS} \
                 (use a coarser voxel)",
                self.shape
            ))),
        }
    }

    #[inline]
    fn point(&self, i: usize, j: usize, k: usize) -> Vec3 {
        [
            self.origin[0] + self.spacing * i as f64,
            self.origin[1] + self.spacing * j as f64,
            self.origin[2] + self.spacing * k as f64,
        ]
    }
}

/// The signed distance to the union of `capsules` at every voxel of `grid`, clamped to
/// [−band, band] (exact wherever its magnitude is below `band`).
pub fn signed_distance(
    capsules: &Capsules,
    grid: &Grid,
    band: f64,
) -> Result<Vec<f32>, InputError> {
    let n = grid.validate()?;
    if !(band.is_finite() && band > 0.0) {
        return Err(InputError(format!(
            "band = {band}: must be a finite number > 0"
        )));
    }
    let [nx, ny, nz] = grid.shape;
    let mut out = vec![band as f32; n];
    if capsules.is_empty() {
        return Ok(out);
    }
    // Slabs along axis 0: thinner than a brick when there are too few to keep all threads busy.
    let want = 4 * rayon::current_num_threads();
    let thickness = (nx / want).clamp(1, BRICK);
    out.par_chunks_mut(thickness * ny * nz)
        .enumerate()
        .for_each(|(slab, values)| {
            let i0 = slab * thickness;
            let ti = values.len() / (ny * nz);
            let mut candidates: Vec<(f64, u32)> = Vec::new();
            for j0 in (0..ny).step_by(BRICK) {
                for k0 in (0..nz).step_by(BRICK) {
                    let tj = BRICK.min(ny - j0);
                    let tk = BRICK.min(nz - k0);
                    fill_brick(
                        capsules,
                        grid,
                        band,
                        [i0, j0, k0],
                        [ti, tj, tk],
                        values,
                        &mut candidates,
                    );
                }
            }
        });
    Ok(out)
}

/// Fills the voxels of one brick (`start` and `size` in voxels) in the slab `values`, which
/// begins at voxel row `start[0]`.
fn fill_brick(
    capsules: &Capsules,
    grid: &Grid,
    band: f64,
    start: [usize; 3],
    size: [usize; 3],
    values: &mut [f32],
    candidates: &mut Vec<(f64, u32)>,
) {
    let [_, ny, nz] = grid.shape;
    let h = grid.spacing;
    let lo = grid.point(start[0], start[1], start[2]);
    let hi = grid.point(
        start[0] + size[0] - 1,
        start[1] + size[1] - 1,
        start[2] + size[2] - 1,
    );
    let cell = Aabb { lo, hi };
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let half_diagonal =
        0.5 * ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    // Exact up to band + half diagonal: enough to decide the whole brick.
    let d_centre = capsules.distance_below(centre, band + half_diagonal + h);
    let uniform = if d_centre - half_diagonal >= band {
        Some(band)
    } else if d_centre + half_diagonal <= -band {
        Some(-band)
    } else {
        None
    };
    let set = |values: &mut [f32], f: &mut dyn FnMut(Vec3) -> f32| {
        for di in 0..size[0] {
            for dj in 0..size[1] {
                let row = (di * ny + start[1] + dj) * nz + start[2];
                for dk in 0..size[2] {
                    let p = grid.point(start[0] + di, start[1] + dj, start[2] + dk);
                    values[row + dk] = f(p);
                }
            }
        }
    };
    if let Some(v) = uniform {
        set(values, &mut |_| v as f32);
        return;
    }
    // No voxel of the brick is above d_centre + half_diagonal, nor needs more than band.
    let limit = band.min(d_centre + half_diagonal) + 1e-12;
    candidates.clear();
    capsules.gather(&cell, limit, candidates);
    candidates.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    set(values, &mut |p| {
        let mut best = band;
        for &(lower, i) in candidates.iter() {
            if lower >= best {
                break;
            }
            best = best.min(capsules.capsule_distance(i as usize, p));
            if best <= -band {
                best = -band;
                break;
            }
        }
        best as f32
    });
}
