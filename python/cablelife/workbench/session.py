"""The workbench's model: the scene being edited, one warm static solver per cable, the
quantities the page colours the cables by, undo, and saving back to TOML.

Moving a clip re-solves its cable from the last equilibrium (``_core.Cable.step_static``,
sub-stepped toward the new pose when a direct Newton solve fails); a failed solve keeps the
last good state and the clip where it was, and says why. Editing a clip's ``s``, type or
length, or a cable's length, rebuilds that cable's solver (a new mesh) and solves it from its
routed shape. The scene's TOML text is kept as a tomlkit document, so that saving changes only
the edited values and keeps the user's comments and layout.
"""

from __future__ import annotations

import math
import threading
import time
import typing
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cablelife.limits import LIMITS
from cablelife.rotations import matrix_quaternions
from cablelife.scene import (
    Cable,
    Clip,
    Placement,
    Scene,
    SceneError,
    load_scene,
    scene_from_dict,
)
from cablelife.simulate import build_cable, euler_matrix

#: Colour quantities: key → (label, unit). Values per node.
QUANTITIES = {
    "bending": ("bending moment |M1, M2|", "N m"),
    "torsion": ("torsion M3", "N m"),
    "tension": ("tension F3", "N"),
    "bend_ratio": ("bend radius ÷ rule", ""),
    "clearance": ("clearance", "mm"),
}

#: Undo steps kept.
UNDO_DEPTH = 200

#: Clip types offered for editing: those of the scene format (docs/scene.md).
CLIP_TYPES = typing.get_args(Clip.model_fields["type"].annotation)


class WorkbenchError(ValueError):
    """A request the workbench cannot carry out; the message names the item and value."""


def quat_matrix(q) -> np.ndarray:
    """Rotation matrix of a quaternion (w, x, y, z), normalised."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def node_average(edge_values: np.ndarray) -> np.ndarray:
    """Edge values (N,) onto the nodes (N+1,): the ends keep their edge, inner nodes average."""
    pad = np.concatenate([edge_values[:1], edge_values, edge_values[-1:]])
    return 0.5 * (pad[:-1] + pad[1:])


@dataclass
class Equilibrium:
    """The last good static state of one cable (global frame, SI units)."""

    positions: np.ndarray  # (N+1, 3)
    quaternions: np.ndarray  # (N, 4)
    forces: np.ndarray  # (N, 3) body frame
    moments: np.ndarray  # (N+1, 3) body frame
    reaction_force: np.ndarray  # (C, 3)
    reaction_moment: np.ndarray  # (C, 3)
    iterations: int
    solve_ms: float
    slid: np.ndarray | None = None  # (C,) m: cable slid through each clip since its s


@dataclass
class LiveCable:
    """One cable of the session: its scene entry, its solver and its last equilibrium."""

    name: str
    core: object  # _core.Cable
    arc_length: np.ndarray
    clip_positions: np.ndarray  # (C, 3) global
    clip_quaternions: np.ndarray  # (C, 4) scalar first
    stiffness: np.ndarray  # EI1, EI2, GJ
    radius: float
    state: Equilibrium | None = None
    message: str = ""  # why the last solve failed ("" after a good one)


@dataclass
class Session:
    """A scene opened in the workbench."""

    path: Path
    scene: Scene
    doc: object  # tomlkit document of the scene file
    bend_factor: float = 10.0
    cables: dict[str, LiveCable] = field(default_factory=dict)
    env: object = None  # surroundings (clearance), or None
    undo_stack: list[str] = field(default_factory=list)
    lock: threading.RLock = field(default_factory=threading.RLock)
    pool: ThreadPoolExecutor | None = None
    solves: int = 0
    harness: object = None  # harness_live.LiveHarness when the scene has [[junctions]]
    opened: Scene | None = None  # the scene as opened (bodies' rest poses of the geometry)
    # The default junction normals in effect as opened (they follow the routed geometry, which
    # moves with the clips): kept for every rebuild and written on save (docs/harness.md).
    junction_pins: dict = field(default_factory=dict)
    track: object = None  # motion.MotionTrack while the bodies' motion is shown, else None
    time_index: int | None = None  # the step of ``track`` shown
    rest: dict | None = None  # clip poses at rest (and a harness's end clips) while moving
    track_cache: tuple | None = None  # (scene text, MotionTrack) last computed

    # ------------------------------------------------------------------ opening
    @classmethod
    def open(cls, path: str | Path, bend_factor: float = 10.0) -> Session:
        """Reads the scene, builds a solver per cable and solves every cable once."""
        import tomlkit

        from cablelife.surroundings.build import load_surroundings

        path = Path(path)
        scene = load_scene(path)
        doc = tomlkit.parse(path.read_text(encoding="utf-8"))
        pins = junction_pins(scene)
        scene = pinned(scene, pins)
        session = cls(path=path, scene=scene, doc=doc, bend_factor=bend_factor,
                      opened=scene.model_copy(deep=True), junction_pins=pins)  # fmt: skip
        session.env = load_surroundings(scene)
        session.pool = ThreadPoolExecutor(max_workers=max(1, min(len(scene.cables), 4)))
        session._rebuild_all()
        failed = [c for c in session.cables.values() if c.state is None]
        if failed:
            raise SceneError(
                "; ".join(f"cable '{c.name}': no static equilibrium: {c.message}" for c in failed)
            )
        return session

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=False, cancel_futures=True)

    def _rebuild_all(self) -> None:
        """Fresh solvers for every cable (one harness solver for a harness), solved."""
        if self.scene.junctions:
            self._rebuild_harness()
        else:
            for cable in self.scene.cables:
                self._rebuild(cable)

    def _live_cable(self, cable: Cable, core, pos: np.ndarray, quat: np.ndarray) -> LiveCable:
        props = cable.properties()
        return LiveCable(
            name=cable.name,
            core=core,
            arc_length=np.asarray(core.arc_length),
            clip_positions=pos,
            clip_quaternions=quat,
            stiffness=np.array(
                [props.bend_stiffness[0], props.bend_stiffness[1], props.bend_stiffness[2]]
            ),  # fmt: skip
            radius=float(props.outer_radius),
        )

    def _rebuild_harness(self) -> None:
        """A fresh harness solver for the whole tree, solved from the routed shapes."""
        from cablelife.workbench.harness_live import build_harness

        self.harness, lives = build_harness(self.scene, self._live_cable, self._set_contact)
        self.cables.update(lives)
        self._solve_harness({})

    def _solve_harness(self, targets: dict) -> bool:
        from cablelife.workbench.harness_live import solve_harness

        ok = solve_harness(self.harness, self.cables, targets, _equilibrium)
        self.solves += ok
        return ok

    def _rebuild(self, cable: Cable) -> LiveCable:
        """A fresh solver for ``cable`` (its mesh follows the clips), solved from its route."""
        from cablelife.simulate import clip_poses

        if self.scene.junctions:
            self._rebuild_harness()
            return self.cables[cable.name]
        core = build_cable(self.scene, cable)
        if self.scene.contact is not None and self.scene.contact.enabled:
            self._set_contact(core, self.scene, cable)
        pos, quat = clip_poses(self.scene, cable, np.array([0.0]), with_motion=False)
        live = self._live_cable(cable, core, pos[0].copy(), quat[0].copy())
        self.cables[cable.name] = live
        self._solve(live, live.clip_positions, live.clip_quaternions)
        return live

    def _contact_on(self, body) -> bool:
        """Contact is solved and ``body`` carries obstacles."""
        c = self.scene.contact
        return c is not None and c.enabled and bool(body.geometry)

    def _set_contacts(self, scene: Scene) -> None:
        """Every cable's contact term with the obstacles of ``scene`` (a harness takes its
        cables' terms again: it keeps copies)."""
        for cable in self.scene.cables:
            self._set_contact(self.cables[cable.name].core, scene, cable)
        if self.harness is not None:
            self.harness.core.update_contact([self.cables[n].core for n in self.harness.names])

    @staticmethod
    def _set_contact(core, scene: Scene, cable: Cable) -> None:
        """The contact term of ``core`` with the obstacles of ``scene``'s bodies at rest (their
        motion not applied, as the clips)."""
        from cablelife.contact_settings import set_contact

        try:
            set_contact(core, at_rest(scene), cable, np.array([0.0]))
        except ValueError as err:
            raise SceneError(f"cable '{cable.name}': {err}") from None

    # ------------------------------------------------------------------ lookups
    def cable_spec(self, name: str) -> Cable:
        for c in self.scene.cables:
            if c.name == name:
                return c
        raise WorkbenchError(
            f"cable {name!r} is not in the scene; allowed: "
            + ", ".join(repr(c.name) for c in self.scene.cables)
        )

    def clip_index(self, cable: Cable, clip: str) -> int:
        for j, c in enumerate(cable.clips):
            if c.name == clip:
                return j
        raise WorkbenchError(
            f"cable '{cable.name}' has no clip {clip!r}; allowed: "
            + ", ".join(repr(c.name) for c in cable.clips)
        )

    # ------------------------------------------------------------------ solving
    def _solve(self, live: LiveCable, positions: np.ndarray, quaternions: np.ndarray) -> bool:
        """One warm-started equilibrium; keeps the last good one on failure."""
        start = time.perf_counter()
        try:
            out = live.core.step_static(
                np.ascontiguousarray(positions, float), np.ascontiguousarray(quaternions, float)
            )
        except ValueError as err:
            live.message = f"cable '{live.name}': no equilibrium at the new clip pose ({err})"
            return False
        ms = (time.perf_counter() - start) * 1e3
        if not np.isfinite(out["positions"][0]).all():
            live.message = f"cable '{live.name}': the solve gave non-finite positions"
            return False
        live.state = _equilibrium(out, len(live.clip_positions), ms)
        live.clip_positions = np.array(positions, float)
        live.clip_quaternions = np.array(quaternions, float)
        live.message = ""
        self.solves += 1
        return True

    def _check_point(self, what: str, position) -> np.ndarray:
        try:
            p = np.asarray(position, float).reshape(3)
        except (TypeError, ValueError):
            raise WorkbenchError(
                f"{what} = {position!r}: give three numbers [x, y, z] in m"
            ) from None
        lo, hi = LIMITS["coordinate"]
        if not np.isfinite(p).all() or (p < lo).any() or (p > hi).any():
            raise WorkbenchError(
                f"{what} = {p.tolist()}: allowed: finite coordinates within {lo:g} … {hi:g} m"
            )
        return p

    def move_clips(self, moves: list[dict], mark: bool = True) -> dict:
        """Moves clips (global position [x, y, z] m, optional orientation ``quaternion``
        [w, x, y, z] of the clip frame d1, d2, d3) and re-solves the cables concerned (in
        parallel). Each move: {"cable", "clip", "position", "quaternion"?}. Returns
        {cable: error message or ""}: a cable whose solve fails keeps its last state and its
        clips where they were. ``mark``: an undo step starts here (the first move of a drag;
        later moves of the same drag pass False)."""
        with self.lock:
            self._check_at_rest()
            targets: dict[str, tuple[np.ndarray, np.ndarray, list]] = {}
            for m in moves:
                cable = self.cable_spec(str(m.get("cable")))
                j = self.clip_index(cable, str(m.get("clip")))
                what = f"cable '{cable.name}', clip '{cable.clips[j].name}' position"
                p = self._check_point(what, m.get("position"))
                live = self.cables[cable.name]
                pos, quat, edits = targets.setdefault(
                    cable.name,
                    (live.clip_positions.copy(), live.clip_quaternions.copy(), []),
                )
                pos[j] = p
                frame = None
                if m.get("quaternion") is not None:
                    q = np.asarray(m["quaternion"], float).reshape(4)
                    if not np.isfinite(q).all() or np.linalg.norm(q) < 1e-9:
                        raise WorkbenchError(
                            f"cable '{cable.name}', clip '{cable.clips[j].name}' quaternion = "
                            f"{q.tolist()}: give a non-zero [w, x, y, z]"
                        )
                    frame = quat_matrix(q)
                    quat[j] = matrix_quaternions(frame[None])[0]
                edits.append((j, p, frame))
            if mark:
                self._push_undo()
            names = list(targets)
            results = self._solve_targets(targets)
            errors = {}
            for name, ok in zip(names, results, strict=True):
                if ok:
                    for j, p, frame in targets[name][2]:
                        self._set_clip_pose(self.cable_spec(name), j, p, frame)
                errors[name] = self.cables[name].message
            if mark and not any(results):
                self.undo_stack.pop()
            return errors

    def _solve_targets(self, targets: dict) -> list[bool]:
        """Solves the cables of ``targets`` ({cable: (clip positions, quaternions, …)}) at
        their new clip poses: one harness solve, or the cables in parallel."""
        names = list(targets)
        if self.harness is not None:  # one system: every cable of the tree answers
            ok = self._solve_harness({n: targets[n][:2] for n in names})
            return [ok] * len(names)
        return list(self.pool.map(lambda n: self._solve(self.cables[n], *targets[n][:2]), names))

    def move_body(self, body: str, position, quaternion=None, mark: bool = True) -> dict:
        """Moves a body at rest to a new ``origin`` (global [x, y, z] m) and, with
        ``quaternion`` [w, x, y, z], a new orientation of its axes: its clips (in every cable)
        and geometry follow rigidly, the cables concerned are re-solved. All or nothing: when a
        cable has no equilibrium, the body, its clips and every cable stay as they were.
        Geometry in global coordinates moves by the body's ``placement``. Returns {cable: error
        message or ""}; raises WorkbenchError for an unknown body or a bad pose."""
        from cablelife.workbench.bodies import body_pose, matrix_euler, moved_placement

        with self.lock:
            self._check_at_rest()
            spec = self.scene.body(str(body))
            if spec is None:
                raise WorkbenchError(
                    f"body {body!r} is not in the scene; allowed: "
                    + (", ".join(repr(b.name) for b in self.scene.bodies) or "none")
                )
            o0, r0 = body_pose(spec)
            o1 = self._check_point(f"body '{spec.name}' origin", position)
            r1 = r0
            if quaternion is not None:
                q = np.asarray(quaternion, float).reshape(4)
                if not np.isfinite(q).all() or np.linalg.norm(q) < 1e-9:
                    raise WorkbenchError(
                        f"body '{spec.name}' quaternion = {q.tolist()}: give a non-zero "
                        "[w, x, y, z]"
                    )
                r1 = quat_matrix(q)
            a = r1 @ r0.T
            targets: dict[str, tuple] = {}
            for cable in self.scene.cables:
                live = self.cables[cable.name]
                for j, clip in enumerate(cable.clips):
                    if clip.body != spec.name:
                        continue
                    pos, quat, edits = targets.setdefault(
                        cable.name,
                        (live.clip_positions.copy(), live.clip_quaternions.copy(), []),
                    )
                    p = o1 + a @ (live.clip_positions[j] - o0)
                    frame = a @ quat_matrix(live.clip_quaternions[j])
                    pos[j] = p
                    quat[j] = matrix_quaternions(frame[None])[0]
                    edits.append((j, p, frame))
            placed = moved_placement(spec, a, o0, o1)
            if placed is not None:
                placed = {k: [_tidy(v) for v in x] for k, x in placed.items()}
            new_origin = tuple(_tidy(v) for v in o1)
            new_orientation = (
                spec.orientation
                if quaternion is None
                else tuple(_tidy(v) for v in matrix_euler(r1))
            )
            contact = self._contact_on(spec)
            if contact:  # the obstacles of the body's geometry move with it: every cable
                moved = self.scene.model_copy(deep=True)
                b = moved.body(spec.name)
                b.origin, b.orientation = new_origin, new_orientation
                b.placement = None if placed is None else Placement(**placed)
                for cable in self.scene.cables:
                    live = self.cables[cable.name]
                    targets.setdefault(
                        cable.name, (live.clip_positions.copy(), live.clip_quaternions.copy(), [])
                    )
                self._set_contacts(moved)
            keep = {n: (c.state, c.clip_positions, c.clip_quaternions, c.message)
                    for n, c in self.cables.items()}  # fmt: skip
            keep_junctions = None
            if self.harness is not None:
                keep_junctions = (self.harness.junction_positions,
                                  self.harness.junction_quaternions)  # fmt: skip
            results = self._solve_targets(targets)
            errors = {n: self.cables[n].message for n in targets}
            if not all(results):
                for n, (st, p, q, _) in keep.items():
                    c = self.cables[n]
                    c.state, c.clip_positions, c.clip_quaternions = st, p, q
                if keep_junctions is not None:
                    self.harness.junction_positions, self.harness.junction_quaternions = (
                        keep_junctions
                    )
                if contact:
                    self._set_contacts(self.scene)
                return errors
            if mark:
                self._push_undo()
            entry = self._toml_body(spec.name)
            if placed is not None:
                spec.placement = Placement(**placed)
                entry["placement"] = _inline(placed)
            spec.origin = new_origin
            entry["origin"] = list(spec.origin)
            if quaternion is not None:
                spec.orientation = new_orientation
                entry["orientation"] = list(spec.orientation)
            for name, (_, _, edits) in targets.items():
                for j, p, frame in edits:
                    self._set_clip_pose(self.cable_spec(name), j, p, frame)
            return errors

    def _toml_body(self, name: str):
        for entry in self.doc.get("bodies", []):
            if entry.get("name") == name:
                return entry
        raise WorkbenchError(f"body {name!r} is not in the scene file")

    def body_map(self, name: str) -> np.ndarray:
        """(3, 4) [A | b]: a point of body ``name`` at rest in the scene as opened goes to
        A x + b now (identity until the body is dragged)."""
        from cablelife.workbench.bodies import rigid_map

        a, b = rigid_map(self.opened.body(name), self.scene.body(name))
        if self.track is not None:  # then the body's motion at the time shown
            m = self.track.body_map(name, self.time_index)
            a, b = m[:, :3] @ a, m[:, :3] @ b + m[:, 3]
        return np.column_stack([a, b])

    # ------------------------------------------------------------------ body motion
    def _check_at_rest(self) -> None:
        if self.track is not None:
            raise WorkbenchError(
                f"the bodies' motion is shown (t = {self.track.times[self.time_index]:g} s): go "
                "back to rest to move or edit"
            )

    def motion_info(self) -> dict:
        """The quasistatic grid the time slider runs on, or why there is none."""
        from cablelife.workbench.motion import MotionError

        with self.lock:
            try:
                track = self.track or self._motion_track()
            except MotionError as err:
                return {"steps": 0, "why": str(err)}
            return {"steps": int(track.times.size), "times": track.times.tolist()}

    def _motion_track(self):
        """The motion track of the scene as it is now (kept until the scene changes)."""
        from cablelife.workbench.motion import motion_track

        text = self.doc.as_string()
        if self.track_cache is None or self.track_cache[0] != text:
            self.track_cache = (text, motion_track(self.scene))
        return self.track_cache[1]

    def show_time(self, k) -> dict:
        """The static equilibrium with the bodies at their motion's pose at step ``k`` of the
        quasistatic grid, warm-started from the equilibrium shown (the first call starts from
        rest). Returns {cable: error message or ""}; on a failed solve the last time shown
        stays. Moves and edits are refused until :meth:`back_to_rest`."""
        from cablelife.workbench.motion import MotionError

        with self.lock:
            track = self.track
            if track is None:
                try:
                    track = self._motion_track()
                except MotionError as err:
                    raise WorkbenchError(str(err)) from None
            if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < track.times.size:
                raise WorkbenchError(
                    f"time step {k!r}: allowed: an integer 0 … {track.times.size - 1} (t = 0 … "
                    f"{track.times[-1]:g} s)"
                )
            h = self.harness
            rest = self.rest
            if self.track is None:
                rest = {n: (c.clip_positions.copy(), c.clip_quaternions.copy())
                        for n, c in self.cables.items()}  # fmt: skip
                if h is not None:
                    rest["ends"] = ([p.copy() for p in h.end_positions],
                                    [q.copy() for q in h.end_quaternions])  # fmt: skip
            targets = {}
            for cable in self.scene.cables:
                pos, quat = track.poses[cable.name]
                n = len(cable.clips)
                targets[cable.name] = (pos[k, :n].copy(), quat[k, :n].copy())
            keep_ends = None
            if h is not None:
                keep_ends = (h.end_positions, h.end_quaternions)
                h.end_positions = [track.poses[n][0][k, m:].copy()
                                   for n, m in zip(h.names, h.own, strict=True)]  # fmt: skip
                h.end_quaternions = [track.poses[n][1][k, m:].copy()
                                     for n, m in zip(h.names, h.own, strict=True)]  # fmt: skip
            results = self._solve_targets(targets)
            if not all(results) and h is not None:
                h.end_positions, h.end_quaternions = keep_ends
            if all(results) or self.track is not None:
                self.track, self.rest = track, rest
                if all(results):
                    self.time_index = k
            return {n: self.cables[n].message for n in targets}

    def back_to_rest(self) -> dict:
        """Leaves the motion view: the cables are solved warm back to the clips' rest poses
        (rebuilt from the scene if that fails)."""
        with self.lock:
            if self.track is None:
                return {}
            rest, h = self.rest, self.harness
            if h is not None:
                h.end_positions, h.end_quaternions = rest["ends"]
            targets = {n: rest[n] for n in self.cables}
            self.track, self.time_index, self.rest = None, None, None
            if not all(self._solve_targets(targets)):
                self._reload()
            return {n: self.cables[n].message for n in targets}

    def _set_clip_pose(self, cable: Cable, j: int, p: np.ndarray, frame) -> None:
        """Writes a clip's new global pose into the scene (and its TOML), in the clip's frame."""
        clip = cable.clips[j]
        rot, origin = np.eye(3), np.zeros(3)
        if clip.frame == "body":
            body = self.scene.body(clip.body)
            rot, origin = euler_matrix(body.orientation), np.asarray(body.origin, float)
        local = rot.T @ (p - origin)
        clip.position = tuple(_tidy(v) for v in local)
        entry = self._toml_clip(cable.name, clip.name)
        entry["position"] = [_tidy(v) for v in local]
        if frame is not None:
            d3, d1 = rot.T @ frame[:, 2], rot.T @ frame[:, 0]
            clip.direction = tuple(_tidy(v) for v in d3)
            clip.normal = tuple(_tidy(v) for v in d1)
            entry["direction"] = [_tidy(v) for v in d3]
            entry["normal"] = [_tidy(v) for v in d1]

    # ------------------------------------------------------------------ edits
    def edit(self, cable: str, item: str, key: str, value) -> None:
        """Sets a clip's ``s``, ``type``, ``length`` or hinge ``axis`` (item = the clip's name)
        or the cable's ``length`` (item = ""), validated as a scene; rebuilds and re-solves the
        cable (the whole harness on a harness). A new type brings what it needs: a hinge the
        axis d2 ([0, 1, 0]) and a point, a sliding clip a guide of four edges when it held a
        point; a type without them drops axis and friction. On an invalid value or a failed
        solve nothing changes."""
        with self.lock:
            self._check_at_rest()
            spec = self.cable_spec(cable)
            if item:
                clip = spec.clips[self.clip_index(spec, item)]
                allowed = ("s", "type", "length", "axis")
            else:
                allowed = ("length",)
            if key not in allowed:
                raise WorkbenchError(
                    f"cable '{cable}'{f', clip {item!r}' if item else ''}: {key!r} cannot be "
                    f"edited here; allowed: {', '.join(allowed)}"
                )
            if key == "type" and value not in CLIP_TYPES:
                raise WorkbenchError(
                    f"cable '{cable}', clip '{item}': type = {value!r}; allowed: "
                    + ", ".join(CLIP_TYPES)
                )
            if key == "axis":
                ok = (
                    isinstance(value, list | tuple)
                    and len(value) == 3
                    and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
                )
                if not ok:
                    raise WorkbenchError(
                        f"cable '{cable}', clip '{item}': axis = {value!r}; give three numbers "
                        "[a1, a2, a3] in the clip frame"
                    )
                if clip.type != "hinge":
                    raise WorkbenchError(
                        f"cable '{cable}', clip '{item}': axis given for a {clip.type} clip; "
                        "only a hinge clip has an axis"
                    )
                value = [float(v) for v in value]
            elif key != "type":
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise WorkbenchError(
                        f"cable '{cable}'{f', clip {item!r}' if item else ''}: {key} = "
                        f"{value!r}; give a number in m"
                    )
                value = float(value)

            def change(doc) -> None:
                entry = self._toml_clip(cable, item) if item else self._toml_cable(cable)
                entry[key] = value
                if key == "type":
                    _type_needs(entry, value, spec)

            self._change_document(cable, change)

    def add_clip(self, cable: str, s, kind: str = "fixed", body: str = "world") -> str:
        """Adds a clip of type ``kind`` on ``body`` at arc length ``s`` of ``cable``, posed
        where the cable is now (its axis point and frame there, global coordinates), with what
        the type needs (as :meth:`edit`); rebuilds and re-solves the cable (on a harness: the
        tree). Returns the new clip's name. An invalid clip (beyond the cable, overlapping
        another, an unknown type or body) or a failed solve changes nothing."""
        with self.lock:
            self._check_at_rest()
            spec = self.cable_spec(cable)
            if isinstance(s, bool) or not isinstance(s, int | float) or not math.isfinite(s):
                raise WorkbenchError(f"cable '{cable}': new clip s = {s!r}; give a number in m")
            if kind not in CLIP_TYPES:
                raise WorkbenchError(
                    f"cable '{cable}': new clip type = {kind!r}; allowed: " + ", ".join(CLIP_TYPES)
                )
            bodies = ["world", *(b.name for b in self.scene.bodies)]
            if body not in bodies:
                raise WorkbenchError(
                    f"cable '{cable}': new clip body = {body!r}; allowed: "
                    + ", ".join(repr(b) for b in bodies)
                )
            live = self.cables[cable]
            if not 0.0 <= s <= live.arc_length[-1]:
                raise WorkbenchError(
                    f"cable '{cable}': new clip s = {s} m is outside the cable [0, "
                    f"{live.arc_length[-1]:g}] m"
                )
            names = {c.name for c in spec.clips}
            name = next(f"clip-{k}" for k in range(1, len(names) + 2) if f"clip-{k}" not in names)
            p, d3, d1 = _cable_frame_at(live, float(s))
            import tomlkit

            entry = tomlkit.table()
            entry.update(
                {
                    "name": name,
                    "s": _tidy(s),
                    "body": body,
                    "position": [_tidy(v) for v in p],
                    "direction": [_tidy(v) for v in d3],
                    "normal": [_tidy(v) for v in d1],
                    "type": kind,
                }
            )
            _type_needs(entry, kind, spec)
            entry.add(tomlkit.nl())

            def change(doc):
                table = next(c for c in doc["cables"] if c.get("name") == cable)
                if "clips" not in table:
                    table["clips"] = tomlkit.aot()
                clips = table["clips"]
                at = sum(1 for c in clips if float(c.get("s", 0.0)) <= s)
                clips.insert(at, entry)

            self._change_document(cable, change)
            return name

    def remove_clip(self, cable: str, clip: str) -> None:
        """Removes a clip; rebuilds and re-solves the cable. Refused with the reason (and
        nothing changed) when the cable's statics are no longer well posed: no clip left, a
        rigid-body motion left free (the solver's singular-matrix message), or no
        equilibrium."""
        with self.lock:
            self._check_at_rest()
            spec = self.cable_spec(cable)
            self.clip_index(spec, clip)

            def change(doc):
                table = next(c for c in doc["cables"] if c.get("name") == cable)
                clips = table["clips"]
                k = next(i for i, c in enumerate(clips) if c.get("name") == clip)
                del clips[k]
                if not len(clips):
                    del table["clips"]

            try:
                self._change_document(cable, change)
            except (SceneError, WorkbenchError) as err:
                raise WorkbenchError(
                    f"cable '{cable}': clip '{clip}' cannot be removed: {err}"
                ) from None

    def _change_document(self, cable: str, change) -> None:
        """Applies ``change(document)`` to a copy of the TOML document and rebuilds ``cable``;
        one undo step. On an invalid scene or a failed solve the document and the cables stay
        as they were and the error is raised."""
        import tomlkit

        self._push_undo()
        old_doc = self.doc
        self.doc = tomlkit.parse(old_doc.as_string())
        try:
            change(self.doc)
            self._reload(cable)
        except (SceneError, WorkbenchError):
            self.doc = old_doc
            self.undo_stack.pop()
            self._reload(cable)
            raise

    def _reload(self, changed: str | None = None) -> None:
        """Validates the TOML document as a scene; rebuilds the changed cable's solver (all
        when None). Raises SceneError (nothing rebuilt) for an invalid scene or a failed solve."""
        scene = scene_from_dict(
            self.doc.unwrap(), base_dir=self.path.parent.resolve(), source=str(self.path)
        )
        scene = pinned(scene, self.junction_pins)
        keep_scene, keep_cables = self.scene, dict(self.cables)
        # clip poses edited by dragging live in the document too: the new scene has them
        keep_harness = self.harness
        self.scene = scene
        try:
            if scene.junctions:
                self._rebuild_harness()
                if self.harness.message:
                    raise SceneError(self.harness.message)
            for c in scene.cables:
                if not scene.junctions and (changed is None or c.name == changed):
                    live = self._rebuild(c)
                    if live.state is None:
                        raise SceneError(live.message)
        except SceneError:
            self.scene, self.cables, self.harness = keep_scene, keep_cables, keep_harness
            raise

    def undo(self) -> bool:
        """Back to the scene before the last move or edit; False when there is nothing to undo."""
        import tomlkit

        with self.lock:
            self._check_at_rest()
            if not self.undo_stack:
                return False
            self.doc = tomlkit.parse(self.undo_stack.pop())
            if not self._pose_back():
                self._reload()
            return True

    def _pose_back(self) -> bool:
        """Undo of a drag: when the restored document differs from the live scene in clip and
        body poses only, the cables are solved warm back to the restored poses (the branch of
        equilibria the drag followed; a cold solve from the routed shapes may find another).
        False (nothing changed) when more differs or the solve fails."""
        from cablelife.simulate import clip_poses

        scene = scene_from_dict(
            self.doc.unwrap(), base_dir=self.path.parent.resolve(), source=str(self.path)
        )
        scene = pinned(scene, self.junction_pins)
        if _without_poses(scene) != _without_poses(self.scene):
            return False
        targets = {}
        moved = [b for b in scene.bodies if b != self.scene.body(b.name)]
        contact = any(self._contact_on(b) for b in moved)  # obstacles back: every cable
        for cable in scene.cables:
            pos, quat = clip_poses(scene, cable, np.array([0.0]), with_motion=False)
            live = self.cables[cable.name]
            if contact or not (np.array_equal(pos[0], live.clip_positions)
                               and np.array_equal(quat[0], live.clip_quaternions)):  # fmt: skip
                targets[cable.name] = (pos[0], quat[0])
        if contact:
            self._set_contacts(scene)
        if not all(self._solve_targets(targets)):
            return False
        self.scene = scene
        return True

    def _push_undo(self) -> None:
        self.undo_stack.append(self.doc.as_string())
        del self.undo_stack[:-UNDO_DEPTH]

    # ------------------------------------------------------------------ TOML
    def _toml_cable(self, name: str):
        for entry in self.doc.get("cables", []):
            if entry.get("name") == name:
                return entry
        raise WorkbenchError(f"cable {name!r} is not in the scene file")

    def _toml_clip(self, cable: str, clip: str):
        for entry in self._toml_cable(cable).get("clips", []):
            if entry.get("name") == clip:
                return entry
        raise WorkbenchError(f"cable '{cable}' has no clip {clip!r} in the scene file")

    def scene_text(self) -> str:
        return self.doc.as_string()

    def save(self, path: str | Path | None = None) -> Path:
        """Writes the edited scene (atomically) to ``path`` (default: the scene file) and checks
        that it loads back as a scene."""
        from cablelife.atomic import write_text_atomic

        target = Path(path) if path else self.path
        if target.suffix.lower() != ".toml":
            raise WorkbenchError(f"save to {str(target)!r}: give a .toml file")
        if not target.parent.is_dir():
            raise WorkbenchError(f"save to {str(target)!r}: the folder does not exist")
        with self.lock:
            doc = self.doc
            if self.junction_pins:  # written into a copy (undo keeps the document as opened)
                import tomlkit

                doc = tomlkit.parse(doc.as_string())
                for entry in doc["junctions"]:
                    if "normals" not in entry and str(entry["name"]) in self.junction_pins:
                        entry["normals"] = self.junction_pins[str(entry["name"])]
            text = doc.as_string()
            scene_from_dict(doc.unwrap(), base_dir=target.parent.resolve())
            write_text_atomic(target, text)
        load_scene(target)  # round trip
        return target

    # ------------------------------------------------------------------ views
    def node_values(self, live: LiveCable) -> dict[str, list[float]]:
        """The colour quantities per node of a cable's last equilibrium."""
        st = live.state
        m, f = st.moments, st.forces
        bending = np.hypot(m[:, 0], m[:, 1])
        kappa = np.hypot(m[:, 0] / live.stiffness[0], m[:, 1] / live.stiffness[1])
        rule = self.bend_factor * 2 * live.radius
        with np.errstate(divide="ignore"):
            radius = np.where(kappa > 0, 1.0 / kappa, np.inf)
        values = {
            "bending": bending,
            "torsion": m[:, 2],
            "tension": node_average(f[:, 2]),
            "bend_ratio": np.minimum(radius / rule, 1e6),
        }
        clearance = self.clearance(live)
        if clearance is not None:
            values["clearance"] = clearance * 1e3
        return {k: np.round(v, 12).tolist() for k, v in values.items()}

    def clearance(self, live: LiveCable) -> np.ndarray | None:
        """Clearance (N+1,) m of the cable surface to the geometry at rest; None without."""
        if self.env is None:
            return None
        maps = np.zeros((len(self.env.bodies), 1, 3, 4))
        for k, name in enumerate(self.env.bodies):  # global → the body as opened: X = Aᵀ(x − b)
            ab = self.body_map(name)
            maps[k, 0, :, :3] = ab[:, :3].T
            maps[k, 0, :, 3] = -ab[:, :3].T @ ab[:, 3]
        value, _ = self.env.core.clearance(
            np.ascontiguousarray(live.state.positions[None], float), live.radius, maps
        )
        return np.asarray(value)[0]

    def figures(self, live: LiveCable) -> dict:
        """The side panel's figures of one cable."""
        st = live.state
        m, f = st.moments, st.forces
        kappa = np.hypot(m[:, 0] / live.stiffness[0], m[:, 1] / live.stiffness[1])
        i = int(np.argmax(kappa))
        k_edge = int(np.argmax(f[:, 2]))
        k_comp = int(np.argmin(f[:, 2]))
        k_tors = int(np.argmax(np.abs(m[:, 2])))
        s = live.arc_length
        mid = 0.5 * (s[1:] + s[:-1])
        spec = self.cable_spec(live.name)
        out = {
            "minBendRadius": _finite(1.0 / kappa[i]) if kappa[i] > 0 else None,
            "minBendRadiusS": float(s[i]),
            "bendRule": self.bend_factor * 2 * live.radius,
            "maxTension": float(f[k_edge, 2]),
            "maxTensionS": float(mid[k_edge]),
            "maxCompression": float(max(-f[k_comp, 2], 0.0)),
            "maxCompressionS": float(mid[k_comp]),
            "maxTorsion": float(abs(m[k_tors, 2])),
            "maxTorsionS": float(s[k_tors]),
            "iterations": st.iterations,
            "solveMs": st.solve_ms,
            "clips": [
                {
                    "name": c.name,
                    "s": c.s,
                    "type": c.type,
                    "length": c.length,
                    "body": c.body,
                    "axis": None if c.axis is None else list(c.axis),
                    "slid": _slid(st, j) if c.type == "sliding" else None,
                    "force": st.reaction_force[j].tolist(),
                    "moment": st.reaction_moment[j].tolist(),
                }
                for j, c in enumerate(spec.clips)
            ],
            "length": spec.length,
        }
        out["warning"] = strain_warning(live)
        clearance = self.clearance(live)
        if clearance is not None:
            k = int(np.argmin(clearance))
            out["minClearance"] = float(clearance[k])
            out["minClearanceS"] = float(s[k])
        return out

    def state(self) -> dict:
        """What the page draws: per cable the nodes, the clip poses, the colour values, the
        figures and the last solve's message."""
        with self.lock:
            cables = {}
            for name, live in self.cables.items():
                frames = [quat_matrix(q) for q in live.clip_quaternions]
                cables[name] = {
                    "positions": live.state.positions.tolist(),
                    "arcLength": live.arc_length.tolist(),
                    "radius": live.radius,
                    "clipPositions": live.clip_positions.tolist(),
                    "clipFrames": [r.T.tolist() for r in frames],  # rows d1, d2, d3
                    "clipAxes": [
                        _hinge_axis(c, r)
                        for c, r in zip(self.cable_spec(name).clips, frames, strict=True)
                    ],  # fmt: skip
                    "values": self.node_values(live),
                    "figures": self.figures(live),
                    "message": live.message,
                }
            out = {"cables": cables, "solves": self.solves, "undo": len(self.undo_stack)}
            out["time"] = (
                None
                if self.track is None
                else {"step": self.time_index, "t": float(self.track.times[self.time_index])}
            )
            out["bodies"] = {b.name: self._body_view(b) for b in self.scene.bodies}
            h = self.harness
            if h is not None and h.junction_positions is not None:
                out["junctions"] = {
                    name: {"position": h.junction_positions[k].tolist(),
                           "frame": quat_matrix(h.junction_quaternions[k]).T.tolist()}
                    for k, name in enumerate(h.junction_names)
                }  # fmt: skip
            return out

    def _body_view(self, body) -> dict:
        from cablelife.workbench.bodies import body_pose

        o, r = body_pose(body)
        if self.track is not None:  # at the time shown
            m = self.track.body_map(body.name, self.time_index)
            o, r = m[:, :3] @ o + m[:, 3], m[:, :3] @ r
        clips = sum(c.body == body.name for cable in self.scene.cables for c in cable.clips)
        return {
            "origin": o.tolist(),
            "frame": r.T.tolist(),  # rows: the body's axes
            "map": self.body_map(body.name).tolist(),
            "clips": int(clips),
        }

    def geometry(self) -> dict:
        """The bodies' meshes (global, at rest) and names, for the page (once)."""
        if self.env is None:
            return {"bodies": []}
        out = []
        for name, (v, f) in zip(self.env.bodies, self.env.display_meshes(), strict=True):
            out.append(
                {
                    "name": name,
                    "vertices": np.round(np.asarray(v, float), 6).ravel().tolist(),
                    "faces": np.asarray(f, np.int64).ravel().tolist(),
                }
            )
        return {"bodies": out}


def strain_warning(live: LiveCable) -> str:
    """A warning when the equilibrium's strains leave the model's validity range
    (docs/solver.md), else ""."""
    from types import SimpleNamespace

    from cablelife import validity

    st = live.state
    c = SimpleNamespace(positions=st.positions[None], quaternions=st.quaternions[None],
                        arc_length=live.arc_length)  # fmt: skip
    axial, shear = validity.strains(c)
    s = 0.5 * (live.arc_length[1:] + live.arc_length[:-1])
    for name, v, limit in (("axial", axial[0], validity.AXIAL_STRAIN_LIMIT),
                           ("shear", shear[0], validity.SHEAR_STRAIN_LIMIT)):  # fmt: skip
        k = int(np.argmax(np.abs(v)))
        if abs(v[k]) > limit:
            return (
                f"cable '{live.name}': {name} strain {100 * v[k]:.3g} % at s = {s[k]:.3f} m, "
                f"outside the model's validity range (±{100 * limit:g} %): the clips stretch "
                "the cable"
            )
    return ""


def _without_poses(scene: Scene) -> dict:
    """The scene as data without the clips' and bodies' poses (what a drag changes)."""
    data = scene.model_dump(mode="json")
    for body in data.get("bodies", []):
        body.pop("origin", None)
        body.pop("orientation", None)
        body.pop("placement", None)
    for cable in data.get("cables", []):
        for clip in cable.get("clips", []):
            for key in ("position", "direction", "normal"):
                clip.pop(key, None)
    return data


def _cable_frame_at(live: LiveCable, s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cable's axis point, tangent d3 and d1 at arc length ``s`` of its last equilibrium
    (linear between nodes; the frame of the edge that holds s)."""
    x, arc = live.state.positions, live.arc_length
    point = np.array([np.interp(s, arc, x[:, i]) for i in range(3)])
    e = int(np.clip(np.searchsorted(arc, s, side="right") - 1, 0, len(arc) - 2))
    frame = quat_matrix(live.state.quaternions[e])
    return point, frame[:, 2], frame[:, 0]


def _inline(values: dict):
    """A TOML inline table ``{ key = value, … }`` (a placement on one line)."""
    import tomlkit

    table = tomlkit.inline_table()
    table.update(values)
    return table


def _type_needs(entry, kind: str, cable: Cable) -> None:
    """Completes a clip's TOML entry for its new type (see ``Session.edit``)."""
    if kind != "hinge":
        entry.pop("axis", None)
    if kind != "sliding":
        entry.pop("friction", None)
    if kind in ("hinge", "ball"):
        entry["length"] = 0.0
    if kind == "hinge" and "axis" not in entry:
        entry["axis"] = [0.0, 1.0, 0.0]
    if kind == "sliding" and not entry.get("length"):
        entry["length"] = _tidy(4 * cable.length / cable.n_segments)


def _hinge_axis(clip: Clip, frame: np.ndarray) -> list[float] | None:
    """A hinge clip's turning axis in global coordinates (unit), else None."""
    if clip.type != "hinge" or clip.axis is None:
        return None
    a = frame @ np.asarray(clip.axis, float)
    return (a / np.linalg.norm(a)).tolist()


def _slid(st: Equilibrium, j: int) -> float | None:
    if st.slid is None or not np.isfinite(st.slid[j]):
        return None
    return float(st.slid[j])


def _equilibrium(out: dict, clips: int, ms: float) -> Equilibrium:
    """The Equilibrium of a one-step solver record (the first ``clips`` clips: the user's)."""
    slid = out.get("slid_length")
    return Equilibrium(
        positions=out["positions"][0],
        quaternions=out["quaternions"][0],
        forces=out["forces"][0],
        moments=out["moments"][0],
        reaction_force=out["reaction_force"][0][:clips],
        reaction_moment=out["reaction_moment"][0][:clips],
        iterations=int(np.asarray(out["iterations"]).reshape(-1)[0]),
        solve_ms=ms,
        slid=None if slid is None else np.asarray(slid)[0][:clips],
    )


def _tidy(v: float) -> float:
    """A coordinate as written to TOML: rounded to 1e-12 (no 0.30000000000000004)."""
    r = round(float(v), 12)
    return 0.0 if r == 0 else r


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def at_rest(scene: Scene) -> Scene:
    """The scene with every body at rest (no motion): the pose the workbench shows."""
    data = scene.model_dump(mode="json", exclude_none=True)
    for body in data.get("bodies", []):
        body["motion"] = []
        body.pop("motion_file", None)
    data["simulation"]["mode"] = "static"
    return scene_from_dict(data, base_dir=scene.base_dir)


def batch_equilibrium(scene: Scene, cable: str) -> np.ndarray:
    """Node positions (N+1, 3) of a cold static solve by ``simulate`` of one cable of
    ``scene`` with its bodies at rest: the reference the workbench's warm solves are checked
    against."""
    from cablelife.simulate import simulate

    return simulate(at_rest(scene), mode="static").cables[cable].positions[0]


def junction_pins(scene: Scene) -> dict:
    """The normals in effect of the scene's junctions without ``normals`` (by name)."""
    if not scene.junctions:
        return {}
    from cablelife.harness import junction_normals

    return junction_normals(scene)


def pinned(scene: Scene, pins: dict) -> Scene:
    """``scene`` with the pinned normals on its junctions that give none."""
    if not pins:
        return scene
    junctions = [
        j.model_copy(update={"normals": [tuple(n) for n in pins[j.name]]})
        if j.normals is None and j.name in pins
        else j
        for j in scene.junctions
    ]
    return scene.model_copy(update={"junctions": junctions})
