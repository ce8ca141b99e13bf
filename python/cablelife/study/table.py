"""The study's summary table (CSV and Parquet) and its plot of damage over the parameters."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from cablelife.atomic import atomic_path

#: Columns first in the table (those present), then the parameters, then everything else.
_LEADING = ["variant", "status", "rank", "max_damage", "ratio_to_best"]
_TRAILING = ["warnings", "error", "stage", "fingerprint", "skipped"]


def summary_frame(rows: list[dict], parameters: list[str]) -> pd.DataFrame:
    """One row per variant, ranked by max damage (1 = least damage) among finished ones."""
    frame = pd.DataFrame(rows)
    if "warnings" in frame:
        frame["warnings"] = frame["warnings"].map(
            lambda w: "; ".join(w) if isinstance(w, list) else ("" if w is None else str(w))
        )
    if "max_damage" not in frame:
        frame["max_damage"] = np.nan
    ok = frame["status"].eq("ok") & frame["max_damage"].notna()
    frame["rank"] = pd.Series(pd.NA, index=frame.index, dtype="Int64")
    frame.loc[ok, "rank"] = frame.loc[ok, "max_damage"].rank(method="min").astype("Int64")
    best = frame.loc[ok, "max_damage"].min() if ok.any() else math.nan
    frame["ratio_to_best"] = frame["max_damage"] / best if best and best > 0 else np.nan
    lead = [c for c in _LEADING if c in frame]
    params = [p for p in parameters if p in frame and p not in lead]
    trail = [c for c in _TRAILING if c in frame]
    middle = [c for c in frame.columns if c not in lead + params + trail]
    frame = frame[lead + params + middle + trail]
    return frame.sort_values(["rank", "variant"], na_position="last").reset_index(drop=True)


def save_tables(frame: pd.DataFrame, out_dir: Path) -> tuple[Path, Path]:
    """``summary.csv`` and ``summary.parquet`` in ``out_dir`` (written atomically)."""
    csv, parquet = out_dir / "summary.csv", out_dir / "summary.parquet"
    with atomic_path(csv) as tmp:
        frame.to_csv(tmp, index=False)
    with atomic_path(parquet) as tmp:
        frame.to_parquet(tmp, index=False)
    return csv, parquet


def plot_damage_over_parameters(
    frame: pd.DataFrame, parameters: list[str], labels: dict[str, str] | None = None
):
    """Max damage over each parameter (one panel each, log scale; ``labels``: axis label with
    unit per parameter); in a grid, variants that share the other parameters' values are
    joined by lines."""
    from cablelife.plots.figure import new_figure

    ok = frame[frame["status"].eq("ok") & frame["max_damage"].gt(0)]
    params = [p for p in parameters if p in frame]
    fig, axes = new_figure(1, max(1, len(params)), width=4.5 * max(1, len(params)), height=3.6)
    for ax, p in zip(axes[0], params, strict=False):
        others = [q for q in params if q != p]
        groups = ok.groupby(others) if others else [((), ok)]
        for key, g in groups:
            g = g.sort_values(p)
            key = key if isinstance(key, tuple) else (key,)
            label = ", ".join(f"{q}={v:g}" for q, v in zip(others, key, strict=False)) or None
            ax.plot(g[p], g["max_damage"], "o-", label=label)
        ax.set_xlabel((labels or {}).get(p, p))
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        if others and len(ok) and ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
    pseudo = "pseudo_damage" not in ok or ok["pseudo_damage"].all()
    axes[0][0].set_ylabel("max pseudo-damage" if pseudo else "max damage")
    return fig
