//! Triangle mesh with a bounding volume hierarchy and angle-weighted pseudo-normals.
//!
//! The sign of a point's distance is that of (p − c)·n with c the closest point and n the
//! pseudo-normal of the feature c lies on: the face normal inside a face, the sum of the
//! adjacent face normals on an edge, the angle-weighted sum of the incident face normals at a
//! vertex (Bærentzen & Aanæs 2005). For a closed, consistently oriented mesh this is the exact
//! inside test; for an open mesh it says on which side of the surface (by its normals) the
//! point is.
use std::fmt;

use rayon::prelude::*;

use crate::closest::{point_triangle, segment_triangle, Feature};
use crate::wide::{self, f32_up, f32x3, lower, Block4, Rounded, Wide, EMPTY, LEAF};
use crate::{PointProjection, SegmentProjection, Surface, V3};

const LEAF_SIZE: usize = 4;
const PARALLEL_BUILD: usize = 20_000;

#[derive(Debug, Clone, PartialEq)]
pub struct MeshError(pub String);

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for MeshError {}

/// A node of the binary hierarchy (built, then collapsed into the wide tree the searches
/// walk): its box and links, one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    min: V3,
    max: V3,
    /// Leaf: first triangle; inner node: index of the right child (the left one follows).
    index: u32,
    /// Leaf: number of triangles (> 0); inner node: 0.
    count: u32,
}

impl Node {
    /// A placeholder (overwritten by the build).
    const EMPTY: Node = Node {
        min: V3::new(0.0, 0.0, 0.0),
        max: V3::new(0.0, 0.0, 0.0),
        index: 0,
        count: 0,
    };
}

/// Whether a thin disk-like set is farther than sqrt(best_d2) from a segment, exactly
/// (round-off kept on the safe side). The set: points z with axial coordinate n·z in [lo, hi]
/// and in-plane offset |P(z − c)| ≤ r from a center c (P the projection across the unit axis
/// n). The segment: axial coordinates xa, xb of its ends, in-plane offsets pu (start) and
/// pu + e (end) from c. For y(s) on the segment, |y − z|² ≥ gap(s)² + (|q(s)| − r)₊², gap the
/// distance of the axial coordinate to [lo, hi] and q(s) = pu + s e. If this is above best
/// with the least gap and the least offset (taken apart), the set is out; else only the
/// part of the segment with |q(s)| ≤ r + m, m² = best_d2 − (least gap)², can come nearer,
/// and the set is out if the gap there exceeds the bound.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn disk_excludes(
    xa: f64,
    xb: f64,
    lo: f64,
    hi: f64,
    pu: &V3,
    e: &V3,
    r: f64,
    best_d2: f64,
) -> bool {
    const SAFE: f64 = 1.0 - 1e-10;
    let gap = |x1: f64, x2: f64| (lo - x1.max(x2)).max(x1.min(x2) - hi).max(0.0);
    let g = gap(xa, xb);
    let l2 = e.norm_squared();
    let (s0, lat0) = if l2 > 0.0 {
        let s0 = -pu.dot(e) / l2;
        (s0, (pu + e * s0).norm())
    } else {
        (0.0, pu.norm())
    };
    let latc = if (0.0..=1.0).contains(&s0) {
        lat0
    } else {
        (pu + e * s0.clamp(0.0, 1.0)).norm()
    };
    let out = (latc - r).max(0.0);
    if (g * g + out * out) * SAFE > best_d2 {
        return true;
    }
    if l2 == 0.0 || !best_d2.is_finite() {
        return false;
    }
    // offsets within r + m: s in s0 ± δ
    let reach = r + (best_d2 - g * g).max(0.0).sqrt();
    let disc = reach * reach - lat0 * lat0;
    if disc < 0.0 {
        return false; // at the edge of round-off: keep the set
    }
    let delta = (disc / l2).sqrt() * (1.0 + 1e-9) + 1e-12;
    let (s1, s2) = ((s0 - delta).max(0.0), (s0 + delta).min(1.0));
    if s1 > s2 {
        return false;
    }
    let (x1, x2) = (xa + (xb - xa) * s1, xa + (xb - xa) * s2);
    let gi = gap(x1, x2);
    gi * gi * SAFE > best_d2
}

/// Whether the disk of radius r about c in the plane of unit normal n is farther than
/// sqrt(best_d2) from segment [a, b] (the float64 triangle filter of [`TriMesh`]).
#[inline]
fn segment_excluded_by(n: &V3, c: &V3, r: f64, a: &V3, b: &V3, best_d2: f64) -> bool {
    let (u, w) = (a - c, b - c);
    let (ha, hb) = (n.dot(&u), n.dot(&w));
    if ha * hb > 0.0 {
        // both ends on one side: the plane alone may exclude
        let h = ha.abs().min(hb.abs());
        if h * h * (1.0 - 1e-10) > best_d2 {
            return true;
        }
    }
    let pu = u - n * ha;
    let e = (w - n * hb) - pu;
    disk_excludes(ha, hb, 0.0, 0.0, &pu, &e, r, best_d2)
}

/// Tests: [`segment_excluded_by`] for a triangle's disk as `wide`'s tests give it.
#[cfg(test)]
pub(crate) fn triangle_disk_excludes(
    (n, _, _, c, r): &(V3, f64, f64, V3, f64),
    a: &V3,
    b: &V3,
    best_d2: f64,
) -> bool {
    segment_excluded_by(n, c, *r, a, b, best_d2)
}

/// A triangle mesh ready for distance queries.
pub struct TriMesh {
    /// Triangles in hierarchy order.
    triangles: Vec<[V3; 3]>,
    /// Vertex indices of the triangles (for the vertex pseudo-normals).
    corners: Vec<[u32; 3]>,
    face_normals: Vec<V3>,
    /// Per triangle its edges' indices in `edge_sums`, the edges' pseudo-normals (the sums of
    /// their faces' normals).
    edges: Vec<[u32; 3]>,
    edge_sums: Vec<V3>,
    vertex_normals: Vec<V3>,
    /// The binary hierarchy (its leaves' triangle ranges; its boxes give the mesh's bounds).
    nodes: Vec<Node>,
    /// The 4-wide float32 view of `nodes` that every search walks, and per leaf its
    /// triangles' planes and disks in float32, in the leaf block's own frame.
    wide: Vec<Wide>,
    blocks: Vec<Block4>,
    /// Largest vertex coordinate magnitude (the scale of the float32 round-off).
    scale: f64,
    /// Closed and consistently oriented (every edge in two faces, in opposite directions).
    closed: bool,
}

struct BinaryView<'a> {
    nodes: &'a [Node],
    triangles: &'a [[V3; 3]],
    normals: &'a [V3],
}

/// Depth of the traversal stacks: the wide tree is at most as deep as the binary one (median
/// splits: ≤ 32 levels for u32 triangle counts) and a visit adds at most three entries.
const STACK: usize = 128;

impl wide::Binary for BinaryView<'_> {
    fn bounds(&self, node: u32) -> (V3, V3) {
        let n = &self.nodes[node as usize];
        (n.min, n.max)
    }
    fn children(&self, node: u32) -> Option<(u32, u32)> {
        let n = &self.nodes[node as usize];
        (n.count == 0).then_some((node + 1, n.index))
    }
    fn triangles(&self, node: u32) -> (usize, usize) {
        let n = &self.nodes[node as usize];
        (n.index as usize, n.count as usize)
    }
    fn slab(&self, node: u32) -> Option<(V3, f64, f64, V3, f64)> {
        // the subtree's triangles: from its leftmost leaf's first to its rightmost leaf's last
        let leaf = |mut n: u32, next: &dyn Fn(u32) -> u32| {
            while self.nodes[n as usize].count == 0 {
                n = next(n);
            }
            &self.nodes[n as usize]
        };
        let first = leaf(node, &|n| n + 1).index as usize;
        let last = leaf(node, &|n| self.nodes[n as usize].index);
        let end = (last.index + last.count) as usize;
        let s = slab(&self.triangles[first..end], &self.normals[first..end]);
        s.4.is_finite().then_some(s)
    }
    fn disk(&self, t: usize) -> (V3, f64, f64, V3, f64) {
        let (c, r) = triangle_sphere(&self.triangles[t]);
        let n = self.normals[t];
        let x = n.dot(&c);
        (n, x, x, c, r)
    }
}

impl TriMesh {
    /// Builds the mesh from vertices and triangles (vertex indices; shared vertices must be
    /// merged for the pseudo-normals to see the neighbours). Degenerate triangles (zero area)
    /// are an error: drop them before.
    pub fn new(vertices: &[V3], faces: &[[u32; 3]]) -> Result<Self, MeshError> {
        if faces.is_empty() {
            return Err(MeshError("the mesh has no triangles".into()));
        }
        if let Some(v) = vertices.iter().find(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(MeshError(format!("vertex {v:?} is not finite")));
        }
        let n_v = vertices.len() as u32;
        let mut normals = Vec::with_capacity(faces.len());
        for (i, f) in faces.iter().enumerate() {
            if f.iter().any(|&k| k >= n_v) {
                return Err(MeshError(format!(
                    "triangle {i} has vertex index {f:?} beyond the {n_v} vertices"
                )));
            }
            let [a, b, c] = f.map(|k| vertices[k as usize]);
            let n = (b - a).cross(&(c - a));
            let len = n.norm();
            if len == 0.0 || !len.is_finite() {
                return Err(MeshError(format!("triangle {i} is degenerate (zero area)")));
            }
            normals.push(n / len);
        }
        // the pseudo-normals (for the sign: vertices, then edges, largely serial) beside the
        // hierarchy over the triangle centroids (parallel): independent work, joined
        let pseudo_normals = || {
            // vertex pseudo-normals: incident face normals weighted by the incident angle
            let mut vertex_normals = vec![V3::zeros(); vertices.len()];
            for (f, n) in faces.iter().zip(&normals) {
                for k in 0..3 {
                    let p = vertices[f[k] as usize];
                    let u = vertices[f[(k + 1) % 3] as usize] - p;
                    let w = vertices[f[(k + 2) % 3] as usize] - p;
                    let angle = u.angle(&w);
                    vertex_normals[f[k] as usize] += n * angle;
                }
            }
            // edge pseudo-normals: sum of the normals of the faces sharing the edge, and
            // whether the mesh is closed and consistently oriented: every edge in two faces,
            // once in each direction
            (
                vertex_normals,
                edge_normals(vertices.len(), faces, &normals),
            )
        };
        let hierarchy = || {
            // centroids relative to the mesh's middle: float32 keeps their order at the mesh's
            // scale wherever it lies
            let middle = vertices
                .par_iter()
                .fold(
                    || (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY)),
                    |(lo, hi), v| (lo.inf(v), hi.sup(v)),
                )
                .reduce(
                    || (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY)),
                    |a, b| (a.0.inf(&b.0), a.1.sup(&b.1)),
                );
            let middle = (middle.0 + middle.1) * 0.5;
            let mut items: Vec<Item> = faces
                .par_iter()
                .enumerate()
                .map(|(i, f)| {
                    let c = f.iter().fold(V3::zeros(), |s, &k| s + vertices[k as usize]) / 3.0;
                    let c = c - middle;
                    ([c.x as f32, c.y as f32, c.z as f32], i as u32)
                })
                .collect();
            let ctx = BuildData { vertices, faces };
            let mut nodes = vec![Node::EMPTY; tree_size(items.len())];
            build(&mut items, 0, 0, &mut nodes, &ctx);
            (items, nodes)
        };
        let ((vertex_normals, (edge_of, closed)), (items, nodes)) =
            rayon::join(pseudo_normals, hierarchy);
        // the per-triangle arrays in hierarchy order (parallel gathers)
        let order: Vec<usize> = items.par_iter().map(|&(_, i)| i as usize).collect();
        let triangles: Vec<[V3; 3]> = order
            .par_iter()
            .map(|&i| faces[i].map(|k| vertices[k as usize]))
            .collect();
        let corners = order.par_iter().map(|&i| faces[i]).collect();
        let face_normals: Vec<V3> = order.par_iter().map(|&i| normals[i]).collect();
        let edges = order
            .par_iter()
            .map(|&i| [0, 1, 2].map(|k| edge_of.edge[3 * i + k]))
            .collect();
        let view = BinaryView {
            nodes: &nodes,
            triangles: &triangles,
            normals: &face_normals,
        };
        let (wide, blocks) = wide::collapse(&view, 0);
        let scale = vertices.iter().fold(0.0, |m: f64, v| m.max(v.amax()));
        Ok(TriMesh {
            triangles,
            corners,
            face_normals,
            edges,
            edge_sums: edge_of.sum,
            vertex_normals,
            nodes,
            wide,
            blocks,
            scale,
            closed,
        })
    }

    /// Whether the mesh is closed and consistently oriented: then the sign of the distance
    /// (inside or outside) changes only across the surface.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    pub fn n_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Outward unit normal of triangle `t` (an index as in [`PointProjection::feature`]).
    pub fn face_normal(&self, t: usize) -> V3 {
        self.face_normals[t]
    }

    /// Corners of triangle `t`.
    pub fn triangle(&self, t: usize) -> [V3; 3] {
        self.triangles[t]
    }

    /// Axis-aligned bounding box (min, max).
    pub fn bounds(&self) -> (V3, V3) {
        (self.nodes[0].min, self.nodes[0].max)
    }

    #[inline]
    fn pseudo_normal(&self, tri: usize, feature: Feature) -> V3 {
        match feature {
            Feature::Face => self.face_normals[tri],
            Feature::Edge(k) => self.edge_sums[self.edges[tri][k as usize] as usize],
            Feature::Vertex(k) => self.vertex_normals[self.corners[tri][k as usize] as usize],
        }
    }

    /// Whether segment [a, b] is farther than sqrt(best_d2) from triangle t: by
    /// [`disk_excludes`] with the triangle's plane and its circumscribed disk about the
    /// centroid (cheap, and tight under a nearly parallel surface).
    #[inline]
    fn segment_excluded(&self, t: usize, a: &V3, b: &V3, best_d2: f64) -> bool {
        let (c, r) = triangle_sphere(&self.triangles[t]);
        segment_excluded_by(&self.face_normals[t], &c, r, a, b, best_d2)
    }

    /// Closest triangle to p within sqrt(best_d2): (triangle, closest point).
    fn nearest_triangle(&self, p: &V3, mut best_d2: f64, hint: usize) -> Option<(usize, V3)> {
        let mut best = None;
        if hint < self.triangles.len() {
            let [a, b, c] = &self.triangles[hint];
            let (cp, _) = point_triangle(p, a, b, c);
            let d2 = (cp - p).norm_squared();
            if d2 <= best_d2 {
                best_d2 = d2;
                best = Some((hint, cp));
            }
        }
        // the wide tree: per visit four float32 boxes and slab-and-ball bounds (lower bounds),
        // leaves nearest first (their triangles' float32 plane-and-disk bounds, then the
        // exact distance), inner lanes pushed farthest first
        let q = Rounded::new(p, p);
        let pf = f32x3(p);
        let pad = wide::pad(p.amax().max(self.scale));
        let mut stack = [(0u32, 0f32); STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (w, g) = stack[top];
            if lower(g) > best_d2 {
                continue;
            }
            let wn = &self.wide[w as usize];
            let mut g = wn.gaps2(&q);
            if wn.has_disk() {
                let gd = wn.disk.point_bounds2(&pf, pad);
                for l in 0..4 {
                    g[l] = g[l].max(gd[l]);
                }
            }
            let order = wide::order(&g);
            for &l in &order {
                if lower(g[l]) > best_d2 {
                    break;
                }
                if wn.wide[l] & LEAF == 0 || wn.node[l] == EMPTY {
                    continue;
                }
                let node = &self.nodes[wn.node[l] as usize];
                let tb = self.blocks[(wn.wide[l] & !LEAF) as usize].point_bounds2(p);
                let start = node.index as usize;
                for (i, b) in tb.iter().enumerate().take(node.count as usize) {
                    let t = start + i;
                    if lower(*b) > best_d2 || t == hint {
                        continue; // (the hint: measured first)
                    }
                    let [a, b, c] = &self.triangles[t];
                    let (cp, _) = point_triangle(p, a, b, c);
                    let d2 = (cp - p).norm_squared();
                    if d2 < best_d2 || (d2 == best_d2 && best.is_none()) {
                        best_d2 = d2;
                        best = Some((t, cp));
                    }
                }
            }
            for &l in order.iter().rev() {
                if wn.wide[l] & LEAF == 0 && lower(g[l]) <= best_d2 {
                    stack[top] = (wn.wide[l], g[l]);
                    top += 1;
                }
            }
        }
        best
    }

    /// Nearest of the segments [a, ends[j]] (a shared start, such as the two half-edges at a
    /// cable node) to the mesh within `max_distance`, in one traversal: a node is skipped when
    /// no segment can come nearer than the best found for any of them. Returns (distance,
    /// index j, triangle); `hint` is a triangle to try first. The distance is the one
    /// [`Surface::closest_to_segment`] gives for segment j.
    pub fn nearest_of_segments(
        &self,
        a: &V3,
        ends: &[V3],
        max_distance: f64,
        hint: usize,
    ) -> Option<(f64, usize, usize)> {
        assert!(ends.len() <= 2, "at most two segments");
        if ends.is_empty() {
            return None;
        }
        let mut best_d2 = max_distance * max_distance;
        let mut best: Option<(usize, usize)> = None;
        let check = |t: usize, best_d2: &mut f64, best: &mut Option<(usize, usize)>| {
            let [p, q, r] = &self.triangles[t];
            for (j, b) in ends.iter().enumerate() {
                if self.segment_excluded(t, a, b, *best_d2) {
                    continue;
                }
                let (_, x, y) = segment_triangle(a, b, p, q, r);
                let d2 = (x - y).norm_squared();
                if d2 < *best_d2 || (d2 == *best_d2 && best.is_none()) {
                    *best_d2 = d2;
                    *best = Some((j, t));
                }
            }
        };
        if hint < self.triangles.len() {
            check(hint, &mut best_d2, &mut best);
        }
        // the wide tree: per visit eight float32 lanes, the four boxes and slab-and-ball
        // bounds for each segment (one segment: taken twice, its lanes then equal), a lane's
        // bound the least over the segments; leaves nearest first (per triangle and segment
        // the float32 plane-and-disk bound with its second stage given the best so far, then
        // the exact distance), inner lanes pushed farthest first. The second stage excludes
        // nearly all that the float64 test of the triangle's disk did, which is left out
        // (clearance benchmark: 26.6 of 50 kept, that test then kept 26.2; 5.7 → 5.05 µs per
        // node), and does not pay at inner nodes (5.05 → 5.6 µs per node)
        let scale = ends.iter().fold(a.amax(), |m, b| m.max(b.amax()));
        let pad = wide::pad(scale.max(self.scale));
        let af = f32x3(a);
        let pair = [&ends[0], &ends[ends.len() - 1]];
        let bf = pair.map(f32x3);
        let qs = pair.map(|b| Rounded::new(&a.inf(b), &a.sup(b)));
        let mut stack = [(0u32, 0f32); STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (w, g) = stack[top];
            if lower(g) > best_d2 {
                continue;
            }
            let wn = &self.wide[w as usize];
            // (where every lane has a slab and ball, their bound alone: the boxes rarely add
            // to it; measured 1.7 % faster)
            let g: [f32; 4] = if wn.all_disks() {
                let gd = wn
                    .disk
                    .segment_bounds2_pair(&af, &bf, [pad, pad], f32::INFINITY);
                std::array::from_fn(|l| gd[l].min(gd[l + 4]))
            } else if wn.has_disk() {
                let gb = wn.gaps2_pair(&qs);
                let gd = wn
                    .disk
                    .segment_bounds2_pair(&af, &bf, [pad, pad], f32::INFINITY);
                std::array::from_fn(|l| gb[l].max(gd[l]).min(gb[l + 4].max(gd[l + 4])))
            } else {
                let gb = wn.gaps2_pair(&qs);
                std::array::from_fn(|l| gb[l].min(gb[l + 4]))
            };
            let order = wide::order(&g);
            for &l in &order {
                if lower(g[l]) > best_d2 {
                    break;
                }
                if wn.wide[l] & LEAF == 0 || wn.node[l] == EMPTY {
                    continue;
                }
                let node = &self.nodes[wn.node[l] as usize];
                let block = &self.blocks[(wn.wide[l] & !LEAF) as usize];
                // per segment j its four lanes: tb[4 j + i] for triangle i
                let tb = block.segment_bounds2_pair(&block.local(a), pair, f32_up(best_d2));
                let start = node.index as usize;
                for i in 0..node.count as usize {
                    let t = start + i;
                    if t == hint {
                        continue; // measured first
                    }
                    let [p, q, r] = &self.triangles[t];
                    for (j, b) in ends.iter().enumerate() {
                        if lower(tb[4 * j + i]) > best_d2 {
                            continue;
                        }
                        let (_, x, y) = segment_triangle(a, b, p, q, r);
                        let d2 = (x - y).norm_squared();
                        if d2 < best_d2 || (d2 == best_d2 && best.is_none()) {
                            best_d2 = d2;
                            best = Some((j, t));
                        }
                    }
                }
            }
            for &l in order.iter().rev() {
                if wn.wide[l] & LEAF == 0 && lower(g[l]) <= best_d2 {
                    stack[top] = (wn.wide[l], g[l]);
                    top += 1;
                }
            }
        }
        best.map(|(j, t)| (best_d2.sqrt(), j, t))
    }

    /// The signed point projection of p on triangle t with closest point c (the sign by the
    /// pseudo-normal of the feature c lies on).
    pub(crate) fn point_projection(&self, p: &V3, t: usize, c: V3) -> PointProjection {
        let [a, b, cc] = &self.triangles[t];
        let (_, feature) = point_triangle(p, a, b, cc);
        let n = self.pseudo_normal(t, feature);
        let d = p - c;
        let dist = d.norm();
        let sign = if d.dot(&n) < 0.0 { -1.0 } else { 1.0 };
        let normal = if dist > 1e-12 * (1.0 + c.norm()) {
            d * (sign / dist)
        } else {
            n.normalize()
        };
        PointProjection {
            distance: sign * dist,
            point: c,
            normal,
            feature: t,
        }
    }

    /// Closest triangle to segment [a, b] within `max_distance`: (triangle, parameter on the
    /// segment, closest points), by the wide tree's search.
    fn nearest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        max_distance: f64,
        hint: usize,
    ) -> Option<(usize, f64, V3, V3)> {
        let (_, _, t) = self.nearest_of_segments(a, std::slice::from_ref(b), max_distance, hint)?;
        let [p, q, r] = &self.triangles[t];
        let (s, x, y) = segment_triangle(a, b, p, q, r);
        Some((t, s, x, y))
    }
}

impl Surface for TriMesh {
    fn project_point(&self, p: &V3, max_distance: f64, hint: usize) -> Option<PointProjection> {
        let (t, c) = self.nearest_triangle(p, max_distance * max_distance, hint)?;
        Some(self.point_projection(p, t, c))
    }

    fn closest_to_segment(
        &self,
        a: &V3,
        b: &V3,
        max_distance: f64,
        hint: usize,
    ) -> Option<SegmentProjection> {
        let (t, s, x, y) = self.nearest_to_segment(a, b, max_distance, hint)?;
        let [p, q, r] = &self.triangles[t];
        let (_, feature) = point_triangle(&x, p, q, r);
        let n = self.pseudo_normal(t, feature);
        let d = x - y;
        let dist = d.norm();
        let normal = if dist > 1e-12 * (1.0 + y.norm()) {
            let sign = if d.dot(&n) < 0.0 { -1.0 } else { 1.0 };
            d * (sign / dist)
        } else {
            n.normalize()
        };
        Some(SegmentProjection {
            distance: dist,
            t: s,
            on_segment: x,
            on_surface: y,
            normal,
            feature: t,
        })
    }
}

/// A triangle's centroid and the radius about it that holds the triangle (rounded up).
#[inline]
fn triangle_sphere(v: &[V3; 3]) -> (V3, f64) {
    let c = (v[0] + v[1] + v[2]) / 3.0;
    let r = v
        .iter()
        .map(|x| (x - c).norm_squared())
        .fold(0.0, f64::max)
        .sqrt();
    (c, r * (1.0 + 1e-12))
}

/// The edges' pseudo-normals: per side (3 t + k: edge k of triangle t) its edge, per edge the
/// sum of the normals of its faces.
struct EdgeSums {
    edge: Vec<u32>,
    sum: Vec<V3>,
}

impl EdgeSums {
    #[cfg(test)]
    fn of(&self, side: usize) -> V3 {
        self.sum[self.edge[side] as usize]
    }
}

/// The edges' normal sums ([`EdgeSums`]) and whether every edge is in two faces, once in each
/// direction. The sides are grouped by a counting sort on their lower vertex (linear in the
/// triangles; the edges of one vertex, a handful, are matched by their other vertex), in
/// parallel over vertex ranges: each range sorts its buckets and counts its edges, then, the
/// ranges' first edges known, numbers them and sums their normals (an edge's sum in
/// increasing side order). One sum per edge, not per side: half the memory to fault in.
fn edge_normals(n_vertices: usize, faces: &[[u32; 3]], normals: &[V3]) -> (EdgeSums, bool) {
    use std::sync::atomic::{AtomicU32, Ordering};
    // whether a side runs from its lower vertex to its higher one
    let forward = |side: usize| {
        let f = &faces[side / 3];
        f[side % 3] < f[(side + 1) % 3]
    };
    let n_sides = 3 * faces.len();
    let (start, mut other) = crate::topology::sides_by_lower_vertex(n_vertices, faces);
    // per range of vertices (in parallel): each bucket sorted by other vertex, then side (the
    // sides of one edge together, in increasing order); its edges counted
    let chunk = n_vertices
        .div_ceil(8 * rayon::current_num_threads())
        .max(1024);
    let mut parts = Vec::new();
    let (mut rest, mut done) = (other.as_mut_slice(), 0usize);
    for v0 in (0..n_vertices).step_by(chunk) {
        let v1 = (v0 + chunk).min(n_vertices);
        let (part, tail) = std::mem::take(&mut rest).split_at_mut(start[v1] as usize - done);
        parts.push((v0..v1, part));
        rest = tail;
        done = start[v1] as usize;
    }
    let counted: Vec<(usize, bool)> = parts
        .into_par_iter()
        .map(|(vertices, part)| {
            let base = start[vertices.start] as usize;
            let (mut edges, mut closed) = (0, true);
            for v in vertices {
                let bucket = &mut part[start[v] as usize - base..start[v + 1] as usize - base];
                bucket.sort_unstable();
                for group in bucket.chunk_by(|x, y| x.0 == y.0) {
                    edges += 1;
                    let side = |i: usize| group[i].1 as usize;
                    closed &= group.len() == 2 && forward(side(0)) != forward(side(1));
                }
            }
            (edges, closed)
        })
        .collect();
    let closed = counted.iter().all(|c| c.1);
    let mut first = Vec::with_capacity(counted.len() + 1);
    first.push(0usize);
    for c in &counted {
        first.push(first.last().unwrap() + c.0);
    }
    // the ranges' edges numbered in turn: sums, and each side's edge
    let mut sum = vec![V3::zeros(); *first.last().unwrap()];
    let edge: Vec<AtomicU32> = (0..n_sides).map(|_| AtomicU32::new(0)).collect();
    let mut sums = Vec::new();
    let mut rest = sum.as_mut_slice();
    for w in first.windows(2) {
        let (part, tail) = std::mem::take(&mut rest).split_at_mut(w[1] - w[0]);
        sums.push((w[0], part));
        rest = tail;
    }
    let ranges: Vec<_> = (0..n_vertices).step_by(chunk).collect();
    ranges
        .into_par_iter()
        .zip(sums)
        .for_each(|(v0, (e0, part))| {
            let v1 = (v0 + chunk).min(n_vertices);
            let mut g = 0;
            for v in v0..v1 {
                let bucket = &other[start[v] as usize..start[v + 1] as usize];
                for group in bucket.chunk_by(|x, y| x.0 == y.0) {
                    let mut total = V3::zeros();
                    for &(_, side) in group {
                        total += normals[side as usize / 3];
                        edge[side as usize].store((e0 + g) as u32, Ordering::Relaxed);
                    }
                    part[g] = total;
                    g += 1;
                }
            }
        });
    let edge = edge.into_iter().map(AtomicU32::into_inner).collect();
    (EdgeSums { edge, sum }, closed)
}

struct BuildData<'a> {
    vertices: &'a [V3],
    faces: &'a [[u32; 3]],
}

/// Subtrees up to this many triangles get a slab bound (the surface is nearly flat there).
const SLAB_MAX: usize = 64;

/// The slab of a subtree's triangles (`tris` and their unit `normals`, in hierarchy order:
/// axis = mean normal, the range of axis·x over them) and a ball holding them (center,
/// radius); axis zero and radius infinite when there is none (more than `SLAB_MAX`
/// triangles, or normals spread). Computed for the wide tree's lanes only.
fn slab(tris: &[[V3; 3]], normals: &[V3]) -> (V3, f64, f64, V3, f64) {
    let none = (
        V3::zeros(),
        f64::NEG_INFINITY,
        f64::INFINITY,
        V3::zeros(),
        f64::INFINITY,
    );
    if tris.len() > SLAB_MAX {
        return none;
    }
    let mean: V3 = normals.iter().sum();
    let len = mean.norm();
    if len < 0.5 * tris.len() as f64 {
        return none; // normals spread: the slab would not be thin
    }
    let axis = mean / len;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut bmin, mut bmax) = (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY));
    for v in tris.iter().flatten() {
        let x = axis.dot(v);
        lo = lo.min(x);
        hi = hi.max(x);
        bmin = bmin.inf(v);
        bmax = bmax.sup(v);
    }
    let center = (bmin + bmax) * 0.5;
    // (the root of the largest square: the largest root, to the last bit)
    let radius = tris
        .iter()
        .flatten()
        .fold(0.0, |r: f64, v| r.max((v - center).norm_squared()))
        .sqrt();
    // widen by the round-off of the projections
    let pad = 1e-12 * (lo.abs() + hi.abs() + (hi - lo));
    let radius = radius * (1.0 + 1e-12) + 1e-12 * center.norm();
    (axis, lo - pad, hi + pad, center, radius)
}

/// Number of nodes of the hierarchy over `k` triangles (median splits).
fn tree_size(k: usize) -> usize {
    if k <= LEAF_SIZE {
        1
    } else {
        1 + tree_size(k / 2) + tree_size(k - k / 2)
    }
}

/// A triangle in the build: its centroid (float32: the splits' keys only) and index.
type Item = ([f32; 3], u32);

/// Builds the hierarchy over `items` (centroid, triangle), reordering them, into `out`
/// (`tree_size(items.len())` nodes, depth first); `offset` is the position of items[0] in
/// the whole triangle order, `base` the index of out[0] among all nodes.
fn build(items: &mut [Item], offset: usize, base: usize, out: &mut [Node], d: &BuildData) {
    if items.len() <= LEAF_SIZE {
        let (mut lo, mut hi) = (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY));
        for (_, i) in items.iter() {
            // (the triangle's box: its vertices')
            for &k in &d.faces[*i as usize] {
                let v = &d.vertices[k as usize];
                lo = lo.inf(v);
                hi = hi.sup(v);
            }
        }
        out[0] = Node {
            min: lo,
            max: hi,
            index: offset as u32,
            count: items.len() as u32,
        };
        return;
    }
    let (mut clo, mut chi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (c, _) in items.iter() {
        for k in 0..3 {
            clo[k] = clo[k].min(c[k]);
            chi[k] = chi[k].max(c[k]);
        }
    }
    let extent = [0, 1, 2].map(|k| chi[k] - clo[k]);
    let axis = (0..3).fold(0, |m, k| if extent[k] > extent[m] { k } else { m });
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |x, y| x.0[axis].total_cmp(&y.0[axis]));
    let (left_items, right_items) = items.split_at_mut(mid);
    let n_left = tree_size(mid);
    let (head, rest) = out.split_at_mut(1);
    let (left, right) = rest.split_at_mut(n_left);
    let right_at = base + 1 + n_left;
    if left_items.len() + right_items.len() > PARALLEL_BUILD {
        rayon::join(
            || build(left_items, offset, base + 1, left, d),
            || build(right_items, offset + mid, right_at, right, d),
        );
    } else {
        build(left_items, offset, base + 1, left, d);
        build(right_items, offset + mid, right_at, right, d);
    }
    head[0] = Node {
        min: left[0].min.inf(&right[0].min),
        max: left[0].max.sup(&right[0].max),
        index: right_at as u32,
        count: 0,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit cube [0, 1]³ as 12 outward triangles.
    pub fn cube() -> TriMesh {
        let v: Vec<V3> = (0..8)
            .map(|i| V3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1], // z = 0, normal −z
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        let mut f = vec![];
        for q in quads {
            f.push([q[0], q[1], q[2]]);
            f.push([q[0], q[2], q[3]]);
        }
        TriMesh::new(&v, &f).unwrap()
    }

    fn cube_sdf(p: &V3) -> f64 {
        let q = (p - V3::repeat(0.5)).abs() - V3::repeat(0.5);
        let out = q.sup(&V3::zeros()).norm();
        out + q.max().min(0.0)
    }

    #[test]
    fn cube_signed_distance_is_exact() {
        let m = cube();
        let mut rnd = crate::test_random(12345);
        for _ in 0..2000 {
            let p = V3::new(rnd() * 3.0 - 1.0, rnd() * 3.0 - 1.0, rnd() * 3.0 - 1.0);
            let r = m.project_point(&p, f64::INFINITY, usize::MAX).unwrap();
            assert!((r.distance - cube_sdf(&p)).abs() < 1e-14, "{p:?}");
            assert!((p - r.point).norm() - r.distance.abs() < 1e-14);
        }
        // corners and edges: vertex and edge pseudo-normals decide the sign
        let r = m
            .project_point(&V3::new(1.1, 1.1, 1.1), 10.0, usize::MAX)
            .unwrap();
        assert!((r.distance - 3f64.sqrt() * 0.1).abs() < 1e-14);
        let r = m
            .project_point(&V3::new(0.9, 0.95, 0.5), 10.0, usize::MAX)
            .unwrap();
        assert!((r.distance + 0.05).abs() < 1e-14);
        assert!((r.normal - V3::new(0.0, 1.0, 0.0)).norm() < 1e-14);
    }

    #[test]
    fn bound_and_hint() {
        let m = cube();
        let p = V3::new(0.5, 0.5, 3.0);
        assert!(m.project_point(&p, 1.0, usize::MAX).is_none());
        let r = m.project_point(&p, 2.5, 0).unwrap();
        assert!((r.distance - 2.0).abs() < 1e-15);
        let s = m.closest_to_segment(&V3::new(-1., 2., 0.5), &V3::new(2., 2., 0.5), 10.0, 3);
        let s = s.unwrap();
        assert!((s.distance - 1.0).abs() < 1e-15);
        assert!((s.normal - V3::new(0.0, 1.0, 0.0)).norm() < 1e-14);
        // a segment across a corner: both ends 1 away, the corner √½ − ... closer
        let s = m
            .closest_to_segment(
                &V3::new(2.0, 1.0, 0.5),
                &V3::new(1.0, 2.0, 0.5),
                10.0,
                usize::MAX,
            )
            .unwrap();
        assert!((s.distance - 0.5f64.sqrt()).abs() < 1e-14);
        assert!((s.t - 0.5).abs() < 1e-12);
    }

    #[test]
    fn edge_sums_equal_a_sort_of_all_sides() {
        // a fan of 100 triangles around vertex 0 (its bucket holds 200 sides), a strip, a
        // non-manifold edge in three faces and open boundaries: every side's sum equal to the
        // bit to the sums over a sort of all sides by (edge, side); closedness
        let mut v = vec![V3::zeros()];
        let mut f = vec![];
        for k in 0..100 {
            let a = 2.0 * std::f64::consts::PI * k as f64 / 100.0;
            v.push(V3::new(a.cos(), a.sin(), 0.01 * k as f64));
        }
        for k in 0..100u32 {
            f.push([0, 1 + k, 1 + (k + 1) % 100]);
        }
        let s = v.len() as u32;
        for k in 0..20 {
            v.push(V3::new(3.0 + k as f64 * 0.1, 0.0, 0.0));
            v.push(V3::new(3.0 + k as f64 * 0.1, 0.2, 0.05 * (k as f64).sin()));
        }
        for k in 0..19u32 {
            let a = s + 2 * k;
            f.push([a, a + 2, a + 1]);
            f.push([a + 1, a + 2, a + 3]);
        }
        let w = v.len() as u32;
        v.push(V3::new(5.0, 0.0, 1.0));
        f.push([s, s + 1, w]); // a third face on the strip's first edge
        let check = |v: &[V3], f: &[[u32; 3]]| {
            let normals: Vec<V3> = f
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| v[k as usize]);
                    (b - a).cross(&(c - a)).normalize()
                })
                .collect();
            let (sums, closed) = edge_normals(v.len(), f, &normals);
            let key = |t: &[u32; 3], k: usize| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                (a.min(b), a.max(b))
            };
            let mut keys: Vec<((u32, u32), usize)> = (0..3 * f.len())
                .map(|side| (key(&f[side / 3], side % 3), side))
                .collect();
            keys.sort();
            let edges = keys.chunk_by(|x, y| x.0 == y.0).count();
            assert_eq!(sums.sum.len(), edges);
            for g in keys.chunk_by(|x, y| x.0 == y.0) {
                let mut total = V3::zeros();
                for &(_, side) in g {
                    total += normals[side / 3];
                }
                for &(_, side) in g {
                    assert_eq!(sums.of(side), total, "side {side}");
                }
            }
            closed
        };
        assert!(!check(&v, &f));
        // 40 000 vertices: buckets numbered over many vertex ranges in parallel
        let (v, f) = crate::height_field(199, |x, y| 0.1 * (5.0 * x).sin() * y);
        assert!(!check(&v, &f));
        // the closed cube
        let cube = cube();
        assert!(cube.is_closed());
    }

    #[test]
    fn parallel_collapse_lays_out_the_wide_tree_as_one_pass() {
        // 80 000 triangles (a bumpy grid): the root's subtrees are collapsed in parallel
        let (v, f) = crate::height_field(200, |x, y| 0.05 * (9.0 * x).sin() * (7.0 * y).cos());
        let m = TriMesh::new(&v, &f).unwrap();
        let view = BinaryView {
            nodes: &m.nodes,
            triangles: &m.triangles,
            normals: &m.face_normals,
        };
        let (wide, blocks) = wide::collapse_serial(&view, 0);
        assert!(wide.len() > 1000 && m.wide[0].wide.iter().all(|&w| w & LEAF == 0));
        let show = |x: &dyn std::fmt::Debug| format!("{x:?}");
        assert_eq!(show(&m.wide), show(&wide));
        assert_eq!(show(&m.blocks), show(&blocks));
    }

    #[test]
    fn hierarchy_finds_the_nearest_of_many() {
        // a 60×60 grid of tilted triangles against brute force
        let mut v = vec![];
        let mut f = vec![];
        for i in 0..60 {
            for j in 0..60 {
                let k = v.len() as u32;
                let (x, y) = (i as f64 * 0.1, j as f64 * 0.1);
                v.push(V3::new(x, y, (x * 3.0).sin() * 0.1));
                v.push(V3::new(x + 0.08, y, (y * 2.0).cos() * 0.1));
                v.push(V3::new(x, y + 0.08, 0.05));
                f.push([k, k + 1, k + 2]);
            }
        }
        let m = TriMesh::new(&v, &f).unwrap();
        for q in 0..200 {
            let p = V3::new(
                (q as f64 * 0.37) % 6.5 - 0.2,
                (q as f64 * 0.61) % 6.3,
                0.3 - q as f64 * 0.003,
            );
            let r = m.project_point(&p, f64::INFINITY, usize::MAX).unwrap();
            let brute = f
                .iter()
                .map(|t| {
                    let (c, _) =
                        point_triangle(&p, &v[t[0] as usize], &v[t[1] as usize], &v[t[2] as usize]);
                    (c - p).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(r.distance.abs(), brute);
            let b = p + V3::new(0.05, -0.03, 0.01);
            let s = m.closest_to_segment(&p, &b, f64::INFINITY, q).unwrap();
            let brute = f
                .iter()
                .map(|t| {
                    let (_, x, y) = segment_triangle(
                        &p,
                        &b,
                        &v[t[0] as usize],
                        &v[t[1] as usize],
                        &v[t[2] as usize],
                    );
                    (x - y).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(s.distance, brute);
        }
    }

    #[test]
    fn disk_bounds_agree_with_brute_force_over_a_curved_surface() {
        // a bumpy height field (the clearance benchmark's shape, 40 × 40 quads) and points and
        // half-edge-like segments nearly parallel to it, where the slab/disk bounds of nodes
        // and triangles are tightest: the hierarchy must give the brute-force minimum exactly
        let h =
            |x: f64, y: f64| 0.1 * (x * 6.0).sin() * (y * 9.0).cos() + 0.05 * ((x + y) * 3.0).sin();
        let (v, f) = crate::height_field(40, h);
        let m = TriMesh::new(&v, &f).unwrap();
        let tri = |t: &[u32; 3]| [0, 1, 2].map(|k| v[t[k] as usize]);
        for q in 0..300 {
            let (x, y) = (
                0.1 + (q as f64 * 0.377) % 0.8,
                0.1 + (q as f64 * 0.613) % 0.8,
            );
            let lift = 0.01 + 0.002 * (q % 37) as f64;
            let a = V3::new(x, y, h(x, y) + lift);
            let dir = V3::new((q as f64).cos(), (q as f64).sin(), 0.0) * 0.03;
            let b = V3::new(
                a.x + dir.x,
                a.y + dir.y,
                h(a.x + dir.x, a.y + dir.y) + lift * 0.9,
            );
            let r = m.project_point(&a, f64::INFINITY, q).unwrap();
            let brute = f
                .iter()
                .map(|t| {
                    let [p, u, w] = tri(t);
                    (point_triangle(&a, &p, &u, &w).0 - a).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(r.distance, brute);
            for bound in [f64::INFINITY, brute * 1.01] {
                let s = m.closest_to_segment(&a, &b, bound, usize::MAX).unwrap();
                let brute = f
                    .iter()
                    .map(|t| {
                        let [p, u, w] = tri(t);
                        let (_, x, y) = segment_triangle(&a, &b, &p, &u, &w);
                        (x - y).norm()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(s.distance, brute, "query {q}");
            }
            // both half-edges of a node at a (to b and to a point on the other side) at once
            let c = V3::new(a.x - dir.y * 0.5, a.y + dir.x * 0.5, a.z - lift * 0.3);
            let seg_brute = |e: &V3| {
                f.iter()
                    .map(|t| {
                        let [p, u, w] = tri(t);
                        let (_, x, y) = segment_triangle(&a, e, &p, &u, &w);
                        (x - y).norm()
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let (db, dc) = (seg_brute(&b), seg_brute(&c));
            let (d, j, t) = m
                .nearest_of_segments(&a, &[b, c], f64::INFINITY, q)
                .unwrap();
            assert_eq!(d, db.min(dc), "query {q}");
            assert_eq!(d, if j == 0 { db } else { dc });
            let [p, u, w] = m.triangle(t);
            let e = if j == 0 { b } else { c };
            let (_, x, y) = segment_triangle(&a, &e, &p, &u, &w);
            assert_eq!((x - y).norm(), d);
            // nothing within a bound below the distance (d = 0: a half-edge crosses)
            if d > 0.0 {
                assert!(m.nearest_of_segments(&a, &[b, c], d * 0.99, t).is_none());
            }
        }
    }

    #[test]
    fn float32_hierarchy_is_exact_near_the_surface_and_far_from_the_origin() {
        // the wide tree's float32 bounds against brute force where their round-off matters:
        // a bumpy surface moved far from the origin (the allowance grows with the
        // coordinates), points and half-edges from 1e-9 to 1e-2 above it and just below it,
        let h = |x: f64, y: f64| 0.02 * (x * 11.0).sin() * (y * 7.0).cos();
        let n = 24;
        for offset in [
            V3::zeros(),
            V3::new(3.0, -2.0, 1.0),
            V3::new(250.0, 40.0, -90.0),
        ] {
            let mut v = vec![];
            for i in 0..=n {
                for j in 0..=n {
                    let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                    v.push(offset + V3::new(x, y, h(x, y)));
                }
            }
            // and a second sheet 1 µm above the first (a double wall): nearest triangles
            // decided by less than the float32 resolution of the coordinates
            let k0 = v.len() as u32;
            for k in 0..k0 as usize {
                v.push(v[k] + V3::new(0.0, 0.0, 1e-6));
            }
            let mut f = vec![];
            for sheet in [0, k0] {
                for i in 0..n {
                    for j in 0..n {
                        let a = sheet + (i * (n + 1) + j) as u32;
                        let (b, c, d) = (a + n as u32 + 1, a + 1, a + n as u32 + 2);
                        f.push([a, b, d]);
                        f.push([a, d, c]);
                    }
                }
            }
            let m = TriMesh::new(&v, &f).unwrap();
            let tri = |t: &[u32; 3]| [0, 1, 2].map(|k| v[t[k] as usize]);
            for q in 0..400 {
                let (x, y) = (
                    0.05 + (q as f64 * 0.377) % 0.9,
                    0.05 + (q as f64 * 0.613) % 0.9,
                );
                let lift = if q % 2 == 0 {
                    10f64.powf(-9.0 + 7.0 * (q % 13) as f64 / 12.0)
                        * if q % 5 == 0 { -1.0 } else { 1.0 }
                } else {
                    1e-6 * (q % 17) as f64 / 16.0 // between the sheets
                };
                let a = offset + V3::new(x, y, h(x, y) + lift);
                let dir = V3::new((q as f64).cos(), (q as f64).sin(), 0.0) * 0.02;
                let b = offset + V3::new(x + dir.x, y + dir.y, h(x + dir.x, y + dir.y) + lift);
                let c = offset + V3::new(x - dir.y, y + dir.x, h(x - dir.y, y + dir.x) + lift);
                let r = m.project_point(&a, f64::INFINITY, usize::MAX).unwrap();
                let brute = f
                    .iter()
                    .map(|t| {
                        let [p, u, w] = tri(t);
                        (point_triangle(&a, &p, &u, &w).0 - a).norm()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(r.distance.abs(), brute, "offset {offset:?} query {q}");
                let seg_brute = |e: &V3| {
                    f.iter()
                        .map(|t| {
                            let [p, u, w] = tri(t);
                            let (_, x, y) = segment_triangle(&a, e, &p, &u, &w);
                            (x - y).norm()
                        })
                        .fold(f64::INFINITY, f64::min)
                };
                let (d, _, _) = m
                    .nearest_of_segments(&a, &[b, c], f64::INFINITY, usize::MAX)
                    .unwrap();
                assert_eq!(
                    d,
                    seg_brute(&b).min(seg_brute(&c)),
                    "offset {offset:?} query {q}"
                );
            }
        }
    }

    #[test]
    fn bad_meshes_are_errors() {
        let v = vec![V3::zeros(), V3::x(), V3::y()];
        assert!(TriMesh::new(&v, &[]).is_err());
        assert!(TriMesh::new(&v, &[[0, 1, 3]]).is_err());
        assert!(TriMesh::new(&v, &[[0, 1, 1]]).is_err());
    }
}
