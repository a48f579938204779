"""Figures: the map with avoidance area, corridor and paths; moving obstacles over time.

Figures: the map with avoidance area, corridor and paths (the chapter's Figures 7-11), the
robot's footprint (or disc) at regular times along a timed trajectory, its heading as
arrows with the turns in place marked, and time plots of a trajectory with its limits.
With predicted moving obstacles: :func:`animate` (the robot and the movers over time, as
an mp4, a gif or an HTML player; :mod:`trajopt.analysis.animation`) and :func:`plot_st`
(the movers' forbidden regions of the ``(s, t)`` plane and the chosen profile ``s(t)``;
:mod:`trajopt.analysis.st_diagram`).

matplotlib is imported inside each function, so ``import trajopt`` never pulls it in.
Every function returns the matplotlib objects it drew on, for further styling.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from astar.grid import OccupancyGrid
from trajopt.analysis.animation import Animation, animate_on
from trajopt.analysis.st_diagram import ST_MAX_NODES, plot_st
from trajopt.errors import InvalidInputError
from trajopt.geometry import ParametricCurve
from trajopt.moving import MovingObstacle, check_movers

__all__ = [
    "plot_map",
    "plot_paths",
    "plot_footprints",
    "plot_headings",
    "plot_profiles",
    "path_points",
    "animate",
    "plot_st",
    "ST_MAX_NODES",
]

#: Most poses :func:`plot_footprints` draws; a smaller ``every_s`` is refused.
MAX_FOOTPRINTS = 10_000
#: Most heading arrows :func:`plot_headings` draws.
MAX_ARROWS = 10_000

_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")


def path_points(path: Any, spacing: float | None = None) -> np.ndarray:
    """Points (m), shape (m, 2), of a curve, a timed trajectory or an (m, 2) array.

    Parameters
    ----------
    path : ParametricCurve, timed trajectory or array_like, shape (m, 2)
        Curves are sampled every ``spacing`` metres (default: 400 samples); timed
        trajectories (``Trajectory``, ``TrajectoryChain``, anything with ``duration`` and
        ``sample``) every 10 ms.
    spacing : float, optional
        Sample spacing in metres for curves.
    """
    if isinstance(path, ParametricCurve):
        return path.sample(ds=spacing).xy if spacing else path.sample(400).xy
    if hasattr(path, "sample_uniform"):
        smp = path.sample_uniform(0.01)
        return np.column_stack([smp.x, smp.y])
    if _is_timed(path):
        duration = float(path.duration)
        n = int(np.clip(np.ceil(duration / 0.01), 1, 1_000_000)) + 1
        smp = path.sample(np.linspace(0.0, duration, n))
        return np.column_stack([np.asarray(smp.x, dtype=float), np.asarray(smp.y, dtype=float)])
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
    arrows: int = 0,
    ax: Any = None,
) -> tuple[Any, Any]:
    """Return the map with every method's path (the chapter's Figures 7-10; with ``zoom``, 11).

    Parameters
    ----------
    grid : OccupancyGrid
        Raw map.
    paths : mapping of str to curve, timed trajectory or array_like (m, 2)
        Method name -> path in metres. A timed trajectory (``Trajectory``,
        ``TrajectoryChain``, ...) is drawn along the positions it passes (solid, as curves;
        polylines dashed).
    inflated, corridor : optional
        See :func:`plot_map`.
    start : (x, y), optional
        Start point (m), drawn as a square marker.
    goals : mapping of str to (x, y), optional
        Named targets (m).
    zoom : (xmin, xmax, ymin, ymax), optional
        Axis limits in metres for a zoomed view.
    arrows : int
        Heading arrows per timed trajectory (:func:`plot_headings`: ``theta`` at ``arrows``
        evenly timed samples, both ends included, and its turns in place marked), in the
        trajectory's colour; 0 (default) draws none. Curves and polylines get none.
    ax : matplotlib Axes, optional

    Returns
    -------
    (Figure, Axes)

    Raises
    ------
    ValueError
        ``arrows`` not an integer in ``[0, MAX_ARROWS]``, or a path that is neither a curve,
        a timed trajectory nor an (m, 2) array.
    """
    n_arrows = _arrow_count(arrows)
    fig, ax = plot_map(grid, inflated=inflated, corridor=corridor, ax=ax)
    marked = False  # one legend entry for the turns in place of every trajectory
    for i, (name, path) in enumerate(paths.items()):
        pts = path_points(path)
        timed = _is_timed(path)
        color = _COLORS[i % len(_COLORS)]
        style = "-" if isinstance(path, ParametricCurve) or timed else "--"
        ax.plot(pts[:, 0], pts[:, 1], style, color=color, lw=1.4, label=name)
        if timed and n_arrows:
            _, marks = plot_headings(ax, path, n_arrows, color=color)
            if marks is not None:
                if marked:
                    marks.set_label("_nolegend_")
                marked = True
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


def _is_timed(path: Any) -> bool:
    """Whether ``path`` is a timed trajectory (not a curve, not points)."""
    return (
        not isinstance(path, ParametricCurve)
        and hasattr(path, "duration")
        and callable(getattr(path, "sample", None))
    )


def _arrow_count(arrows: Any) -> int:
    if isinstance(arrows, bool) or not isinstance(arrows, (int, np.integer)):
        raise ValueError(f"arrows must be an integer >= 0, got {arrows!r}")
    if not 0 <= arrows <= MAX_ARROWS:
        raise ValueError(f"arrows must lie in [0, {MAX_ARROWS}], got {arrows!r}")
    return int(arrows)


def plot_headings(
    ax: Any,
    trajectory: Any,
    n: int = 20,
    *,
    length: float | None = None,
    color: str = "tab:blue",
    turns: bool = True,
    label: str | None = None,
) -> tuple[Any, Any]:
    """Draw the heading ``theta`` as arrows at evenly timed samples, and mark the turns in place.

    The arrows point along ``theta`` (for a differential drive the direction of travel, for
    an omnidirectional base its orientation, which may differ from the path's direction).
    A turn in place (the robot stands and yaws: :func:`trajopt.metrics.turns_in_place`) is
    marked by a ring at its spot, annotated with the angle turned.

    Parameters
    ----------
    ax : matplotlib Axes
        Axes in metres (e.g. from :func:`plot_paths`).
    trajectory : Trajectory or TrajectoryChain
        Anything with ``duration`` (s) and ``sample(t)`` returning named arrays ``x, y``
        (m) and ``theta`` (rad); the turns are found from ``v`` (m/s) and ``omega``
        (rad/s), and not marked when the samples lack them.
    n : int
        Number of arrows (>= 1, at most :data:`MAX_ARROWS`), at ``t = k duration / (n - 1)``
        (one arrow at ``t = 0`` when ``n = 1``).
    length : float, optional
        Arrow length (m, finite, > 0); default 6 % of the larger side of the trajectory's
        bounding box (0.1 m for a trajectory that does not move).
    color : str
        Colour of the arrows and the turn marks.
    turns : bool
        Mark the turns in place (default ``True``).
    label : str, optional
        Legend label of the arrows (default none); the turn marks are labelled
        ``"turn in place"``.

    Returns
    -------
    (Quiver, Line2D or None)
        The arrows and the turn marks (``None`` when there is no turn or ``turns`` is off).

    Raises
    ------
    ValueError
        ``n`` not an integer in ``[1, MAX_ARROWS]``, a bad ``length`` or a non-finite
        duration.
    """
    count = _arrow_count(n)
    if count < 1:
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    duration = float(trajectory.duration)
    if not (np.isfinite(duration) and duration >= 0.0):
        raise ValueError(f"trajectory duration must be finite and >= 0 (s), got {duration!r}")
    t = np.linspace(0.0, duration, count)
    smp = trajectory.sample(t)
    x, y, theta = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (smp.x, smp.y, smp.theta))
    if length is None:
        pts = path_points(trajectory)
        extent = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
        arrow = 0.06 * extent if extent > 0.0 else 0.1
    else:
        try:
            arrow = float(length)
        except (TypeError, ValueError):
            raise ValueError(f"length must be a number of metres > 0, got {length!r}") from None
        if not (np.isfinite(arrow) and arrow > 0.0):
            raise ValueError(f"length must be finite and > 0 (m), got {length!r}")
    quiver = ax.quiver(
        x,
        y,
        arrow * np.cos(theta),
        arrow * np.sin(theta),
        angles="xy",
        scale_units="xy",
        scale=1.0,
        width=0.004,
        color=color,
        zorder=4,
        label=label,
    )
    marks = None
    if turns and all(hasattr(smp, k) for k in ("v", "omega")):
        from trajopt.analysis.metrics import turns_in_place

        spans = turns_in_place(trajectory, dt=max(duration / 20_000, 0.01))
        if spans:
            (marks,) = ax.plot(
                [sp.x for sp in spans],
                [sp.y for sp in spans],
                "o",
                ms=11,
                mfc="none",
                mec=color,
                mew=1.4,
                zorder=5,
                label="turn in place",
            )
            for sp in spans:
                ax.annotate(
                    f"{sp.turn_rad:+.2f} rad",
                    (sp.x, sp.y),
                    textcoords="offset points",
                    xytext=(6, -12),
                    fontsize="small",
                    color=color,
                )
    return quiver, marks


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


def animate(
    trajectory: Any,
    grid: OccupancyGrid | None = None,
    movers: Sequence[MovingObstacle] = (),
    robot: Any = None,
    *,
    fps: float = 10.0,
    speed: float = 1.0,
    t_end: float | None = None,
    path: Any = None,
    dpi: float = 80.0,
    figsize: tuple[float, float] = (6.0, 6.0),
    inflated: OccupancyGrid | None = None,
) -> Animation:
    """Animate the robot and the moving obstacles over time on the map.

    Each frame shows the robot (its footprint, or the disc of its radius, at the
    trajectory's pose at time ``t``, with a heading tick) and every mover's shape at ``t``
    (its disc or convex polygon rounded by ``radius_at(t)``), over the map, the faint path
    and the movers' faint predicted tracks (:func:`trajopt.analysis.animation.animate_on`).
    Times are the trajectory's clock (s); lengths are metres.

    Parameters
    ----------
    trajectory : Trajectory or TrajectoryChain
        The timed motion (``duration`` in s, ``sample(t)`` giving ``x, y`` in m and
        ``theta`` in rad).
    grid : OccupancyGrid, optional
        The map drawn below (:func:`plot_map`); ``None``: plain axes in metres.
    movers : sequence of MovingObstacle
        The predicted movers, in the trajectory's clock.
    robot : Robot, optional
        The shape drawn; default ``trajectory.robot``.
    fps : float
        Frames per second of playback (> 0).
    speed : float
        Seconds of the trajectory's clock per second of playback (> 0).
    t_end : float, optional
        The last frame's time (s); default the later of the trajectory's end and the movers'
        last prediction times (the robot stands at its goal meanwhile).
    path : str or os.PathLike, optional
        Save to this file: ``.mp4`` (needs the ffmpeg encoder), ``.gif`` (pillow) or
        ``.html`` (the player). When the encoder is missing
        (``matplotlib.animation.writers.is_available``) the HTML player is written beside
        it (suffix ``.html``) with a ``UserWarning``. ``None``: nothing saved.
    dpi : float
        Resolution of the frames, saved and in the player (dots per inch).
    figsize : (float, float)
        Figure size (inches).
    inflated : OccupancyGrid, optional
        Shaded as the avoidance area (:func:`plot_map`).

    Returns
    -------
    Animation
        Shown in Jupyter as the HTML player (or the gif or mp4 written); its ``animation``
        is the matplotlib ``FuncAnimation``, its ``times`` the frame times (s).

    Raises
    ------
    InvalidInputError
        A bad ``fps``, ``speed``, ``t_end``, ``dpi``, ``figsize`` or ``path`` suffix, too
        many frames, a mover that is not a ``MovingObstacle``, or no robot.
    """
    import matplotlib.pyplot as plt

    try:
        size = tuple(float(v) for v in figsize)
    except (TypeError, ValueError):
        raise InvalidInputError(f"figsize must be two numbers of inches, got {figsize!r}") from None
    if len(size) != 2 or not all(np.isfinite(size)) or min(size) <= 0.0:
        raise InvalidInputError(f"figsize must be two finite numbers > 0 (inches), got {figsize!r}")
    check_movers(movers)  # before any figure is made
    fig, ax = plt.subplots(figsize=size)
    try:
        if grid is not None:
            plot_map(grid, inflated=inflated, ax=ax)
        else:
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
            ax.set_aspect("equal")
        fig.tight_layout()
        return animate_on(
            ax, trajectory, movers, robot, fps=fps, speed=speed, t_end=t_end, path=path, dpi=dpi
        )
    except BaseException:
        plt.close(fig)
        raise
