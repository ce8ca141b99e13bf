"""Type stub of the Rust extension `cablelife._core` (crates/py): thin bindings of the rod
solver, the fatigue kernels, motion-volume distances, surroundings (clearance) and Ctrl-C stop
flags. Arrays are numpy float64 unless said otherwise. Kept current by tests/test_core_stub.py."""

from typing import Any

cpu_features: str
"""Processor features the build's code may use, as named in /proc/cpuinfo (space-separated;
empty where not checked). Also in the ELF section ``.cablelife_cpu`` (``cablelife._cpu``)."""

class Cable:
    """One cable: mesh, state and solver."""
    def __init__(
        self,
        length,
        segments,
        shear_stiffness,
        bend_stiffness,
        mass_per_length,
        rotary_inertia,
        natural_curvature,
        gravity,
        clips,
        loads,
        max_iterations=40,
        step_tolerance=1e-9,
        clip_axes=None,
        clip_friction=None,
    ) -> None: ...
    @property
    def arc_length(self) -> Any: ...
    def condition(self) -> Any:
        """Condition estimate of the tangent stiffness (Jacobi-scaled, `rod::conditioning`) about
        the state of the last run, or about the initial routing (reference clip poses) before
        any run. Returns (condition, λ_max, |λ|_min) of the scaled matrix; infinite condition
        for a singular one.
        """
        ...
    def linearize(self) -> Any:
        """Linearisation about the state of the last run (a static equilibrium): the tangent
        stiffness K (n × n, dense, active unknowns only), the diagonal mass (n,), and for each
        unknown its (block, slot); slots 0–2 node displacement, 3–5 edge rotation (body frame).
        Massless unknowns (swivel twists) have mass 0.
        """
        ...
    def modes(self, count, shear_tau=None, bend_tau=None, tolerance=None) -> Any:
        """The `count` lowest natural modes about the state of the last run (a static
        equilibrium), by the banded shift-invert solver (`rod::modal`). Returns `omega` (k,)
        rad/s, `displacements` (k, N+1, 3) and `rotations` (k, N, 3) mass-normalised (global
        frame), `shares` (k, 4) modal energy shares (bending d1, bending d2, torsion, axial)
        and `kind` (k,) names. With the Kelvin–Voigt retardation times `shear_tau` (GA₁, GA₂,
        EA) and `bend_tau` (EI₁, EI₂, GJ), s, also `damping_ratio` (k,): each mode's Rayleigh
        quotient φᵀCφ / (2ω φᵀMφ) with the damping matrix C of the section law
        (`rod::modal::damping_ratio`). An unstable equilibrium is a ValueError. `tolerance`:
        the relative change of the eigenvalues at which the iteration stops (default 1e-11).
        """
        ...
    @property
    def node_mass(self) -> Any: ...
    def transported_normal(self, from_clip, to_clip) -> Any:
        """The normal (d1, global) of clip `to_clip` when the frame of clip `from_clip` is
        carried along the routed reference centreline to it without twist (parallel
        transport): the default normal of a junction's end (docs/harness.md).
        """
        ...
    def run_dynamic(
        self,
        time_step,
        positions,
        quaternions,
        velocities,
        angular_velocities,
        accelerations,
        angular_accelerations,
        output_every,
        tau_shear,
        tau_bend,
        spectral_radius=0.9,
        newton_tolerance=...,
        progress=None,
        progress_every=100,
        stop=None,
    ) -> Any:
        """Dynamic run: static equilibrium at the clip poses of step 0, then generalized-α steps
        of `time_step` through the clip kinematics (T, C, ·): positions, quaternions, velocities,
        angular velocities, accelerations, angular accelerations (global). Every
        `output_every`-th step is recorded (and step 0). τ: retardation times (GA₁, GA₂, EA),
        (EI₁, EI₂, GJ). Returns the recorded arrays, energies and `error` as `run_sequence`,
        and `unresolved_gain`, `impact_dissipation` (T,): the largest energy gain, relative to
        the energies at play, of an impact sub-step at the step guard's deepest split since the
        last recorded step that it accepted (the motion held less) and that it gave back from
        the motion near the contact (0: none); `stop` as there.
        """
        ...
    def run_sequence(
        self, positions, quaternions, progress=None, progress_every=50, stop=None
    ) -> Any:
        """Runs a sequence of equilibria through the clip poses `positions` (T, C, 3) and
        `quaternions` (T, C, 4). Step 0 is a static solve from the routed shape (with load
        continuation if needed); later steps are warm-started and sub-stepped on failure.
        Returns a dict of arrays for the completed steps and `error` (None, or why it stopped:
        the results up to there are kept). `stop`: a `StopFlag` read after every step (the
        run ends with error "interrupted" when it is set).
        """
        ...
    def step_static(self, positions, quaternions) -> Any:
        """One static equilibrium at the clip poses `positions` (C, 3), `quaternions` (C, 4),
        warm-started from the last equilibrium (sub-stepped toward the poses on failure), or
        solved from the routed shape when there is none (interactive use: the workbench).
        Returns the dict of `run_sequence` with one step; a failed solve is a ValueError and
        keeps the last equilibrium as it was.
        """
        ...
    def set_contact(
        self,
        obstacles,
        n_bodies,
        radius,
        positions,
        quaternions,
        distance=0.0,
        stiffness=0.0,
        stick_distance=0.0,
        stick_velocity=1e-3,
        max_samples=8,
        meshes=...,
        damping=5e-4,
    ) -> Any:
        """Contact with rigid obstacles (docs/contact.md): `obstacles` as (name, body index,
        type, dimensions, friction μ); their global poses per time step of the next run,
        `positions` (T, O, 3) and `quaternions` (T, O, 4, scalar first) — T = 1: at rest.
        distance/stick_distance ≤ 0: the defaults for the radius (1 % and 0.1 % of r).
        `damping`: the normal damping time constant τ_c of dynamic contact, s.
        Type "mesh": dimensions [k], the k-th of `meshes` (vertices (M, 3), faces (F, 3)) in
        the obstacle's frame.
        """
        ...

DEFAULT_NEWTON_TOLERANCE: float

class Harness:
    """A harness: cables (each given with a fixed point clip at every joined end) and junctions;
    `held`: indices of the junctions held by a clip (their pose follows the clip poses given
    for their first end)."""
    def __init__(
        self, cables, names, junctions, max_iterations=40, step_tolerance=1e-9, held=...
    ) -> None: ...
    @property
    def ends(self) -> Any:
        """(cable index, clip index, junction index) of every joined end, in the order of the
        branch outputs."""
        ...
    def run_sequence(
        self, positions, quaternions, progress=None, progress_every=50, stop=None, warm=False
    ) -> Any:
        """Runs a sequence of equilibria through the clip poses of each cable, `positions[c]`
        (T, C_c, 3) and `quaternions[c]` (T, C_c, 4) (the entries of joined ends are ignored).
        Step 0 is a static solve from the routed shapes. Returns `cables` (one dict per cable,
        as `Cable.run_sequence`), `junction_positions` (T, J, 3), `junction_quaternions`
        (T, J, 4, scalar first), `branch_force` and `branch_moment` (T, E, 3: what each joined
        end's cable applies to its junction, global, moment about the junction point),
        `junction_reaction_force` and `junction_reaction_moment` (T, J, 3: of the clip on each
        junction in `held`, zero for the others), `iterations`, `substeps`, `residual`, `steps`
        and `error` (None, or why it stopped: the steps before are kept). Each cable's
        `unstable` is the number of negative eigenvalues of the whole harness's tangent
        stiffness at that step (the tree inertia; 0 = stable). `warm`: step 0 starts from the
        last equilibrium of the previous run (the first from the routed shapes); a failed run
        keeps the previous (the workbench's drags).
        """
        ...
    def update_contact(self, cables) -> Any:
        """Takes each cable's contact term and obstacle poses again from `cables` (the cables it
        was built from, after `Cable.set_contact` moved their obstacles: the workbench's body
        drags); the harness keeps its own copies otherwise.
        """
        ...
    def modes(self, count, shear_tau=None, bend_tau=None, tolerance=None) -> Any:
        """The `count` lowest natural modes of the whole harness about the last step of
        `run_sequence` (a static equilibrium): shift-invert on the tree elimination
        (`rod::harness_modal`). Returns `omega` (k,) rad/s, `cables` (one dict per cable:
        `displacements` (k, N+1, 3) and `rotations` (k, N, 3), global, mass-normalised over
        the harness), `junction_displacements` and `junction_rotations` (k, J, 3, global),
        `shares` (k, 4) and `kind` (k,) as `Cable.modes`. An unstable equilibrium is a
        ValueError. With per-cable Kelvin–Voigt retardation times `shear_tau` and `bend_tau`
        (one triple per cable, as `Cable.modes`), also `damping_ratio` (k,): each mode's
        Rayleigh quotient over the whole harness (`rod::harness_modal::harness_damping_ratio`).
        `tolerance` as `Cable.modes`.
        """
        ...
    def run_dynamic(
        self,
        time_step,
        kinematics,
        output_every,
        tau_shear,
        tau_bend,
        spectral_radius=0.9,
        newton_tolerance=...,
        progress=None,
        progress_every=100,
        stop=None,
    ) -> Any:
        """Dynamic run (generalized-α on the harness): static equilibrium at the clip poses of
        step 0, then steps of `time_step` through each cable's clip kinematics `kinematics[c]`
        = (positions, quaternions, velocities, angular velocities, accelerations, angular
        accelerations), (T, C_c, ·) global (the entries of joined ends are ignored). Every
        `output_every`-th step is recorded (and step 0). τ per cable: `tau_shear[c]`,
        `tau_bend[c]` (3 each). Returns what `run_sequence` returns, the cables' dicts with the
        energies of `Cable.run_dynamic`, and `junction_velocities` (T, J, 6: ẋ global, ω body),
        `kinetic_energy`, `elastic_energy`, `load_potential`, `dissipated_energy` (T,) of the
        whole harness (junctions included), `unresolved_gain`, `impact_dissipation` (T,) as
        `Cable.run_dynamic`.
        Junctions held by a clip follow its motion (given for their first end); sliding clips
        slide (a cable running out of one stops the run).
        """
        ...

INTERRUPTED: str

class StopFlag:
    """A flag shared between the thread that wants a run stopped and the solver threads."""
    def __init__(self) -> None: ...
    def clear(self) -> Any:
        """Withdraws the request."""
        ...
    @property
    def is_set(self) -> Any: ...
    def set(self) -> Any:
        """Asks every run polling this flag to stop after its current step."""
        ...

class Surroundings:
    """Shapes carried by bodies (index 0, 1, …), in each body's reference frame."""
    def __init__(self) -> None: ...
    def add_box(self, body, center, rotation, half_extents) -> Any:
        """Adds a box: centre, rotation (3 × 3, columns = box axes), half extents."""
        ...
    def add_cylinder(self, body, center, axis, radius, half_length) -> Any:
        """Adds a solid cylinder: centre, axis, radius, half length along the axis."""
        ...
    def add_mesh(self, body, vertices, faces) -> Any:
        """Adds a triangle mesh (vertices (V, 3), triangles (F, 3) of vertex indices, merged
        vertices, no degenerate triangles); builds its hierarchy. Returns the part index.
        """
        ...
    def add_plane(self, body, point, normal) -> Any:
        """Adds the half-space below the plane through `point` with outward `normal`."""
        ...
    def add_sphere(self, body, center, radius) -> Any:
        """Adds a solid sphere."""
        ...
    def clearance(self, positions, radius, to_body, progress=None, stop=None) -> Any:
        """Clearance of a cable of outer `radius` with node positions (T, N, 3) (global);
        `to_body` (B, T, 3, 4): per body and step the map [M | v] of global points into the
        body's reference frame, X = M x + v. Returns (clearance (T, N) m, part (T, N) index),
        or None if it was stopped: by `stop` (a `StopFlag`, read before every step) or by
        Ctrl-C when called on the main thread (KeyboardInterrupt is raised again on return).
        `progress(done, total)` is called with the steps done every 50 ms.
        """
        ...
    def closest_to_segments(self, part, a, b) -> Any:
        """Closest points of segments [a_i, b_i] ((P, 3) each) and part `part`: dict of
        distance (P,) (unsigned), t (P,), on_segment, on_surface, normal (P, 3).
        """
        ...
    def project_points(self, part, points) -> Any:
        """Signed distance of points (P, 3) to part `part` (its body frame): dict of
        distance (P,), point (P, 3), normal (P, 3).
        """
        ...

def capsule_distance(starts, ends, radius, points) -> Any:
    """Exact signed distance from each of `points` (P, 3) to the union of capsules, (P,) float64."""
    ...

def capsule_signed_distance(starts, ends, radius, origin, spacing, shape, band) -> Any:
    """Signed distance to the union of capsules on a grid, clamped to [-band, band], float32 of
    shape `shape` (voxel (i, j, k) at origin + spacing * (i, j, k)).
    """
    ...

def fatigue_cycles(series, residue="half", hysteresis=0.0) -> Any:
    """Rainflow cycles of a 1-D series: (range, mean, count, from_index, to_index)."""
    ...

def fatigue_damage_combined(
    signals,
    weights,
    k,
    alpha,
    knee_range=None,
    knee_kind="haibach",
    residue="half",
    hysteresis=0.0,
    threads=None,
) -> Any:
    """Miner damage of the linear combinations `signals[g] @ weights[j]` for every group g
    (signals (n_groups, n_samples, n_channels)) and weight row j (weights (n_series,
    n_channels)); returns (n_groups, n_series). The combined series are never stored.
    """
    ...

def fatigue_damage_many(
    series,
    k,
    alpha,
    knee_range=None,
    knee_kind="haibach",
    residue="half",
    hysteresis=0.0,
    threads=None,
) -> Any:
    """Miner damage of every row of a 2-D array (n_series, n_samples), in parallel."""
    ...

def fatigue_turning_points(series, hysteresis=0.0) -> Any:
    """Turning points of a 1-D series: (indices int64, values float64)."""
    ...

def section_strains(positions, quaternions, arc_length) -> Any:
    """Axial strain Γ₃ and shear strain |(Γ₁, Γ₂)| per step and edge (T, N) of saved positions
    (T, N + 1, 3), edge quaternions (T, N, 4, scalar first) and node arc lengths (N + 1), all
    C-contiguous."""
    ...

def strain_extremes(positions, quaternions, arc_length) -> Any:
    """((value, step, edge) of the largest axial strain, of the largest compression −Γ₃, of
    the largest shear strain), or None for no steps or edges; arrays as `section_strains`,
    C-contiguous. The first of equal values; a NaN counts as largest (numpy's argmax)."""
    ...

def weld_vertices(vertices, faces) -> Any:
    """Merges the vertices (N, 3) of a triangle soup that agree to 8 decimals (first appearance's
    order and coordinates kept) and re-indexes the faces (F, 3): (vertices (M, 3), faces (F, 3)).
    """
    ...

def mesh_topology(faces, n_vertices: int) -> tuple[bool, int, Any, int]:
    """Closedness, boundary edges and shells of a mesh (faces (F, 3), indices below n_vertices):
    (watertight, boundary edge count, shell per face (F,) numbered by first face, shells)."""
    ...
