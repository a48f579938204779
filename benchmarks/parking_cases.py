"""A seeded parking suite (issue 45) and an exact body-vs-polygon checker of car trajectories.

Cases (:func:`make_cases`): a car park seen from above, the aisle along x, a row of slots
below it (y < 0), walls and kerbs round it:

* ``parallel``: a slot between two parked cars, ``1.2-1.6`` car lengths long (bumper to
  bumper), the kerb below; more parked cars fill the row to the street's ends;
* ``perpendicular``: a bay between two parked cars whose free width (side to side, as if
  both neighbours were parked on the bay's lines) is ``1.15-1.4`` car widths; a kerb
  behind the bays;
* ``angled``: the same bays leaning ``45-60`` degrees to the aisle.

The aisle is ``4-7`` m wide for the full-size car (scaled by the car's length for the small
car); its far side is a wall, with a row of cars parked along it in about half the cases.
The street is closed by one U-shaped (non-convex) kerb polygon round the three other sides
and a wall on top; parked cars are rectangles ``0.95-1.05`` car lengths by ``0.95-1.02``
car widths (parallel ones turned by up to 1.5 degrees). The start pose lies in the aisle,
0.5-3 car lengths along it from the slot, with a heading along the aisle either way plus
up to 0.35 rad; it is drawn again until the body keeps 0.1 m (scaled) from every polygon.
The goal puts the body in the slot. ``entry`` is decided by the goal heading: for bays,
``forwards`` when the car faces into the bay, ``backwards`` when it faces out; for a
parallel slot, ``backwards`` when the start lies behind the slot as seen along the goal
heading (the textbook manoeuvre: drive past, back in), ``forwards`` when it lies ahead.

Cars (:data:`CARS`): the full-size car of the public automated-parking cases (4.69 x 1.94 m,
wheelbase 2.8 m, R = 3.0 m, the rear axle 0.96 m from the rear bumper, the reference
point) and a small delivery robot car (0.9 x 0.5 m, wheelbase 0.55 m, R = 0.6 m, the rear
axle 0.184 m from its back: the same proportion).

The checker (:func:`body_overlaps`, :func:`trajectory_poses`, :func:`check_trajectory`) is
independent of the planner and of the grid: the body polygon at each pose against the
obstacle *polygons* by exact segment intersection and point-in-polygon tests (touching
counts as overlap), at poses so dense that no body corner moves more than 1 cm between
consecutive ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

CATEGORIES = ("parallel", "perpendicular", "angled")
ENTRIES = ("backwards", "forwards")
#: The publicly benchmarked car's aisle widths (m), scaled by car length for other cars.
AISLE_M = (4.0, 7.0)
FULL_LENGTH = 4.69


@dataclass(frozen=True)
class Car:
    """A car-like robot with a rectangular body, the rear axle as its reference point.

    Lengths in m, ``steer_rate_max`` in rad/s, ``v_max`` in m/s, ``a_max`` in m/s^2.
    """

    name: str
    length: float
    width: float
    rear_offset: float  # rear axle to rear bumper (m)
    turning_radius: float
    wheelbase: float
    steer_rate_max: float
    v_max: float
    a_max: float

    @property
    def scale(self) -> float:
        """This car's length over the full-size car's (scales the scene's metres)."""
        return self.length / FULL_LENGTH

    def body(self) -> np.ndarray:
        """Corners (4, 2) in the car frame (m): x forward from the rear axle, counter-clockwise."""
        x0, x1, y = -self.rear_offset, self.length - self.rear_offset, 0.5 * self.width
        return np.array([[x0, -y], [x1, -y], [x1, y], [x0, y]])

    def robot(self):
        """The ``trajopt.Robot`` of this car (``Robot.rectangle`` with an Ackermann drive)."""
        import trajopt

        return trajopt.Robot.rectangle(
            self.length,
            self.width,
            rear_offset=self.rear_offset,
            drive=trajopt.Ackermann(
                min_turning_radius=self.turning_radius,
                wheelbase=self.wheelbase,
                steer_rate_max=self.steer_rate_max,
            ),
            v_max=self.v_max,
            a_max=self.a_max,
            j_max=2.0 * self.a_max,
            a_lat_max=self.a_max,
            omega_max=self.v_max / self.turning_radius,
            track_width=None,
            wheel_v_max=None,
        )


CARS = {
    "full": Car("full", 4.69, 1.94, 0.96, 3.0, 2.8, 0.5, 2.5, 1.0),
    "small": Car("small", 0.9, 0.5, 0.9 * 0.96 / 4.69, 0.6, 0.55, 0.5, 1.0, 0.5),
}


@dataclass(frozen=True)
class ParkingCase:
    """One parking query: obstacle polygons, the map's bounds, start and goal poses.

    ``start`` and ``goal`` are ``(x, y, heading)`` of the rear axle (m, m, rad);
    ``size`` is the slot's length in car lengths (parallel) or the bay's free width in car
    widths; ``aisle`` the aisle's width (m); ``angle`` the bays' angle to the aisle (deg).
    """

    case_id: str
    category: str
    entry: str
    car: Car
    polygons: tuple[np.ndarray, ...]
    bounds: tuple[float, float, float, float]
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    size: float
    aisle: float
    angle: float
    params: dict = field(default_factory=dict)

    def grid(self, resolution: float):
        """The conservative occupancy grid of the polygons (``astar.OccupancyGrid.from_polygons``)."""
        import astar

        return astar.OccupancyGrid.from_polygons(self.polygons, resolution, self.bounds)


# ---------------------------------------------------------------------------- geometry


def rect(cx: float, cy: float, length: float, width: float, yaw: float = 0.0) -> np.ndarray:
    """Corners (4, 2) of a ``length x width`` rectangle centred at ``(cx, cy)``, turned by ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    loc = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]) * (length, width)
    return loc @ np.array([[c, s], [-s, c]]) + (cx, cy)


def body_at(body: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """The body's corners at poses ``(N, 3)`` (x, y, theta): shape ``(N, k, 2)`` (m)."""
    p = np.atleast_2d(np.asarray(poses, dtype=float))
    c, s = np.cos(p[:, 2])[:, None], np.sin(p[:, 2])[:, None]
    x = p[:, 0:1] + c * body[None, :, 0] - s * body[None, :, 1]
    y = p[:, 1:2] + s * body[None, :, 0] + c * body[None, :, 1]
    return np.stack([x, y], axis=-1)


@njit(cache=True)
def _seg_meet(ax, ay, bx, by, cx, cy, dx, dy) -> bool:  # pragma: no cover - compiled
    """Closed segments ``a b`` and ``c d`` share a point (touching counts)."""
    o1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    o2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    o3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    o4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    if ((o1 > 0 and o2 < 0) or (o1 < 0 and o2 > 0)) and (
        (o3 > 0 and o4 < 0) or (o3 < 0 and o4 > 0)
    ):
        return True
    if o1 == 0 and min(ax, bx) <= cx <= max(ax, bx) and min(ay, by) <= cy <= max(ay, by):
        return True
    if o2 == 0 and min(ax, bx) <= dx <= max(ax, bx) and min(ay, by) <= dy <= max(ay, by):
        return True
    if o3 == 0 and min(cx, dx) <= ax <= max(cx, dx) and min(cy, dy) <= ay <= max(cy, dy):
        return True
    if o4 == 0 and min(cx, dx) <= bx <= max(cx, dx) and min(cy, dy) <= by <= max(cy, dy):
        return True
    return False


@njit(cache=True)
def _overlaps_kernel(body, poses, verts, starts, out):  # pragma: no cover - compiled
    """``out[i]``: the convex ``body`` at ``poses[i]`` meets a polygon (see body_overlaps)."""
    k = body.shape[0]
    npoly = starts.shape[0] - 1
    bx = np.empty(k)
    by = np.empty(k)
    for i in range(poses.shape[0]):
        c, s = math.cos(poses[i, 2]), math.sin(poses[i, 2])
        for j in range(k):
            bx[j] = poses[i, 0] + c * body[j, 0] - s * body[j, 1]
            by[j] = poses[i, 1] + s * body[j, 0] + c * body[j, 1]
        x0, x1, y0, y1 = bx.min(), bx.max(), by.min(), by.max()
        hit = False
        for p in range(npoly):
            a, b = starts[p], starts[p + 1]
            m = b - a
            # edges against edges (bounding boxes first)
            for e in range(m):
                px, py = verts[a + e, 0], verts[a + e, 1]
                qx, qy = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
                if max(px, qx) < x0 or min(px, qx) > x1 or max(py, qy) < y0 or min(py, qy) > y1:
                    continue
                for j in range(k):
                    jn = (j + 1) % k
                    if _seg_meet(bx[j], by[j], bx[jn], by[jn], px, py, qx, qy):
                        hit = True
                        break
                if hit:
                    break
            if hit:
                break
            # no boundaries meet: one inside the other, or apart. A body corner inside the
            # polygon (even-odd) ...
            inside = False
            for e in range(m):
                px, py = verts[a + e, 0], verts[a + e, 1]
                qx, qy = verts[a + (e + 1) % m, 0], verts[a + (e + 1) % m, 1]
                if (py > by[0]) != (qy > by[0]):
                    xc = px + (by[0] - py) * (qx - px) / (qy - py)
                    if bx[0] < xc:
                        inside = not inside
            if inside:
                hit = True
                break
            # ... or a polygon vertex inside the convex body (counter-clockwise)
            vx, vy = verts[a, 0], verts[a, 1]
            allin = True
            for j in range(k):
                jn = (j + 1) % k
                if (bx[jn] - bx[j]) * (vy - by[j]) - (by[jn] - by[j]) * (vx - bx[j]) < 0:
                    allin = False
                    break
            if allin:
                hit = True
                break
        out[i] = hit


def _packed(polygons) -> tuple[np.ndarray, np.ndarray]:
    polys = [np.ascontiguousarray(p, dtype=float) for p in polygons]
    verts = np.vstack(polys) if polys else np.zeros((0, 2))
    starts = np.r_[0, np.cumsum([len(p) for p in polys])].astype(np.int64)
    return verts, starts


def body_overlaps(body: np.ndarray, poses: np.ndarray, polygons) -> np.ndarray:
    """Poses at which the convex body meets an obstacle polygon, exactly (touching counts).

    The body (convex, counter-clockwise, ``(k, 2)`` in the car frame, m) at pose
    ``(x, y, theta)`` meets a simple polygon iff an edge of one meets an edge of the other
    (closed segments, orientation tests), or, when no boundaries meet, a body corner lies
    inside the polygon (the body inside it) or a polygon vertex lies inside the body (the
    polygon inside it). A compiled loop (numba, cached on disk beside this file: numba names
    the cache after the source file, so the benchmark, which imports the suite as
    ``parking_cases``, and the tests, which import it as ``benchmarks.parking_cases``, load
    the same compiled code): about a microsecond per pose against a car park's polygons.

    Parameters
    ----------
    body : ndarray, shape (k, 2)
        Convex body, counter-clockwise, in the car frame (m).
    poses : ndarray, shape (N, 3)
        Reference-point poses (m, m, rad).
    polygons : sequence of ndarray, shape (m_i, 2)
        Obstacle polygons (m), simple, convex or not, either orientation.

    Returns
    -------
    ndarray of bool, shape (N,)
    """
    poses = np.ascontiguousarray(np.atleast_2d(np.asarray(poses, dtype=float)))
    out = np.zeros(len(poses), dtype=np.bool_)
    verts, starts = _packed(polygons)
    _overlaps_kernel(np.ascontiguousarray(body, dtype=float), poses, verts, starts, out)
    return out


class PoseChecker:
    """One pose at a time against fixed polygons (OMPL's state validity): True when clear."""

    def __init__(self, body: np.ndarray, polygons) -> None:
        self.body = np.ascontiguousarray(body, dtype=float)
        self.verts, self.starts = _packed(polygons)
        self._pose = np.zeros((1, 3))
        self._out = np.zeros(1, dtype=np.bool_)

    def __call__(self, x: float, y: float, theta: float) -> bool:
        self._pose[0, 0], self._pose[0, 1], self._pose[0, 2] = x, y, theta
        _overlaps_kernel(self.body, self._pose, self.verts, self.starts, self._out)
        return not self._out[0]


def body_clearance(body: np.ndarray, poses: np.ndarray, polygons) -> np.ndarray:
    """Exact distance (m) from the body at each pose to the nearest polygon (0 on overlap).

    For disjoint polygons the distance is the least vertex-to-edge distance either way.
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    d = np.full(len(poses), np.inf)
    over = body_overlaps(body, poses, polygons)
    ea = np.vstack(polygons)
    eb = np.vstack([np.roll(p, -1, axis=0) for p in polygons])
    B = body_at(body, poses)
    B2 = np.roll(B, -1, axis=1)

    def pt_seg(p, a, b):  # p (..., 2), a b (..., 2)
        ab = b - a
        t = np.clip(np.sum((p - a) * ab, -1) / np.maximum(np.sum(ab * ab, -1), 1e-300), 0, 1)
        return np.hypot(*np.moveaxis(p - (a + t[..., None] * ab), -1, 0))

    for i in range(len(poses)):
        v2e = pt_seg(B[i][:, None, :], ea[None], eb[None]).min()
        e2v = pt_seg(ea[:, None, :], B[i][None], B2[i][None]).min()
        d[i] = min(v2e, e2v)
    d[over] = 0.0
    return d


# ---------------------------------------------------------------------------- trajectories


def trajectory_poses(
    traj, body: np.ndarray, step: float = 0.01, max_iter: int = 20
) -> tuple[np.ndarray, np.ndarray]:
    """Times and poses along a trajectory, no body corner moving more than ``step`` m between.

    Starts from samples 5 mm of travel apart at ``|v| = v_max`` (the largest speed seen on
    a first pass) and bisects every interval whose largest corner displacement exceeds
    ``step``, until none does.

    Returns
    -------
    t : ndarray, shape (N,)
    poses : ndarray, shape (N, 3)
    """
    T = float(traj.duration)
    smp = traj.sample(np.linspace(0.0, T, 2001))
    vmax = max(float(np.max(np.abs(smp.v))), 1e-3)
    n = max(2, math.ceil(T * vmax / (0.5 * step)) + 1)
    t = np.linspace(0.0, T, n)
    for _ in range(max_iter):
        s = traj.sample(t)
        poses = np.column_stack([s.x, s.y, s.theta])
        c = body_at(body, poses)
        move = np.max(np.hypot(*np.moveaxis(np.diff(c, axis=0), -1, 0)), axis=1)
        bad = np.flatnonzero(move > step)
        if not len(bad):
            return t, poses
        t = np.sort(np.concatenate([t, 0.5 * (t[bad] + t[bad + 1])]))
    raise RuntimeError(
        f"trajectory_poses: corners still move > {step} m after {max_iter} bisections"
    )


def dense_path_poses(poses: np.ndarray, body: np.ndarray, step: float = 0.01) -> np.ndarray:
    """Check that a pose sequence (e.g. an interpolated OMPL path) moves no corner > ``step``."""
    c = body_at(body, poses)
    move = np.max(np.hypot(*np.moveaxis(np.diff(c, axis=0), -1, 0)), axis=1)
    return move


def count_cusps(poses: np.ndarray) -> int:
    """Changes of the direction of travel (forwards/backwards along the heading) of a pose path."""
    d = np.diff(poses[:, :2], axis=0)
    along = d[:, 0] * np.cos(poses[:-1, 2]) + d[:, 1] * np.sin(poses[:-1, 2])
    sgn = np.sign(along[np.abs(along) > 1e-9])
    return int(np.sum(sgn[1:] != sgn[:-1]))


@dataclass(frozen=True)
class Check:
    """The exact check of one trajectory: overlapping poses, their count, the least clearance (m)."""

    poses: int
    overlaps: int
    min_clearance: float
    max_corner_step: float


def check_poses(body: np.ndarray, poses: np.ndarray, polygons, step: float = 0.01) -> Check:
    """Exact check of a dense pose sequence (corners must move <= ``step`` m between poses)."""
    move = dense_path_poses(poses, body, step)
    over = body_overlaps(body, poses, polygons)
    # the least clearance on a thinned subset (every 10th pose and the ends): a report only
    sub = np.unique(np.r_[np.arange(0, len(poses), 10), len(poses) - 1])
    clr = body_clearance(body, poses[sub], polygons)
    return Check(
        poses=len(poses),
        overlaps=int(over.sum()),
        min_clearance=float(clr.min()),
        max_corner_step=float(move.max()) if len(move) else 0.0,
    )


def check_trajectory(traj, body: np.ndarray, polygons, step: float = 0.01) -> Check:
    """Exact body-vs-polygon check of a trajectory at ``step`` m of corner travel."""
    _, poses = trajectory_poses(traj, body, step)
    return check_poses(body, poses, polygons, step)


# ---------------------------------------------------------------------------- cases


def _u_kerb(x0: float, x1: float, y0: float, y1: float, t: float) -> np.ndarray:
    """A U-shaped kerb (non-convex) round ``[x0, x1] x [y0, y1]``, open at the top, ``t`` thick."""
    return np.array(
        [
            (x0 - t, y0 - t),
            (x1 + t, y0 - t),
            (x1 + t, y1),
            (x1, y1),
            (x1, y0),
            (x0, y0),
            (x0, y1),
            (x0 - t, y1),
        ]
    )


def _clear(car: Car, pose, polygons, margin: float) -> bool:
    p = np.array([pose])
    return not body_overlaps(car.body(), p, polygons)[0] and (
        body_clearance(car.body(), p, polygons)[0] >= margin
    )


def _row_of_cars(rng, x_from, x_to, direction, y_of, car: Car, gap) -> list[np.ndarray]:
    """Parallel-parked cars from ``x_from`` towards ``x_to`` (``direction`` +-1)."""
    out = []
    x = x_from
    while True:
        ln = car.length * rng.uniform(0.95, 1.05)
        wd = car.width * rng.uniform(0.95, 1.02)
        yaw = math.radians(rng.uniform(-1.5, 1.5))
        r = rect(0.0, 0.0, ln, wd, yaw)
        # place its near end at x, its kerb side at y_of(wd)
        xs = x - r[:, 0].min() if direction > 0 else x - r[:, 0].max()
        r = r + (xs, y_of(r))
        if (direction > 0 and r[:, 0].max() > x_to) or (direction < 0 and r[:, 0].min() < x_to):
            return out
        out.append(r)
        x = (r[:, 0].max() if direction > 0 else r[:, 0].min()) + direction * gap()


def _parallel(rng, car: Car, entry: str):
    s = car.scale
    L, W = car.length, car.width
    f = rng.uniform(1.2, 1.6)
    aisle = rng.uniform(*AISLE_M) * s
    slot0, slot1 = 0.0, f * L
    half = 4.0 * L
    x_lo, x_hi = 0.5 * f * L - half, 0.5 * f * L + half
    kerb_gap = lambda r: -r[:, 1].min() + rng.uniform(0.1, 0.3) * s  # noqa: E731
    gap = lambda: rng.uniform(0.6, 1.2) * s  # noqa: E731
    cars = _row_of_cars(rng, slot0, x_lo, -1, kerb_gap, car, gap)
    cars += _row_of_cars(rng, slot1, x_hi, +1, kerb_gap, car, gap)
    # the street ends just beyond the last parked cars
    x_lo = min(float(c[:, 0].min()) for c in cars) - gap()
    x_hi = max(float(c[:, 0].max()) for c in cars) + gap()
    row_top = max(float(c[:, 1].max()) for c in cars)
    y_top = row_top + aisle
    far_cars = []
    if rng.random() < 0.5:
        top = lambda r: y_top - r[:, 1].min()  # noqa: E731
        far_cars = _row_of_cars(rng, x_lo + rng.uniform(0.2, 1.0) * s, x_hi, +1, top, car, gap)
        y_wall = max(float(c[:, 1].max()) for c in far_cars) + rng.uniform(0.1, 0.3) * s
    else:
        y_wall = y_top
    t = 0.5 * s
    polys = [*cars, *far_cars, _u_kerb(x_lo, x_hi, 0.0, y_wall, t)]
    polys.append(
        np.array(
            [(x_lo - t, y_wall), (x_hi + t, y_wall), (x_hi + t, y_wall + t), (x_lo - t, y_wall + t)]
        )
    )
    # the goal: the body centred in the slot, 0.15-0.3 m (scaled) off the kerb
    gh = 0.0 if rng.random() < 0.5 else math.pi
    cx, cy = 0.5 * (slot0 + slot1), rng.uniform(0.15, 0.3) * s + 0.5 * W
    off = 0.5 * L - car.rear_offset  # rear axle to body centre
    goal = (cx - off * math.cos(gh), cy - off * math.sin(gh), gh)
    # the start: behind the slot along the goal heading (backwards entry) or ahead
    side = -1.0 if entry == "backwards" else 1.0
    sx_dir = side * math.cos(gh)  # +1: start at larger x
    bounds = (x_lo - t, -t, x_hi + t, y_wall + t)
    start_region = (cx + sx_dir * 0.5 * L, cx + sx_dir * 3.0 * L, row_top, y_top)
    return polys, bounds, goal, start_region, f, aisle, 0.0


def _bays(rng, car: Car, entry: str, angled: bool):
    s = car.scale
    L, W = car.length, car.width
    f = rng.uniform(1.15, 1.4)
    aisle = rng.uniform(*AISLE_M) * s
    alpha = math.radians(rng.uniform(45.0, 60.0) if angled else 90.0)
    d = np.array([-math.cos(alpha), -math.sin(alpha)])  # into the bay
    n = np.array([math.sin(alpha), -math.cos(alpha)])  # across it
    yaw = math.atan2(d[1], d[0])
    w = f * W
    half = 4.0 * L
    x_lo, x_hi = -half, half

    def place(centre_t: float, ln: float, wd: float, depth_gap: float) -> np.ndarray:
        r = rect(0.0, 0.0, ln, wd, yaw) + centre_t * n
        # slide along d until the corner nearest the aisle is depth_gap below y = 0
        return r + d * ((r[:, 1].max() + depth_gap) / math.sin(alpha))

    cars = []
    for side in (-1.0, 1.0):
        t_edge = 0.5 * w  # the free width's edge
        while True:
            wd = W * rng.uniform(0.95, 1.02)
            ln = L * rng.uniform(0.95, 1.05)
            r = place(side * (t_edge + 0.5 * wd), ln, wd, rng.uniform(0.05, 0.3) * s)
            if r[:, 0].min() < x_lo + 0.2 * s or r[:, 0].max() > x_hi - 0.2 * s:
                break
            cars.append(r)
            t_edge += wd + rng.uniform(0.2, 0.5) * W
    x_lo = min(float(c[:, 0].min()) for c in cars) - rng.uniform(0.2, 0.5) * W
    x_hi = max(float(c[:, 0].max()) for c in cars) + rng.uniform(0.2, 0.5) * W
    depth_gap = rng.uniform(0.1, 0.25) * s
    goal_body = place(0.0, L, W, depth_gap)
    y_back = min(float(c[:, 1].min()) for c in [*cars, goal_body]) - rng.uniform(0.15, 0.4) * s
    y_top = aisle
    far_cars = []
    gap = lambda: rng.uniform(0.6, 1.2) * s  # noqa: E731
    if rng.random() < 0.5:
        top = lambda r: y_top - r[:, 1].min()  # noqa: E731
        far_cars = _row_of_cars(rng, x_lo + rng.uniform(0.2, 1.0) * s, x_hi, +1, top, car, gap)
        y_wall = max(float(c[:, 1].max()) for c in far_cars) + rng.uniform(0.1, 0.3) * s
    else:
        y_wall = y_top
    t = 0.5 * s
    polys = [*cars, *far_cars, _u_kerb(x_lo, x_hi, y_back, y_wall, t)]
    polys.append(
        np.array(
            [(x_lo - t, y_wall), (x_hi + t, y_wall), (x_hi + t, y_wall + t), (x_lo - t, y_wall + t)]
        )
    )
    centre = goal_body.mean(axis=0)
    off = 0.5 * L - car.rear_offset
    gh = yaw if entry == "forwards" else yaw + math.pi
    gh = math.remainder(gh, 2 * math.pi)
    goal = (centre[0] - off * math.cos(gh), centre[1] - off * math.sin(gh), gh)
    bounds = (x_lo - t, y_back - t, x_hi + t, y_wall + t)
    sgn = 1.0 if rng.random() < 0.5 else -1.0
    start_region = (centre[0] + sgn * 0.5 * L, centre[0] + sgn * 3.0 * L, 0.0, y_top)
    return polys, bounds, goal, start_region, f, aisle, math.degrees(alpha)


def make_case(car: Car, category: str, entry: str, seed: int, index: int) -> ParkingCase:
    """One case of the suite (module docstring), drawn from ``default_rng([seed, index])``."""
    rng = np.random.default_rng([seed, index, CATEGORIES.index(category), ENTRIES.index(entry)])
    if category == "parallel":
        polys, bounds, goal, region, size, aisle, angle = _parallel(rng, car, entry)
    else:
        polys, bounds, goal, region, size, aisle, angle = _bays(
            rng, car, entry, category == "angled"
        )
    if not _clear(car, goal, polys, 0.0):
        raise RuntimeError(f"case {category}/{entry}/{index}: the goal body overlaps a polygon")
    L = car.length
    x0, x1, y0, y1 = region
    # inside the street, at least a car length from its ends
    x0, x1 = (float(np.clip(x, bounds[0] + L, bounds[2] - L)) for x in (x0, x1))
    for _ in range(500):
        h = (0.0 if rng.random() < 0.5 else math.pi) + rng.uniform(-0.35, 0.35)
        cx = rng.uniform(min(x0, x1), max(x0, x1))
        cy = rng.uniform(y0 + 0.35 * (y1 - y0), y1 - 0.35 * (y1 - y0))
        off = 0.5 * L - car.rear_offset
        start = (cx - off * math.cos(h), cy - off * math.sin(h), math.remainder(h, 2 * math.pi))
        if _clear(car, start, polys, 0.1 * car.scale):
            break
    else:
        raise RuntimeError(f"case {category}/{entry}/{index}: no clear start pose in 500 draws")
    return ParkingCase(
        case_id=f"{car.name}-{category}-{entry}-{index}",
        category=category,
        entry=entry,
        car=car,
        polygons=tuple(np.asarray(p, dtype=float) for p in polys),
        bounds=tuple(float(b) for b in bounds),
        start=tuple(float(v) for v in start),
        goal=tuple(float(v) for v in goal),
        size=float(size),
        aisle=float(aisle),
        angle=float(angle),
    )


def make_cases(car: Car, n: int, seed: int = 0) -> list[ParkingCase]:
    """``n`` cases, cycling through the categories and entries (parallel backwards first)."""
    kinds = [(c, e) for c in CATEGORIES for e in ENTRIES]
    return [make_case(car, *kinds[i % len(kinds)], seed, i // len(kinds)) for i in range(n)]


# ---------------------------------------------------------------------------- witnesses


def arc_poses(pose, kappa: float, length: float, direction: int, step: float) -> np.ndarray:
    """Rear-axle poses along a constant-curvature move, ``step`` m of travel apart at most.

    ``kappa`` (1/m, signed, 0 for a straight line) is the path's curvature in the body's
    frame, ``direction`` +1 forwards, -1 backwards.
    """
    x, y, th = pose
    n = max(2, math.ceil(length / step) + 1)
    s = np.linspace(0.0, length, n) * direction
    if abs(kappa) < 1e-12:
        return np.column_stack([x + s * math.cos(th), y + s * math.sin(th), np.full(n, th)])
    t = th + kappa * s
    return np.column_stack(
        [x + (np.sin(t) - math.sin(th)) / kappa, y - (np.cos(t) - math.cos(th)) / kappa, t]
    )


def cell_squares(case: ParkingCase, resolution: float, reach: float) -> list[np.ndarray]:
    """The occupied cells of ``case.grid(resolution)`` within ``reach`` (m, per axis) of the
    goal, as square polygons: what a planner that sees only the conservative grid avoids."""
    g = case.grid(resolution)
    ox, oy = g.origin
    gx, gy, _ = case.goal
    out = []
    for i, j in np.argwhere(np.asarray(g.occupied)):
        cx, cy = ox + (j + 0.5) * resolution, oy + (i + 0.5) * resolution
        if abs(cx - gx) < reach and abs(cy - gy) < reach:
            out.append(rect(cx, cy, resolution, resolution))
    return out


def reverse_s_family(case: ParkingCase, spacing: float):
    """Yield the one-manoeuvre entries into a parallel slot: ``(d, phi, poses)`` (m, rad, (n, 3)).

    Built backwards from the goal: back up ``d`` inside the slot, then drive forwards out on
    an arc of radius ``R`` towards the aisle through ``phi`` and on the opposite arc through
    ``phi``; driven in reverse this is the textbook reverse S into the slot. ``d`` from 0 in
    5 cm steps (scaled), ``phi`` from 88 degrees down to 10 in 2 degree steps; the poses'
    body corners at most ``spacing`` (m) apart; only entries whose last pose has the whole
    body above the slot's row of cars (in the aisle).
    """
    if case.category != "parallel":
        raise ValueError(f"a reverse-S entry needs a parallel case, got {case.category!r}")
    car = case.car
    body = car.body()
    R = car.turning_radius
    rc = float(np.max(np.hypot(body[:, 0], body[:, 1])))
    step = spacing / (1.0 + rc / R)
    gx, gy, gh = case.goal
    row_top = max(
        float(p[:, 1].max())
        for p in case.polygons
        if len(p) == 4 and p[:, 1].max() < gy + 2.0 * car.width
    )
    side = 1.0 if math.cos(gh) > 0 else -1.0  # the aisle is at +y: turn left facing +x
    for d in np.arange(0.0, 0.6 * car.length * (case.size - 1.0) + 1e-9, 0.05 * car.scale):
        back = arc_poses(case.goal, 0.0, float(d), -1, step)
        for phi in np.radians(np.arange(88.0, 8.0, -2.0)):
            a1 = arc_poses(tuple(back[-1]), side / R, R * phi, +1, step)
            a2 = arc_poses(tuple(a1[-1]), -side / R, R * phi, +1, step)
            if body_at(body, a2[-1:])[0][:, 1].min() < row_top:
                continue
            yield float(d), float(phi), np.vstack([back, a1, a2])


def reverse_s_entries(case: ParkingCase, obstacles=None) -> tuple[int, int]:
    """Count the entries of :func:`reverse_s_family` (corners 1 cm apart) that are clear.

    How many are clear of the polygons, and how many of those are also clear of
    ``obstacles`` (other polygons, e.g. :func:`cell_squares`; the same count without).
    """
    body = case.car.body()
    clear = both = 0
    for _, _, poses in reverse_s_family(case, 0.01):
        if body_overlaps(body, poses, case.polygons).any():
            continue
        clear += 1
        both += obstacles is None or not body_overlaps(body, poses, obstacles).any()
    return clear, both


def reverse_s_entry(case: ParkingCase) -> tuple[float, float] | None:
    """A one-manoeuvre entry into a parallel slot, if one is clear: ``(d, phi)`` (m, rad).

    The first entry of :func:`reverse_s_family` (corners 8 mm apart) whose poses are all
    clear of the polygons by :func:`body_overlaps`; None when there is none (a shorter slot
    needs more moves, or none exists). A witness that the slot end of the case is feasible,
    not a planner.
    """
    body = case.car.body()
    for d, phi, poses in reverse_s_family(case, 0.008):
        if not body_overlaps(body, poses, case.polygons).any():
            return d, phi
    return None


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description="parallel slots with a clear reverse-S entry")
    ap.add_argument("--car", choices=sorted(CARS), default="full")
    ap.add_argument("--limit", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--resolution",
        type=float,
        default=None,
        help="also count the entries clear of the conservative grid's cells at this resolution",
    )
    ap.add_argument("--cases", type=str, default=None, help="only these case ids (comma-separated)")
    args = ap.parse_args()
    found = 0
    par = [c for c in make_cases(CARS[args.car], args.limit, args.seed) if c.category == "parallel"]
    if args.cases:
        par = [c for c in par if c.case_id in args.cases.split(",")]
    for c in par:
        w = reverse_s_entry(c)
        found += w is not None
        how = f"d {w[0]:.2f} m, phi {math.degrees(w[1]):.0f} deg" if w else "none"
        line = f"{c.case_id}: slot {c.size:.2f} car lengths, reverse S entry: {how}"
        if args.resolution is not None and w is not None:
            cells = cell_squares(c, args.resolution, 3.0 * c.car.length)
            n, m = reverse_s_entries(c, cells)
            line += (
                f"; of the family {n} clear of the polygons, {m} of the {args.resolution} m cells"
            )
        print(line, flush=True)
    print(f"{found}/{len(par)} parallel slots have a clear one-manoeuvre (reverse S) entry")
