"""Harnesses (docs/harness.md): cables joined at junctions into a tree, solved as one system.

Each joined cable end gets a fixed point clip ("junction <name>") whose pose follows the
junction; the Rust harness solver (``_core.Harness``) eliminates the cables onto the junctions
and solves the junction tree. Static and quasistatic runs (each state checked for stability),
dynamic runs (generalized-α on the whole harness) and modal analysis
(``cablelife.modal.harness_modes``).
"""

from __future__ import annotations

import time as _time
from typing import TYPE_CHECKING

import numpy as np

from cablelife.results import CONTACT_KEYS, CableResult, ClipReaction, JunctionResult

if TYPE_CHECKING:
    from cablelife.scene import Cable, Junction, Scene


def _fail(msg: str):
    raise ValueError(msg)


def check_junctions(scene: Scene) -> None:
    """Cross-checks the junctions against the cables (inside the scene's validation: errors
    are ValueErrors naming the junction, the end and what is allowed)."""
    cables = {c.name: c for c in scene.cables}
    names = [j.name for j in scene.junctions]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        _fail(f"junction names must be unique; repeated: {sorted(dup)}")
    used: dict[tuple[str, str], str] = {}
    for j in scene.junctions:
        for i in range(len(j.ends)):
            cable, which = j.end(i)
            where = f"junctions '{j.name}' ends[{i}] = {j.ends[i]!r}"
            if cable not in cables:
                _fail(f"{where}: no cable named {cable!r}; cables: {sorted(cables)}")
            if (cable, which) in used:
                _fail(
                    f"{where}: that end is already joined at junction '{used[cable, which]}'; "
                    "a cable end can be joined once"
                )
            used[cable, which] = j.name
            c = cables[cable]
            s_end = 0.0 if which == "start" else c.length
            for clip in c.clips:
                lo, hi = clip.s - clip.length / 2, clip.s + clip.length / 2
                if lo - 1e-9 * c.length <= s_end <= hi + 1e-9 * c.length:
                    _fail(
                        f"{where}: clip '{clip.name}' of cable '{cable}' already holds that "
                        f"end (s = {s_end:g} m); the junction holds it: remove the clip or "
                        "join the other end"
                    )
    held = {cable for cable, _ in used}
    for i, c in enumerate(scene.cables):
        if not c.clips and c.name not in held:
            _fail(
                f"cables[{i}] ('{c.name}') has no clips and no junction joins it; give at "
                "least one clip"
            )
    # Loops: union–find over the junctions; a cable joined at both ends links two.
    parent = {j.name: j.name for j in scene.junctions}

    def find(a: str) -> str:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for c in scene.cables:
        a, b = used.get((c.name, "start")), used.get((c.name, "end"))
        if a is None or b is None:
            continue
        ra, rb = find(a), find(b)
        if ra == rb:
            _fail(
                f"harness with a loop: cable '{c.name}' closes a loop through junctions "
                f"'{a}' and '{b}'; loops are not supported yet"
            )
        parent[ra] = rb
    # Every connected harness needs a clip somewhere (else it floats: a rigid-body motion).
    clipped: dict[str, bool] = {}
    for j in scene.junctions:
        r = find(j.name)
        held_here = j.clip is not None or any(cables[j.end(i)[0]].clips for i in range(len(j.ends)))
        clipped[r] = clipped.get(r, False) or held_here
    for j in scene.junctions:
        if not clipped[find(j.name)]:
            group = sorted(k.name for k in scene.junctions if find(k.name) == find(j.name))
            _fail(
                f"the harness through junctions {group} is held by no clip: it could move as "
                "a rigid body; give at least one of its cables or junctions a clip"
            )


def end_clip_name(junction: Junction) -> str:
    """The name of the point clip that holds a joined end."""
    return f"junction {junction.name}"


def harness_cables(scene: Scene) -> tuple[list[Cable], list[tuple]]:
    """The scene's cables with a fixed point clip at every joined end (on the body of the
    junction's clip, if it has one), and the junctions as (name, mass, rotary inertia [3],
    ends as (cable index, clip index))."""
    from cablelife.scene import Clip

    index = {c.name: k for k, c in enumerate(scene.cables)}
    extra: dict[str, list] = {c.name: [] for c in scene.cables}
    specs = []
    for j in scene.junctions:
        ends = []
        for i in range(len(j.ends)):
            cable, which = j.end(i)
            c = scene.cables[index[cable]]
            d = np.asarray(j.directions[i], float)
            tangent = d if which == "start" else -d  # d3 runs along increasing s
            clip = Clip(
                name=end_clip_name(j),
                s=0.0 if which == "start" else c.length,
                position=j.position,
                direction=tuple(float(v) for v in tangent),
                normal=None if j.normals is None else j.normals[i],
                type="fixed",
                # A junction held by a clip: its ends' clips move with the clip's body (the
                # solver takes the junction's pose from its first end's clip).
                body="world" if j.clip is None else j.clip.body,
            )
            ends.append((index[cable], len(c.clips) + len(extra[cable])))
            extra[cable].append(clip)
        specs.append((j.name, float(j.mass), [float(j.rotary_inertia)] * 3, ends))
    cables = [
        c.model_copy(update={"clips": [*c.clips, *extra[c.name]]}) if extra[c.name] else c
        for c in scene.cables
    ]
    given = {end_clip_name(j) for j in scene.junctions if j.normals is not None}
    for k, c in enumerate(cables):
        open_ends = [
            e
            for e, clip in enumerate(c.clips)
            if e >= len(scene.cables[k].clips) and clip.name not in given
        ]
        if open_ends:
            cables[k] = default_normals(scene, c, len(scene.cables[k].clips), given, open_ends)
    return cables, specs


def junction_normals(scene: Scene) -> dict[str, list[list[float]]]:
    """The normals in effect (d1 of each end, global) of the junctions without ``normals``,
    by name: what a tool that edits the scene writes into it to keep the junctions'
    stress-free twist when it moves clips (the workbench)."""
    from cablelife.simulate import frame_matrix

    cables, _ = harness_cables(scene)
    clips = {(c.name, k.name): k for c in cables for k in c.clips}
    out = {}
    for j in scene.junctions:
        if j.normals is None:
            ends = [clips[(j.end(i)[0], end_clip_name(j))] for i in range(len(j.ends))]
            out[j.name] = [
                [float(v) for v in frame_matrix(e.direction, e.normal)[:, 0]] for e in ends
            ]
    return out


def default_normals(scene: Scene, cable: Cable, n_own: int, given: set, ends: list[int]) -> Cable:
    """``cable`` with the normals of its joined-end clips ``ends`` (junctions without
    ``normals``) taken from the routed reference geometry: the frame of the nearest clip of
    the cable whose frame is given (its own clips, or ends of junctions with ``normals``)
    carried along the routed centreline without twist (parallel transport). Without such a
    clip (a cable held only at junctions without normals) the clip rule stays."""
    from cablelife.simulate import build_cable

    sources = [k for k, clip in enumerate(cable.clips) if k < n_own or clip.name in given]
    if not sources:
        return cable
    core = build_cable(scene, cable, check=False)  # built and checked again for the run
    clips = list(cable.clips)
    for e in ends:
        src = min(sources, key=lambda k: abs(cable.clips[k].s - cable.clips[e].s))
        normal = core.transported_normal(src, e)
        clips[e] = clips[e].model_copy(update={"normal": tuple(float(v) for v in normal)})
    return cable.model_copy(update={"clips": clips})


def harness_equilibrium(scene: Scene):
    """The harness solver at the static equilibrium with the clip poses of t = 0: (the
    ``_core.Harness``, its cables, their ``_core.Cable`` objects, the run's output)."""
    from cablelife import _core
    from cablelife.scene import SceneError
    from cablelife.simulate import body_motions, build_cable, clip_kinematics

    cables, specs = harness_cables(scene)
    cores = [build_cable(scene, c) for c in cables]
    times = np.array([0.0])
    try:
        core = _core.Harness(
            cores, [c.name for c in cables], specs, max_iterations=scene.simulation.max_iterations
        )
        motions = body_motions(scene, times)
        kin = [clip_kinematics(scene, c, times, motions=motions) for c in cables]
        out = core.run_sequence([k["positions"] for k in kin], [k["quaternions"] for k in kin])
    except ValueError as err:
        raise SceneError(f"harness: {err}") from None
    if out["error"]:
        raise SceneError(f"harness: no static equilibrium: {out['error']}")
    return core, cables, cores, out


def run_harness(scene: Scene, times: np.ndarray, mode: str, progress, stop):
    """Runs a harness scene (static, quasistatic or dynamic). Returns the cable results (by
    name), the junction results (by name), the error message (None: complete) and the
    harness's total energies (dynamic runs: ``time`` and the energies (T,) of all cables and
    junctions; else empty)."""
    from cablelife import _core
    from cablelife.contact_settings import set_contact
    from cablelife.scene import SceneError
    from cablelife.simulate import (
        _stability_info,
        body_motions,
        build_cable,
        check_turn_per_step,
        clip_kinematics,
        output_every,
    )

    if mode not in ("static", "quasistatic", "dynamic"):
        raise SceneError(
            f"mode = {mode!r}: {mode} analysis of harnesses (scenes with [[junctions]]) is not "
            "supported yet; allowed for harnesses: 'static', 'quasistatic', 'dynamic'"
        )
    cables, specs = harness_cables(scene)
    cores = [build_cable(scene, c) for c in cables]
    motions = body_motions(scene, times)  # once for all cables (clips and obstacles)
    for c, co in zip(cables, cores, strict=True):  # each cable's contact: a harness term
        try:
            set_contact(co, scene, c, times, motions)
        except ValueError as err:
            raise SceneError(f"cable '{c.name}': {err}") from None
    try:
        core = _core.Harness(
            cores,
            [c.name for c in cables],
            specs,
            max_iterations=scene.simulation.max_iterations,
            held=[k for k, j in enumerate(scene.junctions) if j.clip is not None],
        )
    except ValueError as err:
        raise SceneError(f"harness: {err}") from None
    kin = [clip_kinematics(scene, c, times, motions=motions) for c in cables]
    poses = [(k["positions"], k["quaternions"]) for k in kin]
    callback = (lambda k, n: progress("harness", k, n)) if progress else None
    extra: dict = {}
    if mode == "dynamic":
        from cablelife.modal import mode1_bending_damping, retardation_times, uses_mode1

        for c, k in zip(cables, kin, strict=True):
            check_turn_per_step(c, k, scene.simulation.time_step)
        every = output_every(scene)
        # Default bending damping calibrated on mode 1 of the whole harness (docs/harness.md).
        mode1 = None
        if any(map(uses_mode1, cables)):  # on this harness (not built again) at t = 0
            first = core.run_sequence([p[:1] for p, _ in poses], [q[:1] for _, q in poses])
            if first["error"]:
                raise SceneError(f"harness: no static equilibrium: {first['error']}")
            try:
                mode1 = mode1_bending_damping(core, len(cables))
            except ValueError as err:
                raise SceneError(f"harness: {err}") from None
        taus = [retardation_times(scene, c, mode1) for c in cables]
        names = ("positions", "quaternions", "velocities", "angular_velocities")
        names += ("accelerations", "angular_accelerations")
        start = _time.perf_counter()
        out = core.run_dynamic(
            scene.simulation.time_step,
            [tuple(k[m] for m in names) for k in kin],
            every,
            [t[0] for t in taus],
            [t[1] for t in taus],
            scene.simulation.spectral_radius,
            scene.simulation.newton_tolerance,
            callback,
            max(1, times.size // 200),
            stop=stop,
        )
        saved_all = times[::every]
        extra = dict(
            spectral_radius=scene.simulation.spectral_radius,
            newton_tolerance=scene.simulation.newton_tolerance,
            time_step=scene.simulation.time_step,
        )
    else:
        start = _time.perf_counter()
        out = core.run_sequence(
            [p for p, _ in poses],
            [q for _, q in poses],
            callback,
            max(1, times.size // 100),
            stop=stop,
        )
        saved_all = times
    wall = _time.perf_counter() - start
    n = int(out["steps"])
    saved = saved_all[:n]
    simulated = float(saved[-1] - saved[0]) if n > 1 else 0.0
    results: dict[str, CableResult] = {}
    for k, (c, co, o) in enumerate(zip(cables, cores, out["cables"], strict=True)):
        n_own = len(scene.cables[k].clips)
        clips = {
            clip.name: ClipReaction(
                clip.name,
                clip.s,
                o["reaction_force"][:, j].copy(),
                o["reaction_moment"][:, j].copy(),
                o["slid_length"][:, j].copy() if clip.type == "sliding" else None,
            )
            for j, clip in enumerate(c.clips[:n_own])
        }
        solver = dict(
            iterations=out["iterations"],
            substeps=out["substeps"],
            residual=out["residual"],
            segments=int(co.arc_length.size - 1),
            wall_time=wall,
            real_time_factor=wall / simulated if simulated > 0 else float("nan"),
            error=out["error"] or "",
            harness=1,
            **extra,
        )
        energies = {"elastic_energy": o["elastic_energy"]}
        if "contact_gap" in o:
            energies["contact_energy"] = o["contact_energy"]
        if mode == "dynamic":
            tau_shear, tau_bend, info = taus[k]
            solver.update(
                tau_shear=np.array(tau_shear),
                tau_bend=np.array(tau_bend),
                damping_source=info["source"],
                damping_ratio=info.get("ratio", float("nan")),
                omega1=info.get("omega1", float("nan")),  # the whole harness's first mode
                bending_share=info.get("bending_share", float("nan")),
                viscous_peak=np.asarray(o["viscous_peak"]),
            )
            energies.update(
                kinetic_energy=o["kinetic_energy"],
                dissipated_energy=o["dissipated_energy"],
                load_potential=o["load_potential"],
            )
        solver.update(_stability_info(o, saved, co.arc_length, c.name))
        results[c.name] = CableResult(
            name=c.name,
            time=saved.copy(),
            arc_length=co.arc_length,
            positions=o["positions"],
            quaternions=o["quaternions"],
            forces=o["forces"],
            moments=o["moments"],
            clips=clips,
            section=c.properties().as_attrs(),
            solver=solver,
            energies=energies,
            contact={k: o[k] for k in CONTACT_KEYS if k in o},
        )
    if mode == "dynamic":
        from cablelife import validity

        gains = np.asarray(out["unresolved_gain"])
        given_back = np.asarray(out["impact_dissipation"])
        for res in results.values():
            res.solver["unresolved_gain"] = gains
            res.solver["impact_dissipation"] = given_back
        validity.report(
            validity.impact_messages("harness", gains, saved, given_back),
            validity.ImpactWarning,
        )
    junctions: dict[str, JunctionResult] = {}
    ends = core.ends
    for jj, j in enumerate(scene.junctions):
        branches = {}
        for e, (ci, clip, ji) in enumerate(ends):
            if ji != jj:
                continue
            which = "start" if cables[ci].clips[clip].s == 0.0 else "end"
            branches[f"{cables[ci].name}:{which}"] = (
                out["branch_force"][:, e].copy(),
                out["branch_moment"][:, e].copy(),
            )
        junctions[j.name] = JunctionResult(
            name=j.name,
            time=saved.copy(),
            position=out["junction_positions"][:, jj].copy(),
            quaternion=out["junction_quaternions"][:, jj].copy(),
            branch_force={k: v[0] for k, v in branches.items()},
            branch_moment={k: v[1] for k, v in branches.items()},
            reaction_force=None if j.clip is None else out["junction_reaction_force"][:, jj].copy(),
            reaction_moment=None
            if j.clip is None
            else out["junction_reaction_moment"][:, jj].copy(),
        )
        if mode == "dynamic":
            v = out["junction_velocities"][:, jj]
            junctions[j.name].velocity = v[:, :3].copy()
            junctions[j.name].angular_velocity = rotate(junctions[j.name].quaternion, v[:, 3:])
    energies: dict[str, np.ndarray] = {}
    if mode == "dynamic":
        energies = {"time": saved.copy()}
        for key in ("kinetic_energy", "elastic_energy", "load_potential", "dissipated_energy"):
            energies[key] = np.asarray(out[key], float)
    return results, junctions, out["error"], energies


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors v (T, 3) turned by the unit quaternions q (T, 4, scalar first)."""
    w, u = q[:, :1], q[:, 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def junction_table(result):
    """A rich table of the junctions: the largest displacement from the first saved step and
    the largest branch force and moment on each junction."""
    from rich.markup import escape
    from rich.table import Table

    t = Table(title="junctions (max over time)", title_justify="left")
    for col in ("junction", "branch", "|force| [N]", "|moment| [N m]", "moved [mm]"):
        t.add_column(escape(col), justify="left" if col in ("junction", "branch") else "right")
    for name, j in result.junctions.items():
        moved = float(np.linalg.norm(j.position - j.position[:1], axis=1).max(initial=0.0))
        for k, (end, force) in enumerate(j.branch_force.items()):
            t.add_row(
                escape(name) if k == 0 else "",
                escape(end),
                f"{np.linalg.norm(force, axis=1).max(initial=0.0):.4g}",
                f"{np.linalg.norm(j.branch_moment[end], axis=1).max(initial=0.0):.4g}",
                f"{1e3 * moved:.3g}" if k == 0 else "",
            )
    return t
