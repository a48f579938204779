"""The passage out of a tight bay: how narrow it is, and how many cusps a car needs through it.

A probe of one parking case of :mod:`parking_cases` (by default the suite's index 9,
``full-perpendicular-forwards-1``: a bay 1.20 car widths wide entered nose first off a 4.3 m
aisle, which :mod:`parking_feasibility` proves feasible at 2.5 cm cells), in two parts, both
tested against the obstacle polygons exactly (:func:`astar.bodies_distance`, the body's
distance to the polygons), never against a grid:

* **The passage** (:func:`passage_table`): for headings stepped away from the goal's, the
  rear-axle positions ``(x, y)`` on a 1 cm x 5 cm lattice (x across the aisle-bay axis of a
  perpendicular bay, y along it) whose body keeps ``--clearance`` from every polygon: per
  heading the band of ``y`` with a free position, the widest clearance, and the free ``x``
  interval at the ``y`` of that clearance. Where the interval's centre moves by more per
  degree than the car can move sideways (a car's rear axle moves sideways only at second
  order: through cusps), the passage is a thin tube that only many short moves follow.
* **An escape** (:func:`escape`): the library's :func:`astar.find_escape` (the car
  planner's last try: :mod:`trajopt.planning._car_escape`) from the goal pose, with its
  options (``--turn``, ``--rotation-weight``, ``--margin``, ``--room``, ``--cell``,
  ``--cell-deg``, ``--longest``, ``--max-expansions``; lengths in m for the full-size car,
  scaled by the car): a best-first search over continuous poses, arcs at ``1/(1.05 R)``
  and straight, every pose of every move ``--margin`` from the polygons exactly. The path
  (goal to the pose with room; driven backwards in time it enters the bay) is checked again
  by :func:`parking_cases.check_poses` at poses no body corner moves more than 1 cm
  between. A path it finds proves that a car path with that many cusps exists; it does not
  bound how few cusps a path needs.
* **The plan** (``--plan RESOLUTION``, :func:`plan_case`): ``trajopt.plan`` on the case,
  whose last try is that escape joined to an ordinary search, fitted and timed; its stages'
  times, cusps and the exact check of the trajectory.

Run: ``python benchmarks/bay_passage.py [--car full] [--case 9] [--turn both|ccw|cw]
[--rotation-weight 300] [--max-expansions 300000] [--no-escape] [--plan 0.1]`` (the escape
search of case 9 at the defaults, both senses in turn: about 180 000 expansions, 10-20 s on
a 2-core machine shared with other jobs; ``--turn ccw``, the sense the planner tries first
there: about 100 000, 7 s; the planner's own, whose stretches between cusps are at least 0.3
map cells long: 91 031).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import parking_cases as pc  # noqa: E402

import astar.escape as astar_escape  # noqa: E402
from astar.body_polygons import bodies_distance  # noqa: E402
from astar.reeds_shepp import advance  # noqa: E402


def passage_table(
    case: pc.ParkingCase,
    headings_deg: np.ndarray,
    clearance: float,
    x_span: tuple[float, float],
    y_span: tuple[float, float],
) -> list[tuple[float, float, float, float, float, float]]:
    """Per heading (deg): ``(heading, y_lo, y_hi, best clearance, x_lo, x_hi)`` (m), or NaNs.

    ``y_lo, y_hi``: the lattice's ``y`` rows with a free position (body clearance ``>=
    clearance``); ``x_lo, x_hi``: the free positions' extent on the row of the best clearance.
    """
    s = case.car.scale
    xs = np.arange(x_span[0], x_span[1], 0.01 * s)
    ys = np.arange(y_span[0], y_span[1], 0.05 * s)
    gx, gy = np.meshgrid(xs, ys)
    body = case.car.body()
    out = []
    for deg in headings_deg:
        th = math.radians(float(deg))
        poses = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, th)])
        d = bodies_distance(body, poses, case.polygons, 1.0 * s).reshape(gx.shape)
        ok = d >= clearance
        rows = np.flatnonzero(ok.any(axis=1))
        if not len(rows):
            out.append((float(deg), *([math.nan] * 5)))
            continue
        best = int(rows[np.argmax(d[rows].max(axis=1))])
        free_x = xs[ok[best]]
        out.append(
            (
                float(deg),
                float(ys[rows[0]]),
                float(ys[rows[-1]]),
                float(d[best].max()),
                float(free_x.min()),
                float(free_x.max()),
            )
        )
    return out


def escape(
    case: pc.ParkingCase,
    *,
    turns: tuple[float, ...] = (1.0, -1.0),
    rot_w: float = astar_escape.ROTATION_WEIGHT,
    margin: float | None = None,
    room: float | None = None,
    cell: float | None = None,
    cell_deg: float | None = None,
    longest: float | None = None,
    max_expansions: int = 300_000,
) -> dict:
    """Search an escape from the goal pose with :func:`astar.find_escape` (module docstring).

    Lengths in m for the full-size car (scaled by the car), None: the library's defaults
    (those of the planner's last try but ``room``: the planner gives 0.35 m scaled by
    ``1.05 R / 3 m``); arcs at ``1.05 R``. Returns a dict: ``found``, ``expanded``,
    ``seconds``, and when found ``cusps``, ``segments``, ``pieces`` (arcs after merging equal
    neighbours), ``length_m``, ``end`` (the pose with room), ``arcs`` (``(pieces, 5)``: per
    arc its start pose, curvature and signed length, m, rad, 1/m, from the goal outwards) and
    ``check`` (:func:`parking_cases.check_poses` of the path); when not found, ``reason``.
    """
    s = case.car.scale
    car = case.car
    fp = np.ascontiguousarray(car.body(), dtype=float)
    lengths = {"margin": margin, "room": room, "cell": cell, "longest": longest}
    kw = {k: v * s for k, v in lengths.items() if v is not None}
    if cell_deg is not None:
        kw["heading_cell"] = math.radians(cell_deg)
    t0 = time.perf_counter()
    try:
        esc = astar_escape.find_escape(
            fp,
            case.goal,
            case.polygons,
            1.05 * car.turning_radius,
            rotation_weight=rot_w,
            turns=turns,
            max_expansions=max_expansions,
            **kw,
        )
    except astar_escape.NoEscapeError as exc:
        seconds = time.perf_counter() - t0
        return {"found": False, "expanded": exc.expanded, "seconds": seconds, "reason": exc.reason}
    seconds = time.perf_counter() - t0
    res: dict = {"found": True, "expanded": esc.expanded, "seconds": seconds}
    # dense poses: the corner of the body farthest from the axle moves at most 5 mm per step
    rc = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    dense = [np.array([case.goal])]
    for x, y, th, k, ln in esc.pieces:
        m = max(1, math.ceil(abs(ln) * (1.0 + rc * abs(k)) / (0.005 * s)))
        q = ln * np.arange(1, m + 1) / m
        dense.append(np.array([advance.py_func(x, y, th, k, v) for v in q]))
    poses = np.vstack(dense)
    res.update(
        cusps=esc.cusps,
        segments=esc.cusps + 1,
        pieces=len(esc.pieces),
        length_m=esc.length,
        end=esc.end,
        arcs=np.array(esc.pieces),
        check=pc.check_poses(fp, poses, case.polygons, 0.01 * s),
    )
    return res


def main(argv: list[str] | None = None) -> int:
    """Run the probe (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--car", choices=sorted(pc.CARS), default="full")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--case", type=int, default=9, help="index in the suite (0-based)")
    ap.add_argument("--clearance", type=float, default=0.01, help="passage table (m, scaled)")
    ap.add_argument("--turn", choices=("both", "ccw", "cw"), default="both")
    ap.add_argument("--rotation-weight", type=float, default=300.0, help="cusps per radian")
    ap.add_argument("--margin", type=float, default=None, help="m, scaled (default: the library's)")
    ap.add_argument("--room", type=float, default=None, help="m, scaled (default: the library's)")
    ap.add_argument(
        "--longest", type=float, default=None, help="m, scaled (default: the library's)"
    )
    ap.add_argument("--cell", type=float, default=None, help="m, scaled (default: the library's)")
    ap.add_argument("--cell-deg", type=float, default=None)
    ap.add_argument("--max-expansions", type=int, default=300_000)
    ap.add_argument("--no-escape", action="store_true")
    ap.add_argument(
        "--plan",
        type=float,
        default=None,
        metavar="RESOLUTION",
        help="also run trajopt.plan on the case (its last try: the escape; plan_case)",
    )
    args = ap.parse_args(argv)
    car = pc.CARS[args.car]
    case = pc.make_cases(car, args.case + 1, args.seed)[args.case]
    s = car.scale
    gx, gy, gth = case.goal
    print(
        f"{case.case_id}: size {case.size:.3f}, aisle {case.aisle:.2f} m, goal "
        f"({gx:.3f}, {gy:.3f}, {math.degrees(gth):.1f} deg)"
    )
    sign = 1.0 if args.turn != "cw" else -1.0
    heads = math.degrees(gth) + sign * np.arange(2.0, 47.0, 3.0)
    x_span = (gx - 2.5 * s, gx + 2.5 * s)
    y_span = (gy, gy + 5.0 * s)
    print(f"passage (clearance >= {args.clearance} m; x across the bay, y along it):")
    print(f"{'heading':>8} {'y band':>15} {'best clr':>9} {'free x at best y':>18} {'centre':>7}")
    for deg, ylo, yhi, best, xlo, xhi in passage_table(
        case, heads, args.clearance * s, x_span, y_span
    ):
        print(
            f"{deg:8.1f} {ylo:7.2f}-{yhi:<7.2f} {best:9.3f} {xlo:8.2f} - {xhi:<7.2f} "
            f"{0.5 * (xlo + xhi):7.2f}"
        )
    if not args.no_escape:
        res = escape(
            case,
            turns={"both": (1.0, -1.0), "ccw": (1.0,), "cw": (-1.0,)}[args.turn],
            rot_w=args.rotation_weight,
            margin=args.margin,
            room=args.room,
            cell=args.cell,
            cell_deg=args.cell_deg,
            longest=args.longest,
            max_expansions=args.max_expansions,
        )
        if not res["found"]:
            print(
                f"escape: none ({res['reason']}) within {res['expanded']} expansions "
                f"({res['seconds']:.1f} s)"
            )
        else:
            chk = res["check"]
            ex, ey, eth = res["end"]
            print(
                f"escape: {res['cusps']} cusps ({res['pieces']} arcs), {res['length_m']:.1f} m "
                f"driven, to ({ex:.2f}, {ey:.2f}, {math.degrees(eth):.1f} deg); "
                f"{res['expanded']} expansions, {res['seconds']:.1f} s; exact check: "
                f"{chk.overlaps} overlapping of {chk.poses} poses, least clearance "
                f"{chk.min_clearance:.4f} m, largest corner step {chk.max_corner_step * 1e3:.1f} mm"
            )
    if args.plan is not None:
        print(plan_case(case, args.plan))
    return 0


def plan_case(case: pc.ParkingCase, resolution: float) -> str:
    """``trajopt.plan`` on the case at ``resolution`` (m): time, stages, cusps, exact check.

    The trajectory is checked by :func:`parking_cases.check_trajectory`. Returns a line of
    text.
    """
    import trajopt

    car = case.car
    grid = case.grid(resolution)
    t0 = time.perf_counter()
    try:
        traj = trajopt.plan(
            grid,
            case.start[:2],
            case.goal[:2],
            car.robot(),
            start_heading=case.start[2],
            goal_heading=case.goal[2],
        )
    except trajopt.TrajoptError as exc:
        return f"plan: {type(exc).__name__} after {time.perf_counter() - t0:.1f} s: {exc}"
    seconds = time.perf_counter() - t0
    st = traj.stats
    stages = ", ".join(f"{k} {v:.2f}" for k, v in st["stages_s"].items())
    chk = pc.check_trajectory(traj, car.body(), case.polygons)
    return (
        f"plan ({resolution} m grid): {seconds:.1f} s, {st['car']['cusps']} cusps, "
        f"{st['car']['segments']} fitted segments, {st['car']['expansions']} expansions, "
        f"stages s: {stages}; manoeuvre {float(traj.duration):.0f} s; last try: "
        f"{st['car']['tries'][-1]!r}; exact check: {chk.overlaps} overlapping of {chk.poses} "
        f"poses, least clearance {chk.min_clearance * 1e3:.1f} mm"
    )


if __name__ == "__main__":
    raise SystemExit(main())
