//! Harnesses (docs/harness.md): a tree of cables joined at junctions: topology, validation
//! and state. The solver is `harness_solver`.
//!
//! A junction is a small rigid body with six unknowns (ΔX, Θ body frame, Q ← Q ⊗ exp(Θ/2)).
//! Each joined cable end is a fixed point clip of its cable whose pose is the junction's pose
//! times the end's stress-free relative rotation; the coupling term (`junction::HeldEnds`)
//! gives the Jacobian blocks of the end. The Newton system is solved by block elimination on
//! the tree, leaves first (docs/solver.md): each cable segment's block-tridiagonal chain is
//! eliminated onto its junctions (Schur complement: 6×6 blocks between junctions), the
//! junction tree is eliminated leaves first to its roots, then everything is back-substituted.
//! O(N), no fill-in, no general sparse factorisation.
pub use crate::harness_solver::HarnessStatics;
use crate::junction::{EndBlocks, EndTopology, HeldEnds};
use crate::model::{ClipKind, Pose, Rod, SpecError};
use crate::rotation::{rotate_body, rotation_matrix, Quat};
use crate::state::State;
use nalgebra::{Matrix3, Vector3, Vector6};
use std::fmt;

/// A junction: its name, mass and rotary inertia (body frame), and the cable ends it holds
/// as (cable index, clip index of the end's point clip).
#[derive(Clone, Debug)]
pub struct JunctionSpec {
    pub name: String,
    pub mass: f64,
    pub rotary_inertia: Vector3<f64>,
    pub ends: Vec<(usize, usize)>,
}

/// One held cable end.
#[derive(Clone, Debug)]
pub struct End {
    pub junction: usize,
    pub cable: usize,
    pub topo: EndTopology,
    /// The end's orientation in the junction frame (stress-free relative rotation) and its
    /// matrix R: the end's ghost rotation is Q ⊗ relative, its increment φ = Rᵀ Θ.
    pub relative: Quat,
    pub rel: Matrix3<f64>,
    /// Index of the end in its cable's `HeldEnds`, and the cable segment it couples to.
    pub(crate) local: usize,
    pub(crate) segment: Option<usize>,
}

/// A cable segment joining two junctions: its Schur complement couples them.
#[derive(Clone, Debug)]
pub(crate) struct Link {
    pub(crate) a: usize,
    pub(crate) b: usize,
    pub(crate) end_a: usize,
    pub(crate) end_b: usize,
}

/// Invalid harness or failed solve; the message names the cable or junction.
#[derive(Clone, Debug, PartialEq)]
pub struct HarnessError(pub String);

impl fmt::Display for HarnessError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for HarnessError {}

/// The harness: cables (each with point clips at its joined ends), junctions, and the tree.
#[derive(Clone, Debug)]
pub struct Harness {
    pub names: Vec<String>,
    pub cables: Vec<Rod>,
    pub junctions: Vec<JunctionSpec>,
    pub ends: Vec<End>,
    /// Reference pose of each junction (orientation identity: the relative rotations are the
    /// ends' reference orientations).
    pub reference: Vec<Pose>,
    /// Ends of each cable (indices into `ends`).
    pub cable_ends: Vec<Vec<usize>>,
    /// Ends of each junction.
    pub junction_ends: Vec<Vec<usize>>,
    pub(crate) links: Vec<Link>,
    /// Junctions in breadth-first order from the roots, each with its parent (junction, link).
    pub(crate) order: Vec<usize>,
    pub(crate) parent: Vec<Option<(usize, usize)>>,
    pub gravity: Vector3<f64>,
    /// Junctions held by a clip (`hold_junction`): their pose is prescribed, not solved for.
    pub held: Vec<bool>,
}

fn err(s: String) -> SpecError {
    SpecError(s)
}

impl Harness {
    /// Builds the harness and validates it: every end a fixed point clip at a cable end, used
    /// once; the ends of a junction at one point; no loops.
    pub fn new(
        names: Vec<String>,
        cables: Vec<Rod>,
        junctions: Vec<JunctionSpec>,
    ) -> Result<Harness, SpecError> {
        let mut ends: Vec<End> = Vec::new();
        let mut cable_ends: Vec<Vec<usize>> = vec![Vec::new(); cables.len()];
        let mut junction_ends = vec![Vec::new(); junctions.len()];
        let mut reference = Vec::with_capacity(junctions.len());
        for (j, js) in junctions.iter().enumerate() {
            if !(js.mass.is_finite() && js.mass >= 0.0) {
                return Err(err(format!(
                    "junction '{}': mass = {}: must be ≥ 0 kg",
                    js.name, js.mass
                )));
            }
            if js
                .rotary_inertia
                .iter()
                .any(|v| !(v.is_finite() && *v >= 0.0))
            {
                return Err(err(format!(
                    "junction '{}': rotary_inertia = {:?}: must be 3 numbers ≥ 0 kg m²",
                    js.name,
                    js.rotary_inertia.as_slice()
                )));
            }
            if js.ends.is_empty() {
                return Err(err(format!("junction '{}' holds no cable end", js.name)));
            }
            let mut position = None;
            for &(c, clip) in &js.ends {
                let rod = cables.get(c).ok_or_else(|| {
                    err(format!(
                        "junction '{}': cable index {c} out of range",
                        js.name
                    ))
                })?;
                let name = &names[c];
                let spec = rod.spec.clips.get(clip).ok_or_else(|| {
                    err(format!(
                        "junction '{}': clip index {clip} of cable '{name}' out of range",
                        js.name
                    ))
                })?;
                if spec.kind != ClipKind::Fixed || spec.length != 0.0 {
                    return Err(err(format!(
                        "junction '{}': the end of cable '{name}' must be held as a fixed point",
                        js.name
                    )));
                }
                let topo = EndTopology::new(rod, clip).ok_or_else(|| {
                    err(format!(
                        "junction '{}': clip '{}' of cable '{name}' is not at an end of the \
                         cable (s = {} m; allowed: 0 or {} m)",
                        js.name, spec.name, spec.s, rod.spec.length
                    ))
                })?;
                if let Some(&k) = cable_ends[c]
                    .iter()
                    .find(|&&k| ends[k].topo.node == topo.node)
                {
                    return Err(err(format!(
                        "cable '{name}': its {} is joined twice (junctions '{}' and '{}')",
                        if topo.at_start { "start" } else { "end" },
                        junctions[ends[k].junction].name,
                        js.name
                    )));
                }
                let p = spec.pose.position;
                let tol = 1e-6 * rod.spec.length.max(1e-3);
                match position {
                    None => position = Some(p),
                    Some(q) if (p - q).norm() > tol => {
                        return Err(err(format!(
                            "junction '{}': the end of cable '{name}' is at {:?}, not at the \
                             junction {:?}",
                            js.name,
                            p.as_slice(),
                            q.as_slice()
                        )))
                    }
                    _ => {}
                }
                let relative = spec.pose.orientation;
                let k = ends.len();
                cable_ends[c].push(k);
                junction_ends[j].push(k);
                let segment = rod.segments.iter().position(|s| {
                    topo.blocks()
                        .iter()
                        .any(|b| s.blocks.contains(b) && rod.mask[*b].iter().any(|&m| m))
                });
                ends.push(End {
                    junction: j,
                    cable: c,
                    topo,
                    relative,
                    rel: rotation_matrix(&relative),
                    local: 0,
                    segment,
                });
            }
            reference.push(Pose {
                position: position.unwrap(),
                orientation: Quat::identity(),
            });
        }
        for (c, list) in cable_ends.iter().enumerate() {
            for (i, &k) in list.iter().enumerate() {
                ends[k].local = i;
            }
            if list.len() == 2 && cables[c].n_edges() < 2 {
                return Err(err(format!(
                    "cable '{}' is joined at both ends with 1 segment: give it at least 2",
                    names[c]
                )));
            }
        }
        // Loops: union–find over the junctions, a cable joined at both ends is an edge.
        let mut root: Vec<usize> = (0..junctions.len()).collect();
        fn find(root: &mut [usize], mut i: usize) -> usize {
            while root[i] != i {
                root[i] = root[root[i]];
                i = root[i];
            }
            i
        }
        let mut links = Vec::new();
        for (c, list) in cable_ends.iter().enumerate() {
            if list.len() != 2 {
                continue;
            }
            let (ka, kb) = (list[0], list[1]);
            let (ja, jb) = (ends[ka].junction, ends[kb].junction);
            let (ra, rb) = (find(&mut root, ja), find(&mut root, jb));
            if ra == rb {
                return Err(err(format!(
                    "harness with a loop: cable '{}' closes a loop through junctions '{}' and \
                     '{}'; loops are not supported yet",
                    names[c], junctions[ja].name, junctions[jb].name
                )));
            }
            root[ra] = rb;
            if ends[ka].segment.is_some() && ends[ka].segment == ends[kb].segment {
                links.push(Link {
                    a: ja,
                    b: jb,
                    end_a: ka,
                    end_b: kb,
                });
            }
        }
        // Breadth-first order of the junction forest.
        let n = junctions.len();
        let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
        for (l, link) in links.iter().enumerate() {
            adj[link.a].push((link.b, l));
            adj[link.b].push((link.a, l));
        }
        let mut order = Vec::with_capacity(n);
        let mut parent = vec![None; n];
        let mut seen = vec![false; n];
        for r in 0..n {
            if seen[r] {
                continue;
            }
            seen[r] = true;
            let start = order.len();
            order.push(r);
            let mut i = start;
            while i < order.len() {
                let j = order[i];
                for &(o, l) in &adj[j] {
                    if !seen[o] {
                        seen[o] = true;
                        parent[o] = Some((j, l));
                        order.push(o);
                    }
                }
                i += 1;
            }
        }
        let gravity = cables.first().map_or(Vector3::zeros(), |r| r.spec.gravity);
        Ok(Harness {
            names,
            cables,
            junctions,
            ends,
            reference,
            cable_ends,
            junction_ends,
            links,
            order,
            parent,
            gravity,
            held: vec![false; n],
        })
    }

    /// Holds junction `j` by a clip (docs/harness.md, "Clips holding a junction"): its pose
    /// follows the target poses given for its first end's clip (`set_clip_poses`, the entries
    /// otherwise ignored), times the inverse of that end's relative rotation; the solver
    /// prescribes it and reports the clip's reaction (`HarnessStatics::junction_reactions`).
    pub fn hold_junction(&mut self, j: usize) -> Result<(), SpecError> {
        if j >= self.junctions.len() {
            return Err(err(format!(
                "junction index {j} out of range: the harness has {} junctions",
                self.junctions.len()
            )));
        }
        self.held[j] = true;
        Ok(())
    }

    /// The pose of junction j that puts the clip of its first end at `end_pose`.
    pub fn junction_pose_from_end(&self, j: usize, end_pose: &Pose) -> Pose {
        let e = &self.ends[self.junction_ends[j][0]];
        Pose {
            position: end_pose.position,
            orientation: end_pose.orientation * e.relative.conjugate(),
        }
    }

    /// The coupling terms of each cable (one `EndBlocks` per held end).
    pub fn held_ends(&self) -> Vec<HeldEnds> {
        self.cable_ends
            .iter()
            .map(|list| HeldEnds {
                ends: list
                    .iter()
                    .map(|&k| EndBlocks::new(self.ends[k].topo))
                    .collect(),
            })
            .collect()
    }

    /// The pose of end k's clip for the junction pose `q`.
    pub fn end_pose(&self, k: usize, junction: &Pose) -> Pose {
        Pose {
            position: junction.position,
            orientation: junction.orientation * self.ends[k].relative,
        }
    }

    /// Number of unknowns (active cable slots and 6 per junction).
    pub fn n_unknowns(&self) -> usize {
        self.cables
            .iter()
            .map(|r| r.mask.iter().flatten().filter(|&&m| m).count())
            .sum::<usize>()
            + 6 * self.junctions.len()
    }
}

/// The configuration of a harness: each cable's state and each junction's pose.
#[derive(Clone, Debug)]
pub struct HarnessState {
    pub cables: Vec<State>,
    pub junctions: Vec<Pose>,
}

impl HarnessState {
    pub fn empty() -> Self {
        HarnessState {
            cables: vec![],
            junctions: vec![],
        }
    }

    /// Moves the held ends (node, ghost rotation, clip pose) to the junction poses.
    pub fn sync_ends(&mut self, h: &Harness) {
        for (k, e) in h.ends.iter().enumerate() {
            let pose = h.end_pose(k, &self.junctions[e.junction]);
            let st = &mut self.cables[e.cable];
            st.x[e.topo.node] = pose.position;
            st.ghost[e.topo.ghost] = pose.orientation;
            st.clip_pose[e.topo.clip] = pose;
        }
    }

    /// Applies a Newton increment scaled by `alpha`.
    pub fn apply_increment(
        &mut self,
        h: &Harness,
        delta: &[Vec<Vector6<f64>>],
        dj: &[Vector6<f64>],
        alpha: f64,
    ) {
        for (c, rod) in h.cables.iter().enumerate() {
            self.cables[c].apply_increment(rod, &delta[c], alpha);
        }
        for (pose, d) in self.junctions.iter_mut().zip(dj) {
            pose.position += alpha * Vector3::new(d[0], d[1], d[2]);
            pose.orientation =
                rotate_body(&pose.orientation, &(alpha * Vector3::new(d[3], d[4], d[5])));
        }
        self.sync_ends(h);
    }

    /// Sets the poses of the clips that hold cables (not the junction ends) to `poses[c]`
    /// (all clips of cable c; the entries of junction ends are ignored, but for a held
    /// junction's first end, which gives the junction's pose). `buffer` is scratch.
    pub fn set_clip_poses_with(
        &mut self,
        h: &Harness,
        poses: &[Vec<Pose>],
        buffer: &mut Vec<Pose>,
    ) {
        let mut moved = false;
        for (j, held) in h.held.iter().enumerate() {
            if *held {
                let e = &h.ends[h.junction_ends[j][0]];
                self.junctions[j] = h.junction_pose_from_end(j, &poses[e.cable][e.topo.clip]);
                moved = true;
            }
        }
        if moved {
            self.sync_ends(h);
        }
        for (c, rod) in h.cables.iter().enumerate() {
            let st = &mut self.cables[c];
            buffer.clone_from(&poses[c]);
            for &k in &h.cable_ends[c] {
                let clip = h.ends[k].topo.clip;
                buffer[clip] = st.clip_pose[clip];
            }
            st.set_clip_poses(rod, buffer);
        }
    }

    /// `set_clip_poses_with` with a scratch buffer of its own.
    pub fn set_clip_poses(&mut self, h: &Harness, poses: &[Vec<Pose>]) {
        self.set_clip_poses_with(h, poses, &mut Vec::new());
    }
}

#[cfg(test)]
#[path = "harness_tests.rs"]
pub(crate) mod tests;
