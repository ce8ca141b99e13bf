"""Static solutions through the scene API (TOML-equivalent dicts) against analytical values.

The Rust tests (crates/rod/tests) cover the solver in depth; these check that the scene path
(sections, clip frames, bodies, loads, result arrays) carries the physics through unchanged.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from cablelife.scene import scene_from_dict
from cablelife.sections import shear_coefficient
from cablelife.simulate import simulate


def cantilever(scene_dict, segments=50):
    cable = scene_dict["cables"][0]
    cable["segments"] = segments
    cable["clips"] = cable["clips"][:1]
    return scene_dict


def test_cantilever_under_own_weight(scene_dict):
    # Steel wire, deflection/L ~ 1e-4: linear theory applies; N = 50 is within 0.5 %.
    d = cantilever(scene_dict)
    r, e, nu, rho = 0.004, 2.0e11, 0.3, 7850.0
    d["cables"][0]["section"] = {"shape": "circle", "radius": r}
    d["cables"][0]["material"] = {"youngs_modulus": e, "poisson_ratio": nu, "density": rho}
    res = simulate(scene_from_dict(d)).cable
    area, inertia = math.pi * r**2, math.pi * r**4 / 4
    q = rho * area * 9.81
    ga = shear_coefficient(nu) * e / (2 * (1 + nu)) * area
    exact = q / (8 * e * inertia) + q / (2 * ga)
    tip = -res.positions[0, -1, 2]
    assert tip == pytest.approx(exact, rel=5e-3)
    # The clamp carries the weight; its moment is qL²/2 about the bending axis.
    reaction = res.clips["a"]
    assert reaction.force[0] == pytest.approx([0, 0, q], abs=1e-9 * q)
    assert abs(reaction.moment[0][1]) == pytest.approx(q / 2, rel=1e-3)


def test_measured_stiffness_cantilever_tip_force(scene_dict):
    d = cantilever(scene_dict, segments=40)
    cable = d["cables"][0]
    del cable["section"], cable["material"]
    ei, ga, f = 0.02, 1.0, -1e-4  # tip rotation 2.5e-3 rad: linear; shear ~6 %
    cable["stiffness"] = {
        "EA": 1e5,
        "GA": ga,
        "EI": ei,
        "GJ": 0.015,
        "mass_per_length": 0.1,
        "radius": 0.005,
    }
    cable["loads"] = [{"s": 1.0, "force": [0.0, 0.0, f]}]
    d["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    res = simulate(scene_from_dict(d)).cable
    exact = f / ga + f / (3 * ei)
    assert res.positions[0, -1, 2] == pytest.approx(exact, rel=2e-3)
    # Shear force F and bending moment M along the cable: |F| = |f|, |M(s)| = |f|(L − s).
    assert np.abs(res.forces[0, :, 0]).max() == pytest.approx(abs(f), rel=2e-3)
    m_bend = np.hypot(res.moments[0, 1:-1, 0], res.moments[0, 1:-1, 1])
    assert m_bend == pytest.approx(abs(f) * (1 - res.arc_length[1:-1]), rel=5e-3)


def test_reactions_balance_the_weight_for_every_clip_type(scene_dict):
    cable = scene_dict["cables"][0]
    cable["length"] = 1.2
    cable["clips"] = [
        {**cable["clips"][0], "length": 0.02, "s": 0.01},
        {
            "name": "m",
            "s": 0.5,
            "position": [0.45, 0.1, -0.05],
            "direction": [1.0, 0.2, 0.0],
            "type": "swivel",
        },
        {
            "name": "n",
            "s": 0.8,
            "position": [0.7, 0.15, -0.02],
            "direction": [1.0, 0.0, 0.0],
            "type": "ball",
        },
        {**cable["clips"][1], "s": 1.2, "position": [0.95, 0.2, 0.0]},
    ]
    cable["loads"] = [{"s": 0.3, "force": [0.0, 0.5, -1.0]}]
    res = simulate(scene_from_dict(scene_dict)).cable
    weight = res.section["mass_per_length"] * 1.2 * 9.81
    total = sum(r.force[0] for r in res.clips.values())
    np.testing.assert_allclose(total, [0.0, -0.5, 1.0 + weight], atol=1e-8)
    # A ball clip transmits no moment; a swivel none about the cable axis.
    assert np.linalg.norm(res.clips["n"].moment[0]) < 1e-9
    q = res.quaternions[0]
    assert np.abs(np.linalg.norm(q, axis=1) - 1).max() < 1e-12


def test_moment_balance_about_the_origin(scene_dict):
    # Σ (x_c × F_c + M_c) + Σ x_n × m_n g = 0: the clip moments are consistent with the forces.
    res = simulate(scene_from_dict(scene_dict)).cable
    total = np.zeros(3)
    for r, c in zip(res.clips.values(), scene_dict["cables"][0]["clips"], strict=True):
        total += np.cross(c["position"], r.force[0]) + r.moment[0]
    mass = np.diff(res.arc_length)
    node_mass = np.zeros(res.arc_length.size)
    node_mass[:-1] += mass / 2
    node_mass[1:] += mass / 2
    node_mass *= res.section["mass_per_length"]
    gravity = np.array([0.0, 0.0, -9.81])
    total += np.cross(res.positions[0], node_mass[:, None] * gravity).sum(0)
    assert np.linalg.norm(total) < 1e-9


def test_body_frame_clips_and_body_orientation(scene_dict):
    # The same clip given in the frame of a rotated, shifted body gives the same solution.
    base = simulate(scene_from_dict(scene_dict)).cable
    angle = 0.7
    c, s = math.cos(angle), math.sin(angle)
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    origin = np.array([0.3, -0.2, 0.1])
    clip = scene_dict["cables"][0]["clips"][1]
    local_pos = rz.T @ (np.array(clip["position"]) - origin)
    local_dir = rz.T @ np.array(clip["direction"])
    local_nrm = rz.T @ np.array(clip["normal"])
    scene_dict["bodies"] = [
        {"name": "bracket", "origin": origin.tolist(), "orientation": [0.0, 0.0, angle]}
    ]
    clip.update(
        body="bracket",
        frame="body",
        position=local_pos.tolist(),
        direction=local_dir.tolist(),
        normal=local_nrm.tolist(),
    )
    moved = simulate(scene_from_dict(scene_dict)).cable
    np.testing.assert_allclose(moved.positions, base.positions, atol=1e-10)
    np.testing.assert_allclose(moved.moments, base.moments, atol=1e-9)
