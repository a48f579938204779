"""Summaries and figures of a benchmark dataset (``trajopt bench report DATASET``).

:func:`summary` aggregates the rows per method (vectorised pandas, columns read
selectively, so 10^5 rows take well under a second); :func:`format_summary` prints it;
:func:`figures` writes the distributions (matplotlib, imported there).

Columns of the summary, per method:

* ``queries``: rows; ``feasible``: rows whose reference A* exists (the end points are free
  for the radius and connected); ``success``: rows with a path (``ok``);
  ``success_pct``: of the feasible;
* ``collisions``: successful rows whose path comes closer than the radius to the raw map;
* ``compute_median_ms``, ``compute_p95_ms``: ``runtime_s`` of the successful rows;
* ``length_ratio``: median path length over the reference's;
* ``min_clearance_over_radius``: median of ``min_clearance_m / radius_m`` (>= 1: no
  collision);
* ``max_curvature_x_radius``: median of ``max_curvature_1pm * radius_m``;
* ``max_heading_jump_rad``: median largest heading change between samples;
* ``duration_s``: median duration of the timed trajectories (trajopt's methods).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from trajopt.analysis.bench._dataset import read_dataset

#: Columns the report reads.
REPORT_COLUMNS = (
    "method",
    "ok",
    "failure",
    "collision",
    "runtime_s",
    "length_ratio",
    "min_clearance_m",
    "radius_m",
    "max_curvature_1pm",
    "max_heading_jump_rad",
    "duration_s",
)
_INFEASIBLE_NOTE = "reference A*"


def _frame(data: Any) -> Any:
    import pandas as pd

    if isinstance(data, pd.DataFrame):
        return data
    return read_dataset(data, columns=list(REPORT_COLUMNS) + ["note"])


def summary(data: Any) -> Any:
    """Per-method summary of a dataset (a folder path or a DataFrame of its rows).

    Returns
    -------
    pandas.DataFrame
        Indexed by method (in order of first appearance); columns in the module docstring.
    """
    import pandas as pd

    df = _frame(data)
    infeasible = df["note"].str.startswith(_INFEASIBLE_NOTE) & ~df["ok"]
    d = pd.DataFrame(
        {
            "method": df["method"],
            "feasible": ~infeasible,
            "ok": df["ok"],
            "collision": df["ok"] & df["collision"],
        }
    )
    ok = df["ok"].to_numpy()
    nan = np.nan
    d["runtime_ms"] = np.where(ok, df["runtime_s"] * 1e3, nan)
    d["length_ratio"] = np.where(ok, df["length_ratio"], nan)
    d["clear_r"] = np.where(ok, df["min_clearance_m"] / df["radius_m"], nan)
    d["kappa_r"] = np.where(ok, df["max_curvature_1pm"] * df["radius_m"], nan)
    d["jump"] = np.where(ok, df["max_heading_jump_rad"], nan)
    d["duration"] = np.where(ok, df["duration_s"], nan)
    g = d.groupby("method", sort=False)
    out = pd.DataFrame(
        {
            "queries": g.size(),
            "feasible": g["feasible"].sum(),
            "success": g["ok"].sum(),
        }
    )
    out["success_pct"] = 100.0 * out["success"] / out["feasible"].where(out["feasible"] > 0)
    out["collisions"] = g["collision"].sum()
    out["compute_median_ms"] = g["runtime_ms"].median()
    out["compute_p95_ms"] = g["runtime_ms"].quantile(0.95)
    out["length_ratio"] = g["length_ratio"].median()
    out["min_clearance_over_radius"] = g["clear_r"].median()
    out["max_curvature_x_radius"] = g["kappa_r"].median()
    out["max_heading_jump_rad"] = g["jump"].median()
    out["duration_s"] = g["duration"].median()
    return out


def format_summary(table: Any) -> str:
    """Return the summary as a fixed-width text table (one line per method)."""
    heads = {
        "queries": "queries",
        "feasible": "feasible",
        "success": "success",
        "success_pct": "success %",
        "collisions": "collisions",
        "compute_median_ms": "median ms",
        "compute_p95_ms": "p95 ms",
        "length_ratio": "length ratio",
        "min_clearance_over_radius": "clear/r",
        "max_curvature_x_radius": "kmax*r",
        "max_heading_jump_rad": "max jump rad",
        "duration_s": "duration s",
    }

    counts = ("queries", "feasible", "success", "collisions")

    def fmt(c: str, v: Any) -> str:
        v = float(v)
        if not np.isfinite(v):
            return "-"
        return str(int(v)) if c in counts else f"{v:.4g}"

    rows = [["method", *heads.values()]]
    for method, r in table.iterrows():
        rows.append([str(method), *(fmt(c, r[c]) for c in heads)])
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    lines = [
        "  ".join(
            c.ljust(w) if i == 0 else c.rjust(w)
            for i, (c, w) in enumerate(zip(row, widths, strict=True))
        )
        for row in rows
    ]
    return "\n".join(lines)


def figures(data: Any, out_dir: str | os.PathLike[str]) -> list[Path]:
    """Distribution plots per method (successful rows).

    Compute time, length ratio, clearance / radius, max curvature x radius. Writes
    ``distributions.png`` and ``outcomes.png`` (success, collision and failure counts) into
    ``out_dir``.

    Returns
    -------
    list of Path
        The files written.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    df = _frame(data)
    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    methods = list(dict.fromkeys(df["method"]))
    ok = df[df["ok"]]
    panels = [
        ("compute time (ms, log)", ok["runtime_s"] * 1e3, True),
        ("length / reference length", ok["length_ratio"], False),
        ("min clearance / radius", ok["min_clearance_m"] / ok["radius_m"], False),
        ("max curvature x radius (log)", ok["max_curvature_1pm"] * ok["radius_m"], True),
    ]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 0.45 * len(methods) + 2))
    for ax, (title, values, log) in zip(axes, panels, strict=True):
        data_m = []
        for m in methods:
            v = values[ok["method"] == m].to_numpy(dtype=float)
            v = v[np.isfinite(v) & ((v > 0) if log else True)]
            data_m.append(v if len(v) else np.array([np.nan]))
        ax.boxplot(data_m, orientation="horizontal", showfliers=True, flierprops={"markersize": 2})
        ax.set_yticks(range(1, len(methods) + 1), methods if ax is axes[0] else [""] * len(methods))
        ax.set_title(title)
        if log:
            ax.set_xscale("log")
        if "clearance" in title:
            ax.axvline(1.0, color="r", lw=0.8)
    fig.tight_layout()
    files = [d / "distributions.png"]
    fig.savefig(files[0], dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 0.45 * len(methods) + 1.5))
    flags = df[["method", "ok"]].assign(hit=df["ok"] & df["collision"])
    g = flags.groupby("method", sort=False)
    coll = g["hit"].sum().reindex(methods)
    succ = g["ok"].sum().reindex(methods) - coll
    fail = (g.size() - g["ok"].sum()).reindex(methods)
    y = np.arange(len(methods))
    ax.barh(y, succ, color="tab:green", label="path, no collision")
    ax.barh(y, coll, left=succ, color="tab:red", label="path with collision")
    ax.barh(y, fail, left=succ + coll, color="tab:gray", label="no path")
    ax.set_yticks(y, methods)
    ax.invert_yaxis()
    ax.set_xlabel("queries")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    files.append(d / "outcomes.png")
    fig.savefig(files[1], dpi=110)
    plt.close(fig)
    return files


def report(
    dataset: str | os.PathLike[str], figures_dir: str | os.PathLike[str] | None = None
) -> str:
    """Read a dataset, return the summary table as text.

    Read a dataset, return the summary table as text, and write the figures when ``figures_dir``
    is given.
    """
    df = _frame(dataset)
    text = format_summary(summary(df))
    if figures_dir is not None:
        figures(df, figures_dir)
    return text
