"""The ``(s, t)`` diagram of a trajectory among predicted movers (matplotlib).

Along the trajectory's path, each mover forbids a region of the plane of time ``t`` (s) and
arc length ``s`` (m) (:func:`trajopt.moving.st_grid`); a speed profile is a curve ``s(t)``
in that plane, and a profile that keeps clear of the movers passes outside the regions.
:func:`plot_st` draws both; it is also :func:`trajopt.plotting.plot_st`. matplotlib is
imported inside the function.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from trajopt.analysis.animation import MOVER_COLORS
from trajopt.errors import InvalidInputError
from trajopt.moving import MovingObstacle, check_movers, st_grid

__all__ = ["plot_st", "ST_MAX_NODES"]

#: Most ``(s, t)`` nodes :func:`plot_st` computes; finer spacings are refused.
ST_MAX_NODES = 2_000_000


def _timed_curve(trajectory: Any) -> Any:
    """Return the one timed curve of ``trajectory`` (itself, or a chain's only curve piece)."""
    if not hasattr(trajectory, "duration") or not callable(getattr(trajectory, "sample", None)):
        raise InvalidInputError(
            f"trajectory must be a timed trajectory, got {type(trajectory).__name__}"
        )
    pieces = getattr(trajectory, "pieces", None)
    if pieces is None:
        curves, starts = [trajectory], [0.0]
    else:
        idx = [i for i, p in enumerate(pieces) if hasattr(p, "path")]
        curves = [pieces[i] for i in idx]
        starts = [float(trajectory.starts[i]) for i in idx]
    if len(curves) != 1 or not hasattr(curves[0], "path") or starts[0] != 0.0:
        raise InvalidInputError(
            "trajectory must follow one path: a Trajectory, or a TrajectoryChain of one timed "
            f"curve played from its start and motions at rest, got {type(trajectory).__name__} "
            f"with {len(curves)} curves"
        )
    return curves[0]


def _spacing(name: str, value: Any, default: float, unit: str) -> float:
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidInputError(f"{name} must be a number > 0 ({unit}), got {value!r}")
    x = float(value)
    if not (np.isfinite(x) and x > 0.0):
        raise InvalidInputError(f"{name} must be finite and > 0 ({unit}), got {value!r}")
    return x


def plot_st(
    trajectory: Any,
    movers: Sequence[MovingObstacle],
    *,
    margin: float = 0.0,
    ds: float | None = None,
    dt: float | None = None,
    t_end: float | None = None,
    label: str = "s(t), chosen",
    ax: Any = None,
) -> tuple[Any, Any]:
    """Draw the ``(s, t)`` diagram: the movers' forbidden regions along the path, and ``s(t)``.

    Time ``t`` (s) runs along x, the arc length ``s`` (m) of the trajectory's path along
    y. A cell is filled (in its mover's colour) where the robot, anywhere within
    ``ds / 2`` of the cell's arc length ``s_i`` on the path, is closer to that mover at the
    cell's time ``t_k`` than ``robot radius + mover radius(t_k) + margin`` (for a footprint
    robot: its polygon turned by the path's heading, to the mover's shape, closer than
    ``margin``): the necessary grid of :func:`trajopt.moving.st_grid`, cells drawn
    ``dt`` wide about ``t_k``. A certified trajectory's profile ``s(t)``, drawn on top
    (black), passes no filled cell at the cells' times. The goal ``s = L`` is dashed.

    Parameters
    ----------
    trajectory : Trajectory or TrajectoryChain
        The timed motion along one path: a ``Trajectory`` (e.g. from
        ``Planner.plan(..., moving_obstacles=...)``), or a chain of one timed curve and
        motions at rest (turns in place, at fixed ``s``).
    movers : sequence of MovingObstacle
        The predictions, in the trajectory's clock.
    margin : float
        Extra distance (m), >= 0 (the plan's ``mover_margin``).
    ds, dt : float, optional
        Cell sizes (m, s), > 0; default ``L / 300`` and ``t_end / 300``.
    t_end : float, optional
        The last time drawn (s), > 0; default the later of the trajectory's end and the
        movers' last prediction times.
    label : str
        Legend label of the profile.
    ax : matplotlib Axes, optional

    Returns
    -------
    (Figure, Axes)
        The forbidden cells are the ``QuadMesh`` with gid ``"forbidden"`` (its array holds
        the mover's index per cell, masked where free), the profile the ``Line2D`` with gid
        ``"profile"``.

    Raises
    ------
    InvalidInputError
        Not a trajectory along one path of positive length, a mover that is not a
        ``MovingObstacle``, a bad ``margin``, ``ds``, ``dt`` or ``t_end``, or more than
        :data:`ST_MAX_NODES` nodes.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    movers = check_movers(movers)
    curve = _timed_curve(trajectory)
    length = float(curve.length)
    if not (np.isfinite(length) and length > 0.0):
        raise InvalidInputError(f"the trajectory's path must have a length > 0 m, got {length!r}")
    if isinstance(margin, bool) or not isinstance(margin, int | float | np.integer | np.floating):
        raise InvalidInputError(f"margin must be a number >= 0 (m), got {margin!r}")
    if not (np.isfinite(margin) and margin >= 0.0):
        raise InvalidInputError(f"margin must be finite and >= 0 (m), got {margin!r}")
    duration = float(trajectory.duration)
    end = max([duration] + [m.t_last for m in movers])
    end = _spacing("t_end", t_end, end, "s")
    step_s = _spacing("ds", ds, length / 300.0, "m")
    step_t = _spacing("dt", dt, end / 300.0, "s")
    nodes = (np.ceil(length / step_s) + 1.0) * (np.ceil(end / step_t) + 1.0)
    if nodes > ST_MAX_NODES:
        raise InvalidInputError(
            f"ds={step_s:.4g} m and dt={step_t:.4g} s give {nodes:.3g} nodes, more than "
            f"ST_MAX_NODES = {ST_MAX_NODES}; use larger cells"
        )
    robot = trajectory.robot
    path = curve.path
    footprint = getattr(robot, "footprint", None)
    body, stretch = None, 1.0
    limit = float(robot.radius) + float(margin)
    if footprint is not None:
        v = np.asarray(footprint.vertices, dtype=float)
        area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
        body = v if area2 > 0.0 else v[::-1].copy()
        reach = float(np.max(np.hypot(body[:, 0], body[:, 1])))
        kappa = np.abs(np.asarray(path.curvature(path.u_at_s(np.linspace(0.0, length, 2001)))))
        stretch = 1.0 + reach * float(np.max(kappa))  # from dense samples: a drawing's bound
        limit = float(margin)
    grid = st_grid(
        path,
        length,
        movers,
        limit,
        ds=step_s,
        dt=step_t,
        horizon=end,
        speed=float(robot.v_max),
        sufficient=False,
        body=body,
        stretch=stretch,
    )
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4))
    else:
        fig = ax.figure
    t_edges = np.append(grid.t - 0.5 * grid.dt, grid.t[-1] + 0.5 * grid.dt)
    s_edges = np.append(grid.s - 0.5 * grid.ds, grid.s[-1] + 0.5 * grid.ds)
    colors = [MOVER_COLORS[j % len(MOVER_COLORS)] for j in range(max(1, len(movers)))]
    who = np.ma.masked_less(grid.who.T.astype(float), 0.0)  # (n, K): rows s, columns t
    mesh = ax.pcolormesh(
        t_edges,
        s_edges,
        who,
        cmap=ListedColormap(colors),
        vmin=-0.5,
        vmax=len(colors) - 0.5,
        alpha=0.6,
        shading="flat",
        rasterized=True,
    )
    mesh.set_gid("forbidden")
    t_line = np.union1d(grid.t, np.linspace(0.0, end, 2001))
    smp = trajectory.sample(np.minimum(t_line, duration))
    (line,) = ax.plot(t_line, np.asarray(smp.s, dtype=float), "k-", lw=1.6, label=label)
    line.set_gid("profile")
    ax.axhline(length, ls="--", color="0.4", lw=0.8, label=f"goal, s = {length:.2f} m")
    handles = [line, *ax.get_lines()[-1:]]
    handles += [
        Patch(color=c, alpha=0.6, label=m.name) for m, c in zip(movers, colors, strict=False)
    ]
    ax.legend(handles=handles, loc="best", fontsize="small")
    ax.set_xlim(0.0, end)
    ax.set_ylim(-0.02 * length, 1.05 * length)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("arc length s [m]")
    ax.set_title("movers' forbidden (s, t) regions and the chosen profile", fontsize="medium")
    ax.grid(alpha=0.3)
    return fig, ax
