//! The discretised cable: mesh on a staggered grid, section data, clips, loads and the map from
//! unknowns to the blocks of the block-tridiagonal Jacobian.
//!
//! Block n (n = 0..N) holds 6 slots: slots 0..3 are Δx_n of node n (or, at a point swivel or
//! hinge clip, slot 0 is the clip's free angle about its axis), slots 3..6 are θ of edge n+½ (none for n = N).
//! Prescribed unknowns are eliminated: their slots are inactive.
use crate::rotation::{rotation_matrix, Quat};
use nalgebra::Vector3;
use std::fmt;

/// How a clip holds the cable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClipKind {
    /// Position and full orientation prescribed.
    Fixed,
    /// Like fixed, but free rotation about the cable axis.
    Swivel,
    /// Position prescribed, rotation free (point clips only).
    Ball,
    /// Position prescribed, rotation free about `axis` only (clip frame: d1, d2, d3 = cable
    /// tangent; point clips only). A swivel is the hinge about d3.
    Hinge { axis: Vector3<f64> },
    /// A guide of the clip's length holding the cable's axis on its line (position and
    /// direction d3) while the cable slides through axially (`sliding.rs`); `friction` μ.
    Sliding { friction: f64 },
}

impl ClipKind {
    /// The clip-frame axis of the one free rotation of a point clip (unit), if it has one.
    pub fn free_axis(&self) -> Option<Vector3<f64>> {
        match self {
            ClipKind::Swivel => Some(Vector3::z()),
            ClipKind::Hinge { axis } => Some(axis.normalize()),
            ClipKind::Fixed | ClipKind::Ball | ClipKind::Sliding { .. } => None,
        }
    }
}

/// A clip's pose in the global frame: the point of the clip centre on the cable axis and the
/// orientation of the cable's material frame there (d3 = cable tangent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub position: Vector3<f64>,
    pub orientation: Quat,
}

#[derive(Clone, Debug)]
pub struct ClipSpec {
    pub name: String,
    /// Arc length of the clip centre.
    pub s: f64,
    /// Held length (0: point clip).
    pub length: f64,
    pub kind: ClipKind,
    /// Pose at the reference configuration.
    pub pose: Pose,
}

/// A dead load (global frame) at an arc length.
#[derive(Clone, Debug)]
pub struct PointLoad {
    pub s: f64,
    pub force: Vector3<f64>,
    pub moment: Vector3<f64>,
}

/// Effective section properties.
#[derive(Clone, Debug)]
pub struct Section {
    /// C^Γ = diag(GA₁, GA₂, EA), N.
    pub shear_stiffness: Vector3<f64>,
    /// C^K = diag(EI₁, EI₂, GJ), N m².
    pub bend_stiffness: Vector3<f64>,
    /// ρA, kg/m.
    pub mass_per_length: f64,
    /// ρ diag(I₁, I₂, I₁+I₂), kg m (rotary inertia per length).
    pub rotary_inertia: Vector3<f64>,
}

#[derive(Clone, Debug)]
pub struct CableSpec {
    pub length: f64,
    /// Requested number of segments (edges); the mesh may need more to put nodes at clips.
    pub segments: usize,
    pub section: Section,
    /// Natural curvature K⁰ (κ₁, κ₂, twist), 1/m.
    pub natural_curvature: Vector3<f64>,
    pub clips: Vec<ClipSpec>,
    pub loads: Vec<PointLoad>,
    pub gravity: Vector3<f64>,
}

/// Invalid cable specification; the message names the offending item and value.
#[derive(Clone, Debug, PartialEq)]
pub struct SpecError(pub String);

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for SpecError {}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    Free,
    Prescribed { clip: usize },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeKind {
    Free,
    Prescribed {
        clip: usize,
    },
    /// Inside a swivel clip of finite length: only the twist about d3 is free.
    TwistFree {
        clip: usize,
    },
}

/// A rotation referenced by a bending term: an edge, or the ghost rotation of a point clip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotRef {
    Edge(usize),
    Ghost(usize),
}

/// One bending cell: the curvature between rotations a and b over the cell length `weight`.
#[derive(Clone, Copy, Debug)]
pub struct BendTerm {
    pub a: RotRef,
    pub b: RotRef,
    pub weight: f64,
    pub node: usize,
}

/// The ghost rotation of a point clip (fixed, swivel or hinge): the clip's orientation, which
/// splits the bending term at the clip node into two half cells.
#[derive(Clone, Copy, Debug)]
pub struct Ghost {
    pub clip: usize,
    pub node: usize,
    /// Swivel or hinge: the unit axis (body frame of the ghost, which is the clip frame turned
    /// about this same axis) of the free angle, an unknown in slot 0 of the node's block; the
    /// ghost moves as g ← g ⊗ exp(δ axis).
    pub free_axis: Option<Vector3<f64>>,
}

impl Ghost {
    pub fn is_free(&self) -> bool {
        self.free_axis.is_some()
    }
}

/// A set of consecutive blocks whose unknowns are coupled to no others: the cable splits into
/// independent systems at fixed clips (their prescribed position and orientation decouple the
/// two sides), so each segment can be solved on its own.
#[derive(Clone, Debug)]
pub struct Segment {
    pub blocks: std::ops::Range<usize>,
    /// Shear elements (edges) and bending terms acting on the segment's unknowns.
    pub edges: Vec<usize>,
    pub bend_terms: Vec<usize>,
    /// Swivel ghosts whose free twist is in the segment.
    pub ghosts: Vec<usize>,
    /// The clips whose prescribed nodes, edges or ghosts these elements use.
    pub clips: Vec<usize>,
}

/// The discretised cable.
#[derive(Clone, Debug)]
pub struct Rod {
    pub spec: CableSpec,
    /// Arc lengths s_n of the N+1 nodes.
    pub arc: Vec<f64>,
    /// Δs of the N edges.
    pub ds_edge: Vec<f64>,
    /// δs of the nodes (half edges at the ends).
    pub ds_node: Vec<f64>,
    pub node_kind: Vec<NodeKind>,
    pub edge_kind: Vec<EdgeKind>,
    pub ghosts: Vec<Ghost>,
    /// Ghost index of each clip, if it has one.
    pub clip_ghost: Vec<Option<usize>>,
    pub bend_terms: Vec<BendTerm>,
    /// Lumped nodal masses ρA δs_n.
    pub node_mass: Vec<f64>,
    /// Point-load forces per node (global).
    pub node_force: Vec<Vector3<f64>>,
    /// Point-load moments per edge (global, dead).
    pub edge_moment: Vec<Vector3<f64>>,
    /// Active slots of each block.
    pub mask: Vec<[bool; 6]>,
    /// Nodes and edges held by each clip.
    pub clip_nodes: Vec<Vec<usize>>,
    pub clip_edges: Vec<Vec<usize>>,
    /// The independent parts of the system (segments without unknowns are left out).
    pub segments: Vec<Segment>,
}

fn fmt_clip(c: &ClipSpec) -> String {
    format!("clip '{}' (s = {} m, length = {} m)", c.name, c.s, c.length)
}

impl Rod {
    /// Builds the mesh and the constraint maps; validates the specification.
    pub fn new(spec: CableSpec) -> Result<Rod, SpecError> {
        let l = spec.length;
        if !(l.is_finite() && l > 0.0) {
            return Err(SpecError(format!(
                "cable length = {l}: must be a positive number of metres"
            )));
        }
        if spec.segments < 1 {
            return Err(SpecError("segments = 0: must be at least 1".into()));
        }
        let eps = 1e-9 * l;
        // Breakpoints: cable ends, clip ends, load points.
        let mut intervals: Vec<(f64, f64, usize)> = Vec::new();
        let mut sliding: Vec<usize> = Vec::new();
        for (i, c) in spec.clips.iter().enumerate() {
            if !(c.length >= 0.0 && c.length.is_finite()) {
                return Err(SpecError(format!("{}: length must be ≥ 0", fmt_clip(c))));
            }
            if c.kind == ClipKind::Ball && c.length > 0.0 {
                return Err(SpecError(format!(
                    "{}: a ball clip holds a point; its length must be 0",
                    fmt_clip(c)
                )));
            }
            if let ClipKind::Hinge { axis } = c.kind {
                if c.length > 0.0 {
                    return Err(SpecError(format!(
                        "{}: a hinge holds a point; its length must be 0 (a held length \
                         turning about the cable axis is a swivel)",
                        fmt_clip(c)
                    )));
                }
                if !(axis.iter().all(|a| a.is_finite()) && axis.norm() > 1e-12) {
                    return Err(SpecError(format!(
                        "{}: hinge axis = [{}, {}, {}]: must be a finite non-zero vector in the \
                         clip frame",
                        fmt_clip(c),
                        axis.x,
                        axis.y,
                        axis.z
                    )));
                }
            }
            let (a, b) = (c.s - 0.5 * c.length, c.s + 0.5 * c.length);
            if a < -eps || b > l + eps || !c.s.is_finite() {
                return Err(SpecError(format!(
                    "{} lies outside the cable [0, {l}] m (it covers [{a}, {b}] m)",
                    fmt_clip(c)
                )));
            }
            if let ClipKind::Sliding { friction } = c.kind {
                if c.length <= 0.0 {
                    return Err(SpecError(format!(
                        "{}: a sliding clip is a guide; its length must be > 0 (it holds the \
                         cable's direction over that length)",
                        fmt_clip(c)
                    )));
                }
                if !(friction.is_finite() && friction >= 0.0) {
                    return Err(SpecError(format!(
                        "{}: friction = {friction}: must be a number ≥ 0",
                        fmt_clip(c)
                    )));
                }
                sliding.push(i);
                continue;
            }
            intervals.push((a.max(0.0), b.min(l), i));
        }
        intervals.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap());
        for w in intervals.windows(2) {
            if w[1].0 <= w[0].1 + eps {
                return Err(SpecError(format!(
                    "{} and {} overlap: clips must be apart along the cable",
                    fmt_clip(&spec.clips[w[0].2]),
                    fmt_clip(&spec.clips[w[1].2])
                )));
            }
        }
        let mut breaks = vec![0.0, l];
        for &(a, b, _) in &intervals {
            breaks.push(a);
            breaks.push(b);
        }
        for &i in &sliding {
            breaks.push(spec.clips[i].s.clamp(0.0, l));
        }
        for (i, ld) in spec.loads.iter().enumerate() {
            if !(ld.s >= -eps && ld.s <= l + eps) {
                return Err(SpecError(format!(
                    "load {i} at s = {} m lies outside the cable [0, {l}] m",
                    ld.s
                )));
            }
            breaks.push(ld.s.clamp(0.0, l));
        }
        breaks.sort_by(|a, b| a.partial_cmp(b).unwrap());
        breaks.dedup_by(|a, b| (*a - *b).abs() <= eps);
        *breaks.last_mut().unwrap() = l;
        let arc = mesh_intervals(&breaks, spec.segments);
        let n_edges = arc.len() - 1;
        let ds_edge: Vec<f64> = arc.windows(2).map(|w| w[1] - w[0]).collect();
        let mut ds_node = vec![0.0; n_edges + 1];
        for (e, &d) in ds_edge.iter().enumerate() {
            ds_node[e] += 0.5 * d;
            ds_node[e + 1] += 0.5 * d;
        }
        let node_at = |s: f64| -> usize {
            arc.iter()
                .enumerate()
                .min_by(|a, b| (a.1 - s).abs().partial_cmp(&(b.1 - s).abs()).unwrap())
                .unwrap()
                .0
        };

        let mut node_kind = vec![NodeKind::Free; n_edges + 1];
        let mut edge_kind = vec![EdgeKind::Free; n_edges];
        let mut clip_nodes = vec![Vec::new(); spec.clips.len()];
        let mut clip_edges = vec![Vec::new(); spec.clips.len()];
        let mut ghosts = Vec::new();
        let mut clip_ghost = vec![None; spec.clips.len()];
        for &(a, b, ci) in &intervals {
            let (na, nb) = (node_at(a), node_at(b));
            for (n, kind) in node_kind.iter_mut().enumerate().take(nb + 1).skip(na) {
                *kind = NodeKind::Prescribed { clip: ci };
                clip_nodes[ci].push(n);
            }
            let c = &spec.clips[ci];
            for (e, kind) in edge_kind.iter_mut().enumerate().take(nb).skip(na) {
                *kind = match c.kind {
                    ClipKind::Swivel => EdgeKind::TwistFree { clip: ci },
                    _ => EdgeKind::Prescribed { clip: ci },
                };
                clip_edges[ci].push(e);
            }
            if na == nb && c.kind != ClipKind::Ball {
                clip_ghost[ci] = Some(ghosts.len());
                ghosts.push(Ghost {
                    clip: ci,
                    node: na,
                    free_axis: c.kind.free_axis(),
                });
            }
        }
        // A sliding clip holds no node: its node at the reference only routes the cable.
        let max_ds = ds_edge.iter().cloned().fold(0.0, f64::max);
        for &ci in &sliding {
            let c = &spec.clips[ci];
            if c.length < 2.0 * max_ds {
                return Err(SpecError(format!(
                    "{}: the guide must hold at least three nodes to hold the direction, but \
                     edges are up to {max_ds:.4} m long; allowed: length ≥ {:.4} m, or more \
                     segments (about {})",
                    fmt_clip(c),
                    2.0 * max_ds,
                    (spec.segments as f64 * max_ds / (0.5 * c.length)).ceil()
                )));
            }
            clip_nodes[ci].push(node_at(c.s));
        }
        let ghost_at: Vec<Option<usize>> = (0..=n_edges)
            .map(|n| ghosts.iter().position(|g| g.node == n))
            .collect();
        let mut bend_terms = Vec::new();
        for n in 0..=n_edges {
            match ghost_at[n] {
                Some(g) => {
                    if n > 0 {
                        bend_terms.push(BendTerm {
                            a: RotRef::Edge(n - 1),
                            b: RotRef::Ghost(g),
                            weight: 0.5 * ds_edge[n - 1],
                            node: n,
                        });
                    }
                    if n < n_edges {
                        bend_terms.push(BendTerm {
                            a: RotRef::Ghost(g),
                            b: RotRef::Edge(n),
                            weight: 0.5 * ds_edge[n],
                            node: n,
                        });
                    }
                }
                None if n > 0 && n < n_edges => bend_terms.push(BendTerm {
                    a: RotRef::Edge(n - 1),
                    b: RotRef::Edge(n),
                    weight: ds_node[n],
                    node: n,
                }),
                None => {}
            }
        }
        let mut mask = vec![[false; 6]; n_edges + 1];
        for n in 0..=n_edges {
            if node_kind[n] == NodeKind::Free {
                mask[n][0..3].copy_from_slice(&[true; 3]);
            } else if let Some(g) = ghost_at[n] {
                mask[n][0] = ghosts[g].is_free();
            }
            if n < n_edges {
                match edge_kind[n] {
                    EdgeKind::Free => mask[n][3..6].copy_from_slice(&[true; 3]),
                    EdgeKind::TwistFree { .. } => mask[n][5] = true,
                    EdgeKind::Prescribed { .. } => {}
                }
            }
        }
        let node_mass = ds_node
            .iter()
            .map(|d| d * spec.section.mass_per_length)
            .collect();
        let mut node_force = vec![Vector3::zeros(); n_edges + 1];
        let mut edge_moment = vec![Vector3::zeros(); n_edges];
        for ld in &spec.loads {
            let n = node_at(ld.s);
            node_force[n] += ld.force;
            match (n, n_edges) {
                (0, _) => edge_moment[0] += ld.moment,
                (n, ne) if n == ne => edge_moment[ne - 1] += ld.moment,
                (n, _) => {
                    edge_moment[n - 1] += 0.5 * ld.moment;
                    edge_moment[n] += 0.5 * ld.moment;
                }
            }
        }
        let segments = find_segments(&mask, &node_kind, &edge_kind, &ghosts, &bend_terms);
        Ok(Rod {
            spec,
            arc,
            ds_edge,
            ds_node,
            node_kind,
            edge_kind,
            ghosts,
            clip_ghost,
            bend_terms,
            node_mass,
            node_force,
            edge_moment,
            mask,
            clip_nodes,
            clip_edges,
            segments,
        })
    }

    pub fn n_edges(&self) -> usize {
        self.ds_edge.len()
    }

    /// Global position of the cable point at node n when held by clip c at pose `pose`.
    pub fn clip_node_position(&self, c: usize, n: usize, pose: &Pose) -> Vector3<f64> {
        let offset = self.arc[n] - self.spec.clips[c].s;
        pose.position + rotation_matrix(&pose.orientation) * Vector3::z() * offset
    }

    /// A length scale for norms: the mean edge length.
    pub fn mean_ds(&self) -> f64 {
        self.spec.length / self.n_edges() as f64
    }
}

/// The segments of the system: blocks b and b+1 are coupled when an element acts on active
/// unknowns of both (a shear element through x_{b+1}, a bending term between two edges or
/// through a swivel ghost's twist in slot 0 of a block).
fn find_segments(
    mask: &[[bool; 6]],
    node_kind: &[NodeKind],
    edge_kind: &[EdgeKind],
    ghosts: &[Ghost],
    bend_terms: &[BendTerm],
) -> Vec<Segment> {
    let n_blocks = mask.len();
    let n_edges = edge_kind.len();
    let node_free = |n: usize| node_kind[n] == NodeKind::Free;
    let edge_active = |e: usize| !matches!(edge_kind[e], EdgeKind::Prescribed { .. });
    // The block holding an element variable, if it is an unknown.
    let rot_block = |r: RotRef| match r {
        RotRef::Edge(e) => edge_active(e).then_some(e),
        RotRef::Ghost(g) => ghosts[g].is_free().then_some(ghosts[g].node),
    };
    // coupled[b]: blocks b and b+1.
    let mut coupled: Vec<bool> = (0..n_blocks)
        .map(|e| e < n_edges && node_free(e + 1) && (node_free(e) || edge_active(e)))
        .collect();
    for t in bend_terms {
        if let (Some(a), Some(b)) = (rot_block(t.a), rot_block(t.b)) {
            coupled[a.min(b)..a.max(b)].fill(true);
        }
    }
    let mut segments: Vec<Segment> = Vec::new();
    let mut start = 0;
    for b in 0..n_blocks {
        if b + 1 == n_blocks || !coupled[b] {
            if mask[start..=b].iter().any(|m| m.iter().any(|&x| x)) {
                segments.push(Segment {
                    blocks: start..b + 1,
                    edges: vec![],
                    bend_terms: vec![],
                    ghosts: vec![],
                    clips: vec![],
                });
            }
            start = b + 1;
        }
    }
    let mut block_segment = vec![None; n_blocks];
    for (k, s) in segments.iter().enumerate() {
        for b in s.blocks.clone() {
            block_segment[b] = Some(k);
        }
    }
    let segment_of = |b: usize| block_segment[b];
    for e in 0..n_edges {
        let block = if node_free(e) || edge_active(e) {
            Some(e)
        } else if node_free(e + 1) {
            Some(e + 1)
        } else {
            None
        };
        if let Some(k) = block.and_then(segment_of) {
            segments[k].edges.push(e);
        }
    }
    for (i, t) in bend_terms.iter().enumerate() {
        if let Some(k) = rot_block(t.a).or(rot_block(t.b)).and_then(segment_of) {
            segments[k].bend_terms.push(i);
        }
    }
    for (g, ghost) in ghosts.iter().enumerate() {
        if ghost.is_free() {
            if let Some(k) = segment_of(ghost.node) {
                segments[k].ghosts.push(g);
            }
        }
    }
    let node_clip = |n: usize| match node_kind[n] {
        NodeKind::Prescribed { clip } => Some(clip),
        NodeKind::Free => None,
    };
    let edge_clip = |e: usize| match edge_kind[e] {
        EdgeKind::Prescribed { clip } | EdgeKind::TwistFree { clip } => Some(clip),
        EdgeKind::Free => None,
    };
    let rot_clip = |r: RotRef| match r {
        RotRef::Edge(e) => edge_clip(e),
        RotRef::Ghost(g) => Some(ghosts[g].clip),
    };
    for seg in &mut segments {
        let mut clips: Vec<usize> = seg
            .edges
            .iter()
            .flat_map(|&e| [node_clip(e), node_clip(e + 1), edge_clip(e)])
            .chain(
                seg.bend_terms
                    .iter()
                    .flat_map(|&i| [rot_clip(bend_terms[i].a), rot_clip(bend_terms[i].b)]),
            )
            .flatten()
            .collect();
        clips.sort_unstable();
        clips.dedup();
        seg.clips = clips;
    }
    segments
}

/// Distributes `segments` edges over the intervals between breakpoints, each at least one edge,
/// uniform inside an interval, so that edges are as even as possible.
fn mesh_intervals(breaks: &[f64], segments: usize) -> Vec<f64> {
    let lens: Vec<f64> = breaks.windows(2).map(|w| w[1] - w[0]).collect();
    let total: f64 = lens.iter().sum();
    let h = total / segments as f64;
    let mut counts: Vec<usize> = lens
        .iter()
        .map(|&d| ((d / h).round() as usize).max(1))
        .collect();
    // Adjust to the requested total where possible: add to the coarsest, remove from the finest.
    loop {
        let sum: usize = counts.iter().sum();
        if sum < segments {
            let i = (0..counts.len())
                .max_by(|&a, &b| {
                    (lens[a] / counts[a] as f64)
                        .partial_cmp(&(lens[b] / counts[b] as f64))
                        .unwrap()
                })
                .unwrap();
            counts[i] += 1;
        } else if sum > segments {
            let cand = (0..counts.len())
                .filter(|&i| counts[i] > 1)
                .min_by(|&a, &b| {
                    (lens[a] / counts[a] as f64)
                        .partial_cmp(&(lens[b] / counts[b] as f64))
                        .unwrap()
                });
            match cand {
                Some(i) => counts[i] -= 1,
                None => break,
            }
        } else {
            break;
        }
    }
    let mut arc = vec![breaks[0]];
    for (i, &c) in counts.iter().enumerate() {
        for k in 1..=c {
            arc.push(breaks[i] + lens[i] * k as f64 / c as f64);
        }
        *arc.last_mut().unwrap() = breaks[i + 1];
    }
    arc
}

#[cfg(test)]
mod tests {
    use super::*;

    pub fn section() -> Section {
        Section {
            shear_stiffness: Vector3::new(1e4, 1e4, 3e4),
            bend_stiffness: Vector3::new(0.02, 0.02, 0.015),
            mass_per_length: 0.1,
            rotary_inertia: Vector3::new(1e-6, 1e-6, 2e-6),
        }
    }

    fn clip(name: &str, s: f64, length: f64, kind: ClipKind) -> ClipSpec {
        ClipSpec {
            name: name.into(),
            s,
            length,
            kind,
            pose: Pose {
                position: Vector3::zeros(),
                orientation: Quat::identity(),
            },
        }
    }

    fn spec(clips: Vec<ClipSpec>) -> CableSpec {
        CableSpec {
            length: 1.0,
            segments: 10,
            section: section(),
            natural_curvature: Vector3::zeros(),
            clips,
            loads: vec![],
            gravity: Vector3::zeros(),
        }
    }

    #[test]
    fn mesh_puts_nodes_at_clips_and_keeps_the_count() {
        let rod = Rod::new(spec(vec![
            clip("a", 0.0, 0.0, ClipKind::Fixed),
            clip("b", 0.33, 0.04, ClipKind::Fixed),
            clip("c", 0.77, 0.0, ClipKind::Swivel),
        ]))
        .unwrap();
        for s in [0.0, 0.31, 0.35, 0.77, 1.0] {
            assert!(
                rod.arc.iter().any(|a| (a - s).abs() < 1e-12),
                "no node at {s}"
            );
        }
        assert_eq!(rod.n_edges(), 10);
        let total: f64 = rod.ds_node.iter().sum();
        assert!((total - 1.0).abs() < 1e-14);
        assert_eq!(rod.ghosts.len(), 2);
    }

    #[test]
    fn the_system_splits_at_fixed_clips_only() {
        let rod = Rod::new(spec(vec![
            clip("a", 0.0, 0.0, ClipKind::Fixed),
            clip("b", 0.3, 0.0, ClipKind::Fixed),
            clip("c", 0.5, 0.1, ClipKind::Fixed),
            clip("d", 0.8, 0.0, ClipKind::Swivel),
            clip("e", 0.9, 0.0, ClipKind::Ball),
        ]))
        .unwrap();
        let at = |s: f64| rod.arc.iter().position(|a| (a - s).abs() < 1e-12).unwrap();
        let starts: Vec<usize> = rod.segments.iter().map(|g| g.blocks.start).collect();
        // Splits at the point clip b and at both ends of the held length of c; not at the swivel
        // (its free twist couples both sides) nor at the ball clip.
        assert_eq!(starts, vec![0, at(0.3), at(0.55)]);
        assert_eq!(rod.segments.last().unwrap().blocks.end, rod.arc.len());
        // Every active slot is in exactly one segment, every element acting on one too.
        for (b, m) in rod.mask.iter().enumerate() {
            let n = rod
                .segments
                .iter()
                .filter(|g| g.blocks.contains(&b))
                .count();
            assert_eq!(n, usize::from(m.iter().any(|&x| x)), "block {b}");
        }
        let edges: usize = rod.segments.iter().map(|g| g.edges.len()).sum();
        let held = rod
            .edge_kind
            .iter()
            .filter(|k| matches!(k, EdgeKind::Prescribed { .. }))
            .count();
        assert_eq!(edges, rod.n_edges() - held);
        assert_eq!(
            rod.segments.iter().map(|g| g.ghosts.len()).sum::<usize>(),
            1
        );
    }

    #[test]
    fn bad_clips_are_named() {
        let e = Rod::new(spec(vec![clip("a", 1.2, 0.0, ClipKind::Fixed)])).unwrap_err();
        assert!(e.0.contains("clip 'a'") && e.0.contains("outside"), "{e}");
        let e = Rod::new(spec(vec![
            clip("a", 0.5, 0.1, ClipKind::Fixed),
            clip("b", 0.52, 0.0, ClipKind::Fixed),
        ]))
        .unwrap_err();
        assert!(
            e.0.contains("'a'") && e.0.contains("'b'") && e.0.contains("overlap"),
            "{e}"
        );
        let hinge = |axis: Vector3<f64>| ClipKind::Hinge { axis };
        let e = Rod::new(spec(vec![clip("h", 0.5, 0.1, hinge(Vector3::y()))])).unwrap_err();
        assert!(
            e.0.contains("clip 'h'") && e.0.contains("length must be 0"),
            "{e}"
        );
        let e = Rod::new(spec(vec![clip("h", 0.5, 0.0, hinge(Vector3::zeros()))])).unwrap_err();
        assert!(
            e.0.contains("clip 'h'") && e.0.contains("axis = [0, 0, 0]"),
            "{e}"
        );
    }

    #[test]
    fn a_hinge_is_a_ghost_with_its_unit_axis_and_couples_both_sides() {
        let axis = Vector3::new(0.0, 3.0, 4.0);
        let rod = Rod::new(spec(vec![
            clip("a", 0.0, 0.0, ClipKind::Fixed),
            clip("h", 0.5, 0.0, ClipKind::Hinge { axis }),
        ]))
        .unwrap();
        let g = rod.clip_ghost[1].unwrap();
        assert_eq!(rod.ghosts[g].free_axis, Some(axis / 5.0));
        assert!(rod.mask[rod.ghosts[g].node][0]);
        assert_eq!(rod.segments.len(), 1);
        assert_eq!(ClipKind::Swivel.free_axis(), Some(Vector3::z()));
    }
}
