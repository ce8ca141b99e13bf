//! Capsules (segments with a radius) and a bounding-volume hierarchy over them.
//!
//! The signed distance of a point p to one capsule with axis [a, b] and radius r is
//! |p − closest point of [a, b]| − r; to a union of capsules it is the minimum over them (exact
//! outside the union, a 1-Lipschitz under-estimate of the depth inside).
//!
//! The hierarchy splits at median axis centres; each node bounds its capsules by the box of
//! their axes and by a representative segment with a slack (every axis lies within the slack
//! of it). The boxes alone cannot separate the capsules of one cable edge at thousands of
//! saved steps (a sloped edge's box is wider than its motion); the segments can, so a distance
//! query visits the few capsules that come within the slack of the nearest, not all of them.
//! The capsules are stored in leaf order (64 bytes each); large subtrees are built in
//! parallel.

/// A 3-vector.
pub type Vec3 = [f64; 3];

#[inline]
fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub lo: Vec3,
    pub hi: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    /// The smallest box holding both boxes.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            lo: [0, 1, 2].map(|i| self.lo[i].min(o.lo[i])),
            hi: [0, 1, 2].map(|i| self.hi[i].max(o.hi[i])),
        }
    }

    /// Euclidean distance from a point to the box (0 inside).
    #[inline]
    pub fn distance_to_point(&self, p: Vec3) -> f64 {
        let mut s = 0.0;
        for ((lo, hi), x) in self.lo.iter().zip(&self.hi).zip(&p) {
            let d = (lo - x).max(x - hi).max(0.0);
            s += d * d;
        }
        s.sqrt()
    }

    /// Euclidean distance between two boxes (0 when they overlap).
    #[inline]
    pub fn distance_to_box(&self, o: &Aabb) -> f64 {
        let mut s = 0.0;
        for i in 0..3 {
            let d = (self.lo[i] - o.hi[i]).max(o.lo[i] - self.hi[i]).max(0.0);
            s += d * d;
        }
        s.sqrt()
    }
}

/// A set of capsules, stored in the order of the hierarchy's leaves.
#[derive(Clone, Debug)]
pub struct Capsules {
    capsules: Vec<Capsule>,
    nodes: Vec<Node>,
}

/// One capsule: axis start and start-to-end vector, 1/|axis|² (0 for a ball), radius; one
/// cache line.
#[derive(Clone, Copy, Debug, Default)]
struct Capsule {
    start: Vec3,
    axis: Vec3,
    inv_len2: f64,
    radius: f64,
}

impl Capsule {
    fn new(start: Vec3, end: Vec3, radius: f64) -> Capsule {
        let axis = sub(end, start);
        let l2 = dot(axis, axis);
        Capsule {
            start,
            axis,
            inv_len2: if l2 > 0.0 { 1.0 / l2 } else { 0.0 },
            radius,
        }
    }

    /// Distance from `p` to the axis.
    #[inline]
    fn axis_distance(&self, p: Vec3) -> f64 {
        let ap = sub(p, self.start);
        let ab = self.axis;
        let t = (dot(ap, ab) * self.inv_len2).clamp(0.0, 1.0);
        let d = [ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]];
        dot(d, d).sqrt()
    }

    fn end(&self) -> Vec3 {
        [0, 1, 2].map(|k| self.start[k] + self.axis[k])
    }
}

/// A node of the hierarchy over the capsules `first..first + count` (in storage order) when
/// `count > 0` (a leaf), otherwise over those of its children, the nodes `first` (always the
/// next node) and `right`.
///
/// Two lower bounds of the distance from a point to the axis of any capsule below: the
/// distance to the box of the axes, and the distance to the axis of `segment` minus `slack`,
/// the largest distance of an axis end point below from the matching end of that segment (so
/// every axis point lies within `slack` of the segment). The box is tight for scattered
/// capsules; the segment for the nearly coincident capsules of one cable edge at consecutive
/// steps, whose boxes are as wide as the edge's slope makes them.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    segment: Capsule,
    slack: f64,
    /// Whether the segment is worth its cost: its slack is small against the box.
    use_segment: bool,
    first: u32,
    count: u32,
    right: u32,
}

impl Node {
    /// A lower bound of the signed distance from `p` to every capsule below the node
    /// (`segment.radius` is their largest radius), or +inf when the box alone shows that
    /// none is below `best`.
    #[inline]
    fn lower_bound(&self, p: Vec3, best: f64) -> f64 {
        let mut s = 0.0;
        for ((lo, hi), x) in self.bounds.lo.iter().zip(&self.bounds.hi).zip(&p) {
            let d = (lo - x).max(x - hi).max(0.0);
            s += d * d;
        }
        let reach = best + self.segment.radius;
        if !(reach > 0.0 && s < reach * reach) {
            return f64::INFINITY;
        }
        let to_box = s.sqrt();
        if !self.use_segment {
            return to_box - self.segment.radius;
        }
        let to_segment = self.segment.axis_distance(p) - self.slack;
        to_box.max(to_segment) - self.segment.radius
    }
}

const LEAF_SIZE: usize = 8;

/// Subtrees of at most this many capsules get the slack of their segment from the capsules
/// themselves, larger ones from their leaves.
const EXACT_SLACK: usize = 64;

/// Subtrees with more capsules than this are built in parallel.
const PARALLEL_BUILD: usize = 1 << 14;

/// Input errors: which argument, which value, what is allowed.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError(pub String);

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for InputError {}

impl Capsules {
    /// Capsules with axes from `starts[i]` to `ends[i]` and radii `radius[i]`.
    pub fn new(starts: &[Vec3], ends: &[Vec3], radius: &[f64]) -> Result<Self, InputError> {
        let m = starts.len();
        if ends.len() != m || radius.len() != m {
            return Err(InputError(format!(
                "starts, ends and radius must have the same length, got {}, {} and {}",
                m,
                ends.len(),
                radius.len()
            )));
        }
        for i in 0..m {
            if starts[i]
                .iter()
                .chain(ends[i].iter())
                .any(|x| !x.is_finite())
            {
                return Err(InputError(format!(
                    "capsule {i}: end points {:?}, {:?} must be finite",
                    starts[i], ends[i]
                )));
            }
            if !(radius[i].is_finite() && radius[i] >= 0.0) {
                return Err(InputError(format!(
                    "radius[{i}] = {}: must be finite and >= 0",
                    radius[i]
                )));
            }
        }
        if m > u32::MAX as usize / 2 {
            return Err(InputError(format!(
                "{m} capsules: at most {} are supported",
                u32::MAX / 2
            )));
        }
        let mut items: Vec<Item> = (0..m)
            .map(|i| Item {
                centre: [0, 1, 2].map(|k| (0.5 * (starts[i][k] + ends[i][k])) as f32),
                index: i as u32,
            })
            .collect();
        let mut capsules = vec![Capsule::default(); m];
        let mut nodes = vec![Node::EMPTY; if m > 0 { subtree_nodes(m) } else { 0 }];
        if m > 0 {
            let input = Input {
                starts,
                ends,
                radius,
            };
            build(&input, &mut items, &mut capsules, &mut nodes, 0, 0);
        }
        Ok(Capsules { capsules, nodes })
    }

    /// Number of capsules.
    pub fn len(&self) -> usize {
        self.capsules.len()
    }

    /// True when there are no capsules.
    pub fn is_empty(&self) -> bool {
        self.capsules.is_empty()
    }

    /// Exact signed distance from `p` to the union (+inf without capsules).
    pub fn distance(&self, p: Vec3) -> f64 {
        self.distance_below(p, f64::INFINITY)
    }

    /// The signed distance from `p` to the union if it is below `bound`, else `bound`.
    pub fn distance_below(&self, p: Vec3, bound: f64) -> f64 {
        self.distance_between(p, f64::NEG_INFINITY, bound)
    }

    /// The signed distance d from `p` to the union when `floor < d < bound`; `bound` when
    /// d ≥ `bound`; some value in [d, `floor`] when d ≤ `floor`.
    ///
    /// Depth first, nearer child first, pruning every subtree whose lower bound is not below
    /// the best distance so far.
    pub fn distance_between(&self, p: Vec3, floor: f64, bound: f64) -> f64 {
        let mut best = bound;
        let Some(root) = self.nodes.first() else {
            return best;
        };
        // (lower bound, node); the depth is at most log2(len) + 1 < 64.
        let mut stack = [(0.0f64, 0u32); 64];
        stack[0] = (root.lower_bound(p, best), 0);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (lower, index) = stack[top];
            if lower >= best {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for c in &self.capsules[first..first + node.count as usize] {
                    best = best.min(c.axis_distance(p) - c.radius);
                }
                if best <= floor {
                    return best;
                }
            } else {
                let (l, r) = (node.first, node.right);
                let ll = self.nodes[l as usize].lower_bound(p, best);
                let lr = self.nodes[r as usize].lower_bound(p, best);
                // Visit the nearer child first: push it last.
                let (near, far) = if ll <= lr {
                    ((ll, l), (lr, r))
                } else {
                    ((lr, r), (ll, l))
                };
                if far.0 < best {
                    stack[top] = far;
                    top += 1;
                }
                if near.0 < best {
                    stack[top] = near;
                    top += 1;
                }
            }
        }
        best
    }
}

impl Capsules {
    /// Signed distance from `p` to capsule `i` (in storage order).
    #[inline]
    pub(crate) fn capsule_distance(&self, i: usize, p: Vec3) -> f64 {
        let c = &self.capsules[i];
        c.axis_distance(p) - c.radius
    }

    /// A lower bound of the signed distance from any point of `cell` to capsule `i`.
    #[inline]
    pub(crate) fn capsule_lower_bound(&self, i: usize, cell: &Aabb) -> f64 {
        let c = &self.capsules[i];
        let b = c.end();
        let axis = Aabb {
            lo: [0, 1, 2].map(|k| c.start[k].min(b[k])),
            hi: [0, 1, 2].map(|k| c.start[k].max(b[k])),
        };
        axis.distance_to_box(cell) - c.radius
    }

    /// Appends to `out` every capsule (as `(lower bound, index)`) whose lower bound of the
    /// signed distance over `cell` is below `limit`, and returns true; returns false as soon
    /// as there are more than `max` (`out` is then incomplete).
    pub(crate) fn gather(
        &self,
        cell: &Aabb,
        limit: f64,
        max: usize,
        out: &mut Vec<(f64, u32)>,
    ) -> bool {
        if self.nodes.is_empty() {
            return true;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if node.bounds.distance_to_box(cell) - node.segment.radius >= limit {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for i in first..first + node.count as usize {
                    let lower = self.capsule_lower_bound(i, cell);
                    if lower < limit {
                        if out.len() == max {
                            return false;
                        }
                        out.push((lower, i as u32));
                    }
                }
            } else {
                stack[top] = node.first;
                stack[top + 1] = node.right;
                top += 2;
            }
        }
        true
    }
}

/// The capsules as given.
struct Input<'a> {
    starts: &'a [Vec3],
    ends: &'a [Vec3],
    radius: &'a [f64],
}

/// A capsule while the hierarchy is built: the centre of its axis and its input index.
#[derive(Clone, Copy)]
struct Item {
    centre: [f32; 3],
    index: u32,
}

impl Node {
    const EMPTY: Node = Node {
        bounds: Aabb::EMPTY,
        segment: Capsule {
            start: [0.0; 3],
            axis: [0.0; 3],
            inv_len2: 0.0,
            radius: 0.0,
        },
        slack: 0.0,
        use_segment: false,
        first: 0,
        count: 0,
        right: 0,
    };
}

/// Number of nodes of the hierarchy over `n` > 0 capsules: leaves hold at most LEAF_SIZE,
/// larger sets split into ⌊n/2⌋ and ⌈n/2⌉.
fn subtree_nodes(n: usize) -> usize {
    // (leaves over a, leaves over a + 1), a ≥ 1: halves of consecutive sizes are consecutive.
    fn leaves(a: usize) -> (usize, usize) {
        if a <= LEAF_SIZE {
            return (1, if a < LEAF_SIZE { 1 } else { 2 });
        }
        let (lk, lk1) = leaves(a / 2);
        if a.is_multiple_of(2) {
            (2 * lk, lk + lk1)
        } else {
            (lk + lk1, 2 * lk1)
        }
    }
    2 * leaves(n).0 - 1
}

#[inline]
fn distance(a: Vec3, b: Vec3) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

/// The representative segment of `segments` (start, end, weight, own slack): the weighted mean
/// of the end points, each segment oriented like the first one; and its slack, the largest
/// end point distance from it (each segment in its better orientation) plus own slack.
///
/// Every point (1 − t) a + t b of a segment lies within max(|a − A|, |b − B|) of the point
/// (1 − t) A + t B of [A, B], so within the slack of [A, B].
fn representative(
    segments: impl Iterator<Item = (Vec3, Vec3, f64, f64)> + Clone,
) -> (Capsule, f64) {
    let mut reference = None;
    let (mut sum_a, mut sum_b, mut total) = ([0.0; 3], [0.0; 3], 0.0);
    for (a, b, w, _) in segments.clone() {
        let (ra, rb) = *reference.get_or_insert((a, b));
        let same = dot(sub(a, ra), sub(a, ra)) + dot(sub(b, rb), sub(b, rb));
        let reversed = dot(sub(a, rb), sub(a, rb)) + dot(sub(b, ra), sub(b, ra));
        let (a, b) = if same <= reversed { (a, b) } else { (b, a) };
        for k in 0..3 {
            sum_a[k] += w * a[k];
            sum_b[k] += w * b[k];
        }
        total += w;
    }
    let sa = sum_a.map(|x| x / total);
    let sb = sum_b.map(|x| x / total);
    let mut slack: f64 = 0.0;
    for (a, b, _, own) in segments {
        let same = distance(a, sa).max(distance(b, sb));
        let reversed = distance(a, sb).max(distance(b, sa));
        slack = slack.max(own + same.min(reversed));
    }
    // The margin covers the round-off of these distances and of the point-segment distance.
    let scale = sa.iter().chain(&sb).fold(1.0f64, |m, x| m.max(x.abs()));
    (
        Capsule::new(sa, sb, 0.0),
        slack * (1.0 + 1e-12) + 1e-13 * scale,
    )
}

/// Whether a node's segment bound can be much tighter than its box: when its slack is below a
/// quarter of the box diagonal (the nearly coincident capsules of one edge), not for scattered
/// capsules.
fn worth_it(bounds: &Aabb, slack: f64) -> bool {
    let d2: f64 = (0..3).map(|k| (bounds.hi[k] - bounds.lo[k]).powi(2)).sum();
    slack * slack < d2 / 16.0
}

/// Builds the subtree over `items` into `nodes` (its root first; `base` is the index of
/// `nodes[0]`) and stores its capsules in `capsules` (storage index `offset` onwards). Splits
/// at the median of the axis centres along their widest extent, so the depth is about
/// log2(m / LEAF_SIZE); large subtrees are built in parallel.
fn build(
    input: &Input,
    items: &mut [Item],
    capsules: &mut [Capsule],
    nodes: &mut [Node],
    base: usize,
    offset: usize,
) {
    let n = items.len();
    if n <= LEAF_SIZE {
        let mut bounds = Aabb::EMPTY;
        let mut max_radius: f64 = 0.0;
        for (item, c) in items.iter().zip(capsules.iter_mut()) {
            let i = item.index as usize;
            let (a, b) = (input.starts[i], input.ends[i]);
            *c = Capsule::new(a, b, input.radius[i]);
            bounds = bounds.union(&Aabb {
                lo: [0, 1, 2].map(|k| a[k].min(b[k])),
                hi: [0, 1, 2].map(|k| a[k].max(b[k])),
            });
            max_radius = max_radius.max(input.radius[i]);
        }
        let (mut segment, slack) =
            representative(capsules.iter().map(|c| (c.start, c.end(), 1.0, 0.0)));
        segment.radius = max_radius;
        nodes[0] = Node {
            bounds,
            segment,
            slack,
            use_segment: worth_it(&bounds, slack),
            first: offset as u32,
            count: n as u32,
            right: 0,
        };
        return;
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for item in items.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(item.centre[k]);
            hi[k] = hi[k].max(item.centre[k]);
        }
    }
    let ext = [0, 1, 2].map(|k| hi[k] - lo[k]);
    let axis = (0..3)
        .max_by(|&a, &b| ext[a].total_cmp(&ext[b]))
        .unwrap_or(0);
    let mid = n / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centre[axis].total_cmp(&b.centre[axis]));
    let left_nodes = subtree_nodes(mid);
    let (head, rest) = nodes.split_at_mut(1);
    let (left, right) = rest.split_at_mut(left_nodes);
    let (left_items, right_items) = items.split_at_mut(mid);
    let (left_caps, right_caps) = capsules.split_at_mut(mid);
    let (l, r) = (base + 1, base + 1 + left_nodes);
    if n > PARALLEL_BUILD {
        rayon::join(
            || build(input, left_items, left_caps, left, l, offset),
            || build(input, right_items, right_caps, right, r, offset + mid),
        );
    } else {
        build(input, left_items, left_caps, left, l, offset);
        build(input, right_items, right_caps, right, r, offset + mid);
    }
    // The segment and slack from the capsules themselves in small subtrees, from the leaves'
    // segments (slack = leaf slack + leaf segment's distance) in larger ones: O(m log m) in
    // all, tight where it matters (the subtrees of one edge's capsules).
    let (mut segment, slack) = if n <= EXACT_SLACK {
        representative(capsules.iter().map(|c| (c.start, c.end(), 1.0, 0.0)))
    } else {
        representative(
            left.iter()
                .chain(right.iter())
                .filter(|c| c.count > 0)
                .map(|c| (c.segment.start, c.segment.end(), c.count as f64, c.slack)),
        )
    };
    let (a, b) = (&left[0], &right[0]);
    segment.radius = a.segment.radius.max(b.segment.radius);
    let bounds = a.bounds.union(&b.bounds);
    head[0] = Node {
        bounds,
        segment,
        slack,
        use_segment: worth_it(&bounds, slack),
        first: l as u32,
        count: 0,
        right: r as u32,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every node bounds its capsules: box, radius, and slack around its segment; the leaves
    /// hold every capsule once; the node count is the precomputed one.
    fn check_hierarchy(caps: &Capsules) {
        let m = caps.len();
        assert_eq!(caps.nodes.len(), if m > 0 { subtree_nodes(m) } else { 0 });
        let mut seen = vec![0u8; m];
        // (node, first capsule, count) by recursion over the children.
        fn walk(caps: &Capsules, index: usize, seen: &mut [u8]) -> (usize, usize) {
            let node = &caps.nodes[index];
            let (first, count) = if node.count > 0 {
                let first = node.first as usize;
                for s in &mut seen[first..first + node.count as usize] {
                    *s += 1;
                }
                (first, node.count as usize)
            } else {
                assert_eq!(node.first as usize, index + 1);
                let (lf, lc) = walk(caps, index + 1, seen);
                let (rf, rc) = walk(caps, node.right as usize, seen);
                assert_eq!(lf + lc, rf);
                (lf, lc + rc)
            };
            let seg = &node.segment;
            for c in &caps.capsules[first..first + count] {
                let (a, b) = (c.start, c.end());
                for k in 0..3 {
                    let (lo, hi) = (node.bounds.lo[k], node.bounds.hi[k]);
                    let tol = 1e-15 * (1.0 + lo.abs().max(hi.abs()));
                    assert!(a[k].min(b[k]) >= lo - tol && a[k].max(b[k]) <= hi + tol);
                }
                assert!(c.radius <= seg.radius);
                let (sa, sb) = (seg.start, seg.end());
                let same = distance(a, sa).max(distance(b, sb));
                let reversed = distance(a, sb).max(distance(b, sa));
                assert!(same.min(reversed) <= node.slack, "node {index}");
            }
            (first, count)
        }
        if m > 0 {
            assert_eq!(walk(caps, 0, &mut seen), (0, m));
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn hierarchy_bounds_its_capsules() {
        let mut x = 12345u64;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for m in [0, 1, 7, 8, 9, 17, 100, 1000, 40_000] {
            let starts: Vec<Vec3> = (0..m).map(|_| [next(), next(), next()]).collect();
            // Every other capsule nearly repeats the previous one, reversed half the time.
            let ends: Vec<Vec3> = starts
                .iter()
                .map(|s| [s[0] + 0.1 * next(), s[1], s[2] - 0.05 * next()])
                .collect();
            let (mut s, mut e) = (starts.clone(), ends.clone());
            for i in (1..m).step_by(2) {
                let d = 1e-3 * next();
                let (a, b) = (starts[i - 1], ends[i - 1]);
                let (a, b) = if next() < 0.5 { (a, b) } else { (b, a) };
                s[i] = [a[0] + d, a[1], a[2]];
                e[i] = [b[0], b[1] - d, b[2]];
            }
            let r: Vec<f64> = (0..m).map(|_| 0.01 * next()).collect();
            let caps = Capsules::new(&s, &e, &r).unwrap();
            assert_eq!(caps.len(), m);
            check_hierarchy(&caps);
        }
    }
}
