//! Temporal coherence of mesh queries over saved steps: a candidate set per query.
//!
//! Between saved steps a cable node moves little. For a query Q (a point, or segments from a
//! shared start) gathered at Q₀ with nearest distance d₀, keep every triangle within
//! d₀ + 2·margin of Q₀ with its distance δ. While every position of Q stays within `margin`
//! of Q₀ (moved ≤ margin; a segment moves no farther than its ends), the distance to any
//! triangle changes by at most `moved` (it is 1-Lipschitz), so the nearest triangle T* of Q
//! has δ(T*) ≤ d(Q) + moved ≤ d₀ + 2·moved: it is in the set, and the set answers exactly
//! (the same distances as the hierarchy, to the last bit). Scanned in order of δ, the set
//! stops at the first δ − moved above the best so far. When Q moves farther, the set is
//! gathered again (one traversal of the hierarchy, bounded by best + 2·margin).
//!
//! The margin follows the motion: `SKIN_STEPS` times the last step's displacement, so a set
//! lasts several steps of steady motion. The set grows with d·margin (more so under a
//! concave surface), the hierarchy's work with d alone: where that margin exceeds
//! `SKIN_OF_DISTANCE` of the distance, the query goes to the hierarchy (warm-started) and
//! no set is kept. Measured on the clearance benchmark's case (`clearance_profile -- 707 1000
//! DT`, one thread), after the hierarchy's bounds were tightened (session 19): with saved
//! steps 3 µs apart (nodes moving ~0.006 % of their distance per step) 0.165 s instead of
//! 0.244 s, at 10 µs 0.228 s instead of 0.242 s; from 30 µs (~0.06 %) on the sets no longer
//! pay, and a margin of 1 % of the distance (as before) made 100 µs 54 % slower: so sets only
//! where the margin is within 0.2 % of the distance. At the benchmark's 1 ms (2 % per step,
//! 60 Hz motion) every query goes to the hierarchy. Where many triangles
//! are nearly equally far (near the axis of a ring, under a concave surface) a set is long
//! even for a small margin: a set longer than `MAX_SET` halves the node's margin (in steps),
//! below `MIN_SKIN` steps the hierarchy answers and the margin grows back slowly.
use crate::{PointProjection, Surface, TriMesh, V3};

/// The margin in steps of the last displacement.
const SKIN_STEPS: f64 = 8.0;
/// A set longer than this costs more to scan than the hierarchy: the margin is halved for
/// the node's next set.
const MAX_SET: usize = 96;
/// Below this many steps of margin a set does not last: the hierarchy answers, and the
/// margin grows back slowly (by `REGROW` per query) to try a set again.
const MIN_SKIN: f64 = 2.0;
const REGROW: f64 = 1.02;
/// A set only where the margin is at most this fraction of the distance.
const SKIN_OF_DISTANCE: f64 = 0.002;

/// Candidate triangles of one query (a node, or its half-edges) on one mesh.
#[derive(Clone, Debug)]
pub struct Candidates {
    /// Positions when gathered (the start, then the ends) and their number (0: no set).
    at: [V3; 3],
    n_at: usize,
    /// Positions at the previous query and their number (0: none).
    last: [V3; 3],
    n_last: usize,
    /// Distance found by the previous query.
    distance: f64,
    margin: f64,
    /// The margin in steps of the last displacement (adapted to the set's length).
    skin: f64,
    /// Number of sets gathered so far.
    gatherings: usize,
    /// (δ, triangle), sorted by δ.
    list: Vec<(f64, u32)>,
}

impl Default for Candidates {
    fn default() -> Self {
        Self::new()
    }
}

impl Candidates {
    pub fn new() -> Self {
        Candidates {
            at: [V3::zeros(); 3],
            n_at: 0,
            last: [V3::zeros(); 3],
            n_last: 0,
            distance: 0.0,
            margin: 0.0,
            skin: SKIN_STEPS,
            gatherings: 0,
            list: Vec::new(),
        }
    }

    /// Records the positions of this query. Returns the distance moved since the set was
    /// gathered (rounded up; None when the set does not hold: none, other positions, or
    /// moved as far as the margin) and the margin for a new set (0: no set, query the
    /// hierarchy).
    fn update(&mut self, pos: &[V3]) -> (Option<f64>, f64) {
        let mut moved: f64 = 0.0;
        let mut step: f64 = f64::INFINITY;
        if self.n_last == pos.len() {
            step = 0.0;
            for (p, q) in pos.iter().zip(&self.last) {
                step = step.max((p - q).norm());
            }
        }
        if self.n_at == pos.len() {
            for (p, q) in pos.iter().zip(&self.at) {
                moved = moved.max((p - q).norm());
            }
        }
        self.last[..pos.len()].copy_from_slice(pos);
        self.n_last = pos.len();
        let moved = moved * (1.0 + 1e-9);
        if self.n_at == pos.len() && moved <= self.margin * (1.0 - 1e-9) {
            return (Some(moved), 0.0);
        }
        // a few steps of the last displacement, if small against the distance (the set grows
        // with distance × margin, the hierarchy's work with the distance alone)
        if self.skin < MIN_SKIN {
            self.skin = (self.skin * REGROW).min(SKIN_STEPS);
            return (None, 0.0);
        }
        let margin = self.skin * step;
        let margin = if margin.is_finite() && margin <= SKIN_OF_DISTANCE * self.distance {
            margin
        } else {
            0.0
        };
        (None, margin)
    }

    fn gathered(&mut self, pos: &[V3], margin: f64) {
        self.at[..pos.len()].copy_from_slice(pos);
        self.n_at = pos.len();
        self.margin = margin;
        self.gatherings += 1;
        self.skin = if self.list.len() > MAX_SET {
            0.5 * self.skin
        } else {
            (self.skin * 1.25).min(SKIN_STEPS)
        };
    }

    /// Number of candidate sets gathered so far (the other queries were answered by a set or
    /// by the hierarchy).
    pub fn gatherings(&self) -> usize {
        self.gatherings
    }

    /// Whether a candidate set is held.
    pub fn holds_set(&self) -> bool {
        self.n_at > 0
    }

    /// Signed distance of p to `mesh` as [`crate::Surface::project_point`] (no bound), from the
    /// set while it holds, else gathered again; `hint` warm-starts a new gathering.
    pub fn project_point(
        &mut self,
        mesh: &TriMesh,
        p: &V3,
        hint: usize,
    ) -> Option<PointProjection> {
        let pos = [*p];
        let moved = match self.update(&pos) {
            (Some(m), _) => m,
            (None, margin) if margin > 0.0 => {
                mesh.gather_point(p, margin, hint, &mut self.list);
                self.gathered(&pos, margin);
                0.0
            }
            (None, _) => {
                self.n_at = 0;
                let r = mesh.project_point(p, f64::INFINITY, hint)?;
                self.distance = r.distance.abs();
                return Some(r);
            }
        };
        // (a set holds the nearest triangle; empty only for a non-finite p)
        let (t, c) = mesh.nearest_triangle_among(p, &self.list, moved, f64::INFINITY)?;
        let r = mesh.point_projection(p, t, c);
        self.distance = r.distance.abs();
        Some(r)
    }

    /// [`TriMesh::nearest_of_segments`] of [a, ends[j]] within `max_distance`, from the set
    /// while it holds, else gathered again (the set does not depend on `max_distance`).
    pub fn nearest_of_segments(
        &mut self,
        mesh: &TriMesh,
        a: &V3,
        ends: &[V3],
        max_distance: f64,
        hint: usize,
    ) -> Option<(f64, usize, usize)> {
        assert!(ends.len() <= 2, "at most 2 segments");
        let mut pos = [*a; 3];
        pos[1..=ends.len()].copy_from_slice(ends);
        let pos = &pos[..=ends.len()];
        let found = match self.update(pos) {
            (Some(moved), _) => {
                mesh.nearest_of_segments_among(a, ends, &self.list, moved, max_distance)
            }
            (None, margin) if margin > 0.0 => {
                mesh.gather_segments(a, ends, margin, hint, &mut self.list);
                self.gathered(pos, margin);
                mesh.nearest_of_segments_among(a, ends, &self.list, 0.0, max_distance)
            }
            (None, _) => {
                self.n_at = 0;
                mesh.nearest_of_segments(a, ends, max_distance, hint)
            }
        };
        // the distance for the next margin: a bounded query that found nothing says only
        // that it is beyond the bound
        self.distance = found.map_or(max_distance, |f| f.0);
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::closest::{point_triangle, segment_triangle};

    /// A bumpy height field over [0, 1]² (n × n quads), normals up.
    fn bumpy(n: usize) -> (Vec<V3>, Vec<[u32; 3]>) {
        crate::height_field(n, |x, y| 0.1 * (x * 6.0).sin() * (y * 9.0).cos())
    }

    #[test]
    fn candidate_sets_agree_with_brute_force_over_a_moving_cable() {
        let (v, f) = bumpy(40);
        let mesh = TriMesh::new(&v, &f).unwrap();
        let tris: Vec<[V3; 3]> = f.iter().map(|t| t.map(|k| v[k as usize])).collect();
        let point_brute = |p: &V3| {
            tris.iter()
                .map(|[a, b, c]| (point_triangle(p, a, b, c).0 - p).norm())
                .fold(f64::INFINITY, f64::min)
        };
        let seg_brute = |a: &V3, b: &V3| {
            tris.iter()
                .map(|[p, q, r]| {
                    let (_, x, y) = segment_triangle(a, b, p, q, r);
                    (x - y).norm()
                })
                .fold(f64::INFINITY, f64::min)
        };
        // five nodes 3–8 cm above the surface drifting slowly (sets kept for several steps),
        // node 2 jumping 0.3 m away and back at steps 40 and 41, node 4 dipping through the
        // surface (distance 0: the margin falls to 0, the hierarchy answers)
        let n = 5;
        let node = |t: usize, i: usize| {
            let s = t as f64 * 2e-6;
            let mut p = V3::new(
                0.2 + 0.12 * i as f64 + s,
                0.3 + 0.05 * i as f64 + 0.5 * s,
                0.03 + 0.01 * i as f64 + 0.3 * (0.7 * s * 1e4).sin() * 1e-4,
            );
            if i == 2 && t == 40 {
                p += V3::new(0.3, -0.1, 0.05);
            }
            if i == 4 && (60..64).contains(&t) {
                p.z = -0.2;
            }
            p
        };
        let mut points = vec![Candidates::new(); n];
        let mut edges = vec![Candidates::new(); n];
        let (mut queries, mut held) = (0, 0);
        for t in 0..120 {
            let x: Vec<V3> = (0..n).map(|i| node(t, i)).collect();
            for i in 0..n {
                let r = points[i].project_point(&mesh, &x[i], usize::MAX).unwrap();
                let h = mesh
                    .project_point(&x[i], f64::INFINITY, usize::MAX)
                    .unwrap();
                assert_eq!(r.distance, h.distance, "step {t} node {i}");
                assert_eq!(r.distance.abs(), point_brute(&x[i]), "step {t} node {i}");
                let mut ends = vec![];
                for nb in [i.wrapping_sub(1), i + 1] {
                    if nb < n {
                        ends.push((x[i] + x[nb]) * 0.5);
                    }
                }
                let brute = ends
                    .iter()
                    .map(|e| seg_brute(&x[i], e))
                    .fold(f64::INFINITY, f64::min);
                let (d, j, tri) = edges[i]
                    .nearest_of_segments(&mesh, &x[i], &ends, f64::INFINITY, usize::MAX)
                    .unwrap();
                assert_eq!(d, brute, "step {t} node {i}");
                let [p, q, w] = mesh.triangle(tri);
                let (_, a, b) = segment_triangle(&x[i], &ends[j], &p, &q, &w);
                assert_eq!((a - b).norm(), d);
                // a bound below the distance: nothing
                if d > 0.0 {
                    let none = edges[i].nearest_of_segments(&mesh, &x[i], &ends, d * 0.99, 0);
                    assert!(none.is_none());
                }
                queries += 1;
                held += points[i].holds_set() as usize;
            }
        }
        // the sets answered most queries (not the hierarchy each time)
        let gathered: usize = points.iter().map(|c| c.gatherings()).sum();
        assert!(held > queries / 2, "{held} of {queries}");
        assert!(gathered < queries / 4, "{gathered} of {queries}");
    }

    #[test]
    fn candidate_sets_are_exact_near_the_center_of_a_trough() {
        // a trough (half cylinder of radius 5 cm, axis along y, normals inwards): near its
        // axis every triangle is nearly equally far, so the nearest changes with tiny motions
        // and a set missing any triangle within d₀ + 2·margin would answer wrongly
        let (k, m, rad) = (48, 12, 0.05);
        let mut v = vec![];
        for j in 0..=m {
            for i in 0..=k {
                let a = std::f64::consts::PI * (i as f64 / k as f64 + 1.0);
                v.push(V3::new(
                    rad * a.cos(),
                    0.1 * j as f64 / m as f64,
                    rad * a.sin(),
                ));
            }
        }
        let mut f = vec![];
        for j in 0..m {
            for i in 0..k {
                let a = (j * (k + 1) + i) as u32;
                let (b, c, d) = (a + 1, a + k as u32 + 1, a + k as u32 + 2);
                f.push([a, c, d]);
                f.push([a, d, b]);
            }
        }
        let mesh = TriMesh::new(&v, &f).unwrap();
        let tris: Vec<[V3; 3]> = f.iter().map(|t| t.map(|k| v[k as usize])).collect();
        let mut sets = vec![(Candidates::new(), Candidates::new()); 3];
        let mut held = 0;
        for t in 0..400 {
            let s = t as f64;
            let x: Vec<V3> = (0..3)
                .map(|i| {
                    let w = 0.3 + 0.2 * i as f64;
                    V3::new(
                        2e-3 * (w * s * 0.01).sin(),
                        0.03 + 0.02 * i as f64 + 1e-6 * s,
                        -4e-3 + 2e-3 * (w * s * 0.0074).cos(),
                    )
                })
                .collect();
            for i in 0..3 {
                let r = sets[i].0.project_point(&mesh, &x[i], usize::MAX).unwrap();
                let brute = tris
                    .iter()
                    .map(|[a, b, c]| (point_triangle(&x[i], a, b, c).0 - x[i]).norm())
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(r.distance.abs(), brute, "step {t} node {i}");
                let ends: Vec<V3> = [i.wrapping_sub(1), i + 1]
                    .into_iter()
                    .filter(|&nb| nb < 3)
                    .map(|nb| (x[i] + x[nb]) * 0.5)
                    .collect();
                let (d, _, _) = sets[i]
                    .1
                    .nearest_of_segments(&mesh, &x[i], &ends, f64::INFINITY, usize::MAX)
                    .unwrap();
                let brute = tris
                    .iter()
                    .flat_map(|[p, q, w]| {
                        ends.iter().map(|e| {
                            let (_, a, b) = segment_triangle(&x[i], e, p, q, w);
                            (a - b).norm()
                        })
                    })
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(d, brute, "step {t} node {i}");
                held += sets[i].1.holds_set() as usize;
            }
        }
        assert!(held > 600, "{held}");
    }
}
