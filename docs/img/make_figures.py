"""Draw the documentation's figures from the code as it is: ``python docs/img/make_figures.py``.

* ``paper_scene.png``: the proposed trajectories SP -> A..D on the reconstructed paper
  scene (left), and SP -> D with the chapter's methods and the proposed curve inside its
  corridor (right).
* ``diagonal_passage.png``: a 30-degree staircase passage of free width ``2 r + 1`` cells:
  the box corridor (left; its fit fails) and the polygon corridor with the certified curve
  (right).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

import astar  # noqa: E402
import trajopt  # noqa: E402
from trajopt.analysis.plotting import plot_map, plot_paths  # noqa: E402


def paper_scene() -> None:
    scene = trajopt.scenes.paper()
    robot = trajopt.Robot(radius=scene.robot_radius)
    planner = trajopt.Planner(scene.grid, robot)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 6))
    trajs = {n: planner.plan(scene.start, scene.goal(n)) for n in scene.target_names}
    plot_paths(
        scene.grid,
        {f"SP -> {n}: {t.duration:.2f} s": t.path for n, t in trajs.items()},
        inflated=planner.inflated_grid,
        start=scene.start,
        goals={n: scene.goal(n) for n in scene.target_names},
        ax=ax0,
    )
    ax0.set_title("proposed: SP to A-D (travel times)")
    table = trajopt.compare(
        scene.grid,
        scene.start,
        scene.goal("D"),
        robot_radius=scene.robot_radius,
        w_cells=scene.w_cells,
    )
    paths = {k: v for k, v in table.paths.items() if v is not None}
    plot_paths(
        scene.grid,
        paths,
        inflated=planner.inflated_grid,
        corridor=trajs["D"].steps.corridor,
        start=scene.start,
        goals={"D": scene.goal("D")},
        ax=ax1,
    )
    ax1.set_title("SP to D: the chapter's methods and the proposed curve in its corridor")
    fig.tight_layout()
    fig.savefig(HERE / "paper_scene.png", dpi=80)
    plt.close(fig)


def diagonal_passage() -> None:
    res, r_cells, n, angle = 0.05, 2.5, 60, 30.0
    radius = r_cells * res
    th = math.radians(angle)
    iy, ix = np.mgrid[0:n, 0:n]
    ds = np.array(
        [
            -math.sin(th) * (ix + cx - n / 2) + math.cos(th) * (iy + cy - n / 2)
            for cx, cy in ((0, 0), (1, 0), (0, 1), (1, 1))
        ]
    )
    h = (2 * r_cells + 1) / 2
    occ = np.all(ds >= h, axis=0) | np.all(ds <= -h, axis=0)
    grid = astar.OccupancyGrid(occ, res)
    robot = trajopt.Robot(radius=radius)
    infl = astar.inflate(grid, radius, metric="square", outside_occupied=True)
    ys, xs = np.nonzero(~infl.occupied)
    proj = (xs + 0.5 - 30) * math.cos(th) + (ys + 0.5 - 30) * math.sin(th)
    ia, ib = int(np.argmin(np.abs(proj + 20))), int(np.argmin(np.abs(proj - 20)))
    p0 = grid.cell_to_world(np.array([xs[ia], ys[ia]]))
    p1 = grid.cell_to_world(np.array([xs[ib], ys[ib]]))
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 6))
    path = astar.find_path(
        infl,
        (int(xs[ia]), int(ys[ia])),
        (int(xs[ib]), int(ys[ib])),
        cost=astar.clearance_cost(grid, radius, outside_occupied=True),
    )
    boxes = trajopt.build_corridor(infl, path, radius=radius, raw_grid=grid)
    plot_map(grid, inflated=infl, corridor=boxes, ax=ax0)
    cells = grid.cell_to_world(np.asarray(path.cells))
    ax0.plot(cells[:, 0], cells[:, 1], ".", ms=3, color="tab:red", label="A* cells")
    try:
        trajopt.plan(grid, p0, p1, robot, corridor="boxes")
        ax0.set_title(f"boxes ({len(boxes)})")
    except trajopt.SmoothingError:
        ax0.set_title(f"boxes ({len(boxes)}): no certified curve")
    ax0.legend(loc="upper left")
    traj = trajopt.plan(grid, p0, p1, robot)
    corr = traj.steps.corridor
    plot_map(grid, inflated=infl, corridor=corr, ax=ax1)
    xy = traj.path(np.linspace(*traj.path.domain, 400))
    ax1.plot(
        xy[:, 0], xy[:, 1], color="tab:blue", lw=2, label=f"certified curve, {traj.duration:.2f} s"
    )
    ax1.set_title(f"polygons ({len(corr.regions)})")
    ax1.legend(loc="upper left")
    for ax in (ax0, ax1):
        ax.set_xlim(0.4, 2.6)
        ax.set_ylim(0.5, 2.3)
    fig.tight_layout()
    fig.savefig(HERE / "diagonal_passage.png", dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    paper_scene()
    diagonal_passage()
