"""Draw the documentation's figures from the code as it is: ``python docs/img/make_figures.py``.

* ``paper_scene.png``: the proposed trajectories SP -> A..D on the reconstructed paper
  scene (left), and SP -> D with the chapter's methods and the proposed curve inside its
  corridor (right).
* ``diagonal_passage.png``: a 30-degree staircase passage of free width ``2 r + 1`` cells:
  the box corridor (left; its fit fails) and the polygon corridor with the certified curve
  (right).
* ``costmap_weights.png``: one query on a Nav2-style inflation costmap at ``costmap_weight``
  0, 1, 3 and 10: the A* path and the smoothed trajectory over the graded cost.
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


def costmap_weights() -> None:
    from scipy import ndimage

    res = 0.05
    occ = np.zeros((80, 140), dtype=bool)  # 7 m x 4 m
    occ[[0, -1], :] = True
    occ[:, [0, -1]] = True
    occ[0:34, 46:50] = True  # a wall from the bottom with a gap above it
    occ[46:80, 92:96] = True  # and one from the top
    occ[20:30, 110:125] = True  # a table
    d = ndimage.distance_transform_edt(~occ) * res
    r_ins, r_inf, k = 0.15, 0.6, 3.0
    values = np.zeros(occ.shape, np.uint8)
    band = (d > r_ins) & (d <= r_inf)
    values[band] = np.floor(252.0 * np.exp(-k * (d[band] - r_ins))).astype(np.uint8)
    values[d <= r_ins] = 253
    values[occ] = 254
    cm = astar.from_costmap(values, res, convention="costmap_2d")
    robot = trajopt.Robot(radius=r_ins)
    start, goal = (0.6, 0.6), (6.4, 3.4)
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.4))
    for ax, w in zip(axes.ravel(), (0.0, 1.0, 3.0, 10.0), strict=True):
        traj = trajopt.Planner(cm, robot, search="costmap", costmap_weight=w).plan(start, goal)
        ax.imshow(
            np.where(occ, np.nan, cm.cost),
            origin="lower",
            extent=(0, occ.shape[1] * res, 0, occ.shape[0] * res),
            cmap="Oranges",
            vmin=0,
            vmax=1,
        )
        ax.imshow(
            np.where(occ, 1.0, np.nan),
            origin="lower",
            extent=(0, occ.shape[1] * res, 0, occ.shape[0] * res),
            cmap="Greys",
            vmin=0,
            vmax=1,
        )
        cells = np.asarray(traj.steps.grid_path.cells, dtype=float)
        ax.plot(*((cells + 0.5) * res).T, "--", color="tab:blue", lw=1, label="A* path")
        sp = traj.steps.smooth_path
        a, b = sp.curve.domain
        xy = sp.curve(np.linspace(a, b, 2000))
        ax.plot(*xy.T, color="tab:green", lw=2, label="trajectory")
        seg = np.linalg.norm(np.diff(xy, axis=0), axis=1)
        mid = np.floor(0.5 * (xy[1:] + xy[:-1]) / res).astype(int)
        mean = float(np.sum(cm.cost[mid[:, 1], mid[:, 0]] * seg) / np.sum(seg))
        ax.set_title(f"costmap_weight {w:g}: mean cost {mean:.3f}, {traj.duration:.2f} s")
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
    axes[0, 0].legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(HERE / "costmap_weights.png", dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    paper_scene()
    diagonal_passage()
    costmap_weights()
