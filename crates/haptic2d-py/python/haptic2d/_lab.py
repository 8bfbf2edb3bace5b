"""The lab's engines: wall sweeps on any executor, the paper's reproduction, and run logs."""

from __future__ import annotations

import os
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from . import _haptic2d
from ._checks import count, positive

#: Class codes of :func:`sweep_walls`'s ``class`` column.
SWEEP_CLASSES = ("dissipative", "marginal", "gains_energy")


def _log_space(a: float, b: float, n: int) -> List[float]:
    # Same formula as haptic2d_lab::sweep::log_space, so the grid is identical to the CLI's.
    import math

    la, lb = math.log(a), math.log(b)
    return [math.exp(la + (lb - la) * i / (n - 1)) for i in range(n)]


def sweep_task(params: Dict[str, Any]) -> Dict[str, Any]:
    """Runs one sweep task: the grid ``ks x bs`` of one wall law (a picklable dict with keys
    ``model, ks, bs, rate, duration``). Module-level so executors can pickle it."""
    out = _haptic2d.sweep_task(
        params["model"], list(params["ks"]), list(params["bs"]), params["rate"], params["duration"]
    )
    out["model"] = params["model"]
    return out


def sweep_walls(
    models: Optional[Sequence[str]] = None,
    *,
    rate: float = 500.0,
    points: int = 12,
    k_range: Tuple[float, float] = (100.0, 1e5),
    b_range: Tuple[float, float] = (0.01, 100.0),
    duration: float = 10.0,
    executor: Any = None,
) -> Dict[str, np.ndarray]:
    """The Z-width style wall sweep of ``haptic2d sweep walls``: for each wall law, a log-spaced
    ``points x points`` grid of stiffness ``K`` (N/m) and damping (N*s/m: the law's own damping
    parameter for minsky, colgate and paper, the plant damping otherwise), each point a Fig. 4
    harness run of ``duration`` s at ``rate`` Hz, classified from its bounce ratios.

    ``executor`` is anything with ``submit(fn, arg)`` returning a future with ``result()``: a
    ``concurrent.futures`` executor or a Dask ``distributed.Client``. One task per law; each task is
    a picklable dict and returns arrays. ``None`` runs the tasks here, one after the other.

    Returns columns: ``model``, ``k_n_m``, ``damping_n_s_m``, ``damping_kind``, ``separations``,
    ``mean_ratio`` (NaN with no completed contact) and ``class`` (strings of :data:`SWEEP_CLASSES`),
    in the CLI's order (law, then K, then damping).
    """
    valid = _haptic2d.sweep_models()
    models = list(valid if models is None else models)
    for m in models:
        if m not in valid:
            raise ValueError(f"unknown sweep model {m!r}; valid: {', '.join(valid)}")
    rate = positive("rate", rate)
    points = count("points", points, 2)
    if points > 64:
        raise ValueError(f"points must be between 2 and 64, got {points}")
    for name, (a, b) in (("k_range", k_range), ("b_range", b_range)):
        a, b = positive(f"{name}[0]", a), positive(f"{name}[1]", b)
        if not b > a:
            raise ValueError(f"{name} must satisfy 0 < min < max, got {a} ... {b}")
    duration = positive("duration", duration)
    ks = _log_space(float(k_range[0]), float(k_range[1]), points)
    bs = _log_space(float(b_range[0]), float(b_range[1]), points)
    tasks = [dict(model=m, ks=ks, bs=bs, rate=rate, duration=duration) for m in models]
    if executor is None:
        results = [sweep_task(t) for t in tasks]
    else:
        if not callable(getattr(executor, "submit", None)):
            raise TypeError("executor must have submit(fn, *args) (concurrent.futures or dask.distributed.Client)")
        futures = [executor.submit(sweep_task, t) for t in tasks]
        results = [f.result() for f in futures]
    n = points * points
    return {
        "model": np.repeat(np.array([r["model"] for r in results]), n),
        "k_n_m": np.concatenate([r["k_n_m"] for r in results]),
        "damping_n_s_m": np.concatenate([r["damping_n_s_m"] for r in results]),
        "damping_kind": np.repeat(np.array([r["damping_kind"] for r in results]), n),
        "separations": np.concatenate([r["separations"] for r in results]),
        "mean_ratio": np.concatenate([r["mean_ratio"] for r in results]),
        "class": np.array(SWEEP_CLASSES)[np.concatenate([r["class"] for r in results])],
    }


def reproduce(figure: str = "all", out: "str | os.PathLike[str]" = "reproduction") -> Dict[str, Any]:
    """Runs the paper's experiments (``all``, ``fig4``, ``fig5``, ``fig7`` or ``fig8``) as
    ``haptic2d reproduce`` does, writing ``out/<figure>/`` (CSV, SVG, PNG, metrics.json) and
    ``out/REPORT.md``. Returns ``report`` (path), ``seconds`` and per figure ``passed``, ``total``,
    ``comparisons`` and ``failing`` case names."""
    if not isinstance(figure, str):
        raise TypeError("figure must be a str: all, fig4, fig5, fig7 or fig8")
    report, seconds, figs = _haptic2d.reproduce(figure, os.fspath(out))
    return {
        "report": str(report),
        "seconds": seconds,
        "figures": {
            name: {"passed": p, "total": t, "comparisons": c, "failing": list(fl)}
            for (name, p, t, c, fl) in figs
        },
    }


def read_log(path: "str | os.PathLike[str]") -> Dict[str, np.ndarray]:
    """Reads a numeric CSV written by haptic2d (``simulate --out``, ``run --log``, the lab's series)
    into one float64 array per column, by header name. Errors name the file, line and column."""
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as f:
            header = f.readline()
            if not header.strip():
                raise ValueError(f"{path}: empty file (expected a header line of column names)")
            names = [h.strip() for h in header.rstrip("\n").split(",")]
            rows: List[List[float]] = []
            for lineno, line in enumerate(f, start=2):
                if not line.strip():
                    continue
                cells = line.rstrip("\n").split(",")
                if len(cells) != len(names):
                    raise ValueError(
                        f"{path}: line {lineno} has {len(cells)} fields, the header has {len(names)}"
                    )
                try:
                    rows.append([float(c) for c in cells])
                except ValueError:
                    bad = next(i for i, c in enumerate(cells) if not _is_float(c))
                    raise ValueError(
                        f"{path}: line {lineno}, column {names[bad]!r}: {cells[bad]!r} is not a number"
                    ) from None
    except OSError as e:
        raise ValueError(f"cannot read log {path}: {e}") from None
    data = np.array(rows, dtype=np.float64).reshape(len(rows), len(names))
    return {n: np.ascontiguousarray(data[:, i]) for i, n in enumerate(names)}


def _is_float(s: str) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False
