"""Batch runs over Moving AI scenarios for ``trajopt bench`` (one scenario per call, so
that a process pool gives the same results as a serial run)."""

from __future__ import annotations

import functools
import math
import time
from typing import Any

import numpy as np

__all__ = ["run_scenario", "select_scenarios", "summarize"]


def select_scenarios(scenarios: list[Any], limit: int) -> list[Any]:
    """``limit`` scenarios evenly spread over the list (which is sorted by bucket), always
    including the first and the last (longest bucket). Deterministic."""
    n = len(scenarios)
    if limit >= n:
        return list(scenarios)
    idx = np.unique(np.round(np.linspace(0, n - 1, limit)).astype(int))
    return [scenarios[i] for i in idx]


@functools.lru_cache(maxsize=4)
def _planner(map_path: str, radius_cells: float, fallback: str | None = None):
    import astar
    from trajopt.pipeline import Planner
    from trajopt.robot import Robot

    grid = astar.load_map(map_path)
    robot = Robot(radius=radius_cells * grid.resolution)
    return Planner(grid, robot, fallback=fallback)  # type: ignore[arg-type]


def run_scenario(
    map_path: str, radius_cells: float, scenario: Any, *, fallback: str | None = None
) -> dict[str, Any]:
    """Plan one scenario with the proposed method and score a plain B-spline fit of the
    same A* path. Returns a flat dict of outcomes and metrics (never raises for planning
    failures: they are recorded as ``outcome``). With ``fallback="stop_and_turn"`` the
    planner may return the stop-and-turn fallback; the record then has ``fallback=True``."""
    import astar
    from trajopt import fits
    from trajopt.errors import TrajoptError
    from trajopt.metrics import path_metrics

    planner = _planner(map_path, radius_cells, fallback)
    grid = planner.grid
    start = grid.cell_to_world(scenario.start)
    goal = grid.cell_to_world(scenario.goal)
    rec: dict[str, Any] = {
        "bucket": scenario.bucket,
        "start": tuple(scenario.start),
        "goal": tuple(scenario.goal),
    }
    t0 = time.perf_counter()
    path = None
    try:
        traj = planner.plan(start, goal)
    except (TrajoptError, astar.AstarError) as exc:
        rec["outcome"] = type(exc).__name__
        rec["time_s"] = time.perf_counter() - t0
    else:
        rec["outcome"] = "ok"
        if fallback is not None:
            rec["fallback"] = bool(traj.stats.get("fallback"))
        rec["time_s"] = traj.stats["stages_s"]["total"]
        rec["smooth_s"] = traj.stats["stages_s"]["smooth"]
        rec["duration_s"] = traj.duration
        path = traj.steps.grid_path
        ref = path.to_world(grid)
        m = path_metrics(
            traj.path,
            grid=grid,
            reference=ref,
            radius=planner.robot.radius,
            sample_spacing=0.05 * grid.resolution,
            border_occupied=True,
        )
        rec["collision"] = bool(m.collision)
        rec["clearance_margin_m"] = m.min_clearance_m - planner.robot.radius
        rec["hausdorff_m"] = m.hausdorff_m
        rec["max_curvature_1pm"] = m.max_curvature_1pm
        rec["length_ratio"] = m.length_ratio
    if path is None:
        try:
            path = astar.find_path(
                planner.inflated_grid,
                tuple(scenario.start),
                tuple(scenario.goal),
                cost=planner.search_cost,
            )
        except astar.AstarError:
            return rec
    ref = path.to_world(grid)
    if len(ref) >= 8:
        n_ctrl = int(min(max(6, len(ref) // 4), len(ref) - 1))
        plain = fits.fit_bspline(ref, degree=3, n_ctrl=n_ctrl, parameterization="chord")
        pm = path_metrics(
            plain,
            grid=grid,
            reference=ref,
            radius=planner.robot.radius,
            sample_spacing=0.05 * grid.resolution,
            border_occupied=True,
        )
        rec["plain_collision"] = bool(pm.collision)
        rec["plain_hausdorff_m"] = pm.hausdorff_m
    return rec


def summarize(results: list[dict[str, Any]]) -> str:
    """A text summary of :func:`run_scenario` records."""
    n = len(results)
    ok = [r for r in results if r.get("outcome") == "ok"]
    fails: dict[str, int] = {}
    for r in results:
        if r.get("outcome") != "ok":
            fails[r["outcome"]] = fails.get(r["outcome"], 0) + 1

    def med(key: str, rows: list[dict[str, Any]], scale: float = 1.0) -> str:
        vals = [r[key] * scale for r in rows if key in r and math.isfinite(r[key])]
        return f"{np.median(vals):.4g}" if vals else "n/a"

    plain = [r for r in results if "plain_collision" in r]
    lines = [
        f"scenarios                      {n}",
        f"proposed: success              {len(ok)}/{n} ({100 * len(ok) / max(n, 1):.1f}%)",
    ]
    if any("fallback" in r for r in ok):
        fb = sum(bool(r.get("fallback")) for r in ok)
        lines.append(f"proposed: of which fallback    {fb} (stop and turn)")
    lines += [
        f"proposed: failures             {fails or 'none'}",
        f"proposed: collisions           {sum(r['collision'] for r in ok)}",
        f"proposed: median plan time     {med('time_s', ok, 1e3)} ms",
        f"proposed: median smooth time   {med('smooth_s', ok, 1e3)} ms",
        f"proposed: median duration      {med('duration_s', ok)} s",
        f"proposed: median max curvature {med('max_curvature_1pm', ok)} 1/m",
        f"proposed: median Hausdorff     {med('hausdorff_m', ok)} m",
        f"proposed: median margin        {med('clearance_margin_m', ok)} m (clearance - radius)",
        f"plain B-spline: collisions     {sum(r['plain_collision'] for r in plain)}/{len(plain)}",
        f"plain B-spline: median Hausd.  {med('plain_hausdorff_m', plain)} m",
    ]
    return "\n".join(lines)
