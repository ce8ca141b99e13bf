//! A 4-wide view of a binary bounding volume hierarchy, for the hot queries of the clearance.
//!
//! Each wide node holds the boxes of up to four nodes of the binary tree (its children and
//! grandchildren) in float32, structure of arrays (`min[axis][lane]`), so one visit tests four
//! boxes in loops the compiler turns into SIMD, and the tree takes a quarter of the memory
//! traffic of the float64 binary nodes. The float32 boxes are rounded outwards and the query
//! rounded down and up ([`Rounded`]), so a float32 box distance (scaled by [`F32_SAFE`]) is a
//! lower bound of the exact float64 distance: it only ever skips what the float64 test would
//! skip. The wide nodes also hold, where a lane's subtree is nearly flat, its slab and ball
//! ([`Disk4`]); leaf lanes point at their binary node (its triangle range) and at a block of
//! their triangles' planes and disks ([`Block4`]); the triangles are then measured exactly.
use rayon::prelude::*;
use wide::f32x8;

use crate::V3;

/// A lane with no node: an empty box (every distance infinite).
pub(crate) const EMPTY: u32 = u32::MAX;

/// A float32 squared box distance times this is at most the exact squared distance: the
/// outward-rounded boxes and the rounded query already bound the distance from below; six
/// float32 operations on it (a subtraction, three squares, two sums) each round up by at most
/// 2⁻²⁴ relative.
pub(crate) const F32_SAFE: f64 = 1.0 - 1e-6;

/// A lower bound of the exact squared distance from a float32 one of [`Wide::gaps2`]: scaled
/// by [`F32_SAFE`], less the absolute round-off of float32 results below the normal range.
#[inline(always)]
pub(crate) fn lower(g: f32) -> f64 {
    g as f64 * F32_SAFE - 4.0 * f32::MIN_POSITIVE as f64
}

/// Lane indices in increasing order of `g` (empty lanes, infinite, last).
#[inline(always)]
pub(crate) fn order(g: &[f32; 4]) -> [usize; 4] {
    let mut o = [0, 1, 2, 3];
    for i in 1..4 {
        let mut j = i;
        while j > 0 && g[o[j - 1]] > g[o[j]] {
            o.swap(j - 1, j);
            j -= 1;
        }
    }
    o
}

#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Wide {
    pub min: [[f32; 4]; 3],
    pub max: [[f32; 4]; 3],
    /// Per lane: the binary node (`EMPTY`: none).
    pub node: [u32; 4],
    /// Per lane: the wide node of an inner binary node, `LEAF | block` for a leaf (its
    /// triangles' disks in `blocks[block]`), `EMPTY` for none.
    pub wide: [u32; 4],
    /// Per lane: the node's slab and ball ([`Disk4::NONE`] lanes without).
    pub disk: Disk4,
}

impl Wide {
    /// Whether a lane has a slab and ball (nodes of up to `SLAB_MAX` triangles, near the
    /// leaves): the boxes alone bound the others, so their disk bounds are not computed.
    #[inline(always)]
    pub fn has_disk(&self) -> bool {
        self.disk.radius != [f32::INFINITY; 4]
    }

    /// Whether every lane has a slab and ball.
    #[inline(always)]
    pub fn all_disks(&self) -> bool {
        self.disk.radius.iter().all(|r| r.is_finite())
    }
}

/// Flag of a leaf lane in [`Wide::wide`].
pub(crate) const LEAF: u32 = 1 << 31;

/// The float32 round-off allowance of [`Disk4`] bounds for a query whose coordinates and
/// the mesh's are at most `scale` in magnitude: every float32 quantity of the bounds (the
/// rounded query and stored data, and a dozen operations on them) is within a few dozen
/// 2⁻²⁴·scale of its exact value; 2⁻¹⁶·scale covers that with a margin of ×4 or more.
/// Infinite (no pruning) where float32 squares could overflow.
#[inline]
pub(crate) fn pad(scale: f64) -> f32 {
    if scale < 1e15 {
        f32_up(scale * (1.0 / 65536.0))
    } else {
        f32::INFINITY
    }
}

/// Four thin disk-like sets in float32, structure of arrays: per lane the points z with
/// axis·z in [lo, hi] and |P(z − center)| ≤ radius (P the projection across the unit axis),
/// a node's slab and ball or a triangle (its plane, lo = hi, and circumscribed disk about the
/// centroid). The bounds are those of the float64 `disk_excludes` (first stage), less the
/// allowance [`pad`] on each gap, so they stay below the exact distance.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(crate) struct Disk4 {
    pub axis: [[f32; 4]; 3],
    pub lo: [f32; 4],
    pub hi: [f32; 4],
    pub center: [[f32; 4]; 3],
    pub radius: [f32; 4],
}

impl Disk4 {
    /// Every lane unbounded (bound 0): no slab.
    pub const NONE: Disk4 = Disk4 {
        axis: [[0.0; 4]; 3],
        lo: [f32::NEG_INFINITY; 4],
        hi: [f32::INFINITY; 4],
        center: [[0.0; 4]; 3],
        radius: [f32::INFINITY; 4],
    };

    /// Lane `l` holds the set (axis unit; lo, hi, radius already widened for the float64
    /// round-off of their computation).
    pub fn set(&mut self, l: usize, axis: &V3, lo: f64, hi: f64, center: &V3, radius: f64) {
        for k in 0..3 {
            self.axis[k][l] = axis[k] as f32;
            self.center[k][l] = center[k] as f32;
        }
        self.lo[l] = f32_down(lo);
        self.hi[l] = f32_up(hi);
        self.radius[l] = f32_up(radius);
    }

    /// Lower bounds of the squared distances of point p (float32) to the four sets.
    #[inline(always)]
    pub fn point_bounds2(&self, p: &[f32; 3], pad: f32) -> [f32; 4] {
        let mut out = [0.0f32; 4];
        for (l, o) in out.iter_mut().enumerate() {
            let a = [self.axis[0][l], self.axis[1][l], self.axis[2][l]];
            let v = [
                p[0] - self.center[0][l],
                p[1] - self.center[1][l],
                p[2] - self.center[2][l],
            ];
            let x = a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
            let h = ((self.lo[l] - x).max(x - self.hi[l]) - pad).max(0.0);
            let av = a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
            let w = [v[0] - a[0] * av, v[1] - a[1] * av, v[2] - a[2] * av];
            let wn = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            let lat = (wn - self.radius[l] - pad).max(0.0);
            *o = h * h + lat * lat;
        }
        out
    }
}

/// Four lanes twice (eight lanes: both halves the same).
#[inline(always)]
fn twice(v: &[f32; 4]) -> f32x8 {
    f32x8::from([v[0], v[1], v[2], v[3], v[0], v[1], v[2], v[3]])
}

/// `x` in lanes 0–3, `y` in lanes 4–7.
#[inline(always)]
fn halves(x: f32, y: f32) -> f32x8 {
    f32x8::from([x, x, x, x, y, y, y, y])
}

impl Disk4 {
    /// Lower bounds of the squared distances of two segments from one start `a` to `b[0]` and
    /// `b[1]` (the two half-edges of a cable node; one segment: given twice) to the four
    /// sets, `pad` per segment. The larger of two bounds: the least axial gap over the
    /// segment and the least in-plane offset of the projected segment beyond the radius,
    /// taken apart; and the tangents at the segment's ends of the (convex) squared distance
    /// to the set along it. Eight lanes: 0–3 the first segment, 4–7 the second (the `wide`
    /// crate's 8-lane vectors: AVX where built with it, two SSE halves otherwise).
    ///
    /// With a finite `best` (a squared distance, rounded up), the second stage of the float64
    /// `disk_excludes` follows: a lane whose set is certainly farther than sqrt(best) is
    /// infinite (out), the others keep the bound. Leaf blocks use it: there it excludes
    /// nearly all the triangles a float64 test of their disks did, which is then left out.
    #[inline(always)]
    pub fn segment_bounds2_pair(
        &self,
        a: &[f32; 3],
        b: &[[f32; 3]; 2],
        pad: [f32; 2],
        best: f32,
    ) -> [f32; 8] {
        let zero = f32x8::ZERO;
        let pad = halves(pad[0], pad[1]);
        let n = [
            twice(&self.axis[0]),
            twice(&self.axis[1]),
            twice(&self.axis[2]),
        ];
        let av = [f32x8::splat(a[0]), f32x8::splat(a[1]), f32x8::splat(a[2])];
        let d: [f32x8; 3] = std::array::from_fn(|k| halves(b[0][k] - a[k], b[1][k] - a[k]));
        let xa = n[0] * av[0] + n[1] * av[1] + n[2] * av[2];
        let xd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        let xb = xa + xd;
        let (lo, hi) = (twice(&self.lo), twice(&self.hi));
        let g = ((lo - xa.max(xb)).max(xa.min(xb) - hi) - pad).max(zero);
        let u: [f32x8; 3] = std::array::from_fn(|k| av[k] - twice(&self.center[k]));
        let xu = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
        let pu: [f32x8; 3] = std::array::from_fn(|k| u[k] - n[k] * xu);
        let e: [f32x8; 3] = std::array::from_fn(|k| d[k] - n[k] * xd);
        let l2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        let pe = pu[0] * e[0] + pu[1] * e[1] + pu[2] * e[2];
        // l2 = 0 (e = 0, so pe = 0): 0/0 is NaN, and max(NaN, 0) = 0 in `wide` (the start)
        let s0 = -pe / l2;
        let s = s0.max(zero).min(f32x8::ONE);
        let q: [f32x8; 3] = std::array::from_fn(|k| pu[k] + e[k] * s);
        let qn = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        let radius = twice(&self.radius);
        let lat = (qn - radius - pad).max(zero);
        let first = g * g + lat * lat;
        // tangents: with the pads, f(s) = gap(s)² + lat(s)² over the segment (s in [0, 1]) is
        // convex (each term the square of a non-negative convex function) and continuously
        // differentiable, so it lies above its tangents at both ends, and the least value of
        // their upper envelope bounds it from below: the value at an end where f rises into
        // the segment, else where the tangents cross. Tight where the nearest point is an
        // end, as where a cable's segment passes obliquely above an inclined part of a
        // surface, which the first stage's gap and offset taken apart are not
        let two = f32x8::splat(2.0);
        let tiny = f32x8::splat(f32::MIN_POSITIVE);
        // at an end x (axial) and q (across): (gap, d(gap²)/ds) and (lat, d(lat²)/ds)
        let gap_at = |x: f32x8| {
            let (up, down) = ((x - hi).max(zero), (lo - x).max(zero));
            let gap = (up.max(down) - pad).max(zero);
            (gap, two * gap * up.simd_gt(zero).select(xd, -xd))
        };
        let lat_at = |q: [f32x8; 3]| {
            let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            let lat = (n - radius - pad).max(zero);
            let qe = q[0] * e[0] + q[1] * e[1] + q[2] * e[2];
            (lat, two * lat * qe / n.max(tiny))
        };
        let ((ga, dga), (gb, dgb)) = (gap_at(xa), gap_at(xb));
        let ((la, dla), (lb, dlb)) = (lat_at(pu), lat_at(std::array::from_fn(|k| pu[k] + e[k])));
        let (f0, f1) = (ga * ga + la * la, gb * gb + lb * lb);
        let (d0, d1) = (dga + dla, dgb + dlb);
        let cross = ((f1 - d1 - f0) / (d0 - d1)).max(zero).min(f32x8::ONE);
        let tangent = d0
            .simd_ge(zero)
            .select(f0, d1.simd_le(zero).select(f1, f0 + d0 * cross));
        // float32 round-off of the values and of the slopes of the tangents used (a few 2⁻²⁴
        // of each, also for the sign of a slope and where the tangents cross): 1e-5 allowed
        let (slopes0, slopes1) = (dga.abs() + dla.abs(), dgb.abs() + dlb.abs());
        let slopes = d0
            .simd_ge(zero)
            .select(slopes0, d1.simd_le(zero).select(slopes1, slopes0 + slopes1));
        let tangent = tangent - (tangent.abs() + slopes) * f32x8::splat(1e-5);
        let bound = first.max(tangent);
        if !best.is_finite() {
            return bound.to_array();
        }
        // second stage (as the float64 `disk_excludes`): only the part of the segment whose
        // in-plane offset is within r + m, m² = best − g², can come nearer than best; the set
        // is out if the axial gap over that part exceeds it. Widened for float32 round-off:
        // m and the reach by the pad, the part by 2⁻¹⁰ of the segment and of its half width
        // (far above float32's 2⁻²⁴); only where the projected segment is not short against
        // the segment (the part's ends then well-conditioned)
        let bestv = f32x8::splat(best);
        let m = (bestv - g * g).max(zero).sqrt();
        let reach = radius + m + pad + pad;
        let q0: [f32x8; 3] = std::array::from_fn(|k| pu[k] + e[k] * s0);
        let lat0 = ((q0[0] * q0[0] + q0[1] * q0[1] + q0[2] * q0[2]).sqrt() - pad).max(zero);
        let disc = reach * reach - lat0 * lat0;
        const WIDEN: f32 = 1.0 / 1024.0;
        let delta = (disc.max(zero) / l2).sqrt() * f32x8::splat(1.0 + WIDEN) + f32x8::splat(WIDEN);
        let s1 = (s0 - delta).max(zero);
        let s2 = (s0 + delta).min(f32x8::ONE);
        let (x1, x2) = (xa + xd * s1, xa + xd * s2);
        let gi = ((lo - x1.max(x2)).max(x1.min(x2) - hi) - pad).max(zero);
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let staged = l2.simd_gt(dd * f32x8::splat(1e-4))
            & disc.simd_ge(zero)
            & s1.simd_le(s2)
            & (gi * gi).simd_gt(bestv);
        staged.select(f32x8::splat(f32::INFINITY), bound).to_array()
    }
}

/// A leaf's triangle disks ([`Disk4`]) in float32 coordinates relative to the block's own
/// origin, a float32 point near them: the round-off of the bounds, and so the allowance
/// [`pad`], scale with the distances within the block and to the query instead of with the
/// distance from the global origin (1 m away, 2⁻¹⁶ m ≈ 15 µm; 2 cm from a block, 0.3 µm).
/// The query is shifted in float64 (exact to 2⁻⁵³ of the shift's size, far below the pad).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(crate) struct Block4 {
    pub disk: Disk4,
    /// The origin (a float32 point: the same in float64).
    pub origin: [f32; 3],
    /// The largest magnitude of the block's float32 coordinates (centers, plane offsets).
    pub extent: f32,
}

impl Block4 {
    pub const NONE: Block4 = Block4 {
        disk: Disk4::NONE,
        origin: [0.0; 3],
        extent: 0.0,
    };

    /// The block of up to four triangles' planes and disks (normal, n·c, n·c, centroid c,
    /// circumradius; global), about the first centroid.
    pub fn new(disks: &[(V3, f64, f64, V3, f64)]) -> Self {
        let mut b = Block4::NONE;
        let Some(first) = disks.first() else {
            return b;
        };
        b.origin = f32x3(&first.3);
        let o = b.origin_f64();
        let mut extent: f64 = 0.0;
        for (l, (n, _, _, c, r)) in disks.iter().enumerate() {
            let c = c - o;
            let x = n.dot(&c);
            b.disk.set(l, n, x, x, &c, *r);
            extent = extent.max(c.amax()).max(x.abs());
        }
        b.extent = f32_up(extent);
        b
    }

    #[inline(always)]
    fn origin_f64(&self) -> V3 {
        V3::new(
            self.origin[0] as f64,
            self.origin[1] as f64,
            self.origin[2] as f64,
        )
    }

    /// A query point in the block's frame (float32) and the magnitude that sets its
    /// allowance (with the block's extent).
    #[inline(always)]
    pub fn local(&self, p: &V3) -> ([f32; 3], f64) {
        let q = p - self.origin_f64();
        (f32x3(&q), q.amax().max(self.extent as f64))
    }

    /// [`Disk4::point_bounds2`] of the global point p.
    #[inline(always)]
    pub fn point_bounds2(&self, p: &V3) -> [f32; 4] {
        let (q, m) = self.local(p);
        self.disk.point_bounds2(&q, local_pad(m))
    }

    /// [`Disk4::segment_bounds2_pair`] of the two segments from `a` (given by
    /// [`Self::local`]) to the global points `b[0]` and `b[1]`.
    #[inline(always)]
    pub fn segment_bounds2_pair(
        &self,
        (a, ma): &([f32; 3], f64),
        b: [&V3; 2],
        best: f32,
    ) -> [f32; 8] {
        let ((q0, m0), (q1, m1)) = (self.local(b[0]), self.local(b[1]));
        let pad = [local_pad(ma.max(m0)), local_pad(ma.max(m1))];
        self.disk.segment_bounds2_pair(a, &[q0, q1], pad, best)
    }
}

/// [`pad`] for [`Block4`] queries, without rounding up (round to nearest: within 2⁻²⁴ of
/// it, well inside its margin) to keep it cheap; infinite (no pruning) where float32 squares
/// could overflow.
#[inline(always)]
fn local_pad(scale: f64) -> f32 {
    if scale < 1e15 {
        scale as f32 * (1.0 / 65536.0)
    } else {
        f32::INFINITY
    }
}

/// A float64 point rounded to nearest float32.
#[inline(always)]
pub(crate) fn f32x3(p: &V3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// float32 nearest below / above a float64 (infinities stay).
#[inline(always)]
pub(crate) fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f.next_down()
    } else {
        f
    }
}

#[inline(always)]
pub(crate) fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

/// A box [lo, hi] in float32 holding a float64 box (a point: lo = hi).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rounded {
    pub lo: [f32; 3],
    pub hi: [f32; 3],
}

impl Rounded {
    #[inline(always)]
    pub fn new(lo: &V3, hi: &V3) -> Self {
        Rounded {
            lo: [f32_down(lo.x), f32_down(lo.y), f32_down(lo.z)],
            hi: [f32_up(hi.x), f32_up(hi.y), f32_up(hi.z)],
        }
    }
}

impl Wide {
    /// [`Self::gaps2`] of two boxes in eight lanes (0–3: `q[0]`, 4–7: `q[1]`; the same
    /// values).
    #[inline(always)]
    pub fn gaps2_pair(&self, q: &[Rounded; 2]) -> [f32; 8] {
        let mut d2 = f32x8::ZERO;
        for k in 0..3 {
            let e = (twice(&self.min[k]) - halves(q[0].hi[k], q[1].hi[k]))
                .max(halves(q[0].lo[k], q[1].lo[k]) - twice(&self.max[k]))
                .max(f32x8::ZERO);
            d2 += e * e;
        }
        d2.to_array()
    }

    /// A node with no lanes.
    const EMPTY: Wide = Wide {
        min: [[f32::INFINITY; 4]; 3],
        max: [[f32::NEG_INFINITY; 4]; 3],
        node: [EMPTY; 4],
        wide: [EMPTY; 4],
        disk: Disk4::NONE,
    };

    /// Lower bounds (float32, see [`F32_SAFE`]) of the squared distances between the box q
    /// and the four lanes' boxes; infinite for empty lanes.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // structure of arrays: lane l of each
    pub fn gaps2(&self, q: &Rounded) -> [f32; 4] {
        let mut d2 = [0.0f32; 4];
        for k in 0..3 {
            for l in 0..4 {
                let e = (self.min[k][l] - q.hi[k])
                    .max(q.lo[k] - self.max[k][l])
                    .max(0.0);
                d2[l] += e * e;
            }
        }
        d2
    }
}

/// The binary tree as the wide builder sees it.
pub(crate) trait Binary {
    /// The node's box.
    fn bounds(&self, node: u32) -> (V3, V3);
    /// An inner node's two children (None: a leaf).
    fn children(&self, node: u32) -> Option<(u32, u32)>;
    /// A leaf's triangles (first, count ≤ 4).
    fn triangles(&self, node: u32) -> (usize, usize);
    /// The node's slab and ball (axis, lo, hi, center, radius), if it has one.
    fn slab(&self, node: u32) -> Option<(V3, f64, f64, V3, f64)>;
    /// Triangle t's plane and disk (normal, n·c, n·c, centroid c, circumradius).
    fn disk(&self, t: usize) -> (V3, f64, f64, V3, f64);
    fn size(&self, node: u32) -> f64 {
        let (lo, hi) = self.bounds(node);
        let e = hi - lo;
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// Wide nodes over the binary tree rooted at `root` (wide node 0 holds the root's children,
/// or the root itself when it is a leaf) and the leaves' triangle disks. The subtrees under
/// wide node 0 are counted, then collapsed in parallel into their places of arrays laid out
/// as one depth-first pass would lay them out (the same arrays, no copies).
pub(crate) fn collapse<T: Binary + Sync + ?Sized>(tree: &T, root: u32) -> (Vec<Wide>, Vec<Block4>) {
    let lanes = match tree.children(root) {
        Some(c) => lanes_of(tree, c),
        None => ([root, 0, 0, 0], 1),
    };
    let lanes = &lanes.0[..lanes.1];
    // per lane of wide node 0: its subtree's wide nodes and blocks, and their lanes
    let (sizes, plans): (Vec<(usize, usize)>, Vec<Vec<Lanes>>) = lanes
        .par_iter()
        .map(|&n| {
            let mut plan = Vec::new();
            let size = tree
                .children(n)
                .map_or((0, 1), |c| count(tree, lanes_of(tree, c), &mut plan));
            (size, plan)
        })
        .unzip();
    let n_wide = 1 + sizes.iter().map(|s| s.0).sum::<usize>();
    let n_blocks = sizes.iter().map(|s| s.1).sum::<usize>();
    let mut wide: Vec<Wide> = (0..n_wide).into_par_iter().map(|_| Wide::EMPTY).collect();
    let mut blocks: Vec<Block4> = (0..n_blocks)
        .into_par_iter()
        .map(|_| Block4::NONE)
        .collect();
    let (head, mut wide_rest) = wide.split_at_mut(1);
    let mut block_rest = blocks.as_mut_slice();
    let mut sinks = Vec::with_capacity(lanes.len());
    let (mut w_base, mut b_base) = (1u32, 0u32);
    for &(nw, nb) in &sizes {
        let (w, wr) = std::mem::take(&mut wide_rest).split_at_mut(nw);
        let (b, br) = std::mem::take(&mut block_rest).split_at_mut(nb);
        sinks.push(Sink {
            wide: w,
            blocks: b,
            n_wide: 0,
            n_blocks: 0,
            w_base,
            b_base,
        });
        (wide_rest, block_rest) = (wr, br);
        (w_base, b_base) = (w_base + nw as u32, b_base + nb as u32);
    }
    let links: Vec<u32> = lanes
        .par_iter()
        .zip(sinks)
        .zip(plans)
        .map(|((&n, mut sink), plan)| match tree.children(n) {
            Some(_) => push(tree, &mut plan.into_iter(), &mut sink),
            None => leaf_block(tree, n, &mut sink),
        })
        .collect();
    for (l, (&n, link)) in lanes.iter().zip(links).enumerate() {
        set_lane(tree, &mut head[0], l, n);
        head[0].wide[l] = link;
    }
    (wide, blocks)
}

/// Where [`push`] writes a subtree: its part of the wide nodes and of the blocks, how many
/// it wrote, and the index of the part's first node and block in the whole arrays.
struct Sink<'a> {
    wide: &'a mut [Wide],
    blocks: &'a mut [Block4],
    n_wide: usize,
    n_blocks: usize,
    w_base: u32,
    b_base: u32,
}

/// Up to four lanes (binary nodes) of a wide node.
type Lanes = ([u32; 4], usize);

/// `lanes` with the largest inner lanes opened until there are four (or only leaves).
fn open<T: Binary + ?Sized>(tree: &T, (mut lanes, mut len): Lanes) -> Lanes {
    while len < 4 {
        let open = lanes[..len]
            .iter()
            .enumerate()
            .filter(|(_, &n)| tree.children(n).is_some())
            .max_by(|a, b| tree.size(*a.1).total_cmp(&tree.size(*b.1)));
        let Some((i, &n)) = open else { break };
        let (l, r) = tree.children(n).unwrap();
        lanes[i] = l;
        lanes[len] = r;
        len += 1;
    }
    (lanes, len)
}

/// The lanes of an inner node's wide node: its two children, opened.
fn lanes_of<T: Binary + ?Sized>(tree: &T, (a, b): (u32, u32)) -> Lanes {
    open(tree, ([a, b, 0, 0], 2))
}

/// The wide nodes and blocks [`push`] writes for the wide node of `lanes`, whose lanes (and
/// those of the wide nodes below, depth first) go to `plan` for [`push`].
fn count<T: Binary + ?Sized>(tree: &T, lanes: Lanes, plan: &mut Vec<Lanes>) -> (usize, usize) {
    plan.push(lanes);
    let mut n = (1, 0);
    for &l in &lanes.0[..lanes.1] {
        let (w, b) = tree
            .children(l)
            .map_or((0, 1), |c| count(tree, lanes_of(tree, c), plan));
        n = (n.0 + w, n.1 + b);
    }
    n
}

/// Lane `l` of `w` for binary node `n`: its box, index and slab (not its link).
fn set_lane<T: Binary + ?Sized>(tree: &T, w: &mut Wide, l: usize, n: u32) {
    let (lo, hi) = tree.bounds(n);
    let r = Rounded::new(&lo, &hi);
    for k in 0..3 {
        w.min[k][l] = r.lo[k];
        w.max[k][l] = r.hi[k];
    }
    w.node[l] = n;
    if let Some((axis, slo, shi, center, radius)) = tree.slab(n) {
        w.disk.set(l, &axis, slo, shi, &center, radius);
    }
}

/// Writes the triangle disks of leaf `n` as the sink's next block; returns its link
/// (`LEAF | block`).
fn leaf_block<T: Binary + ?Sized>(tree: &T, n: u32, sink: &mut Sink) -> u32 {
    let (first, count) = tree.triangles(n);
    assert!(count <= 4, "a leaf holds at most 4 triangles");
    let mut disks = [(V3::zeros(), 0.0, 0.0, V3::zeros(), 0.0); 4];
    for (i, d) in disks.iter_mut().enumerate().take(count) {
        *d = tree.disk(first + i);
    }
    sink.blocks[sink.n_blocks] = Block4::new(&disks[..count]);
    sink.n_blocks += 1;
    LEAF | (sink.b_base + sink.n_blocks as u32 - 1)
}

/// [`collapse`] in one depth-first pass (what the parallel one must equal).
#[cfg(test)]
pub(crate) fn collapse_serial<T: Binary + ?Sized>(tree: &T, root: u32) -> (Vec<Wide>, Vec<Block4>) {
    let lanes = match tree.children(root) {
        Some(c) => lanes_of(tree, c),
        None => ([root, 0, 0, 0], 1),
    };
    let mut plan = Vec::new();
    let (n_wide, n_blocks) = count(tree, lanes, &mut plan);
    let mut out = (vec![Wide::EMPTY; n_wide], vec![Block4::NONE; n_blocks]);
    let mut sink = Sink {
        wide: &mut out.0,
        blocks: &mut out.1,
        n_wide: 0,
        n_blocks: 0,
        w_base: 0,
        b_base: 0,
    };
    push(tree, &mut plan.into_iter(), &mut sink);
    out
}

/// Writes the next wide node of `plan` (its lanes, as [`count`] opened them) and, depth
/// first, those of its inner lanes; returns its index.
fn push<T: Binary + ?Sized>(
    tree: &T,
    plan: &mut impl Iterator<Item = Lanes>,
    sink: &mut Sink,
) -> u32 {
    let (lanes, len) = plan.next().expect("a plan for every wide node");
    let at = sink.n_wide;
    sink.n_wide += 1;
    for (l, &n) in lanes[..len].iter().enumerate() {
        set_lane(tree, &mut sink.wide[at], l, n);
        sink.wide[at].wide[l] = match tree.children(n) {
            Some(_) => push(tree, plan, sink),
            None => leaf_block(tree, n, sink),
        };
    }
    sink.w_base + at as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_brackets_the_value() {
        for x in [
            0.1,
            -0.1,
            1.0 / 3.0,
            -2.0 / 3.0,
            1e-40,
            -1e-40,
            0.0,
            1e30,
            123456.789,
            f64::INFINITY,
        ] {
            let (lo, hi) = (f32_down(x), f32_up(x));
            assert!((lo as f64) <= x && x <= hi as f64, "{x}");
            // the nearest ones: one float32 step at most
            assert!(lo == hi || lo.next_up() == hi, "{x}");
        }
        assert_eq!(order(&[3.0, f32::INFINITY, 1.0, 2.0]), [2, 3, 0, 1]);
        assert_eq!(f32_down(0.5), 0.5);
        assert_eq!(f32_up(0.5), 0.5);
    }

    #[test]
    fn float32_gaps_are_lower_bounds() {
        // boxes and points chosen so that float32 rounding to nearest would overestimate the
        // gap (the box's face and the point a fraction of a float32 step apart): the bound
        // must stay at or below the exact float64 distance, times F32_SAFE
        let mut rnd = crate::test_random(7);
        for _ in 0..20000 {
            let scale = [1e-3, 1.0, 1e3][(rnd() * 3.0) as usize % 3];
            let lo = V3::new(rnd(), rnd(), rnd()) * scale;
            let hi = lo + V3::new(rnd(), rnd(), rnd()) * scale * 0.1;
            // a point just outside a face, gaps from ~1 float32 step to a box size
            let gap = scale * 10f64.powf(-9.0 * rnd());
            let mut p = (lo + hi) * 0.5;
            let k = (rnd() * 3.0) as usize % 3;
            p[k] = if rnd() < 0.5 {
                lo[k] - gap
            } else {
                hi[k] + gap
            };
            let exact2 = {
                let e = (lo - p).sup(&(p - hi)).sup(&V3::zeros());
                e.norm_squared()
            };
            let r = Rounded::new(&lo, &hi);
            let mut w = Wide {
                min: [[f32::INFINITY; 4]; 3],
                max: [[f32::NEG_INFINITY; 4]; 3],
                node: [EMPTY; 4],
                wide: [EMPTY; 4],
                disk: Disk4::NONE,
            };
            for j in 0..3 {
                w.min[j][1] = r.lo[j];
                w.max[j][1] = r.hi[j];
            }
            let g = w.gaps2(&Rounded::new(&p, &p));
            assert!(lower(g[1]) <= exact2, "{lo:?} {hi:?} {p:?}");
            assert!(g[0].is_infinite() && g[2].is_infinite() && g[3].is_infinite());
        }
    }

    /// The size of case `case`'s triangles (1 mm, 1 m, 1 km in turn) and their offset from the
    /// origin (0, 10 or 1000 × the size, in turn over three cases).
    fn case_scale(rnd: &mut impl FnMut() -> f64, case: usize) -> (f64, V3) {
        let size = [1e-3, 1.0, 1e3][case % 3];
        let off = V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)
            * size
            * [0.0, 10.0, 1000.0][case / 3 % 3];
        (size, off)
    }

    /// A triangle's plane and circumscribed disk about its centroid, as the mesh stores them:
    /// (normal, n·c, n·c, centroid c, radius).
    fn triangle_disk(v: &[V3]) -> (V3, f64, f64, V3, f64) {
        let n = (v[1] - v[0]).cross(&(v[2] - v[0])).normalize();
        let c = (v[0] + v[1] + v[2]) / 3.0;
        let r = v.iter().map(|x| (x - c).norm()).fold(0.0, f64::max) * (1.0 + 1e-12);
        (n, n.dot(&c), n.dot(&c), c, r)
    }

    /// A point near triangle v of normal n (on it, lifted by 1e-12 … 1 of its size, moved
    /// across by up to 1 % of it) and the end of a segment from there (nearly parallel to the
    /// triangle, up to 20 % of its size long).
    fn near_point_and_segment(
        rnd: &mut impl FnMut() -> f64,
        v: &[V3],
        n: &V3,
        size: f64,
    ) -> (V3, V3) {
        let (w0, w1) = (rnd(), rnd());
        let (w0, w1) = if w0 + w1 > 1.0 {
            (1.0 - w0, 1.0 - w1)
        } else {
            (w0, w1)
        };
        let on = v[0] + (v[1] - v[0]) * w0 + (v[2] - v[0]) * w1;
        let lift = size * 10f64.powf(-12.0 * rnd());
        let p = on
            + n * lift * if rnd() < 0.5 { 1.0 } else { -1.0 }
            + V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * size * 0.01 * rnd().powi(4);
        let b = p
            + (V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.2 + n * 0.01 * (rnd() - 0.5))
                * size;
        (p, b)
    }

    /// `k` triangles of [`random_triangle`] and their disks ([`triangle_disk`]).
    #[allow(clippy::type_complexity)]
    fn random_triangles(
        k: usize,
        rnd: &mut impl FnMut() -> f64,
        size: f64,
        off: V3,
    ) -> (Vec<Vec<V3>>, Vec<(V3, f64, f64, V3, f64)>) {
        let tris: Vec<Vec<V3>> = (0..k).map(|_| random_triangle(rnd, size, off)).collect();
        let disks = tris.iter().map(|v| triangle_disk(v)).collect();
        (tris, disks)
    }

    /// A triangle with corners uniform in the cube of side `size` at `off`.
    fn random_triangle(rnd: &mut impl FnMut() -> f64, size: f64, off: V3) -> Vec<V3> {
        (0..3)
            .map(|_| off + V3::new(rnd(), rnd(), rnd()) * size)
            .collect()
    }

    /// Random triangles at scales 1 mm … 1 km and offsets up to 1000 × their size from the
    /// origin, and points and segments near them (nearly touching, nearly parallel, far):
    /// the float32 plane-and-disk bounds must stay at or below the exact distances, and
    /// without the round-off allowance they would not (the test sees the rounding).
    #[test]
    fn float32_disk_bounds_are_lower_bounds() {
        use crate::closest::{point_triangle, segment_triangle};
        let mut rnd = crate::test_random(99);
        let mut over_without_pad = 0;
        for case in 0..20000 {
            let (size, off) = case_scale(&mut rnd, case);
            let v = random_triangle(&mut rnd, size, off);
            let (n, x, _, c, r) = triangle_disk(&v);
            let mut disk = Disk4::NONE;
            disk.set(0, &n, x, x, &c, r);
            let (p, b) = near_point_and_segment(&mut rnd, &v, &n, size);
            let scale = v
                .iter()
                .chain([&p, &b])
                .fold(0.0, |m: f64, x| m.max(x.amax()));
            let exact_p = (point_triangle(&p, &v[0], &v[1], &v[2]).0 - p).norm_squared();
            let (_, sx, sy) = segment_triangle(&p, &b, &v[0], &v[1], &v[2]);
            let exact_s = (sx - sy).norm_squared();
            let (pf, bf) = (f32x3(&p), f32x3(&b));
            let gp = disk.point_bounds2(&pf, pad(scale))[0];
            let gs = disk.segment_bounds2_pair(&pf, &[bf, bf], [pad(scale); 2], f32::INFINITY)[0];
            assert!(
                lower(gp) <= exact_p,
                "point, case {case}: {} > {exact_p}",
                lower(gp)
            );
            assert!(
                lower(gs) <= exact_s,
                "segment, case {case}: {} > {exact_s}",
                lower(gs)
            );
            let gp0 = disk.point_bounds2(&pf, 0.0)[0];
            let gs0 = disk.segment_bounds2_pair(&pf, &[bf, bf], [0.0; 2], f32::INFINITY)[0];
            if lower(gp0) > exact_p || lower(gs0) > exact_s {
                over_without_pad += 1;
            }
            // the bound is not void: where the nearest point is inside the face, it is the
            // plane distance less the allowance
            let hp = n.dot(&(p - c)).abs();
            if (exact_p.sqrt() - hp).abs() < 1e-9 * size {
                let h = (hp - 2.0 * pad(scale) as f64).max(0.0);
                assert!(gp as f64 >= 0.98 * h * h, "case {case}");
            }
        }
        assert!(over_without_pad > 100, "{over_without_pad}");
    }

    /// The eight-lane bounds of two segments (the two half-edges of a node) are those of each
    /// segment alone (given twice), to the last bit: wide-node disks (also with the best so
    /// far), leaf blocks in their frame, and the boxes are the four-lane ones; full and empty
    /// lanes, scales from 1 mm to 1 km, a zero-length segment, a segment along a slab's axis.
    #[test]
    fn eight_lanes_are_each_segments_own_bounds() {
        let mut rnd = crate::test_random(17);
        let same =
            |x: [f32; 4], y: &[f32]| x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits());
        // a pair's lanes are each segment's own (that segment given twice: both halves equal)
        let own = |pair: &[f32; 8], one: &[f32; 8], other: &[f32; 8]| {
            let half = |x: &[f32]| -> [f32; 4] { x.try_into().unwrap() };
            same(half(&one[..4]), &pair[..4])
                && same(half(&other[4..]), &pair[4..])
                && same(half(&one[..4]), &one[4..])
        };
        for case in 0..5000 {
            let (size, off) = case_scale(&mut rnd, case);
            let (tris, disks) = random_triangles(3, &mut rnd, size, off);
            // a disk lane per triangle, lane 3 empty (NONE), as wide nodes and leaves have
            let mut disk = Disk4::NONE;
            for (l, (n, x, _, c, r)) in disks.iter().enumerate() {
                disk.set(l, n, *x, *x + size * rnd(), c, *r);
            }
            let (a, b0) = near_point_and_segment(&mut rnd, &tris[0], &disks[0].0, size);
            let b1 = match case % 5 {
                0 => a,                                     // zero length
                1 => a + disks[0].0 * size * (rnd() + 0.1), // along the axis of lane 0
                _ => near_point_and_segment(&mut rnd, &tris[1], &disks[1].0, size).1,
            };
            let scale = [a, b0, b1].iter().fold(size, |m: f64, x| m.max(x.amax()));
            let (af, b0f, b1f) = (f32x3(&a), f32x3(&b0), f32x3(&b1));
            for best in [f32::INFINITY, f32_up(size * size * rnd())] {
                let (p0, p1) = (pad(scale), 0.5 * pad(scale));
                let pair = disk.segment_bounds2_pair(&af, &[b0f, b1f], [p0, p1], best);
                let one = disk.segment_bounds2_pair(&af, &[b0f, b0f], [p0, p0], best);
                let other = disk.segment_bounds2_pair(&af, &[b1f, b1f], [p1, p1], best);
                assert!(own(&pair, &one, &other), "case {case}");
            }
            // boxes: a node's four lanes (the last empty) against the two segments' boxes
            let mut w = Wide::EMPTY;
            for (l, v) in tris.iter().enumerate() {
                let (lo, hi) = (v[0].inf(&v[1]).inf(&v[2]), v[0].sup(&v[1]).sup(&v[2]));
                let r = Rounded::new(&lo, &hi);
                for k in 0..3 {
                    w.min[k][l] = r.lo[k];
                    w.max[k][l] = r.hi[k];
                }
            }
            let q = [
                Rounded::new(&a.inf(&b0), &a.sup(&b0)),
                Rounded::new(&a.inf(&b1), &a.sup(&b1)),
            ];
            let gaps = w.gaps2_pair(&q);
            assert!(
                same(w.gaps2(&q[0]), &gaps[..4]) && same(w.gaps2(&q[1]), &gaps[4..]),
                "case {case}"
            );
            // a leaf block of the three triangles in its own frame
            let block = Block4::new(&disks);
            let al = block.local(&a);
            let best = f32_up(size * size * rnd());
            let pair = block.segment_bounds2_pair(&al, [&b0, &b1], best);
            let one = block.segment_bounds2_pair(&al, [&b0, &b0], best);
            let other = block.segment_bounds2_pair(&al, [&b1, &b1], best);
            assert!(own(&pair, &one, &other), "case {case}");
        }
    }

    /// The second stage of the leaf bounds (given the best distance so far) excludes a
    /// triangle only if it is farther than that best: random triangles at scales 1 mm … 1 km
    /// and offsets up to 1000 × their size, segments near them (nearly touching, nearly
    /// parallel) and far from them (2–30 × their size, nearly parallel to them, as a cable
    /// above a finely meshed surface), the best so far from 1 % below to 0.1 % above the
    /// exact distance. It is not void: far from the triangles, of those 1 % farther than the
    /// best that the first stage keeps and the float64 filter it replaced excludes, it
    /// excludes 95 % or more (98 % here).
    #[test]
    fn staged_leaf_bounds_exclude_only_farther_triangles() {
        use crate::closest::segment_triangle;
        let mut rnd = crate::test_random(23);
        let (mut staged, mut by_float64) = (0, 0);
        for case in 0..30000 {
            let (size, off) = case_scale(&mut rnd, case);
            let (tris, disks) = random_triangles(4, &mut rnd, size, off);
            let block = Block4::new(&disks);
            let (n, ..) = disks[0];
            let far = case % 3 == 1;
            let (a, b) = if case % 3 == 2 {
                // beside the corner farthest from the centroid (on the disk's rim)
                let c = (tris[0][0] + tris[0][1] + tris[0][2]) / 3.0;
                let v = tris[0].iter().fold(c, |f, v| {
                    if (v - c).norm() > (f - c).norm() {
                        *v
                    } else {
                        f
                    }
                });
                // from beside the rim, steeply up and inwards: the nearest point is the
                // segment's start, at the edge of the part the second stage keeps
                let out = (v - c).normalize();
                let side = if rnd() < 0.5 { 1.0 } else { -1.0 };
                let a = v + out * size * (0.01 + 0.3 * rnd()) + n * side * size * (0.5 + rnd());
                let inwards = size * (0.5 + rnd());
                (
                    a,
                    a - out * inwards + n * side * inwards * (2.0 + 18.0 * rnd()),
                )
            } else if far {
                let c = (tris[0][0] + tris[0][1] + tris[0][2]) / 3.0;
                let across = n.cross(&V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5));
                let a = c
                    + n * size * (2.0 + 28.0 * rnd())
                    + V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * size;
                (
                    a,
                    a + across * size * (1.0 + 9.0 * rnd()) + n * size * 0.3 * (rnd() - 0.5),
                )
            } else {
                near_point_and_segment(&mut rnd, &tris[0], &n, size)
            };
            let factor = [
                0.99,
                1.0 - 1e-4,
                1.0 - 1e-6,
                1.0 - 1e-7,
                1.0,
                1.0 + 1e-7,
                1.0 + 1e-3,
            ];
            for (k, t) in tris.iter().enumerate() {
                let (_, x, y) = segment_triangle(&a, &b, &t[0], &t[1], &t[2]);
                let exact = (x - y).norm_squared();
                for f in factor {
                    let best = exact * f;
                    let g = block.segment_bounds2_pair(&block.local(&a), [&b, &b], f32_up(best));
                    let g1 = block.segment_bounds2_pair(&block.local(&a), [&b, &b], f32::INFINITY);
                    assert!(
                        g[k] == g[k + 4] && (g[k].is_infinite() || g[k] == g1[k]),
                        "case {case}"
                    );
                    if g[k].is_infinite() {
                        assert!(exact > best, "case {case}, lane {k}: {exact} ≤ {best}");
                    }
                    // the float64 filter this stage replaced (mesh.rs): what it excludes
                    if far
                        && f == 0.99
                        && lower(g1[k]) <= best
                        && crate::mesh::triangle_disk_excludes(&disks[k], &a, &b, best)
                    {
                        by_float64 += 1;
                        staged += (lower(g[k]) > best) as usize;
                    }
                }
            }
        }
        assert!(staged * 100 > 95 * by_float64, "{staged} of {by_float64}");
    }

    /// The tangents make the bound tight where the first stage is not: a segment from beside
    /// a triangle's disk (offset L beyond its rim, height H above its plane) rising steeply
    /// while it moves in over the disk. Its nearest point to the disk is its start, at
    /// sqrt(H² + L²); the gap (least at the start) and the offset (least at the end) taken
    /// apart give about H alone. With the tangents the bound of a leaf block (in its own
    /// frame) is within 0.1 % of the start's distance, at scales 1 mm … 1 km and offsets up
    /// to 1000 × the size, and below the exact distance to the triangle.
    #[test]
    fn tangents_bound_oblique_segments_tightly() {
        use crate::closest::segment_triangle;
        let mut rnd = crate::test_random(31);
        for case in 0..20000 {
            let (size, off) = case_scale(&mut rnd, case);
            let v = random_triangle(&mut rnd, size, off);
            let (n, _, _, c, r) = triangle_disk(&v);
            let block = Block4::new(&[triangle_disk(&v)]);
            let out = n
                .cross(&V3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5))
                .normalize();
            let (h, l) = (size * (0.2 + rnd()), size * (0.2 + rnd()));
            let side = if rnd() < 0.5 { 1.0 } else { -1.0 };
            let a = c + out * (r + l) + n * side * h;
            // in by 0.9 L across, up by 3 L²/H: the squared distance rises from the start
            let b = a - out * 0.9 * l + n * side * 3.0 * l * l / h;
            let g = block.segment_bounds2_pair(&block.local(&a), [&b, &b], f32::INFINITY)[0];
            let start = h * h + l * l;
            assert!(
                lower(g) >= 0.999 * start,
                "case {case}: {} < {start}",
                lower(g)
            );
            let (_, sx, sy) = segment_triangle(&a, &b, &v[0], &v[1], &v[2]);
            assert!(lower(g) <= (sx - sy).norm_squared(), "case {case}");
        }
    }

    /// The same cases through a leaf block in its own frame: lower bounds at offsets up to
    /// 1000 × the triangles' size from the origin, and as tight there as at the origin (the
    /// allowance follows the distances within the block, not the offset).
    #[test]
    fn local_block_bounds_are_lower_bounds_and_tight_far_from_the_origin() {
        use crate::closest::{point_triangle, segment_triangle};
        let mut rnd = crate::test_random(5);
        let mut tight = 0;
        for case in 0..20000 {
            let (size, off) = case_scale(&mut rnd, case);
            // a block of two triangles (its origin at the first's centroid)
            let (v, w) = (
                random_triangle(&mut rnd, size, off),
                random_triangle(&mut rnd, size, off),
            );
            let block = Block4::new(&[triangle_disk(&v), triangle_disk(&w)]);
            let (n, _, _, c, _) = triangle_disk(&v);
            let (p, b) = near_point_and_segment(&mut rnd, &v, &n, size);
            for (k, t) in [&v, &w].into_iter().enumerate() {
                let exact_p = (point_triangle(&p, &t[0], &t[1], &t[2]).0 - p).norm_squared();
                let (_, sx, sy) = segment_triangle(&p, &b, &t[0], &t[1], &t[2]);
                let exact_s = (sx - sy).norm_squared();
                let gp = block.point_bounds2(&p)[k];
                let gs = block.segment_bounds2_pair(&block.local(&p), [&b, &b], f32::INFINITY)[k];
                assert!(lower(gp) <= exact_p, "point, case {case}, lane {k}");
                assert!(lower(gs) <= exact_s, "segment, case {case}, lane {k}");
            }
            // tight: over the face, the plane distance less an allowance of the block's size
            // (≤ 4 size / 65536), whatever the offset
            let hp = n.dot(&(p - c)).abs();
            let exact_p = (point_triangle(&p, &v[0], &v[1], &v[2]).0 - p).norm_squared();
            if (exact_p.sqrt() - hp).abs() < 1e-9 * size {
                let h = (hp - 2.0 * 4.0 * size / 65536.0).max(0.0);
                assert!(
                    block.point_bounds2(&p)[0] as f64 >= 0.98 * h * h,
                    "case {case}"
                );
                tight += 1;
            }
        }
        assert!(tight > 5000, "{tight}");
    }
}
