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
* **An escape** (:func:`escape`): a best-first search from the goal pose over continuous
  poses (no cell holds a single pose for its region: a state is dropped only when its cell of
  ``--cell`` m and ``--cell-deg`` degrees already holds one reached with no more cusps),
  driving arcs of curvature ``-1/(1.05 R)``, 0 and ``1/(1.05 R)`` forwards and backwards,
  5, 10, 25 and 50 cm long (scaled by the car) and as long as they stay clear (up to
  ``--longest`` m; none shorter than ``--shortest`` m), each arc tested at 1 cm steps with its body ``--margin`` m from the
  polygons (between two steps every body point moves at most ``1 cm (1 + r_c / (1.05 R))
  / 2``, under the default margin, so the whole arc is clear). Its order: the rotation made
  from the goal's heading towards ``--turn`` (counter-clockwise: ``ccw``) weighted
  ``--rotation-weight`` per radian, less one per cusp; it stops at the first pose whose body
  keeps ``--room`` m from every polygon (out of the bay, the car has room to turn). The path
  (goal to that pose; driven backwards in time it enters the bay) is checked again by
  :func:`parking_cases.check_poses` at poses no body corner moves more than 1 cm between.
  A path it finds proves that a car path with that many cusps exists; it does not bound
  how few cusps a path needs.
* **What if the planner had it** (``--plan RESOLUTION``, :func:`plan_with_escape`):
  ``trajopt.plan`` on the case with one of its searches answered by a real search from the
  start to the escape's end joined to the escape driven backwards in time, so that the
  planner's own fits, certificates and timing run on such a manoeuvre.

Run: ``python benchmarks/bay_passage.py [--car full] [--case 9] [--turn ccw|cw]
[--rotation-weight 300] [--shortest 0.05] [--max-expansions 400000] [--no-escape]
[--plan 0.1]`` (the escape search of case 9 at the defaults: 0.5-1.5 min on a 2-core
machine).
"""

from __future__ import annotations

import argparse
import heapq
import math
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit, types
from numba.typed import Dict

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import parking_cases as pc  # noqa: E402

from astar.body_polygons import bodies_distance, body_distance, pack_polygons  # noqa: E402

#: Fixed move lengths of the escape search (m, for the full-size car; scaled by the car).
MOVES_M = (0.05, 0.1, 0.25, 0.5)
#: Step (m, scaled) at which the escape search tests its arcs.
STEP_M = 0.01


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


@njit(cache=False)
def _advance(x, y, th, k, s):  # pragma: no cover - compiled
    if k == 0.0:
        return x + s * math.cos(th), y + s * math.sin(th), th
    t = th + k * s
    return x + (math.sin(t) - math.sin(th)) / k, y - (math.cos(t) - math.cos(th)) / k, t


@njit(cache=False)
def _clearance(edges, starts, boxes, fp, x, y, th, cap, buf):  # pragma: no cover - compiled
    c = math.cos(th)
    s = math.sin(th)
    for j in range(fp.shape[0]):
        buf[j, 0] = x + c * fp[j, 0] - s * fp[j, 1]
        buf[j, 1] = y + s * fp[j, 0] + c * fp[j, 1]
    return body_distance(edges, starts, boxes, buf, cap)


@njit(cache=False)
def _reach(
    edges, starts, boxes, fp, x, y, th, k, d, longest, step, margin, buf
):  # pragma: no cover
    """The longest clear length (a multiple of ``step``, at most ``longest``) of an arc."""
    n = int(longest / step)
    best = 0.0
    for i in range(1, n + 1):
        px, py, pt = _advance(x, y, th, k, d * i * step)
        if _clearance(edges, starts, boxes, fp, px, py, pt, 2.0 * margin + 1.0, buf) < margin:
            return best
        best = i * step
    return best


@njit(cache=False)
def _search(
    edges,
    starts,
    boxes,
    fp,
    goal,
    kmax,
    moves,
    longest,
    step,
    margin,
    room,
    cell,
    cell_th,
    rot_w,
    turn,
    max_exp,
    shortest,
):  # pragma: no cover - compiled
    buf = np.empty((fp.shape[0], 2))
    cap = 4 * max_exp + 16
    xs = np.empty(cap)
    ys = np.empty(cap)
    ts = np.empty(cap)
    cusps = np.zeros(cap, np.int64)
    parent = np.full(cap, -1, np.int64)
    dirs = np.zeros(cap, np.int8)
    kap = np.zeros(cap)
    lens = np.zeros(cap)
    xs[0], ys[0], ts[0] = goal[0], goal[1], goal[2]
    n = 1
    best_cusps = Dict.empty(types.int64, types.int64)
    heap = [(0.0, 0)]
    done = np.zeros(cap, np.bool_)
    expanded = 0
    while len(heap) > 0 and expanded < max_exp:
        _, i = heapq.heappop(heap)
        if done[i]:
            continue
        done[i] = True
        expanded += 1
        if _clearance(edges, starts, boxes, fp, xs[i], ys[i], ts[i], room + 1.0, buf) >= room:
            return i, expanded, xs[:n], ys[:n], ts[:n], parent[:n], dirs[:n], kap[:n], lens[:n]
        for d in (-1, 1):
            for kk in (-1.0, 0.0, 1.0):
                k = kk * kmax
                far = _reach(
                    edges, starts, boxes, fp, xs[i], ys[i], ts[i], k, d, longest, step, margin, buf
                )
                for j in range(moves.shape[0] + 1):
                    s = moves[j] if j < moves.shape[0] else far
                    if s > far or s < shortest or (j < moves.shape[0] and s == far):
                        continue
                    x, y, t = _advance(xs[i], ys[i], ts[i], k, d * s)
                    key = (
                        np.int64(round(x / cell)) * 1000003 + np.int64(round(y / cell))
                    ) * 1000003 + np.int64(round(t / cell_th))
                    c = cusps[i] + (1 if dirs[i] != 0 and dirs[i] != d else 0)
                    if key in best_cusps and best_cusps[key] <= c:
                        continue
                    best_cusps[key] = c
                    if n >= cap:
                        return (
                            -1,
                            expanded,
                            xs[:n],
                            ys[:n],
                            ts[:n],
                            parent[:n],
                            dirs[:n],
                            kap[:n],
                            lens[:n],
                        )
                    xs[n], ys[n], ts[n] = x, y, t
                    cusps[n], parent[n], dirs[n], kap[n], lens[n] = c, i, d, k, s
                    heapq.heappush(heap, (c - rot_w * turn * (t - goal[2]), n))
                    n += 1
    return -1, expanded, xs[:n], ys[:n], ts[:n], parent[:n], dirs[:n], kap[:n], lens[:n]


def escape(
    case: pc.ParkingCase,
    *,
    turn: float = 1.0,
    rot_w: float = 300.0,
    margin: float = 0.012,
    room: float = 0.35,
    cell: float = 0.015,
    cell_deg: float = 0.25,
    longest: float = 0.6,
    max_expansions: int = 400_000,
    shortest: float = 0.0,
) -> dict:
    """Search an escape from the goal pose (module docstring); lengths in m for the full car.

    Returns a dict: ``found``, ``expanded``, ``seconds``, and when found ``cusps``,
    ``segments``, ``pieces`` (arcs after merging equal neighbours), ``length_m``,
    ``end`` (the pose with room), ``arcs`` (``(pieces, 5)``: per arc its start pose, curvature
    and signed length, m, rad, 1/m, from the goal outwards) and ``check``
    (:func:`parking_cases.check_poses` of the path).
    """
    s = case.car.scale
    car = case.car
    fp = np.ascontiguousarray(car.body(), dtype=float)
    edges, starts, boxes = pack_polygons(case.polygons)
    kmax = 1.0 / (1.05 * car.turning_radius)
    moves = np.array(MOVES_M) * s
    t0 = time.perf_counter()
    out = _search(
        edges, starts, boxes, fp, np.array(case.goal, dtype=float), kmax, moves, longest * s,
        STEP_M * s, margin * s, room * s, cell * s, math.radians(cell_deg), rot_w, turn,
        max_expansions, max(shortest, 0.5 * STEP_M) * s,
    )  # fmt: skip
    seconds = time.perf_counter() - t0
    last, expanded = int(out[0]), int(out[1])
    res: dict = {"found": last >= 0, "expanded": expanded, "seconds": seconds}
    if last < 0:
        return res
    xs, ys, ts, parent, dirs, kap, lens = out[2:]
    arcs = []
    i = last
    while parent[i] >= 0:
        p = parent[i]
        arcs.append([xs[p], ys[p], ts[p], kap[i], dirs[i] * lens[i]])
        i = p
    arcs.reverse()
    merged: list[list[float]] = []
    for a in arcs:
        if merged and merged[-1][3] == a[3] and (merged[-1][4] < 0) == (a[4] < 0):
            merged[-1][4] += a[4]
        else:
            merged.append(list(a))
    cusps = sum((a[4] < 0) != (b[4] < 0) for a, b in zip(merged, merged[1:], strict=False))
    # dense poses: the corner of the body farthest from the axle moves at most 5 mm per step
    rc = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    dense = [np.array([case.goal])]
    for x, y, th, k, ln in merged:
        m = max(1, math.ceil(abs(ln) * (1.0 + rc * abs(k)) / (0.005 * s)))
        q = ln * np.arange(1, m + 1) / m
        dense.append(np.array([_advance.py_func(x, y, th, k, v) for v in q]))
    poses = np.vstack(dense)
    res.update(
        cusps=int(cusps),
        segments=int(cusps) + 1,
        pieces=len(merged),
        length_m=float(sum(abs(a[4]) for a in merged)),
        end=tuple(float(v) for v in (xs[last], ys[last], ts[last])),
        arcs=np.array(merged, dtype=float).reshape(-1, 5),
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
    ap.add_argument("--turn", choices=("ccw", "cw"), default="ccw")
    ap.add_argument("--rotation-weight", type=float, default=300.0, help="cusps per radian")
    ap.add_argument("--margin", type=float, default=0.012, help="m, scaled")
    ap.add_argument("--room", type=float, default=0.35, help="m, scaled")
    ap.add_argument("--longest", type=float, default=0.6, help="m, scaled")
    ap.add_argument("--cell", type=float, default=0.015, help="m, scaled")
    ap.add_argument("--cell-deg", type=float, default=0.25)
    ap.add_argument("--max-expansions", type=int, default=400_000)
    ap.add_argument("--shortest", type=float, default=0.0, help="shortest arc (m, scaled)")
    ap.add_argument("--no-escape", action="store_true")
    ap.add_argument(
        "--plan",
        type=float,
        default=None,
        metavar="RESOLUTION",
        help="also run trajopt.plan with the escape as its search's answer (plan_with_escape)",
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
    sign = 1.0 if args.turn == "ccw" else -1.0
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
    if args.no_escape:
        return 0
    res = escape(
        case,
        turn=sign,
        rot_w=args.rotation_weight,
        margin=args.margin,
        room=args.room,
        cell=args.cell,
        cell_deg=args.cell_deg,
        longest=args.longest,
        max_expansions=args.max_expansions,
        shortest=args.shortest,
    )
    if not res["found"]:
        print(f"escape: none within {res['expanded']} expansions ({res['seconds']:.1f} s)")
        return 0
    chk = res["check"]
    ex, ey, eth = res["end"]
    print(
        f"escape: {res['cusps']} cusps ({res['pieces']} arcs), {res['length_m']:.1f} m driven, "
        f"to ({ex:.2f}, {ey:.2f}, {math.degrees(eth):.1f} deg); {res['expanded']} expansions, "
        f"{res['seconds']:.1f} s (with compilation); exact check: {chk.overlaps} overlapping "
        f"of {chk.poses} poses, least clearance {chk.min_clearance:.4f} m, largest corner step "
        f"{chk.max_corner_step * 1e3:.1f} mm"
    )
    if args.plan is not None:
        out = plan_with_escape(case, res["arcs"], args.plan)
        print(out)
    return 0


def plan_with_escape(case: pc.ParkingCase, arcs: np.ndarray, resolution: float) -> str:
    """What if the planner's search returned the escape: ``trajopt.plan`` fits and times it.

    ``trajopt.plan`` runs on the case's grid at ``resolution`` (m) with its tries as they are,
    but for one: its first search at ``1.05 R`` on the radius grid (``footprint_min_slack``
    given, no ``fine_radius``) is answered by :func:`astar.find_pose_path` from the start
    to the escape's end pose, with that try's own arguments, followed by the escape driven
    backwards in time (each arc from its end, its length negated), as one
    :class:`astar.PosePath` (:func:`astar.hybrid_shortcut.resample`). The plan's budget
    (``_car_tries.CAR_BUDGET_S``) is lifted. Everything after the search is the planner's:
    the fits of every segment, their certificates, the timing; the trajectory is then
    checked by :func:`parking_cases.check_trajectory`. Returns a line of text.
    """
    import astar
    import trajopt
    import trajopt.planning._car_tries as tries
    from astar.hybrid_shortcut import resample
    from astar.reeds_shepp import advance

    car = case.car
    grid = case.grid(resolution)
    ox, oy = grid.origin
    back = []  # the escape driven backwards in time, in the search's cells (map-local)
    for x, y, th, k, ln in arcs[::-1]:
        ex, ey, eth = advance.py_func(x, y, th, k, ln)
        back.append(
            [
                (ex - ox) / resolution - 0.5,
                (ey - oy) / resolution - 0.5,
                eth,
                k * resolution,
                -ln / resolution,
            ]
        )
    back_arr = np.array(back)
    search = astar.find_pose_path
    used = {"connection": None}
    r_tight = 1.05 * car.turning_radius / resolution

    def answered(grid_, start, goal, **kw):
        tight = kw.get("footprint_min_slack") is not None and "fine_radius" not in kw
        if used["connection"] is None and tight and abs(kw["turning_radius"] - r_tight) < 1e-9:
            first = search(grid_, start, tuple(back_arr[0, :3]), **kw)
            used["connection"] = first.cusps
            b = back_arr.copy()
            b[:, 2] += 2.0 * math.pi * round((first.poses[-1, 2] - b[0, 2]) / (2.0 * math.pi))
            end_th = float(advance.py_func(*b[-1])[2])
            gth = goal[2] + 2.0 * math.pi * round((end_th - goal[2]) / (2.0 * math.pi))
            arrays = resample(
                np.vstack([np.asarray(first.pieces), b]), 0.5, (goal[0], goal[1], gth)
            )
            return astar.PosePath(*arrays, kw["turning_radius"], dict(first.stats))
        return search(grid_, start, goal, **kw)

    budget = tries.CAR_BUDGET_S
    tries.astar.find_pose_path = answered
    tries.CAR_BUDGET_S = math.inf
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
    finally:
        tries.astar.find_pose_path = search
        tries.CAR_BUDGET_S = budget
    seconds = time.perf_counter() - t0
    st = traj.stats
    stages = ", ".join(f"{k} {v:.2f}" for k, v in st["stages_s"].items())
    chk = pc.check_trajectory(traj, car.body(), case.polygons)
    return (
        f"plan ({resolution} m grid): {seconds:.1f} s, {st['car']['cusps']} cusps, "
        f"{st['car']['segments']} fitted segments (the connection {used['connection']} cusps), "
        f"stages s: {stages}; manoeuvre {float(traj.duration):.0f} s; exact check: "
        f"{chk.overlaps} overlapping of {chk.poses} poses, least clearance "
        f"{chk.min_clearance * 1e3:.1f} mm"
    )


if __name__ == "__main__":
    raise SystemExit(main())
