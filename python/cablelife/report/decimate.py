"""What the report draws is decimated: a plot line never needs more points than the screen has
pixels. Min–max decimation keeps every peak (the extremes of each bucket, in time order), so a
decimated line looks the same as the full one; arrays go to the page as float32."""

from __future__ import annotations

import numpy as np

#: Points per line at most (two per bucket: 500 buckets, one per ~2 pixels of a wide plot).
MAX_POINTS = 1000


def minmax(x: np.ndarray, y: np.ndarray, max_points: int = MAX_POINTS):
    """(x, y) reduced to at most ``max_points`` points: per bucket of consecutive samples its
    minimum and maximum in their order (a bucket of NaN stays a gap)."""
    x, y = np.asarray(x), np.asarray(y, dtype=float)
    n = y.size
    if n <= max_points or x.shape != y.shape:
        return x, y
    per = -(-n // (max_points // 2))
    buckets = -(-n // per)
    pad = np.full(buckets * per, np.nan)
    pad[:n] = y
    b = pad.reshape(buckets, per)
    empty = np.all(np.isnan(b), axis=1)
    filled = np.where(np.isnan(b), np.inf, b)
    i = np.argmin(filled, axis=1)
    j = np.argmax(np.where(np.isnan(b), -np.inf, b), axis=1)
    first, second = np.minimum(i, j), np.maximum(i, j)
    k = np.stack([first, second], axis=1) + (np.arange(buckets) * per)[:, None]
    k[empty] = (np.arange(buckets) * per)[empty, None]
    k = np.unique(np.minimum(k.ravel(), n - 1))
    return x[k], y[k]


def nice_range(y: np.ndarray) -> list[float] | None:
    """An axis range for a (nearly) constant series, whose automatic range would be a
    round-off-sized interval labelled with 14-digit ticks; None when the series varies."""
    y = np.asarray(y, dtype=float)
    y = y[np.isfinite(y)]
    if y.size == 0:
        return None
    lo, hi = float(y.min()), float(y.max())
    scale = max(abs(lo), abs(hi))
    if hi - lo > 1e-6 * scale and hi - lo > 0:
        return None
    mid = 0.5 * (lo + hi)
    half = 0.1 * abs(mid) if mid != 0 else 1.0
    return [mid - half, mid + half]


def typed(v):
    """A numpy array of a plotly typed-array dict ({dtype, bdata[, shape]}), else ``v``."""
    import base64

    if isinstance(v, dict) and "bdata" in v and "dtype" in v:
        a = np.frombuffer(base64.b64decode(v["bdata"]), dtype=v["dtype"])
        if "shape" in v:
            a = a.reshape([int(n) for n in str(v["shape"]).split(",")])
        return a
    return v


def _typed_dict(a: np.ndarray) -> dict:
    import base64

    d = {"dtype": a.dtype.str.lstrip("<|"), "bdata": base64.b64encode(a.tobytes()).decode()}
    if a.ndim > 1:
        d["shape"] = ", ".join(map(str, a.shape))
    return d


def compact(obj):
    """A figure dict with float64 arrays (numpy or plotly's typed-array dicts) as float32
    (half the page; 7 significant digits) and int64 arrays (mesh faces) as int32."""
    a = typed(obj)
    if isinstance(a, np.ndarray):
        if a.dtype.kind not in "fiub":  # objects, strings: plain lists (no typed array)
            return [compact(v) for v in a.tolist()]
        if a.dtype == np.float64:
            a = a.astype(np.float32)
        elif a.dtype == np.int64 and (a.size == 0 or np.abs(a).max() < 2**31):
            a = a.astype(np.int32)
        return _typed_dict(np.ascontiguousarray(a))
    if isinstance(obj, dict):
        return {k: compact(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple) and obj and isinstance(obj[0], dict | list | np.ndarray):
        return [compact(v) for v in obj]
    return obj
