//! Clearance of cables over saved steps against parts moving rigidly with their bodies.
//!
//! The parts are given in their body's reference frame; per step, each body's [`RigidMap`]
//! takes the cable's nodes (global) into that frame: one transform per body and step instead
//! of moving meshes. Per node i the clearance is
//!   c_i = min(sd(x_i), d(half-edges at x_i)) − radius   when sd(x_i) ≥ 0,
//!   c_i = sd(x_i) − radius                              when the node is inside,
//! with sd the signed distance to the nearest part and d the unsigned distance of the two
//! half-edges [x_i, (x_{i−1} + x_i)/2] and [x_i, (x_i + x_{i+1})/2] (the capsule between two
//! nodes sees a corner that lies between them). Steps run in parallel in contiguous chunks so
//! that each node's query is warm-started with the feature found at the previous step.
use nalgebra::Matrix3;
use rayon::prelude::*;

use crate::{Candidates, Shape, Surface, V3};

/// Takes global points into a body's reference frame at one step: X = m x + v.
#[derive(Clone, Copy, Debug)]
pub struct RigidMap {
    pub m: Matrix3<f64>,
    pub v: V3,
}

impl RigidMap {
    pub fn identity() -> Self {
        RigidMap {
            m: Matrix3::identity(),
            v: V3::zeros(),
        }
    }

    #[inline]
    pub fn apply(&self, x: &V3) -> V3 {
        self.m * x + self.v
    }
}

/// A shape carried by body `body`, in the body's reference frame.
pub struct Part {
    pub shape: Shape,
    pub body: usize,
}

/// Clearance per step and node (row-major T × nodes) and the nearest part.
pub struct Clearance {
    pub value: Vec<f64>,
    pub part: Vec<u32>,
}

/// Clearance of one cable: `positions` (T × n_nodes, global), `maps[b * T + t]` the map of
/// body b at step t.
pub fn clearance(
    parts: &[Part],
    positions: &[V3],
    n_nodes: usize,
    radius: f64,
    maps: &[RigidMap],
) -> Result<Clearance, String> {
    if parts.is_empty() {
        return Err("no geometry to measure the clearance against".into());
    }
    if n_nodes == 0 || !positions.len().is_multiple_of(n_nodes) {
        return Err(format!(
            "{} positions are not a whole number of steps of {n_nodes} nodes",
            positions.len()
        ));
    }
    if positions.iter().any(|p| !p.iter().all(|x| x.is_finite())) {
        return Err("the cable positions contain non-finite values".into());
    }
    let n_steps = positions.len() / n_nodes;
    let n_bodies = parts.iter().map(|p| p.body + 1).max().unwrap_or(0);
    if maps.len() != n_bodies * n_steps {
        return Err(format!(
            "{} body maps given, {n_bodies} bodies × {n_steps} steps needed",
            maps.len()
        ));
    }
    let mut value = vec![0.0; positions.len()];
    let mut part = vec![0u32; positions.len()];
    let threads = rayon::current_num_threads().max(1);
    let chunk_steps = n_steps.div_ceil(4 * threads).max(1);
    let chunk = chunk_steps * n_nodes;
    value
        .par_chunks_mut(chunk)
        .zip(part.par_chunks_mut(chunk))
        .enumerate()
        .for_each(|(k, (val, prt))| {
            let first = k * chunk_steps;
            // per node and part: the feature nearest to the node, to its two half-edges
            let mut hints = vec![usize::MAX; 3 * n_nodes * parts.len()];
            // per node and mesh part: candidate sets of the node and of its half-edges
            let mut sets = vec![(Candidates::new(), Candidates::new()); n_nodes * parts.len()];
            let mut dist = vec![f64::INFINITY; parts.len()];
            let mut local = vec![V3::zeros(); n_bodies * n_nodes];
            for (j, (vrow, prow)) in val
                .chunks_mut(n_nodes)
                .zip(prt.chunks_mut(n_nodes))
                .enumerate()
            {
                let t = first + j;
                let x = &positions[t * n_nodes..(t + 1) * n_nodes];
                for b in 0..n_bodies {
                    let map = &maps[b * n_steps + t];
                    for (l, p) in local[b * n_nodes..(b + 1) * n_nodes].iter_mut().zip(x) {
                        *l = map.apply(p);
                    }
                }
                step(
                    parts, &local, n_nodes, radius, &mut hints, &mut sets, &mut dist, vrow, prow,
                );
            }
        });
    Ok(Clearance { value, part })
}

/// Clearance of the nodes of one step. `dist`: scratch, per part the node's distance. A
/// half-edge is queried only if it can come nearer than the best so far: the distance is
/// 1-Lipschitz, so on a half-edge of reach ℓ from the node it is at least d(node) − ℓ.
#[allow(clippy::too_many_arguments)]
fn step(
    parts: &[Part],
    local: &[V3],
    n: usize,
    radius: f64,
    hints: &mut [usize],
    sets: &mut [(Candidates, Candidates)],
    dist: &mut [f64],
    value: &mut [f64],
    part: &mut [u32],
) {
    let n_parts = parts.len();
    for i in 0..n {
        let mut best = f64::INFINITY;
        let mut nearest = 0usize;
        for (k, pt) in parts.iter().enumerate() {
            let x = &local[pt.body * n + i];
            let h = &mut hints[3 * (i * n_parts + k)];
            dist[k] = f64::INFINITY;
            let found = match &pt.shape {
                Shape::Mesh(mesh) => sets[i * n_parts + k].0.project_point(mesh, x, *h),
                shape => shape.project_point(x, f64::INFINITY, *h),
            };
            if let Some(r) = found {
                *h = r.feature;
                dist[k] = r.distance;
                if r.distance < best {
                    best = r.distance;
                    nearest = k;
                }
            }
        }
        if best > 0.0 {
            for (k, pt) in parts.iter().enumerate() {
                let base = pt.body * n;
                let x = &local[base + i];
                let at = 3 * (i * n_parts + k);
                // the half-edges that can come nearer than the best so far
                let mut ends = [V3::zeros(); 2];
                let mut sides = [0usize; 2];
                let mut m = 0;
                for (side, nb) in [i.wrapping_sub(1), i + 1].into_iter().enumerate() {
                    if nb >= n {
                        continue;
                    }
                    let mid = (x + local[base + nb]) * 0.5;
                    if dist[k] - (mid - x).norm() >= best {
                        continue; // cannot come nearer than the best so far
                    }
                    ends[m] = mid;
                    sides[m] = side;
                    m += 1;
                }
                if let Shape::Mesh(mesh) = &pt.shape {
                    // both half-edges in one traversal; warm start: the triangle nearest to
                    // them at the previous step, else the node's
                    // (all of the node's half-edges: the candidate set is theirs)
                    if m == 0 {
                        continue;
                    }
                    let mut all = [V3::zeros(); 2];
                    let mut m = 0;
                    for nb in [i.wrapping_sub(1), i + 1] {
                        if nb < n {
                            all[m] = (x + local[base + nb]) * 0.5;
                            m += 1;
                        }
                    }
                    let h = match hints[at + 1] {
                        usize::MAX => hints[at],
                        h => h,
                    };
                    let set = &mut sets[i * n_parts + k].1;
                    if let Some((d, _, t)) = set.nearest_of_segments(mesh, x, &all[..m], best, h) {
                        hints[at + 1] = t;
                        if d < best {
                            best = d;
                            nearest = k;
                        }
                    }
                    continue;
                }
                for (mid, side) in ends[..m].iter().zip(&sides) {
                    // warm start: this half-edge's feature at the previous step, else the node's
                    let h = match hints[at + 1 + side] {
                        usize::MAX => hints[at],
                        h => h,
                    };
                    if let Some(s) = pt.shape.closest_to_segment(x, mid, best, h) {
                        hints[at + 1 + side] = s.feature;
                        if s.distance < best {
                            best = s.distance;
                            nearest = k;
                        }
                    }
                }
            }
        }
        value[i] = best - radius;
        part[i] = nearest as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{HalfSpace, Sphere};

    #[test]
    fn moving_plane_and_half_edges() {
        let parts = vec![
            Part {
                shape: Shape::HalfSpace(HalfSpace::new(V3::zeros(), V3::z())),
                body: 0,
            },
            Part {
                shape: Shape::Sphere(Sphere {
                    center: V3::new(0.5, 0.3, 0.5),
                    radius: 0.1,
                }),
                body: 1,
            },
        ];
        // a straight cable at z = 0.5 along x, nodes at x = 0, 1 (the sphere between them)
        let pos = vec![V3::new(0.0, 0.0, 0.5), V3::new(1.0, 0.0, 0.5)];
        let steps = 3;
        let positions: Vec<V3> = (0..steps).flat_map(|_| pos.clone()).collect();
        // body 0 (the plane) rises by 0.2 per step: x_ref = x − u
        let mut maps = vec![];
        for t in 0..steps {
            let mut m = RigidMap::identity();
            m.v = V3::new(0.0, 0.0, -0.2 * t as f64);
            maps.push(m);
        }
        maps.extend((0..steps).map(|_| RigidMap::identity()));
        let c = clearance(&parts, &positions, 2, 0.01, &maps).unwrap();
        // step 0: plane 0.5 away, sphere surface 0.3 − 0.1 = 0.2 from the half-edge ends at x = 0.5
        assert!((c.value[0] - (0.2 - 0.01)).abs() < 1e-15);
        assert_eq!(c.part[0], 1);
        // step 2: the plane at z = 0.4 is nearer, reached by the node itself
        assert!(
            (c.value[4] - (0.5 - 0.4 - 0.01)).abs() < 1e-15,
            "{}",
            c.value[4]
        );
        assert_eq!(c.part[4], 0);
    }

    #[test]
    fn coherent_steps_equal_cold_steps() {
        // a slowly moving cable over a bumpy mesh (candidate sets kept over steps), with one
        // node jumping far at one step: every step equals the step computed alone (cold: no
        // warm start, no set)
        use crate::TriMesh;
        let n = 30;
        let h = |x: f64, y: f64| 0.05 * (x * 7.0).sin() * (y * 5.0).cos();
        let mut v = vec![];
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                v.push(V3::new(x, y, h(x, y)));
            }
        }
        let mut f = vec![];
        for i in 0..n {
            for j in 0..n {
                let a = (i * (n + 1) + j) as u32;
                let (b, c, d) = (a + n as u32 + 1, a + 1, a + n as u32 + 2);
                f.push([a, b, d]);
                f.push([a, d, c]);
            }
        }
        let parts = vec![Part {
            shape: Shape::Mesh(TriMesh::new(&v, &f).unwrap()),
            body: 0,
        }];
        let (steps, nodes) = (200, 8);
        let mut positions = vec![];
        for t in 0..steps {
            for i in 0..nodes {
                let s = t as f64 * 1e-5;
                let (x, y) = (0.1 + 0.1 * i as f64 + s, 0.4 + 0.03 * i as f64 - s);
                let mut p = V3::new(x, y, h(x, y) + 0.04 + 2e-4 * (t as f64 * 0.1).sin());
                if i == 3 && t == 120 {
                    p.z += 0.5;
                }
                positions.push(p);
            }
        }
        let maps = vec![RigidMap::identity(); steps];
        let c = clearance(&parts, &positions, nodes, 0.005, &maps).unwrap();
        for t in 0..steps {
            let one = &positions[t * nodes..(t + 1) * nodes];
            let cold = clearance(&parts, one, nodes, 0.005, &maps[t..t + 1]).unwrap();
            assert_eq!(cold.value, c.value[t * nodes..(t + 1) * nodes], "step {t}");
        }
    }
}
