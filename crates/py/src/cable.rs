//! Bindings of the rod solver: a `Cable` built from plain numbers and arrays; runs release the
//! GIL, poll Ctrl-C and report progress through an optional Python callable.
use crate::stop::{Poller, StopFlag};
use nalgebra::{Quaternion, Vector3};
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rod::assembly::Workspace;
use rod::contact::{Contact, ContactOptions, Cuboid, Cylinder, Obstacle, Plane, Shape, Sphere};
use rod::contact_mesh::MeshShape;
use rod::routing::route;
use rod::sliding::SlidingClips;
use rod::{
    CableSpec, ClipKind, ClipMotion, ClipSpec, DynamicOptions, Dynamics, NewtonOptions, PointLoad,
    Pose, Rod, Section, State, Statics,
};

pub(crate) fn vec3(v: &[f64], what: &str) -> PyResult<Vector3<f64>> {
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{what} = {v:?}: must be 3 finite numbers"
        )));
    }
    Ok(Vector3::new(v[0], v[1], v[2]))
}

fn quat(v: &[f64], what: &str) -> PyResult<Quaternion<f64>> {
    if v.len() != 4 || v.iter().any(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{what} = {v:?}: must be 4 finite numbers"
        )));
    }
    let q = Quaternion::new(v[0], v[1], v[2], v[3]);
    if q.norm() == 0.0 {
        return Err(PyValueError::new_err(format!(
            "{what} = {v:?}: must be a non-zero quaternion"
        )));
    }
    Ok(q / q.norm())
}

/// (name, s, length, kind, position[3], quaternion[4] scalar first).
type ClipTuple = (String, f64, f64, String, Vec<f64>, Vec<f64>);

/// The largest unresolved and given-back impact gains (`StepStats::unresolved_gain`,
/// `impact_dissipation`) of the steps since the last saved step.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Impacts {
    unresolved: f64,
    dissipation: f64,
}

impl Impacts {
    pub(crate) fn add(&mut self, s: &rod::StepStats) {
        self.unresolved = self.unresolved.max(s.unresolved_gain);
        self.dissipation = self.dissipation.max(s.impact_dissipation);
    }

    /// The gains so far (unresolved, given back), starting afresh.
    pub(crate) fn take(&mut self) -> (f64, f64) {
        let Impacts {
            unresolved,
            dissipation,
        } = std::mem::take(self);
        (unresolved, dissipation)
    }
}

/// The modal solver's stopping tolerance of a `modes` call: `rod::modal::TOLERANCE` unless
/// given; a ValueError outside 0 < tolerance < 1.
pub(crate) fn modal_tolerance(tolerance: Option<f64>) -> PyResult<f64> {
    match tolerance {
        None => Ok(rod::modal::TOLERANCE),
        Some(t) if t > 0.0 && t < 1.0 => Ok(t),
        Some(t) => Err(PyValueError::new_err(format!(
            "tolerance = {t}: allowed 0 < tolerance < 1 (the relative change of the eigenvalues \
             at which the iteration stops; default {:e})",
            rod::modal::TOLERANCE
        ))),
    }
}

/// Per-step outputs collected during a run (flat, row-major).
#[derive(Default)]
pub(crate) struct Record {
    steps: usize,
    positions: Vec<f64>,
    quaternions: Vec<f64>,
    forces: Vec<f64>,
    moments: Vec<f64>,
    reaction_force: Vec<f64>,
    reaction_moment: Vec<f64>,
    iterations: Vec<i64>,
    substeps: Vec<i64>,
    residual: Vec<f64>,
    /// Dynamic runs: per saved step, the largest energy gain of an impact sub-step the step
    /// guard accepted at its deepest split since the last saved step (`StepStats::unresolved_gain`).
    unresolved_gain: Vec<f64>,
    /// Dynamic runs: per saved step, the largest energy gain of such a sub-step that the guard
    /// gave back from the motion near the contact since the last saved step
    /// (`StepStats::impact_dissipation`).
    impact_dissipation: Vec<f64>,
    /// Negative eigenvalues of the tangent stiffness (−1: not checked: dynamic steps, dead
    /// moments).
    unstable: Vec<i64>,
    /// Snap-through in the step: fraction of the step, largest jump (m) and its node.
    snap_fraction: Vec<f64>,
    snap_jump: Vec<f64>,
    snap_node: Vec<i64>,
    elastic_energy: Vec<f64>,
    kinetic_energy: Vec<f64>,
    load_potential: Vec<f64>,
    dissipated_energy: Vec<f64>,
    /// Peaks over the recorded steps of the viscous section loads: |F3|, |F1, F2|, |M1, M2|,
    /// |M3| (body frame).
    viscous_peak: [f64; 4],
    contact_energy: Vec<f64>,
    /// Contact outputs (with contact only): per node normal and friction force (global),
    /// state (0 none, 1 stick, 2 slip); per body total force; smallest gap.
    contact_normal: Vec<f64>,
    contact_friction: Vec<f64>,
    contact_state: Vec<u8>,
    body_contact_force: Vec<f64>,
    contact_gap: Vec<f64>,
    /// Per step and clip: the length of cable slid through the clip since the reference
    /// (σ − s; 0 for clips that hold the cable).
    slid_length: Vec<f64>,
}

impl Record {
    /// A record with room for `n` saved steps (no reallocation while recording).
    pub(crate) fn with_capacity(n: usize, rod: &Rod) -> Record {
        let (nodes, edges, clips) = (rod.arc.len(), rod.n_edges(), rod.spec.clips.len());
        Record {
            steps: 0,
            positions: Vec::with_capacity(n * 3 * nodes),
            quaternions: Vec::with_capacity(n * 4 * edges),
            forces: Vec::with_capacity(n * 3 * edges),
            moments: Vec::with_capacity(n * 3 * nodes),
            reaction_force: Vec::with_capacity(n * 3 * clips),
            reaction_moment: Vec::with_capacity(n * 3 * clips),
            iterations: Vec::with_capacity(n),
            substeps: Vec::with_capacity(n),
            residual: Vec::with_capacity(n),
            unresolved_gain: Vec::with_capacity(n),
            impact_dissipation: Vec::with_capacity(n),
            unstable: Vec::with_capacity(n),
            snap_fraction: Vec::with_capacity(n),
            snap_jump: Vec::with_capacity(n),
            snap_node: Vec::with_capacity(n),
            elastic_energy: Vec::with_capacity(n),
            kinetic_energy: Vec::with_capacity(n),
            load_potential: Vec::with_capacity(n),
            dissipated_energy: Vec::with_capacity(n),
            viscous_peak: [0.0; 4],
            contact_energy: Vec::with_capacity(n),
            ..Default::default()
        }
    }

    pub(crate) fn push(&mut self, rod: &Rod, st: &State, ws: &Workspace, stats: &rod::SolveStats) {
        self.steps += 1;
        for x in &st.x {
            self.positions.extend_from_slice(x.as_slice());
        }
        for p in &st.p {
            self.quaternions.extend_from_slice(&[p.w, p.i, p.j, p.k]);
        }
        for f in &ws.edge_force {
            self.forces.extend_from_slice(f.as_slice());
        }
        for m in &ws.node_moment {
            self.moments.extend_from_slice(m.as_slice());
        }
        for c in 0..rod.spec.clips.len() {
            let (f, m) = ws.clip_reaction(rod, st, c);
            self.reaction_force.extend_from_slice(f.as_slice());
            self.reaction_moment.extend_from_slice(m.as_slice());
        }
        self.iterations.push(stats.iterations as i64);
        self.substeps.push(stats.substeps as i64);
        self.residual.push(stats.residual);
        self.unstable.push(stats.unstable.map_or(-1, |n| n as i64));
        let snap = stats.snap.unwrap_or(rod::Snap {
            fraction: f64::NAN,
            jump: 0.0,
            node: 0,
        });
        self.snap_fraction.push(snap.fraction);
        self.snap_jump.push(snap.jump);
        self.snap_node.push(if stats.snap.is_some() {
            snap.node as i64
        } else {
            -1
        });
        self.elastic_energy.push(ws.elastic_energy);
        self.load_potential.push(ws.load_potential);
        self.contact_energy.push(ws.contact_energy);
    }

    /// The impact gains of the saved step just pushed (dynamic runs): the largest unresolved
    /// and given-back gains since the saved step before (`Impacts::take`).
    pub(crate) fn push_impacts(&mut self, (unresolved, dissipation): (f64, f64)) {
        self.unresolved_gain.push(unresolved);
        self.impact_dissipation.push(dissipation);
    }

    /// The slid length of every clip at the step just pushed.
    pub(crate) fn push_sliding(&mut self, rod: &Rod, sliding: Option<&SlidingClips>) {
        let start = self.slid_length.len();
        self.slid_length
            .extend(std::iter::repeat_n(0.0, rod.spec.clips.len()));
        if let Some(sl) = sliding {
            for (k, &c) in sl.clips.iter().enumerate() {
                self.slid_length[start + c] = sl.sigma[k] - rod.spec.clips[c].s;
            }
        }
    }

    /// Room for the contact outputs of `n` saved steps.
    pub(crate) fn reserve_contact(&mut self, n: usize, nodes: usize, bodies: usize) {
        self.contact_normal.reserve(n * 3 * nodes);
        self.contact_friction.reserve(n * 3 * nodes);
        self.contact_state.reserve(n * nodes);
        self.body_contact_force.reserve(n * 3 * bodies);
        self.contact_gap.reserve(n);
    }

    pub(crate) fn push_contact(&mut self, c: &Contact) {
        for (f, t) in c.normal_force.iter().zip(&c.friction_force) {
            self.contact_normal.extend_from_slice(f.as_slice());
            self.contact_friction.extend_from_slice(t.as_slice());
        }
        self.contact_state.extend_from_slice(&c.node_state);
        for f in &c.body_force {
            self.body_contact_force.extend_from_slice(f.as_slice());
        }
        self.contact_gap.push(c.reported_gap());
    }

    /// Updates the peaks of the viscous section loads (dynamic runs). The shear force and
    /// bending moment magnitudes as √(x² + y²): section loads are far from overflow, and
    /// `f64::hypot` was 1.6 % of a harness run saving every step.
    pub(crate) fn push_viscous(&mut self, ws: &Workspace) {
        let p = &mut self.viscous_peak;
        for f in &ws.edge_force_viscous {
            p[0] = p[0].max(f.z.abs());
            p[1] = p[1].max((f.x * f.x + f.y * f.y).sqrt());
        }
        for m in &ws.node_moment_viscous {
            p[2] = p[2].max((m.x * m.x + m.y * m.y).sqrt());
            p[3] = p[3].max(m.z.abs());
        }
    }

    pub(crate) fn push_energies(&mut self, e: &rod::Energies) {
        self.kinetic_energy.push(e.kinetic);
        self.dissipated_energy.push(e.dissipated);
    }

    pub(crate) fn into_dict<'py>(
        self,
        py: Python<'py>,
        n_nodes: usize,
        n_clips: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let t = self.steps;
        let d = PyDict::new(py);
        let shaped =
            |v: Vec<f64>, shape: &[usize]| PyArray1::from_vec(py, v).reshape(shape.to_vec());
        d.set_item("positions", shaped(self.positions, &[t, n_nodes, 3])?)?;
        d.set_item(
            "quaternions",
            shaped(self.quaternions, &[t, n_nodes - 1, 4])?,
        )?;
        d.set_item("forces", shaped(self.forces, &[t, n_nodes - 1, 3])?)?;
        d.set_item("moments", shaped(self.moments, &[t, n_nodes, 3])?)?;
        d.set_item(
            "reaction_force",
            shaped(self.reaction_force, &[t, n_clips, 3])?,
        )?;
        d.set_item(
            "reaction_moment",
            shaped(self.reaction_moment, &[t, n_clips, 3])?,
        )?;
        d.set_item("slid_length", shaped(self.slid_length, &[t, n_clips])?)?;
        d.set_item("iterations", PyArray1::from_vec(py, self.iterations))?;
        d.set_item("substeps", PyArray1::from_vec(py, self.substeps))?;
        d.set_item("residual", PyArray1::from_vec(py, self.residual))?;
        if !self.unresolved_gain.is_empty() {
            d.set_item(
                "unresolved_gain",
                PyArray1::from_vec(py, self.unresolved_gain),
            )?;
            d.set_item(
                "impact_dissipation",
                PyArray1::from_vec(py, self.impact_dissipation),
            )?;
        }
        d.set_item("unstable", PyArray1::from_vec(py, self.unstable))?;
        d.set_item("snap_fraction", PyArray1::from_vec(py, self.snap_fraction))?;
        d.set_item("snap_jump", PyArray1::from_vec(py, self.snap_jump))?;
        d.set_item("snap_node", PyArray1::from_vec(py, self.snap_node))?;
        for (key, values) in [
            ("elastic_energy", self.elastic_energy),
            ("kinetic_energy", self.kinetic_energy),
            ("load_potential", self.load_potential),
            ("dissipated_energy", self.dissipated_energy),
            ("contact_energy", self.contact_energy),
        ] {
            d.set_item(key, PyArray1::from_vec(py, values))?;
        }
        d.set_item("viscous_peak", self.viscous_peak.to_vec())?;
        if !self.contact_gap.is_empty() {
            let n_bodies = self.body_contact_force.len() / (3 * t).max(1);
            d.set_item(
                "contact_normal",
                shaped(self.contact_normal, &[t, n_nodes, 3])?,
            )?;
            d.set_item(
                "contact_friction",
                shaped(self.contact_friction, &[t, n_nodes, 3])?,
            )?;
            d.set_item(
                "contact_state",
                PyArray1::from_vec(py, self.contact_state).reshape(vec![t, n_nodes])?,
            )?;
            d.set_item(
                "body_contact_force",
                shaped(self.body_contact_force, &[t, n_bodies, 3])?,
            )?;
            d.set_item("contact_gap", PyArray1::from_vec(py, self.contact_gap))?;
        }
        d.set_item("steps", t)?;
        Ok(d)
    }
}

pub(crate) fn read_poses(
    pos: &numpy::ndarray::ArrayView3<f64>,
    qs: &numpy::ndarray::ArrayView3<f64>,
) -> PyResult<Vec<Vec<Pose>>> {
    let (t, c, _) = pos.dim();
    let mut poses = Vec::with_capacity(t);
    for k in 0..t {
        let mut step = Vec::with_capacity(c);
        for j in 0..c {
            let p = pos.slice(numpy::ndarray::s![k, j, ..]);
            let q = qs.slice(numpy::ndarray::s![k, j, ..]);
            step.push(Pose {
                position: Vector3::new(p[0], p[1], p[2]),
                orientation: quat(&[q[0], q[1], q[2], q[3]], "clip orientation")?,
            });
        }
        poses.push(step);
    }
    Ok(poses)
}

/// (clip a, clip b, chord, cable length between them) of each span.
type SpanTuple = (String, String, f64, f64);

/// The obstacle poses at step k (the last given for later steps; None without contact).
pub(crate) fn obstacle_at(poses: &[Vec<Pose>], k: usize) -> Option<&[Pose]> {
    poses.get(k).or(poses.last()).map(|p| p.as_slice())
}

/// One cable: mesh, state and solver.
#[pyclass(module = "cablelife._core")]
pub struct Cable {
    pub(crate) rod: Rod,
    state: Option<State>,
    pub(crate) solver: Statics,
    /// Global poses of the contact obstacles per time step (T, O) (empty: no contact).
    pub(crate) obstacle_poses: Vec<Vec<Pose>>,
}

/// (name, body index, kind, dimensions, friction): plane [], sphere [radius], cylinder
/// [radius, length (inf: infinite)], box [half extents x, y, z].
type ObstacleTuple = (String, usize, String, Vec<f64>, f64);

/// A closed triangle mesh (vertices (M, 3), faces (F, 3)) as a contact shape.
fn mesh_shape(
    name: &str,
    vertices: &PyReadonlyArray2<'_, f64>,
    faces: &PyReadonlyArray2<'_, i64>,
) -> PyResult<Box<dyn Shape>> {
    let bad = |msg: String| PyValueError::new_err(format!("geometry '{name}': {msg}"));
    let v = vertices.as_array();
    let f = faces.as_array();
    if v.ncols() != 3 || f.ncols() != 3 {
        return Err(bad(format!(
            "mesh arrays have shapes {:?} and {:?}: must be (M, 3) and (F, 3)",
            v.shape(),
            f.shape()
        )));
    }
    let verts: Vec<Vector3<f64>> = v
        .rows()
        .into_iter()
        .map(|r| Vector3::new(r[0], r[1], r[2]))
        .collect();
    let tris = crate::geometry::face_rows(faces, verts.len()).map_err(bad)?;
    let mesh = ::geometry::TriMesh::new(&verts, &tris).map_err(|e| bad(e.0))?;
    Ok(Box::new(MeshShape::new(mesh, &verts)))
}

fn shape(name: &str, kind: &str, dims: &[f64]) -> PyResult<Box<dyn Shape>> {
    let positive = |i: usize, what: &str| -> PyResult<f64> {
        match dims.get(i) {
            Some(&v) if v > 0.0 && !v.is_nan() => Ok(v),
            v => Err(PyValueError::new_err(format!(
                "geometry '{name}': {what} = {v:?}: must be a positive length in m"
            ))),
        }
    };
    Ok(match kind {
        "plane" => Box::new(Plane),
        "sphere" => Box::new(Sphere {
            radius: positive(0, "radius")?,
        }),
        "cylinder" => Box::new(Cylinder {
            radius: positive(0, "radius")?,
            length: positive(1, "length")?,
        }),
        "box" => Box::new(Cuboid {
            half: Vector3::new(
                positive(0, "half size x")?,
                positive(1, "half size y")?,
                positive(2, "half size z")?,
            ),
        }),
        other => {
            return Err(PyValueError::new_err(format!(
                "geometry '{name}': type = {other:?}; allowed: plane, sphere, cylinder, box, mesh"
            )))
        }
    })
}

impl Cable {
    /// The spans between consecutive clips at the clip poses of the first step.
    fn spans(&self, poses: Option<&Vec<Pose>>) -> Vec<SpanTuple> {
        let Some(poses) = poses else {
            return vec![];
        };
        let clips = &self.rod.spec.clips;
        rod::routing::span_stretches(&self.rod, poses)
            .into_iter()
            .map(|sp| {
                let (a, b) = sp.clips;
                (
                    clips[a].name.clone(),
                    clips[b].name.clone(),
                    sp.chord,
                    sp.length,
                )
            })
            .collect()
    }
}

#[pymethods]
impl Cable {
    /// clips: list of (name, s, length, kind, position[3], quaternion[4] scalar first);
    /// loads: list of (s, force[3], moment[3]); clip_axes: {clip name: axis[3] in the clip
    /// frame} of the hinge clips; clip_friction: {clip name: μ} of the sliding clips.
    #[new]
    #[pyo3(signature = (length, segments, shear_stiffness, bend_stiffness, mass_per_length,
        rotary_inertia, natural_curvature, gravity, clips, loads, max_iterations=40,
        step_tolerance=1e-9, clip_axes=None, clip_friction=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        length: f64,
        segments: usize,
        shear_stiffness: Vec<f64>,
        bend_stiffness: Vec<f64>,
        mass_per_length: f64,
        rotary_inertia: Vec<f64>,
        natural_curvature: Vec<f64>,
        gravity: Vec<f64>,
        clips: Vec<ClipTuple>,
        loads: Vec<(f64, Vec<f64>, Vec<f64>)>,
        max_iterations: usize,
        step_tolerance: f64,
        clip_axes: Option<std::collections::HashMap<String, Vec<f64>>>,
        clip_friction: Option<std::collections::HashMap<String, f64>>,
    ) -> PyResult<Self> {
        let clip_axes = clip_axes.unwrap_or_default();
        let clip_friction = clip_friction.unwrap_or_default();
        let section = Section {
            shear_stiffness: vec3(&shear_stiffness, "shear_stiffness")?,
            bend_stiffness: vec3(&bend_stiffness, "bend_stiffness")?,
            mass_per_length,
            rotary_inertia: vec3(&rotary_inertia, "rotary_inertia")?,
        };
        let mut clip_specs = Vec::with_capacity(clips.len());
        for (name, s, len, kind, pos, q) in clips {
            let kind = match kind.as_str() {
                "fixed" => ClipKind::Fixed,
                "swivel" => ClipKind::Swivel,
                "ball" => ClipKind::Ball,
                "sliding" => ClipKind::Sliding {
                    friction: clip_friction.get(&name).copied().unwrap_or(0.0),
                },
                "hinge" => match clip_axes.get(&name) {
                    Some(a) => ClipKind::Hinge {
                        axis: vec3(a, &format!("clip '{name}' axis"))?,
                    },
                    None => {
                        return Err(PyValueError::new_err(format!(
                            "clip '{name}': a hinge needs its axis (clip_axes['{name}'])"
                        )))
                    }
                },
                other => {
                    return Err(PyValueError::new_err(format!(
                    "clip '{name}': type = {other:?}; allowed: fixed, swivel, ball, hinge, sliding"
                )))
                }
            };
            let pose = Pose {
                position: vec3(&pos, &format!("clip '{name}' position"))?,
                orientation: quat(&q, &format!("clip '{name}' orientation"))?,
            };
            clip_specs.push(ClipSpec {
                name,
                s,
                length: len,
                kind,
                pose,
            });
        }
        let mut load_specs = Vec::with_capacity(loads.len());
        for (i, (s, f, m)) in loads.into_iter().enumerate() {
            load_specs.push(PointLoad {
                s,
                force: vec3(&f, &format!("load {i} force"))?,
                moment: vec3(&m, &format!("load {i} moment"))?,
            });
        }
        let spec = CableSpec {
            length,
            segments,
            section,
            natural_curvature: vec3(&natural_curvature, "natural_curvature")?,
            clips: clip_specs,
            loads: load_specs,
            gravity: vec3(&gravity, "gravity")?,
        };
        let rod = Rod::new(spec).map_err(|e| PyValueError::new_err(e.0))?;
        let opts = NewtonOptions {
            max_iterations,
            step_tolerance,
            ..Default::default()
        };
        let solver = Statics::new(&rod, opts);
        Ok(Cable {
            rod,
            state: None,
            solver,
            obstacle_poses: Vec::new(),
        })
    }

    /// Contact with rigid obstacles (docs/contact.md): `obstacles` as (name, body index,
    /// type, dimensions, friction μ); their global poses per time step of the next run,
    /// `positions` (T, O, 3) and `quaternions` (T, O, 4, scalar first) — T = 1: at rest.
    /// distance/stick_distance ≤ 0: the defaults for the radius (1 % and 0.1 % of r).
    /// `damping`: the normal damping time constant τ_c of dynamic contact, s.
    /// Type "mesh": dimensions [k], the k-th of `meshes` (vertices (M, 3), faces (F, 3)) in
    /// the obstacle's frame.
    #[pyo3(signature = (obstacles, n_bodies, radius, positions, quaternions, distance=0.0,
        stiffness=0.0, stick_distance=0.0, stick_velocity=1e-3, max_samples=8, meshes=vec![],
        damping=5e-4))]
    #[allow(clippy::too_many_arguments)]
    fn set_contact(
        &mut self,
        obstacles: Vec<ObstacleTuple>,
        n_bodies: usize,
        radius: f64,
        positions: PyReadonlyArray3<'_, f64>,
        quaternions: PyReadonlyArray3<'_, f64>,
        distance: f64,
        stiffness: f64,
        stick_distance: f64,
        stick_velocity: f64,
        max_samples: usize,
        meshes: Vec<(PyReadonlyArray2<'_, f64>, PyReadonlyArray2<'_, i64>)>,
        damping: f64,
    ) -> PyResult<()> {
        let pos = positions.as_array();
        let qs = quaternions.as_array();
        let (t, o, three) = pos.dim();
        if o != obstacles.len() || three != 3 || qs.dim() != (t, o, 4) || t == 0 {
            return Err(PyValueError::new_err(format!(
                "obstacle poses must be (T, {}, 3) and (T, {}, 4); got {:?} and {:?}",
                obstacles.len(),
                obstacles.len(),
                pos.dim(),
                qs.dim()
            )));
        }
        let poses = read_poses(&pos, &qs)?;
        let mut opts = ContactOptions::for_radius(radius);
        if distance > 0.0 {
            opts.distance = distance;
        }
        if stick_distance > 0.0 {
            opts.stick_distance = stick_distance;
        }
        opts.stiffness = stiffness;
        opts.stick_velocity = stick_velocity;
        opts.max_samples = max_samples;
        opts.damping = damping;
        let mut list = Vec::with_capacity(obstacles.len());
        for (k, (name, body, kind, dims, mu)) in obstacles.into_iter().enumerate() {
            let sh = if kind == "mesh" {
                match dims
                    .first()
                    .map(|&k| k as usize)
                    .and_then(|k| meshes.get(k))
                {
                    Some((v, f)) => mesh_shape(&name, v, f)?,
                    None => {
                        return Err(PyValueError::new_err(format!(
                            "geometry '{name}': mesh index {dims:?} not among the {} meshes",
                            meshes.len()
                        )))
                    }
                }
            } else {
                shape(&name, &kind, &dims)?
            };
            list.push(Obstacle::new(&name, body, sh, mu, &poses[0][k]));
        }
        let contact = Contact::new(&self.rod, list, opts, n_bodies)
            .map_err(|e| PyValueError::new_err(e.0))?;
        self.solver.contact = Some(contact);
        self.obstacle_poses = poses;
        Ok(())
    }

    /// Arc lengths of the nodes (N+1,).
    #[getter]
    fn arc_length<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.rod.arc.clone())
    }

    /// The normal (d1, global) of clip `to_clip` when the frame of clip `from_clip` is
    /// carried along the routed reference centreline to it without twist (parallel
    /// transport): the default normal of a junction's end (docs/harness.md).
    fn transported_normal(&self, from_clip: usize, to_clip: usize) -> PyResult<[f64; 3]> {
        let n = self.rod.spec.clips.len();
        if from_clip >= n || to_clip >= n {
            return Err(PyValueError::new_err(format!(
                "clip indices {from_clip}, {to_clip}: the cable has {n} clips"
            )));
        }
        let d1 = rod::routing::transported_normal(&self.rod, from_clip, to_clip)
            .map_err(|e| PyValueError::new_err(e.0))?;
        Ok([d1.x, d1.y, d1.z])
    }

    /// Lumped nodal masses (N+1,).
    #[getter]
    fn node_mass<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.rod.node_mass.clone())
    }

    /// Runs a sequence of equilibria through the clip poses `positions` (T, C, 3) and
    /// `quaternions` (T, C, 4). Step 0 is a static solve from the routed shape (with load
    /// continuation if needed); later steps are warm-started and sub-stepped on failure.
    /// Returns a dict of arrays for the completed steps and `error` (None, or why it stopped:
    /// the results up to there are kept). `stop`: a `StopFlag` read after every step (the
    /// run ends with error "interrupted" when it is set).
    #[pyo3(signature = (positions, quaternions, progress=None, progress_every=50, stop=None))]
    fn run_sequence<'py>(
        &mut self,
        py: Python<'py>,
        positions: PyReadonlyArray3<'py, f64>,
        quaternions: PyReadonlyArray3<'py, f64>,
        progress: Option<Py<PyAny>>,
        progress_every: usize,
        stop: Option<Bound<'py, StopFlag>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let pos = positions.as_array();
        let qs = quaternions.as_array();
        let n_clips = self.rod.spec.clips.len();
        let (t, c, three) = pos.dim();
        if c != n_clips || three != 3 || qs.dim() != (t, n_clips, 4) {
            return Err(PyValueError::new_err(format!(
                "clip poses must be (T, {n_clips}, 3) and (T, {n_clips}, 4); got {:?} and {:?}",
                pos.dim(),
                qs.dim()
            )));
        }
        let poses = read_poses(&pos, &qs)?;
        let spans = self.spans(poses.first());
        let rod = &self.rod;
        let solver = &mut self.solver;
        let state_slot = &mut self.state;
        let mut poller = Poller::new(stop.as_ref(), progress, progress_every, poses.len());
        let obstacle_poses = &self.obstacle_poses;
        let initial = route(rod, poses.first().map(|p| p.as_slice()))
            .map_err(|e| PyValueError::new_err(e.0))?;
        let (record, error) = py.detach(move || {
            let mut rec = Record::default();
            let mut st = initial;
            for (k, target) in poses.iter().enumerate() {
                if let (Some(c), Some(p)) = (&mut solver.contact, obstacle_at(obstacle_poses, k)) {
                    c.set_obstacle_poses(p);
                }
                let result = if k == 0 {
                    solver.solve(rod, &mut st)
                } else {
                    solver.sequence_step(rod, &mut st, target)
                };
                match result {
                    Ok(stats) => {
                        if let Err(kink) = solver.assemble(rod, &st, 1.0, false) {
                            return (rec, Some(format!("kink at node {}", kink.node)));
                        }
                        rec.push(rod, &st, &solver.ws, &stats);
                        rec.push_sliding(rod, solver.sliding.as_ref());
                        if let Some(c) = &solver.contact {
                            rec.push_contact(c);
                        }
                    }
                    Err(e) => {
                        *state_slot = Some(st);
                        return (rec, Some(format!("step {k}: {e}")));
                    }
                }
                if let Some(why) = poller.poll(k + 1) {
                    *state_slot = Some(st);
                    return (rec, Some(why));
                }
            }
            *state_slot = Some(st);
            (rec, None)
        });
        let d = record.into_dict(py, self.rod.arc.len(), n_clips)?;
        d.set_item("error", error)?;
        d.set_item("spans", spans)?;
        Ok(d)
    }

    /// One static equilibrium at the clip poses `positions` (C, 3), `quaternions` (C, 4),
    /// warm-started from the last equilibrium (sub-stepped toward the poses on failure), or
    /// solved from the routed shape when there is none (interactive use: the workbench).
    /// Returns the dict of `run_sequence` with one step; a failed solve is a ValueError and
    /// keeps the last equilibrium as it was.
    fn step_static<'py>(
        &mut self,
        py: Python<'py>,
        positions: PyReadonlyArray2<'py, f64>,
        quaternions: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let n_clips = self.rod.spec.clips.len();
        let (pos, qs) = (positions.as_array(), quaternions.as_array());
        if pos.dim() != (n_clips, 3) || qs.dim() != (n_clips, 4) {
            return Err(PyValueError::new_err(format!(
                "clip poses must be ({n_clips}, 3) and ({n_clips}, 4); got {:?} and {:?}",
                pos.dim(),
                qs.dim()
            )));
        }
        let pos3 = pos.insert_axis(numpy::ndarray::Axis(0));
        let qs3 = qs.insert_axis(numpy::ndarray::Axis(0));
        let target = read_poses(&pos3, &qs3)?.remove(0);
        let rod = &self.rod;
        let solver = &mut self.solver;
        if let (Some(c), Some(p)) = (&mut solver.contact, obstacle_at(&self.obstacle_poses, 0)) {
            c.set_obstacle_poses(p);
        }
        let previous = self.state.clone();
        let (outcome, st) = py.detach(|| {
            let (result, st) = match previous {
                Some(mut st) => (solver.sequence_step(rod, &mut st, &target), st),
                None => match route(rod, Some(&target)) {
                    Ok(mut st) => (solver.solve(rod, &mut st), st),
                    Err(e) => return (Err(e.0), None),
                },
            };
            let outcome = match result {
                Ok(stats) => match solver.assemble(rod, &st, 1.0, false) {
                    Ok(()) => {
                        let mut rec = Record::with_capacity(1, rod);
                        rec.push(rod, &st, &solver.ws, &stats);
                        rec.push_sliding(rod, solver.sliding.as_ref());
                        if let Some(c) = &solver.contact {
                            rec.push_contact(c);
                        }
                        Ok(rec)
                    }
                    Err(kink) => Err(format!("kink at node {}", kink.node)),
                },
                Err(e) => Err(e.to_string()),
            };
            (outcome, Some(st))
        });
        let rec = outcome.map_err(PyValueError::new_err)?;
        self.state = st;
        let d = rec.into_dict(py, self.rod.arc.len(), n_clips)?;
        d.set_item("error", None::<String>)?;
        Ok(d)
    }

    /// Dynamic run: static equilibrium at the clip poses of step 0, then generalized-α steps
    /// of `time_step` through the clip kinematics (T, C, ·): positions, quaternions, velocities,
    /// angular velocities, accelerations, angular accelerations (global). Every
    /// `output_every`-th step is recorded (and step 0). τ: retardation times (GA₁, GA₂, EA),
    /// (EI₁, EI₂, GJ). Returns the recorded arrays, energies and `error` as `run_sequence`,
    /// and `unresolved_gain`, `impact_dissipation` (T,): the largest energy gain, relative to
    /// the energies at play, of an impact sub-step at the step guard's deepest split since the
    /// last recorded step that it accepted (the motion held less) and that it gave back from
    /// the motion near the contact (0: none); `stop` as there.
    #[pyo3(signature = (time_step, positions, quaternions, velocities, angular_velocities,
        accelerations, angular_accelerations, output_every, tau_shear, tau_bend,
        spectral_radius=0.9, newton_tolerance=rod::dynamics::DEFAULT_TOLERANCE, progress=None,
        progress_every=100, stop=None))]
    #[allow(clippy::too_many_arguments)]
    fn run_dynamic<'py>(
        &mut self,
        py: Python<'py>,
        time_step: f64,
        positions: PyReadonlyArray3<'py, f64>,
        quaternions: PyReadonlyArray3<'py, f64>,
        velocities: PyReadonlyArray3<'py, f64>,
        angular_velocities: PyReadonlyArray3<'py, f64>,
        accelerations: PyReadonlyArray3<'py, f64>,
        angular_accelerations: PyReadonlyArray3<'py, f64>,
        output_every: usize,
        tau_shear: Vec<f64>,
        tau_bend: Vec<f64>,
        spectral_radius: f64,
        newton_tolerance: f64,
        progress: Option<Py<PyAny>>,
        progress_every: usize,
        stop: Option<Bound<'py, StopFlag>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !(newton_tolerance > 0.0 && newton_tolerance < 1.0) {
            return Err(PyValueError::new_err(format!(
                "newton_tolerance = {newton_tolerance}: allowed is 0 < tolerance < 1"
            )));
        }
        if !(time_step.is_finite() && time_step > 0.0) {
            return Err(PyValueError::new_err(format!(
                "time_step = {time_step}: must be > 0 s"
            )));
        }
        if !(0.0..=1.0).contains(&spectral_radius) {
            return Err(PyValueError::new_err(format!(
                "spectral_radius = {spectral_radius}: allowed is 0 ≤ ρ∞ ≤ 1"
            )));
        }
        let n_clips = self.rod.spec.clips.len();
        let pos = positions.as_array();
        let qs = quaternions.as_array();
        let t = pos.dim().0;
        let arrays = [
            velocities.as_array(),
            angular_velocities.as_array(),
            accelerations.as_array(),
            angular_accelerations.as_array(),
        ];
        if pos.dim() != (t, n_clips, 3)
            || qs.dim() != (t, n_clips, 4)
            || arrays.iter().any(|a| a.dim() != (t, n_clips, 3))
        {
            return Err(PyValueError::new_err(format!(
                "clip kinematics must be (T, {n_clips}, 3), quaternions (T, {n_clips}, 4)"
            )));
        }
        let poses = read_poses(&pos, &qs)?;
        let vec_at = |a: &numpy::ndarray::ArrayView3<f64>, k: usize, j: usize| {
            Vector3::new(a[[k, j, 0]], a[[k, j, 1]], a[[k, j, 2]])
        };
        let motions: Vec<Vec<ClipMotion>> = (0..t)
            .map(|k| {
                (0..n_clips)
                    .map(|j| ClipMotion {
                        pose: poses[k][j],
                        velocity: vec_at(&arrays[0], k, j),
                        angular_velocity: vec_at(&arrays[1], k, j),
                        acceleration: vec_at(&arrays[2], k, j),
                        angular_acceleration: vec_at(&arrays[3], k, j),
                    })
                    .collect()
            })
            .collect();
        let opts = DynamicOptions {
            rho_inf: spectral_radius,
            tau_shear: vec3(&tau_shear, "tau_shear")?,
            tau_bend: vec3(&tau_bend, "tau_bend")?,
            tolerance: newton_tolerance,
            // Section outputs and energies only on the recorded steps.
            outputs_every_step: false,
            ..Default::default()
        };
        let initial = route(&self.rod, poses.first().map(|p| p.as_slice()))
            .map_err(|e| PyValueError::new_err(e.0))?;
        let spans = self.spans(poses.first());
        let rod = &self.rod;
        let solver = &mut self.solver;
        let state_slot = &mut self.state;
        let obstacle_poses = &self.obstacle_poses;
        let every = output_every.max(1);
        let mut poller = Poller::new(stop.as_ref(), progress, progress_every, t);
        let (record, error) = py.detach(move || {
            let saved = t.saturating_sub(1) / every + 1;
            let mut rec = Record::with_capacity(saved, rod);
            if let Some(c) = &solver.contact {
                rec.reserve_contact(saved, rod.arc.len(), c.body_force.len());
            }
            let mut st = initial;
            if let (Some(c), Some(p)) = (&mut solver.contact, obstacle_at(obstacle_poses, 0)) {
                c.set_obstacle_poses(p);
            }
            let stats = match solver.solve(rod, &mut st) {
                Ok(s) => s,
                Err(e) => return (rec, Some(format!("static equilibrium at t = 0: {e}"))),
            };
            let mut dy = Dynamics::new(rod, &st, &motions[0], opts);
            dy.contact = solver.contact.clone();
            if let Err(e) = dy.start(rod, &st) {
                return (rec, Some(format!("start: {e}")));
            }
            rec.push(rod, &st, &dy.ws, &stats);
            rec.push_sliding(rod, dy.sliding.as_ref());
            rec.push_energies(&dy.energies);
            rec.push_impacts((0.0, 0.0));
            if let Some(c) = &dy.contact {
                rec.push_contact(c);
            }
            let mut impacts = Impacts::default();
            for k in 1..t {
                if let (Some(c), Some(p)) = (&mut dy.contact, obstacle_at(obstacle_poses, k)) {
                    c.set_obstacle_poses(p);
                }
                match dy.advance(rod, &mut st, time_step, &motions[k - 1], &motions[k], 6) {
                    Ok(s) => {
                        impacts.add(&s);
                        if k % every == 0 {
                            if let Err(e) = dy.update_outputs(rod, &st) {
                                *state_slot = Some(st);
                                return (rec, Some(format!("step {k}: {e}")));
                            }
                            let stats = rod::SolveStats {
                                iterations: s.iterations,
                                residual: s.residual,
                                substeps: s.substeps - 1,
                                ..Default::default()
                            };
                            rec.push(rod, &st, &dy.ws, &stats);
                            rec.push_sliding(rod, dy.sliding.as_ref());
                            rec.push_viscous(&dy.ws);
                            rec.push_energies(&dy.energies);
                            rec.push_impacts(impacts.take());
                            if let Some(c) = &dy.contact {
                                rec.push_contact(c);
                            }
                        }
                    }
                    Err(e) => {
                        *state_slot = Some(st);
                        return (
                            rec,
                            Some(format!("step {k} (t = {:.6} s): {e}", k as f64 * time_step)),
                        );
                    }
                }
                if let Some(why) = poller.poll(k + 1) {
                    *state_slot = Some(st);
                    return (rec, Some(why));
                }
            }
            *state_slot = Some(st);
            (rec, None)
        });
        let d = record.into_dict(py, self.rod.arc.len(), n_clips)?;
        d.set_item("error", error)?;
        d.set_item("spans", spans)?;
        Ok(d)
    }

    /// The `count` lowest natural modes about the state of the last run (a static
    /// equilibrium), by the banded shift-invert solver (`rod::modal`). Returns `omega` (k,)
    /// rad/s, `displacements` (k, N+1, 3) and `rotations` (k, N, 3) mass-normalised (global
    /// frame), `shares` (k, 4) modal energy shares (bending d1, bending d2, torsion, axial)
    /// and `kind` (k,) names. With the Kelvin–Voigt retardation times `shear_tau` (GA₁, GA₂,
    /// EA) and `bend_tau` (EI₁, EI₂, GJ), s, also `damping_ratio` (k,): each mode's Rayleigh
    /// quotient φᵀCφ / (2ω φᵀMφ) with the damping matrix C of the section law
    /// (`rod::modal::damping_ratio`). An unstable equilibrium is a ValueError. `tolerance`:
    /// the relative change of the eigenvalues at which the iteration stops (default 1e-11).
    #[pyo3(signature = (count, shear_tau=None, bend_tau=None, tolerance=None))]
    fn modes<'py>(
        &mut self,
        py: Python<'py>,
        count: usize,
        shear_tau: Option<[f64; 3]>,
        bend_tau: Option<[f64; 3]>,
        tolerance: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let tolerance = modal_tolerance(tolerance)?;
        let st = self
            .state
            .as_ref()
            .ok_or_else(|| PyValueError::new_err("run a static solve (run_sequence) first"))?;
        let rod = &self.rod;
        // About an equilibrium with contact: the contact stiffness in K.
        let contact = self.solver.contact.as_mut();
        let modes = py
            .detach(|| rod::modal::lowest_modes_with_contact(rod, st, count, contact, tolerance))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let k = modes.len();
        let (nodes, edges) = (rod.arc.len(), rod.n_edges());
        let mut omega = Vec::with_capacity(k);
        let mut disp = Vec::with_capacity(k * nodes * 3);
        let mut rot = Vec::with_capacity(k * edges * 3);
        let mut shares = Vec::with_capacity(k * 4);
        let mut kinds = Vec::with_capacity(k);
        for m in &modes {
            omega.push(m.omega);
            for u in m.displacements(rod) {
                disp.extend_from_slice(u.as_slice());
            }
            for r in m.rotations(st) {
                rot.extend_from_slice(r.as_slice());
            }
            shares.extend_from_slice(&m.shares);
            kinds.push(m.kind.name());
        }
        let d = PyDict::new(py);
        d.set_item("omega", PyArray1::from_vec(py, omega))?;
        d.set_item(
            "displacements",
            PyArray1::from_vec(py, disp).reshape([k, nodes, 3])?,
        )?;
        d.set_item(
            "rotations",
            PyArray1::from_vec(py, rot).reshape([k, edges, 3])?,
        )?;
        d.set_item("shares", PyArray1::from_vec(py, shares).reshape([k, 4])?)?;
        d.set_item("kind", kinds)?;
        if let Some((ts, tb)) = retardation_times(shear_tau, bend_tau)? {
            let zeta = modes
                .iter()
                .map(|m| rod::modal::damping_ratio(rod, st, &m.shape, m.omega, ts, tb))
                .collect::<Result<Vec<f64>, _>>()
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            d.set_item("damping_ratio", PyArray1::from_vec(py, zeta))?;
        }
        Ok(d)
    }

    /// Condition estimate of the tangent stiffness (Jacobi-scaled, `rod::conditioning`) about
    /// the state of the last run, or about the initial routing (reference clip poses) before
    /// any run. Returns (condition, λ_max, |λ|_min) of the scaled matrix; infinite condition
    /// for a singular one.
    fn condition(&self) -> PyResult<(f64, f64, f64)> {
        let routed;
        let st = match &self.state {
            Some(st) => st,
            None => {
                routed = route(&self.rod, None).map_err(|e| PyValueError::new_err(e.0))?;
                &routed
            }
        };
        let k = rod::modal::tangent_stiffness(&self.rod, st)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let c = rod::conditioning::condition_estimate(&k);
        Ok((c.condition, c.lambda_max, c.lambda_min))
    }

    /// Linearisation about the state of the last run (a static equilibrium): the tangent
    /// stiffness K (n × n, dense, active unknowns only), the diagonal mass (n,), and for each
    /// unknown its (block, slot); slots 0–2 node displacement, 3–5 edge rotation (body frame).
    /// Massless unknowns (swivel twists) have mass 0.
    fn linearize<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let st = self
            .state
            .as_ref()
            .ok_or_else(|| PyValueError::new_err("run a static solve (run_sequence) first"))?;
        let rod = &self.rod;
        let solver = &mut self.solver;
        let ws = &mut solver.ws;
        ws.assemble_terms(rod, st, 1.0, true, &mut [&mut solver.sliding])
            .map_err(|k| PyValueError::new_err(format!("kink at node {}", k.node)))?;
        let mut dofs = Vec::new();
        for (b, m) in rod.mask.iter().enumerate() {
            for (k, &active) in m.iter().enumerate() {
                if active {
                    dofs.push((b, k));
                }
            }
        }
        let n = dofs.len();
        let index: std::collections::HashMap<(usize, usize), usize> =
            dofs.iter().enumerate().map(|(i, d)| (*d, i)).collect();
        let mut k_dense = vec![0.0; n * n];
        for (i, &(b, k)) in dofs.iter().enumerate() {
            for bj in b.saturating_sub(1)..(b + 2).min(rod.mask.len()) {
                let block = if bj == b {
                    &ws.jac.diag[b]
                } else if bj + 1 == b {
                    &ws.jac.lower[b]
                } else {
                    &ws.jac.upper[b]
                };
                for kj in 0..6 {
                    if let Some(&j) = index.get(&(bj, kj)) {
                        k_dense[i * n + j] = block[(k, kj)];
                    }
                }
            }
        }
        let sec = &rod.spec.section;
        let mass: Vec<f64> = dofs
            .iter()
            .map(|&(b, k)| {
                let node_free = rod.node_kind[b] == rod::model::NodeKind::Free;
                let edge_free = b < rod.n_edges() && rod.edge_kind[b] == rod::model::EdgeKind::Free;
                match k {
                    0..=2 if node_free => rod.node_mass[b],
                    3..=5 if edge_free => sec.rotary_inertia[k - 3] * rod.ds_edge[b],
                    _ => 0.0,
                }
            })
            .collect();
        let d = PyDict::new(py);
        d.set_item(
            "stiffness",
            PyArray1::from_vec(py, k_dense).reshape([n, n])?,
        )?;
        d.set_item("mass", PyArray1::from_vec(py, mass))?;
        let blocks: Vec<i64> = dofs.iter().map(|d| d.0 as i64).collect();
        let slots: Vec<i64> = dofs.iter().map(|d| d.1 as i64).collect();
        d.set_item("block", PyArray1::from_vec(py, blocks))?;
        d.set_item("slot", PyArray1::from_vec(py, slots))?;
        Ok(d)
    }
}

type StrainArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Checks saved positions (T, N + 1, 3), quaternions (T, N, 4) and arc lengths (N + 1, as a
/// slice: None if not contiguous) of `what`; returns 1/Δs per edge.
fn saved_shapes(what: &str, x: &[usize], p: &[usize], s: Option<&[f64]>) -> PyResult<Vec<f64>> {
    let (t, n) = (p[0], p[1]);
    let s = s.unwrap_or(&[]);
    if x != [t, n + 1, 3] || p[2] != 4 || s.len() != n + 1 {
        return Err(PyValueError::new_err(format!(
            "{what}: positions {x:?}, quaternions {p:?} and arc lengths ({}) do not match: \
             (T, N + 1, 3), (T, N, 4), N + 1 (contiguous)",
            s.len()
        )));
    }
    Ok((0..n).map(|e| 1.0 / (s[e + 1] - s[e])).collect())
}

/// Over all saved steps and edges, (value, step, edge) of the largest axial strain Γ₃, of the
/// largest compression −Γ₃ and of the largest shear strain |(Γ₁, Γ₂)|, from saved positions
/// (T, N + 1, 3), edge quaternions (T, N, 4) and node arc lengths (N + 1), all C-contiguous;
/// the first of equal values, a NaN counts as largest (numpy's argmax). None for no steps or
/// edges (`rod::shear::saved_strain_extremes`).
#[pyfunction]
fn strain_extremes(
    positions: PyReadonlyArray3<'_, f64>,
    quaternions: PyReadonlyArray3<'_, f64>,
    arc_length: PyReadonlyArray1<'_, f64>,
) -> PyResult<Option<[(f64, usize, usize); 3]>> {
    let inv_ds = saved_shapes(
        "strain_extremes",
        positions.as_array().shape(),
        quaternions.as_array().shape(),
        arc_length.as_slice().ok(),
    )?;
    let (Ok(x), Ok(p)) = (positions.as_slice(), quaternions.as_slice()) else {
        return Err(PyValueError::new_err(
            "strain_extremes: positions and quaternions must be C-contiguous",
        ));
    };
    Ok(rod::shear::saved_strain_extremes(x, p, &inv_ds)
        .map(|e| e.map(|e| (e.value, e.step, e.edge))))
}

/// Axial strain Γ₃ and shear strain |(Γ₁, Γ₂)| per step and edge (T, N) of saved positions
/// (T, N + 1, 3), edge quaternions (T, N, 4, scalar first) and node arc lengths (N + 1),
/// C-contiguous.
#[pyfunction]
fn section_strains<'py>(
    py: Python<'py>,
    positions: PyReadonlyArray3<'py, f64>,
    quaternions: PyReadonlyArray3<'py, f64>,
    arc_length: PyReadonlyArray1<'py, f64>,
) -> PyResult<StrainArrays<'py>> {
    let (x, p) = (positions.as_array(), quaternions.as_array());
    let (t, n) = (p.shape()[0], p.shape()[1]);
    let inv_ds = saved_shapes(
        "section_strains",
        x.shape(),
        p.shape(),
        arc_length.as_slice().ok(),
    )?;
    let (Ok(x), Ok(p)) = (positions.as_slice(), quaternions.as_slice()) else {
        return Err(PyValueError::new_err(
            "section_strains: positions and quaternions must be C-contiguous",
        ));
    };
    let (mut axial, mut shear) = (vec![0.0; t * n], vec![0.0; t * n]);
    for k in 0..t {
        rod::shear::saved_step_strains(
            &x[k * 3 * (n + 1)..(k + 1) * 3 * (n + 1)],
            &p[k * 4 * n..(k + 1) * 4 * n],
            &inv_ds,
            &mut axial[k * n..(k + 1) * n],
            &mut shear[k * n..(k + 1) * n],
        );
    }
    let shape = [t, n];
    Ok((
        PyArray1::from_vec(py, axial).reshape(shape)?,
        PyArray1::from_vec(py, shear).reshape(shape)?,
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Cable>()?;
    m.add_function(wrap_pyfunction!(section_strains, m)?)?;
    m.add_function(wrap_pyfunction!(strain_extremes, m)?)?;
    m.add("DEFAULT_NEWTON_TOLERANCE", rod::dynamics::DEFAULT_TOLERANCE)?;
    Ok(())
}

pub(crate) const BOTH_TAUS: &str = "modes: give both shear_tau and bend_tau (or neither)";

/// The Kelvin–Voigt retardation times of a modal damping request: both or neither, each
/// finite and >= 0 s.
pub(crate) fn retardation_times(
    shear_tau: Option<[f64; 3]>,
    bend_tau: Option<[f64; 3]>,
) -> PyResult<Option<(Vector3<f64>, Vector3<f64>)>> {
    match (shear_tau, bend_tau) {
        (Some(ts), Some(tb)) => {
            let (ts, tb) = (Vector3::from(ts), Vector3::from(tb));
            if !(ts
                .iter()
                .chain(tb.iter())
                .all(|t| t.is_finite() && *t >= 0.0))
            {
                return Err(PyValueError::new_err(format!(
                    "retardation times shear_tau {ts:?}, bend_tau {tb:?}: each must be a \
                     finite number >= 0 s"
                )));
            }
            Ok(Some((ts, tb)))
        }
        (None, None) => Ok(None),
        _ => Err(PyValueError::new_err(BOTH_TAUS)),
    }
}
