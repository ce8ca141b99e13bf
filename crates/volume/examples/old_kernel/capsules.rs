//! Capsules (segments with a radius) and a bounding-volume hierarchy over them.
//!
//! The signed distance of a point p to one capsule with axis [a, b] and radius r is
//! |p − closest point of [a, b]| − r; to a union of capsules it is the minimum over them (exact
//! outside the union, a 1-Lipschitz under-estimate of the depth inside).

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
    start: Vec<Vec3>,
    axis: Vec<Vec3>,
    inv_len2: Vec<f64>,
    radius: Vec<f64>,
    nodes: Vec<Node>,
}

/// A node of the hierarchy: the box of its segments (radius not included) and the largest
/// radius below it; `count > 0` marks a leaf holding capsules `first..first + count`,
/// otherwise the children are the nodes `first` and `right`.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    max_radius: f64,
    first: u32,
    count: u32,
    right: u32,
}

const LEAF_SIZE: usize = 4;

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
        let boxes: Vec<Aabb> = (0..m)
            .map(|i| Aabb {
                lo: [0, 1, 2].map(|k| starts[i][k].min(ends[i][k])),
                hi: [0, 1, 2].map(|k| starts[i][k].max(ends[i][k])),
            })
            .collect();
        let mut order: Vec<usize> = (0..m).collect();
        let mut nodes = Vec::with_capacity(2 * m / LEAF_SIZE + 1);
        if m > 0 {
            build(&boxes, radius, &mut order, 0, m, &mut nodes);
        }
        let mut caps = Capsules {
            start: Vec::with_capacity(m),
            axis: Vec::with_capacity(m),
            inv_len2: Vec::with_capacity(m),
            radius: Vec::with_capacity(m),
            nodes,
        };
        for &i in &order {
            let ab = sub(ends[i], starts[i]);
            let l2 = dot(ab, ab);
            caps.start.push(starts[i]);
            caps.axis.push(ab);
            caps.inv_len2.push(if l2 > 0.0 { 1.0 / l2 } else { 0.0 });
            caps.radius.push(radius[i]);
        }
        Ok(caps)
    }

    /// Number of capsules.
    pub fn len(&self) -> usize {
        self.start.len()
    }

    /// True when there are no capsules.
    pub fn is_empty(&self) -> bool {
        self.start.is_empty()
    }

    /// Signed distance from `p` to capsule `i` (in hierarchy order).
    #[inline]
    pub(crate) fn capsule_distance(&self, i: usize, p: Vec3) -> f64 {
        let ap = sub(p, self.start[i]);
        let ab = self.axis[i];
        let t = (dot(ap, ab) * self.inv_len2[i]).clamp(0.0, 1.0);
        let d = [ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]];
        dot(d, d).sqrt() - self.radius[i]
    }

    /// A lower bound of the signed distance from any point of `cell` to capsule `i`.
    #[inline]
    pub(crate) fn capsule_lower_bound(&self, i: usize, cell: &Aabb) -> f64 {
        let a = self.start[i];
        let b = [0, 1, 2].map(|k| a[k] + self.axis[i][k]);
        let seg = Aabb {
            lo: [0, 1, 2].map(|k| a[k].min(b[k])),
            hi: [0, 1, 2].map(|k| a[k].max(b[k])),
        };
        seg.distance_to_box(cell) - self.radius[i]
    }

    /// Exact signed distance from `p` to the union (+inf without capsules).
    pub fn distance(&self, p: Vec3) -> f64 {
        self.distance_below(p, f64::INFINITY)
    }

    /// The signed distance from `p` to the union if it is below `bound`, else `bound`.
    pub fn distance_below(&self, p: Vec3, bound: f64) -> f64 {
        let mut best = bound;
        if self.nodes.is_empty() {
            return best;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if node.bounds.distance_to_point(p) - node.max_radius >= best {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for i in first..first + node.count as usize {
                    best = best.min(self.capsule_distance(i, p));
                }
            } else {
                let (l, r) = (node.first, node.right);
                let dl = self.nodes[l as usize].bounds.distance_to_point(p);
                let dr = self.nodes[r as usize].bounds.distance_to_point(p);
                // Visit the nearer child first: push it last.
                let (near, far) = if dl <= dr { (l, r) } else { (r, l) };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        best
    }

    /// Appends to `out` every capsule (as `(lower bound, index)`) whose lower bound of the
    /// signed distance over `cell` is below `limit`.
    pub(crate) fn gather(&self, cell: &Aabb, limit: f64, out: &mut Vec<(f64, u32)>) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if node.bounds.distance_to_box(cell) - node.max_radius >= limit {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for i in first..first + node.count as usize {
                    let lb = self.capsule_lower_bound(i, cell);
                    if lb < limit {
                        out.push((lb, i as u32));
                    }
                }
            } else {
                stack[top] = node.first;
                stack[top + 1] = node.right;
                top += 2;
            }
        }
    }
}

/// Builds the subtree over `order[lo..hi]`, returns its node index. Splits at the median of
/// the segment centres along the widest axis, so the depth is about log2(m / LEAF_SIZE).
fn build(
    boxes: &[Aabb],
    radius: &[f64],
    order: &mut [usize],
    lo: usize,
    hi: usize,
    nodes: &mut Vec<Node>,
) -> u32 {
    let mut bounds = Aabb::EMPTY;
    let mut centres = Aabb::EMPTY;
    let mut max_radius: f64 = 0.0;
    for &i in &order[lo..hi] {
        bounds = bounds.union(&boxes[i]);
        let c = [0, 1, 2].map(|k| 0.5 * (boxes[i].lo[k] + boxes[i].hi[k]));
        centres = centres.union(&Aabb { lo: c, hi: c });
        max_radius = max_radius.max(radius[i]);
    }
    let index = nodes.len() as u32;
    nodes.push(Node {
        bounds,
        max_radius,
        first: lo as u32,
        count: (hi - lo) as u32,
        right: 0,
    });
    if hi - lo <= LEAF_SIZE {
        return index;
    }
    let ext = [0, 1, 2].map(|k| centres.hi[k] - centres.lo[k]);
    let axis = (0..3)
        .max_by(|&a, &b| ext[a].total_cmp(&ext[b]))
        .unwrap_or(0);
    let mid = (lo + hi) / 2;
    let key = |i: &usize| boxes[*i].lo[axis] + boxes[*i].hi[axis];
    order[lo..hi].select_nth_unstable_by(mid - lo, |a, b| key(a).total_cmp(&key(b)));
    let left = build(boxes, radius, order, lo, mid, nodes);
    let right = build(boxes, radius, order, mid, hi, nodes);
    let node = &mut nodes[index as usize];
    node.first = left;
    node.count = 0;
    node.right = right;
    index
}
