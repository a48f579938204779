"""Animations of a timed trajectory among predicted moving obstacles (matplotlib).

:func:`animate_on` moves, frame by frame, on axes in metres: the robot (its footprint, or the
disc of its radius, at the trajectory's pose at time ``t``, with a heading tick) and every
mover (its shape at ``t``: the convex polygon or disc rounded by ``radius_at(t)``, and its
reference point), over their faint planned path and predicted tracks, with the time in a
corner. :func:`trajopt.plotting.animate` draws the map first and calls it.

Times are the trajectory's clock (s, from the plan's ``t = 0``); frames are ``speed / fps``
seconds of that clock apart and run until ``t_end`` (default: the later of the trajectory's
end and the last prediction time; the robot stands at its goal after its end, a mover at
its last waypoint after its last time).

The result, :class:`Animation`, is saved as an mp4 file (needs the ``ffmpeg`` encoder), a
gif (the ``pillow`` encoder) or an HTML player (``to_jshtml``, no encoder needed) and shows
itself in Jupyter. matplotlib is imported inside the functions.
"""

from __future__ import annotations

import base64
import logging
import math
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from astar.files import atomic_write
from trajopt.errors import InvalidInputError
from trajopt.geometry import rounded_polygon
from trajopt.moving import MovingObstacle, check_movers

__all__ = ["Animation", "animate_on", "mover_outline", "MAX_FRAMES", "ENCODERS", "MOVER_COLORS"]

logger = logging.getLogger(__name__)

#: Most frames an animation may have; more is refused (lower ``fps`` or raise ``speed``).
MAX_FRAMES = 3000
#: File suffix -> the matplotlib writer that encodes it (``.html``: no encoder needed).
ENCODERS = {".mp4": "ffmpeg", ".gif": "pillow", ".html": "html"}

#: Colours of the movers, in order (repeated beyond six).
MOVER_COLORS = ("tab:red", "tab:orange", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")


def mover_outline(mover: MovingObstacle, t: float, *, arc_points: int = 48) -> np.ndarray:
    """Return a mover's outline (m) at time ``t`` (s), shape (k, 2), counter-clockwise.

    The points within ``mover.radius_at(t)`` of its convex polygon (turned by its heading,
    shifted to its reference point) or of its reference point (a disc).
    """
    (c, h) = mover.pose_at(float(t))
    v = mover.shape_vertices
    ch, sh = math.cos(float(h)), math.sin(float(h))
    world = np.column_stack(
        [c[0] + ch * v[:, 0] - sh * v[:, 1], c[1] + sh * v[:, 0] + ch * v[:, 1]]
    )
    return rounded_polygon(world, float(mover.radius_at(float(t))), arc_points=arc_points)


def _positive(name: str, value: Any, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidInputError(f"{name} must be a number > 0 ({unit}), got {value!r}")
    x = float(value)
    if not (math.isfinite(x) and x > 0.0):
        raise InvalidInputError(f"{name} must be finite and > 0 ({unit}), got {value!r}")
    return x


class Animation:
    """A recorded animation: the matplotlib objects, the frame times and where it went.

    Shown in Jupyter by its ``_repr_html_``: the HTML player, the gif or the mp4, embedded.

    Attributes
    ----------
    figure : matplotlib Figure
    animation : matplotlib.animation.FuncAnimation
    times : ndarray, shape (n,)
        Frame times (s, the trajectory's clock).
    fps : float
        Frames per second of playback.
    robot : matplotlib patch
        The robot's ``Polygon`` (a footprint) or ``Circle`` (a disc).
    heading : matplotlib Line2D
        The heading tick, from the robot's reference point along ``theta``.
    movers : list of matplotlib Polygon
        Each mover's outline, in the order of the movers given.
    centres : list of matplotlib Line2D
        Each mover's reference point (one marker).
    clock : matplotlib Text
        The time label.
    path : Path or None
        The file written (an ``.html`` file when the encoder of the requested suffix was
        missing), ``None`` when nothing was saved.
    format : {"mp4", "gif", "html"}
        What :meth:`_repr_html_` shows and ``path`` holds.
    """

    def __init__(
        self,
        figure: Any,
        animation: Any,
        times: np.ndarray,
        fps: float,
        artists: dict[str, Any],
        update: Any,
    ) -> None:
        self.figure = figure
        self.animation = animation
        self.times = times
        self.fps = fps
        self.robot = artists["robot"]
        self.heading = artists["heading"]
        self.movers = artists["movers"]
        self.centres = artists["centres"]
        self.clock = artists["clock"]
        self._update = update
        self.path: Path | None = None
        self.format = "html"
        self._html: str | None = None

    def seek(self, k: int) -> None:
        """Put every artist at frame ``k`` (the time ``times[k]``), as the animation does."""
        if isinstance(k, bool) or not isinstance(k, int | np.integer):
            raise InvalidInputError(f"frame must be an integer, got {k!r}")
        if not 0 <= k < self.times.shape[0]:
            raise InvalidInputError(f"frame must lie in [0, {self.times.shape[0] - 1}], got {k!r}")
        self._update(int(k))

    def to_html(self) -> str:
        """Return the HTML player (``FuncAnimation.to_jshtml``: frames as embedded PNG)."""
        if self._html is None:
            self._html = self.animation.to_jshtml(fps=self.fps)
        return self._html

    def _repr_html_(self) -> str:
        if self.format == "html" or self.path is None:
            return self.to_html()
        data = base64.b64encode(self.path.read_bytes()).decode("ascii")
        if self.format == "gif":
            return f'<img src="data:image/gif;base64,{data}" alt="animation"/>'
        return f'<video controls loop src="data:video/mp4;base64,{data}"></video>'

    def __repr__(self) -> str:
        where = "not saved" if self.path is None else f"{self.format} at {self.path}"
        return f"Animation({self.times.shape[0]} frames, {self.fps:g} fps, {where})"

    def save(self, path: str | Any, *, dpi: float = 80.0) -> Path:
        """Write the animation to ``path``: ``.mp4`` (ffmpeg), ``.gif`` (pillow) or ``.html``.

        When the suffix's encoder is not available
        (``matplotlib.animation.writers.is_available``), the HTML player is written beside it
        instead (same name, suffix ``.html``) and a ``UserWarning`` names the missing encoder.
        The file is written atomically; its folder is created.

        Returns
        -------
        Path
            The file written (also in :attr:`path`; :attr:`format` says what it holds).

        Raises
        ------
        InvalidInputError
            A suffix other than ``.mp4``, ``.gif`` or ``.html``, or a bad ``dpi``.
        """
        from matplotlib import animation as mpl_animation

        target = Path(path)
        suffix = target.suffix.lower()
        if suffix not in ENCODERS:
            raise InvalidInputError(
                f"path must end in one of {sorted(ENCODERS)} (the format), got {str(path)!r}"
            )
        dots = _positive("dpi", dpi, "dots per inch")
        writer = ENCODERS[suffix]
        if writer != "html" and not mpl_animation.writers.is_available(writer):
            fallback = target.with_suffix(".html")
            warnings.warn(
                f"the {writer!r} encoder for {suffix} is not available; wrote the HTML player "
                f"to {fallback} instead",
                UserWarning,
                stacklevel=2,
            )
            logger.info("no %s encoder: HTML player at %s", writer, fallback)
            target, writer = fallback, "html"
        target.parent.mkdir(parents=True, exist_ok=True)
        if writer == "html":
            html = self.to_html()
            atomic_write(target, lambda tmp: tmp.write_text(html, encoding="utf-8"))
            self.format = "html"
        else:
            atomic_write(
                target,
                lambda tmp: self.animation.save(str(tmp), writer=writer, fps=self.fps, dpi=dots),
            )
            self.format = suffix[1:]
        self.path = target
        return target


def animate_on(
    ax: Any,
    trajectory: Any,
    movers: Sequence[MovingObstacle] = (),
    robot: Any = None,
    *,
    fps: float = 10.0,
    speed: float = 1.0,
    t_end: float | None = None,
    path: str | Any = None,
    dpi: float = 80.0,
    close: bool = True,
) -> Animation:
    """Animate a timed trajectory and the movers on axes in metres (module docstring).

    Parameters
    ----------
    ax : matplotlib Axes
        Axes in metres (e.g. from :func:`trajopt.plotting.plot_map`); the faint path and
        tracks and the moving artists are added to it.
    trajectory : Trajectory or TrajectoryChain
        Anything with ``duration`` (s) and ``sample(t)`` returning ``x, y`` (m) and ``theta``
        (rad).
    movers : sequence of MovingObstacle
        The predictions, in the trajectory's clock.
    robot : Robot, optional
        The shape drawn: its ``footprint`` when set, else a disc of its ``radius`` (m).
        Default: ``trajectory.robot``.
    fps : float
        Frames per second of playback (> 0).
    speed : float
        Seconds of the trajectory's clock per second of playback (> 0; 2 plays twice as
        fast). Frames are ``speed / fps`` seconds apart.
    t_end : float, optional
        Last frame time (s, >= 0); default the later of ``trajectory.duration`` and the
        movers' last prediction times.
    path : str or os.PathLike, optional
        Save to this file (:meth:`Animation.save`: ``.mp4``, ``.gif`` or ``.html``, with
        the HTML fallback); ``None`` (default) saves nothing.
    dpi : float
        Resolution of the frames, saved and in the HTML player (dots per inch, > 0; set
        on the figure).
    close : bool
        Close the figure (``plt.close``) once the animation is built, so that Jupyter
        shows the animation only, not also the last still frame (default ``True``).

    Returns
    -------
    Animation

    Raises
    ------
    InvalidInputError
        A bad ``fps``, ``speed``, ``t_end``, ``dpi`` or ``path`` suffix, more than
        :data:`MAX_FRAMES` frames, a mover that is not a :class:`MovingObstacle`, no robot
        given and the trajectory has none, or a trajectory without ``duration`` and ``sample``.
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation
    from matplotlib.patches import Circle, Polygon

    if not hasattr(trajectory, "duration") or not callable(getattr(trajectory, "sample", None)):
        raise InvalidInputError(
            f"trajectory must be a timed trajectory (duration and sample), got "
            f"{type(trajectory).__name__}"
        )
    duration = float(trajectory.duration)
    if not (math.isfinite(duration) and duration >= 0.0):
        raise InvalidInputError(
            f"trajectory duration must be finite and >= 0 (s), got {duration!r}"
        )
    movers = check_movers(movers)
    rate = _positive("fps", fps, "frames per second")
    play = _positive("speed", speed, "trajectory seconds per playback second")
    dots = _positive("dpi", dpi, "dots per inch")
    if path is not None and Path(path).suffix.lower() not in ENCODERS:
        raise InvalidInputError(
            f"path must end in one of {sorted(ENCODERS)} (the format), got {str(path)!r}"
        )
    if t_end is None:
        end = max([duration] + [m.t_last for m in movers])
    else:
        if isinstance(t_end, bool) or not isinstance(t_end, int | float | np.integer | np.floating):
            raise InvalidInputError(f"t_end must be a number of seconds >= 0, got {t_end!r}")
        end = float(t_end)
        if not (math.isfinite(end) and end >= 0.0):
            raise InvalidInputError(f"t_end must be finite and >= 0 (s), got {t_end!r}")
    robot = robot if robot is not None else getattr(trajectory, "robot", None)
    if robot is None:
        raise InvalidInputError("robot is required when the trajectory has no robot attribute")
    step = play / rate
    count = int(math.floor(end / step + 1e-9)) + 1
    if count + 1 > MAX_FRAMES:
        raise InvalidInputError(
            f"fps={fps!r} and speed={speed!r} give {count + 1} frames over {end:.4g} s, more "
            f"than MAX_FRAMES = {MAX_FRAMES}; lower fps or raise speed"
        )
    times = step * np.arange(count)
    if end - times[-1] > 1e-9 * max(1.0, end):
        times = np.append(times, end)
    # the robot's poses at every frame (it stands at its goal after its end)
    smp = trajectory.sample(np.minimum(times, duration))
    x, y, theta = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (smp.x, smp.y, smp.theta))
    footprint = getattr(robot, "footprint", None)
    radius = float(robot.radius)

    # the faint background: the robot's path and each mover's predicted track
    fig = ax.figure
    fig.set_dpi(dots)
    t_path = np.linspace(0.0, duration, 400)
    along = trajectory.sample(t_path)
    ax.plot(
        np.asarray(along.x),
        np.asarray(along.y),
        "-",
        color="tab:blue",
        lw=1.0,
        alpha=0.35,
        label="robot path",
    )
    colors = [MOVER_COLORS[j % len(MOVER_COLORS)] for j in range(len(movers))]
    for m, color in zip(movers, colors, strict=True):
        ax.plot(
            m.positions[:, 0],
            m.positions[:, 1],
            ":",
            color=color,
            lw=1.2,
            alpha=0.5,
            marker=".",
            ms=4,
            label=f"{m.name} (predicted)",
        )
    style = dict(fc="tab:blue", ec="navy", alpha=0.6, lw=1.0, zorder=6)
    if footprint is not None:
        robot_patch = ax.add_patch(
            Polygon(footprint.at(x[0], y[0], theta[0]), closed=True, **style)
        )
    else:
        robot_patch = ax.add_patch(Circle((x[0], y[0]), radius, **style))
    tick = max(radius, 0.05) * 1.3
    (heading,) = ax.plot([], [], "-", color="navy", lw=1.5, zorder=7)
    mover_patches, centres = [], []
    for m, color in zip(movers, colors, strict=True):
        mover_patches.append(
            ax.add_patch(
                Polygon(
                    mover_outline(m, times[0]),
                    closed=True,
                    fc=color,
                    ec=color,
                    alpha=0.45,
                    lw=1.0,
                    zorder=5,
                )
            )
        )
        (dot,) = ax.plot([], [], "x", color=color, ms=5, zorder=6)
        centres.append(dot)
    clock = ax.text(
        0.02,
        0.97,
        "",
        transform=ax.transAxes,
        va="top",
        ha="left",
        zorder=8,
        bbox=dict(fc="white", ec="none", alpha=0.7),
    )

    def update(k: int) -> list[Any]:
        if footprint is not None:
            robot_patch.set_xy(footprint.at(x[k], y[k], theta[k]))
        else:
            robot_patch.set_center((x[k], y[k]))
        heading.set_data(
            [x[k], x[k] + tick * math.cos(theta[k])], [y[k], y[k] + tick * math.sin(theta[k])]
        )
        for m, patch, dot in zip(movers, mover_patches, centres, strict=True):
            patch.set_xy(mover_outline(m, times[k]))
            c = m.position_at(times[k])
            dot.set_data([c[0]], [c[1]])
        clock.set_text(f"t = {times[k]:.2f} s")
        return [robot_patch, heading, clock, *mover_patches, *centres]

    update(0)
    if movers or ax.get_legend_handles_labels()[0]:
        ax.legend(loc="lower right", fontsize="small")
    anim = FuncAnimation(fig, update, frames=times.shape[0], interval=1000.0 / rate, blit=False)
    if close:
        plt.close(fig)
    result = Animation(
        fig,
        anim,
        times,
        rate,
        dict(
            robot=robot_patch, heading=heading, movers=mover_patches, centres=centres, clock=clock
        ),
        update,
    )
    if path is not None:
        result.save(path, dpi=dots)
    return result
