"""The spans of a cable between its clips, and which of them move. A span between two clips on
the same body (or the world) does not move: its loads are constant and its damage numerical
noise, so the comparisons of the report draw the spans that move."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cablelife.results import CableResult

#: A span moves when a node's position varies over time by more than this fraction of the
#: cable length (1 µm per m: far above round-off, far below any motion that loads a cable).
MOVING = 1e-6


@dataclass
class Span:
    """Nodes strictly between two clips (or a clip and a free end)."""

    name: str  # "body-1 → body-2"
    nodes: np.ndarray  # node indices
    edges: np.ndarray  # edge indices
    moves: bool


def cable_spans(cable: CableResult) -> list[Span]:
    """The spans of ``cable`` in order along it (free ends included when there are nodes)."""
    s = cable.arc_length
    clips = sorted(((c.s, n) for n, c in cable.clips.items()), key=lambda x: x[0])
    marks = [(s[0], "start")] + clips + [(s[-1], "end")]
    x = cable.positions
    length = float(s[-1] - s[0]) or 1.0
    motion = np.ptp(x, axis=0).max(axis=1) if x.shape[0] > 1 else np.zeros(s.size)
    mid = 0.5 * (s[1:] + s[:-1])
    out = []
    for (a, na), (b, nb) in zip(marks[:-1], marks[1:], strict=True):
        tol = 1e-9 * length
        nodes = np.flatnonzero((s > a + tol) & (s < b - tol))
        edges = np.flatnonzero((mid > a) & (mid < b))
        if nodes.size == 0 and edges.size == 0:
            continue
        moves = bool(nodes.size and motion[nodes].max() > MOVING * length)
        out.append(Span(f"{na} → {nb}", nodes, edges, moves))
    return out
