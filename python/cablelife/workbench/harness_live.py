"""The workbench on a harness (docs/harness.md): one warm harness solver (``_core.Harness``)
for all the cables joined at junctions. Dragging a clip re-solves the whole tree from the last
equilibrium (``run_sequence(..., warm=True)`` of one step); a failed solve keeps the last good
state of every cable and junction."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from cablelife.scene import Scene, SceneError


@dataclass
class LiveHarness:
    """The harness solver and the poses of the joined-end clips (ignored by the solver but
    part of each cable's clip list)."""

    core: object  # _core.Harness
    names: list[str]
    own: list[int]  # per cable: the number of the user's clips (joined-end clips follow)
    end_positions: list[np.ndarray]  # per cable (E_c, 3)
    end_quaternions: list[np.ndarray]  # per cable (E_c, 4)
    junction_names: list[str]
    junction_positions: np.ndarray | None = None  # (J, 3) last equilibrium
    junction_quaternions: np.ndarray | None = None  # (J, 4)
    message: str = ""


def build_harness(scene: Scene, live_cable, set_contact) -> tuple[LiveHarness, dict]:
    """The harness solver of ``scene`` and a LiveCable per cable (made by ``live_cable(cable
    spec, core, positions, quaternions)`` with the user's clips' poses), not solved yet;
    with contact, ``set_contact(core, scene, cable)`` gives each cable its contact term."""
    from cablelife import _core
    from cablelife.harness import harness_cables
    from cablelife.simulate import build_cable, clip_poses

    cables, specs = harness_cables(scene)
    cores = [build_cable(scene, c) for c in cables]
    if scene.contact is not None and scene.contact.enabled:
        for c, co in zip(cables, cores, strict=True):  # the obstacles of the bodies at rest
            set_contact(co, scene, c)
    try:
        core = _core.Harness(cores, [c.name for c in cables], specs,
                             max_iterations=scene.simulation.max_iterations)  # fmt: skip
    except ValueError as err:
        raise SceneError(f"harness: {err}") from None
    lives, own, end_p, end_q = {}, [], [], []
    for spec, extended, co in zip(scene.cables, cables, cores, strict=True):
        pos, quat = clip_poses(scene, extended, np.array([0.0]), with_motion=False)
        n = len(spec.clips)
        own.append(n)
        end_p.append(pos[0, n:].copy())
        end_q.append(quat[0, n:].copy())
        lives[spec.name] = live_cable(spec, co, pos[0, :n].copy(), quat[0, :n].copy())
    harness = LiveHarness(core=core, names=[c.name for c in cables], own=own,
                          end_positions=end_p, end_quaternions=end_q,
                          junction_names=[j.name for j in scene.junctions])  # fmt: skip
    return harness, lives


def solve_harness(harness: LiveHarness, cables: dict, targets: dict, equilibrium) -> bool:
    """One warm equilibrium of the whole harness with the clips of ``targets`` ({cable:
    (positions (C, 3), quaternions (C, 4))}) moved, the others where they are. On success
    every cable's state is replaced (``equilibrium(record dict, own clips, ms)`` builds it); on
    failure nothing changes and every cable concerned gets the reason."""
    pos, quat = [], []
    for k, name in enumerate(harness.names):
        p, q = targets.get(name, (cables[name].clip_positions, cables[name].clip_quaternions))
        pos.append(np.concatenate([p, harness.end_positions[k]])[None])
        quat.append(np.concatenate([q, harness.end_quaternions[k]])[None])
    start = time.perf_counter()
    try:
        out = harness.core.run_sequence(pos, quat, warm=True)
    except ValueError as err:
        out = {"error": str(err)}
    ms = (time.perf_counter() - start) * 1e3
    error = out["error"]
    if error is None and not all(np.isfinite(c["positions"]).all() for c in out["cables"]):
        error = "the solve gave non-finite positions"
    if error is not None:
        why = f"harness: no equilibrium at the new clip pose ({error})"
        for name in targets or harness.names:
            cables[name].message = why
        harness.message = why
        return False
    for k, name in enumerate(harness.names):
        live = cables[name]
        live.state = equilibrium(out["cables"][k], harness.own[k], ms)
        if name in targets:
            live.clip_positions = np.array(targets[name][0], float)
            live.clip_quaternions = np.array(targets[name][1], float)
        live.message = ""
    harness.junction_positions = np.asarray(out["junction_positions"][0])
    harness.junction_quaternions = np.asarray(out["junction_quaternions"][0])
    harness.message = ""
    return True
