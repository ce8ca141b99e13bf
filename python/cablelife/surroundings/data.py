"""The clearance arrays of one cable result and their HDF5 form::

/cables/<name>/clearance        (T, N+1) m   attrs: unit, min_clearance, definition
/cables/<name>/clearance_body   (T, N+1) int index into attrs["bodies"] (nearest body)
/cables/<name>/clearance_part   (T, N+1) int index into attrs["parts"] ("body/part")
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

DEFINITION = (
    "distance from the cable surface (outer radius) to the nearest geometry, negative inside; "
    "per node the minimum over the node and its two half-edges"
)


@dataclass
class CableClearance:
    value: np.ndarray  # (T, N+1) m
    body: np.ndarray  # (T, N+1) index into bodies
    bodies: list[str]
    part: np.ndarray  # (T, N+1) index into parts
    parts: list[str]
    min_clearance: float = 0.0

    def write(self, group, put) -> None:
        """Writes the datasets with ``put(group, name, data, unit)``: the result file's chunked,
        compressed writer (and its precision for the clearance values)."""
        put(group, "clearance", self.value, "m")
        ds = group["clearance"]
        ds.attrs["min_clearance"] = self.min_clearance
        ds.attrs["definition"] = DEFINITION
        put(group, "clearance_body", self.body.astype(np.int32), "1")
        group["clearance_body"].attrs["bodies"] = np.array(self.bodies, dtype=object)
        put(group, "clearance_part", self.part.astype(np.int32), "1")
        group["clearance_part"].attrs["parts"] = np.array(self.parts, dtype=object)

    @classmethod
    def read(cls, group) -> CableClearance | None:
        if "clearance" not in group:
            return None
        ds, db, dp = group["clearance"], group["clearance_body"], group["clearance_part"]
        return cls(
            value=np.asarray(ds[()], dtype=np.float64),
            body=db[()],
            bodies=[_text(x) for x in db.attrs["bodies"]],
            part=dp[()],
            parts=[_text(x) for x in dp.attrs["parts"]],
            min_clearance=float(ds.attrs.get("min_clearance", 0.0)),
        )

    def body_names(self) -> np.ndarray:
        """(T, N+1) name of the nearest body."""
        return np.array(self.bodies, dtype=object)[self.body]


def _text(x) -> str:
    return x.decode() if isinstance(x, bytes) else str(x)
