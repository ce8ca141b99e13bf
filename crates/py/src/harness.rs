//! Bindings of the harness solver (docs/harness.md): cables joined at junctions, static and
//! quasistatic sequences. Runs release the GIL, poll Ctrl-C and report progress like `Cable`.
use crate::cable::{
    obstacle_at, read_poses, retardation_times, vec3, Cable, Impacts, Record, BOTH_TAUS,
};
use crate::stop::{Poller, StopFlag};
use nalgebra::Vector3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rod::harness::{Harness as Tree, HarnessState, HarnessStatics, JunctionSpec};
use rod::harness_dynamics::HarnessDynamics;
use rod::harness_modal::{harness_damping_ratio, harness_lowest_modes_with_contact, ModalSystem};
use rod::routing::route;
use rod::{ClipMotion, DynamicOptions, NewtonOptions, Pose};

/// (name, mass, rotary inertia [3], ends as (cable index, clip index)).
type JunctionTuple = (String, f64, Vec<f64>, Vec<(usize, usize)>);

/// A harness: cables (each given with a fixed point clip at every joined end) and junctions;
/// `held`: indices of the junctions held by a clip (their pose follows the clip poses given
/// for their first end).
#[pyclass(module = "cablelife._core")]
pub struct Harness {
    tree: Tree,
    solver: HarnessStatics,
    /// The stability check's buffers (the tree inertia of each equilibrium).
    stability: ModalSystem,
    /// The last equilibrium of `run_sequence`: for `modes`, and the start of a `warm` run
    /// (the workbench's warm start).
    state: Option<HarnessState>,
    /// Per cable: the global poses of its contact obstacles per time step (empty: none).
    obstacle_poses: Vec<Vec<Vec<Pose>>>,
}

impl Harness {
    /// Every cable routed through its clip poses `first(c)` (None: its reference route), the
    /// junctions at their reference poses: the start of a solve without a previous state.
    fn routed(&self, first: impl Fn(usize) -> Option<Vec<Pose>>) -> PyResult<HarnessState> {
        let tree = &self.tree;
        let mut st = HarnessState {
            cables: Vec::with_capacity(tree.cables.len()),
            junctions: tree.reference.clone(),
        };
        for (c, rod) in tree.cables.iter().enumerate() {
            st.cables.push(route(rod, first(c).as_deref()).map_err(|e| {
                PyValueError::new_err(format!("cable '{}': {}", tree.names[c], e.0))
            })?);
        }
        Ok(st)
    }
}

#[pymethods]
impl Harness {
    #[new]
    #[pyo3(signature = (cables, names, junctions, max_iterations=40, step_tolerance=1e-9, held=vec![]))]
    fn new(
        cables: Vec<PyRef<'_, Cable>>,
        names: Vec<String>,
        junctions: Vec<JunctionTuple>,
        max_iterations: usize,
        step_tolerance: f64,
        held: Vec<usize>,
    ) -> PyResult<Self> {
        if names.len() != cables.len() {
            return Err(PyValueError::new_err(format!(
                "{} names for {} cables",
                names.len(),
                cables.len()
            )));
        }
        let mut specs = Vec::with_capacity(junctions.len());
        for (name, mass, inertia, ends) in junctions {
            let rotary_inertia = vec3(&inertia, &format!("junction '{name}' rotary_inertia"))?;
            specs.push(JunctionSpec {
                name,
                mass,
                rotary_inertia,
                ends,
            });
        }
        let rods = cables.iter().map(|c| c.rod.clone()).collect();
        let mut tree = Tree::new(names, rods, specs).map_err(|e| PyValueError::new_err(e.0))?;
        for j in held {
            tree.hold_junction(j)
                .map_err(|e| PyValueError::new_err(e.0))?;
        }
        let opts = NewtonOptions {
            max_iterations,
            step_tolerance,
            ..Default::default()
        };
        let mut solver = HarnessStatics::new(&tree, opts);
        // Contact set on a cable (`Cable.set_contact`) is a term of its harness assembly
        // (static and quasistatic; dynamic runs refuse it, `run_dynamic`).
        for (slot, c) in solver.contact.iter_mut().zip(&cables) {
            slot.clone_from(&c.solver.contact);
        }
        let obstacle_poses = cables.iter().map(|c| c.obstacle_poses.clone()).collect();
        let stability = ModalSystem::new(&tree);
        Ok(Harness {
            tree,
            solver,
            stability,
            state: None,
            obstacle_poses,
        })
    }

    /// Takes each cable's contact term and obstacle poses again from `cables` (the cables it
    /// was built from, after `Cable.set_contact` moved their obstacles: the workbench's body
    /// drags); the harness keeps its own copies otherwise.
    fn update_contact(&mut self, cables: Vec<PyRef<'_, Cable>>) -> PyResult<()> {
        if cables.len() != self.tree.cables.len() {
            return Err(PyValueError::new_err(format!(
                "update_contact: {} cables for a harness of {}",
                cables.len(),
                self.tree.cables.len()
            )));
        }
        for (c, cable) in cables.iter().enumerate() {
            self.solver.contact[c].clone_from(&cable.solver.contact);
            self.obstacle_poses[c].clone_from(&cable.obstacle_poses);
        }
        Ok(())
    }

    /// (cable index, clip index, junction index) of every joined end, in the order of the
    /// branch outputs.
    #[getter]
    fn ends(&self) -> Vec<(usize, usize, usize)> {
        self.tree
            .ends
            .iter()
            .map(|e| (e.cable, e.topo.clip, e.junction))
            .collect()
    }

    /// Runs a sequence of equilibria through the clip poses of each cable, `positions[c]`
    /// (T, C_c, 3) and `quaternions[c]` (T, C_c, 4) (the entries of joined ends are ignored).
    /// Step 0 is a static solve from the routed shapes. Returns `cables` (one dict per cable,
    /// as `Cable.run_sequence`), `junction_positions` (T, J, 3), `junction_quaternions`
    /// (T, J, 4, scalar first), `branch_force` and `branch_moment` (T, E, 3: what each joined
    /// end's cable applies to its junction, global, moment about the junction point),
    /// `junction_reaction_force` and `junction_reaction_moment` (T, J, 3: of the clip on each
    /// junction in `held`, zero for the others), `iterations`, `substeps`, `residual`, `steps`
    /// and `error` (None, or why it stopped: the steps before are kept). Each cable's
    /// `unstable` is the number of negative eigenvalues of the whole harness's tangent
    /// stiffness at that step (the tree inertia; 0 = stable). `warm`: step 0 starts from the
    /// last equilibrium of the previous run (the first from the routed shapes); a failed run
    /// keeps the previous (the workbench's drags).
    #[pyo3(signature = (positions, quaternions, progress=None, progress_every=50, stop=None,
        warm=false))]
    #[allow(clippy::too_many_arguments)]
    fn run_sequence<'py>(
        &mut self,
        py: Python<'py>,
        positions: Vec<PyReadonlyArray3<'py, f64>>,
        quaternions: Vec<PyReadonlyArray3<'py, f64>>,
        progress: Option<Py<PyAny>>,
        progress_every: usize,
        stop: Option<Bound<'py, StopFlag>>,
        warm: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let nc = self.tree.cables.len();
        if positions.len() != nc || quaternions.len() != nc {
            return Err(PyValueError::new_err(format!(
                "clip poses of {} and {} cables given for {nc} cables",
                positions.len(),
                quaternions.len()
            )));
        }
        // poses[c][t][clip]
        let mut poses = Vec::with_capacity(nc);
        let mut steps = None;
        for (c, (p, q)) in positions.iter().zip(&quaternions).enumerate() {
            let (pa, qa) = (p.as_array(), q.as_array());
            let n_clips = self.tree.cables[c].spec.clips.len();
            let (t, k, three) = pa.dim();
            if k != n_clips || three != 3 || qa.dim() != (t, n_clips, 4) {
                return Err(PyValueError::new_err(format!(
                    "cable '{}': clip poses must be (T, {n_clips}, 3) and (T, {n_clips}, 4); got \
                     {:?} and {:?}",
                    self.tree.names[c],
                    pa.dim(),
                    qa.dim()
                )));
            }
            if *steps.get_or_insert(t) != t {
                return Err(PyValueError::new_err(
                    "clip poses of all cables must have the same number of steps",
                ));
            }
            poses.push(read_poses(&pa, &qa)?);
        }
        let t = steps.unwrap_or(0);
        let tree = &self.tree;
        let previous = if warm { self.state.clone() } else { None };
        let from_previous = previous.is_some();
        let initial = match previous {
            Some(p) => p,
            None => self.routed(|c| (t > 0).then(|| poses[c][0].clone()))?,
        };
        let solver = &mut self.solver;
        let stability = &mut self.stability;
        let obstacle_poses = &self.obstacle_poses;
        let mut poller = Poller::new(stop.as_ref(), progress, progress_every, t);
        let (nj, ne) = (tree.junctions.len(), tree.ends.len());
        struct Out {
            records: Vec<Record>,
            jpos: Vec<f64>,
            jquat: Vec<f64>,
            force: Vec<f64>,
            moment: Vec<f64>,
            reaction_force: Vec<f64>,
            reaction_moment: Vec<f64>,
            iterations: Vec<i64>,
            substeps: Vec<i64>,
            residual: Vec<f64>,
            steps: usize,
        }
        let (out, error, last) = py.detach(move || {
            let mut out = Out {
                records: (0..nc).map(|_| Record::default()).collect(),
                jpos: Vec::with_capacity(t * nj * 3),
                jquat: Vec::with_capacity(t * nj * 4),
                force: Vec::with_capacity(t * ne * 3),
                moment: Vec::with_capacity(t * ne * 3),
                reaction_force: Vec::with_capacity(t * nj * 3),
                reaction_moment: Vec::with_capacity(t * nj * 3),
                iterations: Vec::with_capacity(t),
                substeps: Vec::with_capacity(t),
                residual: Vec::with_capacity(t),
                steps: 0,
            };
            let mut st = initial;
            let mut target: Vec<Vec<Pose>> = vec![Vec::new(); nc];
            for k in 0..t {
                for (tc, pc) in target.iter_mut().zip(&poses) {
                    tc.clone_from(&pc[k]);
                }
                for (c, contact) in solver.contact.iter_mut().enumerate() {
                    if let (Some(c), Some(p)) = (contact, obstacle_at(&obstacle_poses[c], k)) {
                        c.set_obstacle_poses(p);
                    }
                }
                let result = if k == 0 && !from_previous {
                    st.set_clip_poses(tree, &target);
                    solver.solve_static(tree, &mut st)
                } else {
                    solver.sequence_step(tree, &mut st, &target)
                };
                let mut stats = match result {
                    Ok(s) => s,
                    Err(e) => return (out, Some(format!("step {k}: {e}")), None),
                };
                // (the solver has counted at its result already unless the loads are not
                // conservative: harness_escape). With contact the solve counts it (frictionless
                // contact in K) or skips it (friction: `unstable` −1, not checked).
                if stats.unstable.is_none() && !solver.has_contact() {
                    match stability.negative_count(tree, &st) {
                        Ok(n) => stats.unstable = Some(n),
                        Err(e) => return (out, Some(format!("step {k}: {e}")), None),
                    }
                }
                if let Err(e) = solver.assemble(tree, &st, 1.0, false) {
                    return (out, Some(format!("step {k}: {e}")), None);
                }
                for (c, rod) in tree.cables.iter().enumerate() {
                    out.records[c].push(rod, &st.cables[c], &solver.ws[c], &stats);
                    out.records[c].push_sliding(rod, solver.sliding[c].as_ref());
                    if let Some(contact) = &solver.contact[c] {
                        out.records[c].push_contact(contact);
                    }
                }
                for pose in &st.junctions {
                    out.jpos.extend_from_slice(pose.position.as_slice());
                    let q = pose.orientation;
                    out.jquat.extend_from_slice(&[q.w, q.i, q.j, q.k]);
                }
                for (f, m) in solver.branch_loads(tree, &st) {
                    out.force.extend_from_slice(f.as_slice());
                    out.moment.extend_from_slice(m.as_slice());
                }
                for (f, m) in solver.junction_reactions(tree, &st) {
                    out.reaction_force.extend_from_slice(f.as_slice());
                    out.reaction_moment.extend_from_slice(m.as_slice());
                }
                out.iterations.push(stats.iterations as i64);
                out.substeps.push(stats.substeps as i64);
                out.residual.push(stats.residual);
                out.steps += 1;
                if let Some(why) = poller.poll(k + 1) {
                    return (out, Some(why), Some(st));
                }
            }
            (out, None, (t > 0).then_some(st))
        });
        if last.is_some() {
            self.state = last;
        }
        let n = out.steps;
        let shaped =
            |v: Vec<f64>, shape: &[usize]| PyArray1::from_vec(py, v).reshape(shape.to_vec());
        let d = junction_outputs(py, &self.tree, out.records, &error, out.jpos, out.jquat, n)?;
        d.set_item("branch_force", shaped(out.force, &[n, ne, 3])?)?;
        d.set_item("branch_moment", shaped(out.moment, &[n, ne, 3])?)?;
        d.set_item(
            "junction_reaction_force",
            shaped(out.reaction_force, &[n, nj, 3])?,
        )?;
        d.set_item(
            "junction_reaction_moment",
            shaped(out.reaction_moment, &[n, nj, 3])?,
        )?;
        d.set_item("iterations", PyArray1::from_vec(py, out.iterations))?;
        d.set_item("substeps", PyArray1::from_vec(py, out.substeps))?;
        d.set_item("residual", PyArray1::from_vec(py, out.residual))?;
        d.set_item("steps", n)?;
        d.set_item("error", error)?;
        Ok(d)
    }

    /// The `count` lowest natural modes of the whole harness about the last step of
    /// `run_sequence` (a static equilibrium): shift-invert on the tree elimination
    /// (`rod::harness_modal`). Returns `omega` (k,) rad/s, `cables` (one dict per cable:
    /// `displacements` (k, N+1, 3) and `rotations` (k, N, 3), global, mass-normalised over
    /// the harness), `junction_displacements` and `junction_rotations` (k, J, 3, global),
    /// `shares` (k, 4) and `kind` (k,) as `Cable.modes`. An unstable equilibrium is a
    /// ValueError. With per-cable Kelvin–Voigt retardation times `shear_tau` and `bend_tau`
    /// (one triple per cable, as `Cable.modes`), also `damping_ratio` (k,): each mode's
    /// Rayleigh quotient over the whole harness (`rod::harness_modal::harness_damping_ratio`).
    /// `tolerance` as `Cable.modes`.
    #[pyo3(signature = (count, shear_tau=None, bend_tau=None, tolerance=None))]
    fn modes<'py>(
        &mut self,
        py: Python<'py>,
        count: usize,
        shear_tau: Option<Vec<[f64; 3]>>,
        bend_tau: Option<Vec<[f64; 3]>>,
        tolerance: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let tolerance = crate::cable::modal_tolerance(tolerance)?;
        let nc = self.tree.cables.len();
        let taus = match (shear_tau, bend_tau) {
            (Some(ts), Some(tb)) if ts.len() != nc || tb.len() != nc => {
                return Err(PyValueError::new_err(format!(
                    "modes: {} shear_tau and {} bend_tau triples for {nc} cables (give one per \
                     cable)",
                    ts.len(),
                    tb.len()
                )))
            }
            (Some(ts), Some(tb)) => {
                let mut both = (Vec::with_capacity(nc), Vec::with_capacity(nc));
                for (s, b) in ts.into_iter().zip(tb) {
                    let (s, b) = retardation_times(Some(s), Some(b))?.expect("both given");
                    both.0.push(s);
                    both.1.push(b);
                }
                Some(both)
            }
            (None, None) => None,
            _ => return Err(PyValueError::new_err(BOTH_TAUS)),
        };
        let st = self.state.as_ref().ok_or_else(|| {
            PyValueError::new_err("run a static solve (run_sequence) of the harness first")
        })?;
        let tree = &self.tree;
        let solver = &mut self.solver;
        let modes = py
            .detach(|| {
                // A harness resting on the geometry: its contact stiffness is part of K.
                let contact = solver.has_contact().then_some(&mut solver.contact);
                harness_lowest_modes_with_contact(tree, st, count, contact, tolerance)
            })
            .map_err(|e| PyValueError::new_err(e.0))?;
        let k = modes.len();
        let nj = tree.junctions.len();
        let d = PyDict::new(py);
        let cables = PyList::empty(py);
        for (c, rod) in tree.cables.iter().enumerate() {
            let (nodes, edges) = (rod.arc.len(), rod.n_edges());
            let mut disp = Vec::with_capacity(k * nodes * 3);
            let mut rot = Vec::with_capacity(k * edges * 3);
            for m in &modes {
                let single = rod::modal::Mode {
                    eigenvalue: m.eigenvalue,
                    omega: m.omega,
                    shape: m.cables[c].clone(),
                    shares: m.shares,
                    kind: m.kind,
                };
                for u in single.displacements(rod) {
                    disp.extend_from_slice(u.as_slice());
                }
                for r in single.rotations(&st.cables[c]) {
                    rot.extend_from_slice(r.as_slice());
                }
            }
            let cd = PyDict::new(py);
            cd.set_item(
                "displacements",
                PyArray1::from_vec(py, disp).reshape([k, nodes, 3])?,
            )?;
            cd.set_item(
                "rotations",
                PyArray1::from_vec(py, rot).reshape([k, edges, 3])?,
            )?;
            cables.append(cd)?;
        }
        let mut jd = Vec::with_capacity(k * nj * 3);
        let mut jr = Vec::with_capacity(k * nj * 3);
        for m in &modes {
            for (v, pose) in m.junctions.iter().zip(&st.junctions) {
                jd.extend_from_slice(&[v[0], v[1], v[2]]);
                let r = rod::rotation::rotation_matrix(&pose.orientation)
                    * nalgebra::Vector3::new(v[3], v[4], v[5]);
                jr.extend_from_slice(r.as_slice());
            }
        }
        d.set_item(
            "omega",
            PyArray1::from_vec(py, modes.iter().map(|m| m.omega).collect()),
        )?;
        d.set_item("cables", cables)?;
        d.set_item(
            "junction_displacements",
            PyArray1::from_vec(py, jd).reshape([k, nj, 3])?,
        )?;
        d.set_item(
            "junction_rotations",
            PyArray1::from_vec(py, jr).reshape([k, nj, 3])?,
        )?;
        let shares: Vec<f64> = modes.iter().flat_map(|m| m.shares).collect();
        d.set_item("shares", PyArray1::from_vec(py, shares).reshape([k, 4])?)?;
        d.set_item(
            "kind",
            modes.iter().map(|m| m.kind.name()).collect::<Vec<_>>(),
        )?;
        if let Some((ts, tb)) = taus {
            let zeta = modes
                .iter()
                .map(|m| harness_damping_ratio(tree, st, m, &ts, &tb))
                .collect::<Result<Vec<f64>, _>>()
                .map_err(|e| PyValueError::new_err(e.0))?;
            d.set_item("damping_ratio", PyArray1::from_vec(py, zeta))?;
        }
        Ok(d)
    }

    /// Dynamic run (generalized-α on the harness): static equilibrium at the clip poses of
    /// step 0, then steps of `time_step` through each cable's clip kinematics `kinematics[c]`
    /// = (positions, quaternions, velocities, angular velocities, accelerations, angular
    /// accelerations), (T, C_c, ·) global (the entries of joined ends are ignored). Every
    /// `output_every`-th step is recorded (and step 0). τ per cable: `tau_shear[c]`,
    /// `tau_bend[c]` (3 each). Returns what `run_sequence` returns, the cables' dicts with the
    /// energies of `Cable.run_dynamic`, and `junction_velocities` (T, J, 6: ẋ global, ω body),
    /// `kinetic_energy`, `elastic_energy`, `load_potential`, `dissipated_energy` (T,) of the
    /// whole harness (junctions included), `unresolved_gain`, `impact_dissipation` (T,) as
    /// `Cable.run_dynamic`.
    /// Junctions held by a clip follow its motion (given for their first end); sliding clips
    /// slide (a cable running out of one stops the run).
    #[pyo3(signature = (time_step, kinematics, output_every, tau_shear, tau_bend,
        spectral_radius=0.9, newton_tolerance=rod::dynamics::DEFAULT_TOLERANCE, progress=None,
        progress_every=100, stop=None))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn run_dynamic<'py>(
        &mut self,
        py: Python<'py>,
        time_step: f64,
        kinematics: Vec<(
            PyReadonlyArray3<'py, f64>,
            PyReadonlyArray3<'py, f64>,
            PyReadonlyArray3<'py, f64>,
            PyReadonlyArray3<'py, f64>,
            PyReadonlyArray3<'py, f64>,
            PyReadonlyArray3<'py, f64>,
        )>,
        output_every: usize,
        tau_shear: Vec<Vec<f64>>,
        tau_bend: Vec<Vec<f64>>,
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
        let nc = self.tree.cables.len();
        if kinematics.len() != nc || tau_shear.len() != nc || tau_bend.len() != nc {
            return Err(PyValueError::new_err(format!(
                "clip kinematics and retardation times of {nc} cables expected; got {}, {} and {}",
                kinematics.len(),
                tau_shear.len(),
                tau_bend.len()
            )));
        }
        let mut taus = Vec::with_capacity(nc);
        for (c, (ts, tb)) in tau_shear.iter().zip(&tau_bend).enumerate() {
            let name = &self.tree.names[c];
            taus.push((
                vec3(ts, &format!("cable '{name}' tau_shear"))?,
                vec3(tb, &format!("cable '{name}' tau_bend"))?,
            ));
        }
        // motions[t][c][clip]
        let mut steps = None;
        let mut per_cable: Vec<Vec<Vec<ClipMotion>>> = Vec::with_capacity(nc);
        for (c, (p, q, v, w, a, aw)) in kinematics.iter().enumerate() {
            let n_clips = self.tree.cables[c].spec.clips.len();
            let (pa, qa) = (p.as_array(), q.as_array());
            let arrays = [v.as_array(), w.as_array(), a.as_array(), aw.as_array()];
            let t = pa.dim().0;
            if pa.dim() != (t, n_clips, 3)
                || qa.dim() != (t, n_clips, 4)
                || arrays.iter().any(|x| x.dim() != (t, n_clips, 3))
            {
                return Err(PyValueError::new_err(format!(
                    "cable '{}': clip kinematics must be (T, {n_clips}, 3), quaternions (T, \
                     {n_clips}, 4)",
                    self.tree.names[c]
                )));
            }
            if *steps.get_or_insert(t) != t {
                return Err(PyValueError::new_err(
                    "clip kinematics of all cables must have the same number of steps",
                ));
            }
            let poses = read_poses(&pa, &qa)?;
            let at = |x: &numpy::ndarray::ArrayView3<f64>, k: usize, j: usize| {
                Vector3::new(x[[k, j, 0]], x[[k, j, 1]], x[[k, j, 2]])
            };
            per_cable.push(
                (0..t)
                    .map(|k| {
                        (0..n_clips)
                            .map(|j| ClipMotion {
                                pose: poses[k][j],
                                velocity: at(&arrays[0], k, j),
                                angular_velocity: at(&arrays[1], k, j),
                                acceleration: at(&arrays[2], k, j),
                                angular_acceleration: at(&arrays[3], k, j),
                            })
                            .collect()
                    })
                    .collect(),
            );
        }
        let t = steps.unwrap_or(0);
        let motions: Vec<Vec<Vec<ClipMotion>>> = (0..t)
            .map(|k| per_cable.iter().map(|m| m[k].clone()).collect())
            .collect();
        drop(per_cable);
        let tree = &self.tree;
        // The static equilibrium at t = 0 starts from the last one of `run_sequence` when that
        // was at the same clip poses (the default damping's calibration has just solved it:
        // the solve then converges at once), else from the routed shape.
        // (the clips of the joined ends follow their junctions: not compared)
        let joined = |c: usize, k: usize| {
            tree.cable_ends[c]
                .iter()
                .any(|&e| tree.ends[e].topo.clip == k)
        };
        let same_start = |st: &HarnessState| {
            t > 0
                && st.cables.iter().enumerate().all(|(c, s)| {
                    let own = &motions[0][c];
                    s.clip_pose.len() == own.len()
                        && (own.iter().zip(&s.clip_pose).enumerate())
                            .all(|(k, (m, p))| joined(c, k) || m.pose == *p)
                })
        };
        let initial = match self.state.as_ref().filter(|s| same_start(s)) {
            Some(s) => s.clone(),
            None => {
                self.routed(|c| (t > 0).then(|| motions[0][c].iter().map(|m| m.pose).collect()))?
            }
        };
        let opts = DynamicOptions {
            rho_inf: spectral_radius,
            tolerance: newton_tolerance,
            outputs_every_step: false,
            ..Default::default()
        };
        let solver = &mut self.solver;
        let obstacle_poses = &self.obstacle_poses;
        let every = output_every.max(1);
        let mut poller = Poller::new(stop.as_ref(), progress, progress_every, t);
        let (nj, ne) = (tree.junctions.len(), tree.ends.len());
        struct Out {
            records: Vec<Record>,
            jpos: Vec<f64>,
            jquat: Vec<f64>,
            jvel: Vec<f64>,
            react: [Vec<f64>; 2],
            force: Vec<f64>,
            moment: Vec<f64>,
            energies: [Vec<f64>; 4],
            iterations: Vec<i64>,
            substeps: Vec<i64>,
            residual: Vec<f64>,
            unresolved_gain: Vec<f64>,
            impact_dissipation: Vec<f64>,
            steps: usize,
        }
        let (out, error) = py.detach(move || {
            let saved = t.saturating_sub(1) / every + 1;
            let mut out = Out {
                records: tree
                    .cables
                    .iter()
                    .map(|r| Record::with_capacity(saved, r))
                    .collect(),
                jpos: Vec::with_capacity(saved * nj * 3),
                jquat: Vec::with_capacity(saved * nj * 4),
                jvel: Vec::with_capacity(saved * nj * 6),
                react: std::array::from_fn(|_| Vec::with_capacity(saved * nj * 3)),
                force: Vec::with_capacity(saved * ne * 3),
                moment: Vec::with_capacity(saved * ne * 3),
                energies: std::array::from_fn(|_| Vec::with_capacity(saved)),
                iterations: Vec::with_capacity(saved),
                substeps: Vec::with_capacity(saved),
                residual: Vec::with_capacity(saved),
                unresolved_gain: Vec::with_capacity(saved),
                impact_dissipation: Vec::with_capacity(saved),
                steps: 0,
            };
            if t == 0 {
                return (out, None);
            }
            let mut st = initial;
            let poses: Vec<Vec<Pose>> = motions[0]
                .iter()
                .map(|m| m.iter().map(|x| x.pose).collect())
                .collect();
            st.set_clip_poses(tree, &poses);
            for (c, contact) in solver.contact.iter_mut().enumerate() {
                if let (Some(c), Some(p)) = (contact, obstacle_at(&obstacle_poses[c], 0)) {
                    c.set_obstacle_poses(p);
                }
            }
            for ((rec, c), rod) in out
                .records
                .iter_mut()
                .zip(&solver.contact)
                .zip(&tree.cables)
            {
                if let Some(c) = c {
                    rec.reserve_contact(saved, rod.arc.len(), c.body_force.len());
                }
            }
            let stats = match solver.solve_static(tree, &mut st) {
                Ok(s) => s,
                Err(e) => return (out, Some(format!("static equilibrium at t = 0: {e}"))),
            };
            let mut hd = HarnessDynamics::new(tree, &st, &motions[0], opts);
            for (dy, c) in hd.cables.iter_mut().zip(&solver.contact) {
                dy.contact.clone_from(c); // each cable's contact: a term of its assembly
            }
            for (c, (ts, tb)) in taus.iter().enumerate() {
                hd.set_retardation_times(tree, c, *ts, *tb);
            }
            if let Err(e) = hd.start(tree, &mut st) {
                return (out, Some(format!("start: {e}")));
            }
            let record = |out: &mut Out,
                          hd: &HarnessDynamics,
                          st: &HarnessState,
                          s: &rod::SolveStats,
                          (unresolved, dissipation): (f64, f64)| {
                for (c, rod) in tree.cables.iter().enumerate() {
                    let dy = &hd.cables[c];
                    let rec = &mut out.records[c];
                    rec.push(rod, &st.cables[c], &dy.ws, s);
                    rec.push_sliding(rod, dy.sliding.as_ref());
                    rec.push_viscous(&dy.ws);
                    rec.push_energies(&dy.energies);
                    if let Some(c) = &dy.contact {
                        rec.push_contact(c);
                    }
                }
                for (pose, v) in st.junctions.iter().zip(hd.junction_velocities()) {
                    out.jpos.extend_from_slice(pose.position.as_slice());
                    let q = pose.orientation;
                    out.jquat.extend_from_slice(&[q.w, q.i, q.j, q.k]);
                    out.jvel.extend_from_slice(v.as_slice());
                }
                for (f, m) in hd.branch_loads(tree, st) {
                    out.force.extend_from_slice(f.as_slice());
                    out.moment.extend_from_slice(m.as_slice());
                }
                for (f, m) in hd.junction_reactions(tree, st) {
                    out.react[0].extend_from_slice(f.as_slice());
                    out.react[1].extend_from_slice(m.as_slice());
                }
                let e = &hd.energies;
                for (v, x) in out.energies.iter_mut().zip([
                    e.kinetic,
                    e.elastic,
                    e.load_potential,
                    e.dissipated,
                ]) {
                    v.push(x);
                }
                out.iterations.push(s.iterations as i64);
                out.substeps.push(s.substeps as i64);
                out.residual.push(s.residual);
                out.unresolved_gain.push(unresolved);
                out.impact_dissipation.push(dissipation);
                out.steps += 1;
            };
            record(&mut out, &hd, &st, &stats, (0.0, 0.0));
            let mut impacts = Impacts::default();
            for k in 1..t {
                for (c, dy) in hd.cables.iter_mut().enumerate() {
                    if let (Some(c), Some(p)) =
                        (&mut dy.contact, obstacle_at(&obstacle_poses[c], k))
                    {
                        c.set_obstacle_poses(p);
                    }
                }
                match hd.advance(tree, &mut st, time_step, &motions[k - 1], &motions[k], 6) {
                    Ok(s) => {
                        impacts.add(&s);
                        if k % every == 0 {
                            if let Err(e) = hd.update_outputs(tree, &st) {
                                return (out, Some(format!("step {k}: {e}")));
                            }
                            let stats = rod::SolveStats {
                                iterations: s.iterations,
                                residual: s.residual,
                                substeps: s.substeps - 1,
                                ..Default::default()
                            };
                            record(&mut out, &hd, &st, &stats, impacts.take());
                        }
                    }
                    Err(e) => {
                        return (
                            out,
                            Some(format!("step {k} (t = {:.6} s): {e}", k as f64 * time_step)),
                        )
                    }
                }
                if let Some(why) = poller.poll(k + 1) {
                    return (out, Some(why));
                }
            }
            (out, None)
        });
        let n = out.steps;
        let shaped =
            |v: Vec<f64>, shape: &[usize]| PyArray1::from_vec(py, v).reshape(shape.to_vec());
        let d = junction_outputs(py, &self.tree, out.records, &error, out.jpos, out.jquat, n)?;
        d.set_item("junction_velocities", shaped(out.jvel, &[n, nj, 6])?)?;
        let [rf, rm] = out.react;
        d.set_item("junction_reaction_force", shaped(rf, &[n, nj, 3])?)?;
        d.set_item("junction_reaction_moment", shaped(rm, &[n, nj, 3])?)?;
        d.set_item("branch_force", shaped(out.force, &[n, ne, 3])?)?;
        d.set_item("branch_moment", shaped(out.moment, &[n, ne, 3])?)?;
        let [kin, ela, pot, dis] = out.energies;
        d.set_item("kinetic_energy", PyArray1::from_vec(py, kin))?;
        d.set_item("elastic_energy", PyArray1::from_vec(py, ela))?;
        d.set_item("load_potential", PyArray1::from_vec(py, pot))?;
        d.set_item("dissipated_energy", PyArray1::from_vec(py, dis))?;
        d.set_item("iterations", PyArray1::from_vec(py, out.iterations))?;
        d.set_item("substeps", PyArray1::from_vec(py, out.substeps))?;
        d.set_item("residual", PyArray1::from_vec(py, out.residual))?;
        d.set_item(
            "unresolved_gain",
            PyArray1::from_vec(py, out.unresolved_gain),
        )?;
        d.set_item(
            "impact_dissipation",
            PyArray1::from_vec(py, out.impact_dissipation),
        )?;
        d.set_item("steps", n)?;
        d.set_item("error", error)?;
        Ok(d)
    }
}

/// The outputs every harness run returns: one dict per cable (with the run's `error`) and the
/// junction positions (T, J, 3) and quaternions (T, J, 4, scalar first).
fn junction_outputs<'py>(
    py: Python<'py>,
    tree: &Tree,
    records: Vec<Record>,
    error: &Option<String>,
    jpos: Vec<f64>,
    jquat: Vec<f64>,
    n: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let cables = PyList::empty(py);
    for (rec, rod) in records.into_iter().zip(&tree.cables) {
        let cd = rec.into_dict(py, rod.arc.len(), rod.spec.clips.len())?;
        cd.set_item("error", error.clone())?;
        cables.append(cd)?;
    }
    let nj = tree.junctions.len();
    d.set_item("cables", cables)?;
    d.set_item(
        "junction_positions",
        PyArray1::from_vec(py, jpos).reshape(vec![n, nj, 3])?,
    )?;
    d.set_item(
        "junction_quaternions",
        PyArray1::from_vec(py, jquat).reshape(vec![n, nj, 4])?,
    )?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Harness>()
}
