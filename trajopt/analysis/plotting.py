"""Figures: the map with avoidance area, corridor and paths.

Figures: the map with avoidance area, corridor and paths (the chapter's Figures 7-11), the
robot's footprint (or disc) at regular times along a timed trajectory, and time plots of a
trajectory with its limits.

matplotlib is imported inside each function, so ``import trajopt`` never pulls it in.
Every function returns the matplotlib objects it drew on, for further styling.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.geometry._curve import ParametricCurve

__all__ = ["plot_map", "plot_paths", "plot_footprints", "plot_profiles", "path_points"]

#: Most poses :func:`plot_footprints` draws; a smaller ``every_s`` is refused.
MAX_FOOTPRINTS = 10_000

_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")


def path_points(path: Any, spacing: float | None = None) -> np.ndarray:
    """Points (m), shape (m, 2), of a curve, a timed trajectory or an (m, 2) array.

    Parameters
    ----------
    path : ParametricCurve, timed trajectory or array_like, shape (m, 2)
        Curves are sampled every ``spacing`` metres (default: 400 samples); timed
        trajectories (``Trajectory``, ``TrajectoryChain``, ...) every 10 ms.
    spacing : float, optional
        Sample spacing in metres for curves.
    """
    if isinstance(path, ParametricCurve):
        return path.sample(ds=spacing).xy if spacing else path.sample(400).xy
    if hasattr(path, "sample_uniform"):
        smp = path.sample_uniform(0.01)
        return np.column_stack([smp.x, smp.y])
    pts = np.asarray(path, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"path must be a curve or an (m, 2) array, got shape {pts.shape}")
    return pts


def plot_map(
    grid: OccupancyGrid,
    *,
    inflated: OccupancyGrid | None = None,
    corridor: Any = None,
    ax: Any = None,
) -> tuple[Any, Any]:
    """Draw the raw obstacles (black), the avoidance area (grey) and corridor boxes.

    Parameters
    ----------
    grid : OccupancyGrid
        Raw map.
    inflated : OccupancyGrid, optional
        Inflated grid of the same shape; cells blocked only by inflation are shaded grey.
    corridor : PolygonCorridor or Corridor, optional
        Drawn as outlines: a polygon corridor's ``regions`` (each with ``vertices``, m), or
        a box corridor's ``boxes`` (each with ``xmin, xmax, ymin, ymax``, m; a 45-degree
        bridge by its ``vertices``).
    ax : matplotlib Axes, optional

    Returns
    -------
    (Figure, Axes)
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon, Rectangle

    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 6))
    else:
        fig = ax.figure
    img = np.zeros(grid.shape, dtype=float)
    if inflated is not None:
        if inflated.shape != grid.shape:
            raise ValueError(
                f"inflated grid shape {inflated.shape} differs from the map's {grid.shape}"
            )
        img[inflated.occupied] = 0.35
    img[grid.occupied] = 1.0
    ox, oy = grid.origin
    extent = (ox, ox + grid.width, oy, oy + grid.height)
    ax.imshow(
        img, origin="lower", extent=extent, cmap="Greys", vmin=0, vmax=1, interpolation="nearest"
    )
    if corridor is not None:
        style = dict(fill=False, lw=0.7, ec="tab:cyan", alpha=0.8)
        regions = getattr(corridor, "regions", None)
        for reg in regions if regions is not None else corridor.boxes:
            if regions is None and not getattr(reg, "is_diagonal", False):
                ax.add_patch(
                    Rectangle(
                        (reg.xmin, reg.ymin), reg.xmax - reg.xmin, reg.ymax - reg.ymin, **style
                    )
                )
            else:
                v = reg.vertices() if callable(reg.vertices) else reg.vertices
                ax.add_patch(Polygon(np.asarray(v), closed=True, **style))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    return fig, ax


def plot_paths(
    grid: OccupancyGrid,
    paths: Mapping[str, Any],
    *,
    inflated: OccupancyGrid | None = None,
    corridor: Any = None,
    start: Sequence[float] | None = None,
    goals: Mapping[str, Sequence[float]] | None = None,
    zoom: tuple[float, float, float, float] | None = None,
    ax: Any = None,
) -> tuple[Any, Any]:
    """Return the map with every method's path (the chapter's Figures 7-10; with ``zoom``, 11).

    Parameters
    ----------
    grid : OccupancyGrid
        Raw map.
    paths : mapping of str to curve or array_like (m, 2)
        Method name -> path in metres.
    inflated, corridor : optional
        See :func:`plot_map`.
    start : (x, y), optional
        Start point (m), drawn as a square marker.
    goals : mapping of str to (x, y), optional
        Named targets (m).
    zoom : (xmin, xmax, ymin, ymax), optional
        Axis limits in metres for a zoomed view.
    ax : matplotlib Axes, optional

    Returns
    -------
    (Figure, Axes)
    """
    fig, ax = plot_map(grid, inflated=inflated, corridor=corridor, ax=ax)
    for i, (name, path) in enumerate(paths.items()):
        pts = path_points(path)
        style = "-" if isinstance(path, ParametricCurve) else "--"
        ax.plot(pts[:, 0], pts[:, 1], style, color=_COLORS[i % len(_COLORS)], lw=1.4, label=name)
    if start is not None:
        ax.plot(*start, "ks", ms=7, label="start")
    for name, g in (goals or {}).items():
        ax.plot(*g, "r*", ms=10)
        ax.annotate(name, g, textcoords="offset points", xytext=(4, 4))
    if zoom is not None:
        ax.set_xlim(zoom[0], zoom[1])
        ax.set_ylim(zoom[2], zoom[3])
    ax.legend(loc="best", fontsize="small")
    return fig, ax


def plot_footprints(
    ax: Any,
    trajectory: Any,
    robot: Any = None,
    *,
    every_s: float = 1.0,
    color: str = "tab:purple",
    label: str | None = None,
) -> list[Any]:
    """Draw the robot's outline at regular times along a timed trajectory.

    A robot with a footprint is drawn as its polygon at the sampled pose ``(x, y, theta)``;
    a disc robot as a circle of ``robot.radius``. Outlines only, thin and light, so the
    path and the map stay visible. The poses are at ``t = 0, every_s, 2 every_s, ...``
    and at the end time ``duration``.

    Parameters
    ----------
    ax : matplotlib Axes
        Axes in metres (e.g. from :func:`plot_paths`).
    trajectory : Trajectory or StopAndTurnTrajectory
        Anything with ``duration`` (s) and ``sample(t)`` returning named arrays ``x, y``
        (m) and ``theta`` (rad).
    robot : Robot, optional
        Shape to draw: its ``footprint`` (robot frame, m) when set, else a disc of its
        ``radius`` (m). Default: ``trajectory.robot``.
    every_s : float
        Time between drawn poses (s, finite, > 0).
    color : str
        Outline colour (any matplotlib colour).
    label : str, optional
        Legend label of the first outline (default ``"footprint"`` or ``"robot disc"``).

    Returns
    -------
    list of matplotlib patches
        One ``Polygon`` or ``Circle`` per pose, in time order.

    Raises
    ------
    ValueError
        ``every_s`` not finite and > 0, or giving more than :data:`MAX_FOOTPRINTS` poses;
        no robot given and the trajectory has none; a non-finite duration.
    """
    from matplotlib.patches import Circle, Polygon

    robot = robot if robot is not None else getattr(trajectory, "robot", None)
    if robot is None:
        raise ValueError("robot is required when the trajectory has no robot attribute")
    try:
        step = float(every_s)
    except (TypeError, ValueError):
        raise ValueError(f"every_s must be a number of seconds > 0, got {every_s!r}") from None
    if not (np.isfinite(step) and step > 0.0):
        raise ValueError(f"every_s must be finite and > 0 (s), got {every_s!r}")
    duration = float(trajectory.duration)
    if not (np.isfinite(duration) and duration >= 0.0):
        raise ValueError(f"trajectory duration must be finite and >= 0 (s), got {duration!r}")
    if duration / step + 1 > MAX_FOOTPRINTS:
        raise ValueError(
            f"every_s={every_s!r} s gives {int(duration / step) + 2} poses over "
            f"{duration:.3g} s, more than {MAX_FOOTPRINTS}; use a larger every_s"
        )
    t = step * np.arange(int(np.floor(duration / step + 1e-9)) + 1)
    t = t[t < duration - 1e-9 * max(1.0, duration)]
    t = np.append(t, duration)
    smp = trajectory.sample(t)
    x, y, theta = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (smp.x, smp.y, smp.theta))
    footprint = getattr(robot, "footprint", None)
    if label is None:
        label = "footprint" if footprint is not None else "robot disc"
    style = dict(fill=False, lw=0.6, ec=color, alpha=0.55, zorder=2)
    patches = []
    for i in range(t.shape[0]):
        kw = dict(style, label=label if i == 0 else None)
        if footprint is not None:
            patch = Polygon(footprint.at(x[i], y[i], theta[i]), closed=True, **kw)
        else:
            patch = Circle((x[i], y[i]), float(robot.radius), **kw)
        patches.append(ax.add_patch(patch))
    return patches


def plot_profiles(trajectory: Any, robot: Any = None, *, n: int = 1000) -> tuple[Any, Any]:
    """Speed, acceleration, jerk, heading and yaw rate over time, with limits dashed.

    Parameters
    ----------
    trajectory : Trajectory
        Anything with ``duration`` (s) and ``sample(t)`` returning named arrays
        ``t, v, a, jerk, theta, omega``.
    robot : Robot, optional
        Limits to draw (default: ``trajectory.robot`` when present).
    n : int
        Number of samples.

    Returns
    -------
    (Figure, ndarray of Axes), five rows.
    """
    import matplotlib.pyplot as plt

    robot = robot if robot is not None else getattr(trajectory, "robot", None)
    t = np.linspace(0.0, trajectory.duration, n)
    smp = trajectory.sample(t)
    rows = [
        ("v", "speed [m/s]", "v_max"),
        ("a", "acceleration [m/s²]", "a_max"),
        ("jerk", "jerk [m/s³]", "j_max"),
        ("theta", "heading [rad]", None),
        ("omega", "yaw rate [rad/s]", "omega_max"),
    ]
    fig, axes = plt.subplots(len(rows), 1, figsize=(7, 9), sharex=True)
    for ax, (key, label, limit) in zip(axes, rows, strict=True):
        ax.plot(smp.t if hasattr(smp, "t") else t, getattr(smp, key), lw=1.2)
        if robot is not None and limit is not None:
            lim = getattr(robot, limit)
            ax.axhline(lim, ls="--", c="tab:red", lw=0.8)
            if key != "v":
                ax.axhline(-lim, ls="--", c="tab:red", lw=0.8)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    return fig, axes
