"""Seeded moving-obstacle scenarios placed from a static plan (issue 46), for the benchmark and tests.

Every mover is placed from the static plan's own motion so that it meets the robot (speed
0.3-1.5 m/s; its prediction starts at ``t = 0``). Its shape (``shape``): a disc of radius
0.15-0.35 m (``"disc"``), or a cart (``"polygon"``): a rectangle 0.5-1.2 m long and 0.4-0.7 m
wide, rounded by 0.05 m, heading along its motion (at each waypoint the direction of the
segment that leaves it; turning linearly in time between waypoints, the shorter way);
``"mixed"`` draws each mover's shape at random. The kinds:

* ``crossing``: crosses the path at a random point of its middle 70 %, at 60-120 degrees
  to it, reaching that point within 1 s of the time the static plan gets there, and goes
  on 4 m past it;
* ``head-on``: comes from 2 m beside the path onto it ahead of the robot, drives back
  along it for 1.5-4 m against the robot's direction, timed to meet the static plan
  (within 1 s) in the middle of that stretch, then leaves the path sideways for 2 m;
* ``following``: stands 0.8-2 m ahead on the path at ``t = 0``, drives along it in the
  robot's direction for 2-5 m, then leaves sideways for 2 m;
* ``overtaking``: the same with a slow mover (0.3-0.4 m/s, slower than the robot's
  0.5 m/s) over 3-6 m;
* ``stopping``: comes from 3 m beside the path and stops on it at a random point of its
  middle 60 %, arriving within 1 s of the static plan (its last prediction: it stays there);
* ``mixed``: each mover of a random kind among the first four.

A scenario of ``n`` movers (1-10) has ``n`` movers of its kind for ``crossing``, ``head-on``
and ``mixed``; one of its kind and ``n - 1`` crossing ones for the others. A mover that
would start within 0.1 m of the robot's distance at ``t = 0`` is drawn again. Everything is
drawn from ``numpy.random.default_rng(seed)``: the same seed, map and query give the same
scenario.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import trajopt

KINDS = ("crossing", "head-on", "following", "overtaking", "stopping")
#: the movers' shapes (module docstring)
SHAPES = ("disc", "polygon", "mixed")
#: the kinds a ``mixed`` scenario draws from (each mover its own)
MIXED = ("crossing", "head-on", "following", "overtaking")
SPEED = (0.3, 1.5)
RADIUS = (0.15, 0.35)
#: a cart's length and width (m) and rounding (m)
CART_LENGTH, CART_WIDTH, CART_ROUNDING = (0.5, 1.2), (0.4, 0.7), 0.05


@dataclass(frozen=True)
class Scenario:
    """One query with its movers: ``start``, ``goal`` (m), ``movers``, its ``kind`` and ``seed``."""

    kind: str
    start: tuple[float, float]
    goal: tuple[float, float]
    movers: tuple[trajopt.MovingObstacle, ...]
    seed: int


class PathTrack:
    """The static plan's motion as arc length: ``point(s)``, ``heading(s)``, ``time(s)``.

    From the trajectory's own samples every 5 ms (the polyline through them), so it also
    reads chains with turns in place.
    """

    def __init__(self, traj) -> None:
        t = np.append(np.arange(0.0, traj.duration, 5e-3), traj.duration)
        smp = traj.sample(t)
        p = np.stack([np.asarray(smp.x), np.asarray(smp.y)], axis=-1)
        step = np.hypot(*np.diff(p, axis=0).T)
        keep = np.r_[True, step > 1e-9]
        self.p, self.t = p[keep], t[keep]
        self.s = np.r_[0.0, np.cumsum(step[step > 1e-9])]
        self.length = float(self.s[-1])

    def point(self, s):
        s = np.asarray(s, dtype=float)
        return np.stack([np.interp(s, self.s, self.p[:, i]) for i in (0, 1)], axis=-1)

    def heading(self, s) -> float:
        a, b = self.point(max(s - 0.05, 0.0)), self.point(min(s + 0.05, self.length))
        return math.atan2(b[1] - a[1], b[0] - a[0])

    def time(self, s) -> float:
        """When the static plan passes ``s`` (s)."""
        return float(np.interp(s, self.s, self.t))

    def stretch(self, s0: float, s1: float, spacing: float = 0.1) -> np.ndarray:
        """Points along the path from ``s0`` to ``s1`` (either order), shape (n, 2)."""
        n = max(2, int(math.ceil(abs(s1 - s0) / spacing)) + 1)
        return self.point(np.linspace(s0, s1, n))


def _side(heading: float, sign: float) -> np.ndarray:
    return sign * np.array([-math.sin(heading), math.cos(heading)])


def _route(points: np.ndarray, at: int, t_at: float, speed: float):
    """Times (s) and positions (m) along ``points`` at ``speed``, at ``points[at]`` at ``t_at``.

    Cut at ``t = 0`` (the position there interpolated), so the prediction starts at 0.
    """
    seg = np.hypot(*np.diff(points, axis=0).T)
    keep = np.r_[True, seg > 1e-9]
    points = points[keep]
    at = int(np.count_nonzero(keep[: at + 1]) - 1)
    cum = np.r_[0.0, np.cumsum(seg[seg > 1e-9])]
    times = t_at + (cum - cum[at]) / speed
    if times[0] < 0.0:
        p0 = [np.interp(0.0, times, points[:, i]) for i in (0, 1)]
        later = times > 1e-9
        times = np.r_[0.0, times[later]]
        points = np.vstack([p0, points[later]])
    return times, points


def headings_along(positions: np.ndarray) -> np.ndarray:
    """Headings (rad, unwrapped, shape (k,)) along waypoints ``positions`` (m, shape (k, 2)).

    At each waypoint the direction of the segment that leaves it (the last one keeps the last
    segment's); unwrapped, so that the linear interpolation between two waypoints turns the
    shorter way.
    """
    d = np.diff(positions, axis=0)
    if d.shape[0] == 0:
        return np.zeros(1)
    h = np.arctan2(d[:, 1], d[:, 0])
    return np.unwrap(np.r_[h, h[-1]])


def cart(rng: np.random.Generator) -> np.ndarray:
    """A cart's rectangle in its own frame (m, shape (4, 2), counter-clockwise), seeded."""
    half_l = 0.5 * float(rng.uniform(*CART_LENGTH))
    half_w = 0.5 * float(rng.uniform(*CART_WIDTH))
    return np.array([[-half_l, -half_w], [half_l, -half_w], [half_l, half_w], [-half_l, half_w]])


def reach(mover) -> float:
    """How far the mover's shape reaches from its reference point (m): radius plus vertices."""
    if mover.vertices is None:
        return float(mover.radius)
    return float(mover.radius) + float(np.max(np.hypot(*np.asarray(mover.vertices).T)))


def draw_mover(
    track: PathTrack, kind: str, rng: np.random.Generator, name: str, shape: str = "disc"
):
    """One mover of ``kind`` and ``shape`` (module docstring) placed from ``track``."""
    if shape not in SHAPES:
        raise ValueError(f"shape must be one of {SHAPES}, got {shape!r}")
    radius = float(rng.uniform(*RADIUS))
    sign = float(rng.choice([-1.0, 1.0]))
    L = track.length
    if kind == "crossing":
        speed = float(rng.uniform(*SPEED))
        s = float(rng.uniform(0.15, 0.85)) * L
        p, h = track.point(s), track.heading(s)
        ang = h + sign * (math.pi / 2 + float(rng.uniform(-math.pi / 6, math.pi / 6)))
        u = np.array([math.cos(ang), math.sin(ang)])
        t_c = max(track.time(s) + float(rng.uniform(-1.0, 1.0)), 0.0)
        pts = np.vstack([p - (t_c * speed + 1.0) * u, p, p + 4.0 * u])
        times, pos = _route(pts, 1, t_c, speed)
    elif kind == "head-on":
        speed = float(rng.uniform(*SPEED))
        s_a = float(rng.uniform(0.2, 0.6)) * L
        s_b = min(s_a + float(rng.uniform(1.5, 4.0)), L - 0.3)
        s_a = min(s_a, s_b - 0.5)
        s_m = 0.5 * (s_a + s_b)
        along = track.stretch(s_b, s_a)
        enter = track.point(s_b) + 2.0 * _side(track.heading(s_b), sign)
        leave = track.point(s_a) + 2.0 * _side(track.heading(s_a), sign)
        pts = np.vstack([enter, along, leave])
        meet = 1 + int(np.argmin(np.hypot(*(along - track.point(s_m)).T)))
        t_m = max(track.time(s_m) + float(rng.uniform(-1.0, 1.0)), 0.0)
        times, pos = _route(pts, meet, t_m, speed)
    elif kind in ("following", "overtaking"):
        slow = kind == "overtaking"
        speed = float(rng.uniform(0.3, 0.4) if slow else rng.uniform(*SPEED))
        s0 = min(float(rng.uniform(0.8, 2.0)), 0.5 * L)
        s1 = min(s0 + float(rng.uniform(3.0, 6.0) if slow else rng.uniform(2.0, 5.0)), L - 0.3)
        s1 = max(s1, s0 + 0.3)
        leave = track.point(s1) + 2.0 * _side(track.heading(s1), sign)
        pts = np.vstack([track.stretch(s0, s1), leave])
        times, pos = _route(pts, 0, 0.0, speed)
    elif kind == "stopping":
        speed = float(rng.uniform(*SPEED))
        s = float(rng.uniform(0.2, 0.8)) * L
        p = track.point(s)
        enter = p + 3.0 * _side(track.heading(s), sign)
        t_c = max(track.time(s) + float(rng.uniform(-1.0, 1.0)), 0.0)
        times, pos = _route(np.vstack([enter, p]), 1, t_c, speed)
    else:
        raise ValueError(f"kind must be one of {KINDS + ('mixed',)}, got {kind!r}")
    if shape == "mixed":
        shape = str(rng.choice(("disc", "polygon")))
    if shape == "disc":
        return trajopt.MovingObstacle.from_waypoints(times, pos, radius=radius, name=name)
    return trajopt.MovingObstacle.from_waypoints(
        times,
        pos,
        radius=CART_ROUNDING,
        vertices=cart(rng),
        headings=headings_along(np.asarray(pos, dtype=float)),
        name=name,
    )


def kinds_of(kind: str, n: int, rng: np.random.Generator) -> list[str]:
    """The kinds of a scenario's ``n`` movers (module docstring)."""
    if kind == "mixed":
        return [str(k) for k in rng.choice(MIXED, size=n)]
    if kind in ("crossing", "head-on"):
        return [kind] * n
    return [kind] + ["crossing"] * (n - 1)


def make_movers(traj, kind: str, n: int, seed: int, *, margin: float = 0.0, shape: str = "disc"):
    """``n`` movers of a ``kind`` scenario around the static plan ``traj`` (seeded).

    Parameters
    ----------
    traj : Trajectory or TrajectoryChain
        The static plan (a disc robot's).
    kind : str
        One of :data:`KINDS` or ``"mixed"``.
    n : int
        Number of movers, >= 1.
    seed : int
        Seed of ``numpy.random.default_rng``.
    margin : float
        The mover margin (m) the scenario is run with: a mover is drawn again while it starts
        closer than ``robot radius + its reach + margin + 0.1`` m to the robot (its reach:
        :func:`reach`).
    shape : str
        One of :data:`SHAPES` (module docstring); the default ``"disc"``.

    Returns
    -------
    tuple of MovingObstacle
        Named ``"<kind>-<i>"``.
    """
    rng = np.random.default_rng(seed)
    track = PathTrack(traj)
    smp = traj.sample(np.zeros(1))
    start = np.array([smp.x[0], smp.y[0]])
    out = []
    for i, k in enumerate(kinds_of(kind, n, rng)):
        for _ in range(50):
            m = draw_mover(track, k, rng, f"{k}-{i}", shape)
            gap = float(np.hypot(*(m.positions[0] - start)))
            if gap >= traj.robot.radius + reach(m) + margin + 0.1:
                out.append(m)
                break
    return tuple(out)
