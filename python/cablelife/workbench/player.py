"""Playing a result file in the workbench: one saved step at a time, with the colour
quantities of the live view (bending, torsion, tension, bend radius ÷ rule, clearance)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cablelife.workbench.session import WorkbenchError, node_average


@dataclass
class Player:
    path: Path
    result: object  # cablelife.results.Result (histories read on first use)
    bend_factor: float = 10.0

    @classmethod
    def open(cls, path: str | Path, bend_factor: float = 10.0) -> Player:
        from cablelife.results import load_result

        path = Path(path)
        try:
            result = load_result(path, lazy=False)
        except (OSError, ValueError, KeyError) as err:
            raise WorkbenchError(f"--result {str(path)!r}: {err}") from None
        return cls(path, result, bend_factor)

    @property
    def steps(self) -> int:
        return min(c.n_steps for c in self.result.cables.values())

    def info(self) -> dict:
        first = next(iter(self.result.cables.values()))
        return {
            "path": str(self.path),
            "mode": self.result.mode,
            "steps": self.steps,
            "time": [float(first.time[0]), float(first.time[self.steps - 1])],
            "cables": list(self.result.cables),
        }

    def step(self, k: int) -> dict:
        """The cables at saved step ``k``: positions and colour values per node."""
        if not 0 <= k < self.steps:
            raise IndexError(f"step {k}: the result has steps 0 … {self.steps - 1}")
        cables, time = {}, 0.0
        for name, c in self.result.cables.items():
            time = float(c.time[k])
            m, f = c.moments[k], c.forces[k]
            sec = c.section
            radius = float(sec.get("outer_radius", 0.005))
            kappa = np.hypot(m[:, 0] / sec["EI1"], m[:, 1] / sec["EI2"])
            with np.errstate(divide="ignore"):
                bend = np.where(kappa > 0, 1.0 / kappa, np.inf) / (self.bend_factor * 2 * radius)
            values = {
                "bending": np.hypot(m[:, 0], m[:, 1]),
                "torsion": m[:, 2],
                "tension": node_average(f[:, 2]),
                "bend_ratio": np.minimum(bend, 1e6),
            }
            if c.clearance is not None:
                values["clearance"] = c.clearance[k] * 1e3
            cables[name] = {
                "positions": np.asarray(c.positions[k], float).tolist(),
                "radius": radius,
                "values": {q: np.round(v, 12).tolist() for q, v in values.items()},
            }
        bodies = {}
        geo = self.result.surroundings
        if geo is not None:  # body poses [R | t] at this step (x = R X + t)
            j = int(np.argmin(np.abs(np.asarray(geo.time) - time)))
            bodies = {n: np.asarray(geo.poses[b, j]).tolist() for b, n in enumerate(geo.bodies)}
        return {"step": k, "time": time, "cables": cables, "bodies": bodies}
