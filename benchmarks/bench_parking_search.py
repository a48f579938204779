"""Parking manoeuvres of car bodies: the Hybrid-A* search alone and ``trajopt.plan``.

Cases (issue 45, part 3), each a rectangular body (``Robot.rectangle``, the reference point
``rear_offset`` from the back) from a pose in the lane or aisle (heading 0) to a pose in the
slot:

* ``body``: the body car of ``tests/trajopt/planning/test_car.py`` (0.6 x 0.3 m,
  ``rear_offset`` 0.1 m, ``R = 0.6 m``) and ``small``: a 0.88 x 0.4 m car (``rear_offset``
  0.18 m, ``R = 0.5 m``), each into parallel slots 1.25, 1.3, 1.4 and 1.5 car lengths long,
  1.35 car widths deep, beside a lane 2.75 car widths wide, on 2.5 cm cells;
* ``full``: a full-size car 4.69 x 1.94 m (``rear_offset`` 0.96 m, wheelbase 2.8 m,
  ``R = 3.0 m``) into a parallel slot 1.3 car lengths long and into a perpendicular bay 1.3
  car widths wide beside a 5.5 m aisle, backwards (facing out) and forwards (nose in), on
  0.1 m cells.

Per case: ``search`` runs :func:`astar.find_pose_path` as the car planner's first try does
(``trajopt.planning._car_tries``: its search grid, ``1.15 R``, the footprint mode with its
margin and slack; ``--factor`` changes the radius factor) and reports success, seconds,
expansions and cusps; ``plan`` runs ``trajopt.plan`` (the whole pipeline: tries, fits,
timing) and reports success and seconds. Numba's compilation is paid before the timings.

Run: ``PYTHONPATH=. python benchmarks/bench_parking_search.py [--only NAME ...]
[--no-plan] [--budget S]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass

import numpy as np

import astar
import trajopt
from trajopt.planning import _car_tries


@dataclass(frozen=True)
class Case:
    """One parking query: a raw grid, a body car and its end poses (m, rad)."""

    name: str
    grid: astar.OccupancyGrid
    robot: trajopt.Robot
    start: tuple[float, float, float]
    goal: tuple[float, float, float]


def car(length: float, width: float, rear: float, radius: float, wheelbase: float | None = None):
    """A rectangular car body (m) with an Ackermann drive of turning radius ``radius`` (m)."""
    return trajopt.Robot.rectangle(
        length,
        width,
        rear_offset=rear,
        drive=trajopt.Ackermann(min_turning_radius=radius, wheelbase=wheelbase),
    )


def parallel_case(name, robot, length, width, rear, ratio, res) -> Case:
    """A parallel slot ``ratio`` car lengths long between parked cars, a lane above it."""
    wall = res
    depth = 1.35 * width
    lane = 2.75 * width
    slot = ratio * length
    x0 = 2.0 * length
    size_x = x0 + slot + 2.0 * length
    size_y = wall + depth + lane + wall
    nx, ny = round(size_x / res), round(size_y / res)
    occ = np.zeros((ny, nx), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[: round((wall + depth) / res), :] = True  # the parked cars and the kerb
    occ[
        round(wall / res) : round((wall + depth) / res), round(x0 / res) : round((x0 + slot) / res)
    ] = False
    grid = astar.OccupancyGrid(occ, res)
    start = (x0 - 1.0 * length + rear, wall + depth + 0.5 * lane, 0.0)
    goal = (x0 + 0.5 * (slot - length) + rear, wall + 0.5 * depth, 0.0)
    return Case(name, grid, robot, start, goal)


def bay_case(name, robot, length, width, rear, ratio, aisle, res, backwards) -> Case:
    """A perpendicular bay ``ratio`` car widths wide between parked cars, an aisle above it."""
    wall = res
    depth = length + 0.5
    bay = ratio * width
    x0 = 3.0 * length
    size_x = x0 + bay + 3.0 * length
    size_y = wall + depth + aisle + wall
    nx, ny = round(size_x / res), round(size_y / res)
    occ = np.zeros((ny, nx), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[: round((wall + depth) / res), :] = True
    occ[
        round(wall / res) : round((wall + depth) / res), round(x0 / res) : round((x0 + bay) / res)
    ] = False
    grid = astar.OccupancyGrid(occ, res)
    start = (x0 - 1.5 * length, wall + depth + 0.5 * aisle, 0.0)
    gx = x0 + 0.5 * bay
    if backwards:  # backed in, facing out: the rear edge 0.25 m from the back
        goal = (gx, wall + 0.25 + rear, math.pi / 2)
    else:  # nose first: the front edge 0.25 m from the back
        goal = (gx, wall + 0.25 + (length - rear), -math.pi / 2)
    return Case(name, grid, robot, start, goal)


def angled_case(name, robot, length, width, rear, ratio, aisle, angle, res, backwards, start):
    """A bay ``ratio`` car widths wide at ``angle`` (rad) to the aisle, parked cars round it.

    The bay is the rectangle (``ratio * width`` by ``length + 0.5`` m) whose axis points into
    the solid row below the aisle at ``angle`` from the aisle's direction; a cell is free in
    it when its centre keeps half a cell's diagonal inside the rectangle (the map is
    conservative). ``start``: the start pose (m, m, rad).
    """
    wall = res
    depth = length + 0.5
    bay = ratio * width
    size_x = 30.0
    row = depth * math.sin(angle) + bay + 0.5  # the solid row's depth
    size_y = wall + row + aisle + wall
    nx, ny = round(size_x / res), round(size_y / res)
    occ = np.zeros((ny, nx), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    edge = wall + row
    occ[: round(edge / res), :] = True
    ux, uy = math.cos(-angle), math.sin(-angle)  # into the bay
    nx_, ny_ = -uy, ux
    ex, ey = 18.0, edge  # where the bay's axis meets the aisle's edge
    yy, xx = np.mgrid[0:ny, 0:nx]
    px, py = (xx + 0.5) * res - ex, (yy + 0.5) * res - ey
    along = px * ux + py * uy
    across = px * nx_ + py * ny_
    half = 0.5 * math.sqrt(2.0) * res
    inside = (along >= -bay) & (along <= depth - half) & (np.abs(across) <= 0.5 * bay - half)
    occ[inside & (yy > 0)] = False
    grid = astar.OccupancyGrid(occ, res)
    if backwards:
        s = depth - 0.3 - rear
        goal = (ex + s * ux, ey + s * uy, math.atan2(-uy, -ux))
    else:
        s = depth - 0.3 - (length - rear)
        goal = (ex + s * ux, ey + s * uy, math.atan2(uy, ux))
    return Case(name, grid, robot, (start[0], edge + start[1], start[2]), goal)


def suite(n: int, seed: int, res: float) -> list[Case]:
    """Random parking cases of the full-size car (a suite like issue 45's part 1).

    Per case, seeded: a parallel slot 1.2-1.6 lengths long beside a lane 1.8-2.8 widths wide,
    or a bay 1.15-1.4 widths wide at 90, 60 or 45 degrees off an aisle 4-7 m wide, entered
    backwards or forwards; the start in the lane or aisle, 4-9 m before the slot, its heading
    within 30 degrees of the lane's (backwards too: within 30 degrees of its reverse).
    """
    rng = np.random.default_rng(seed)
    ln, wd, rear = 4.69, 1.94, 0.96
    robot = car(ln, wd, rear, 3.0, wheelbase=2.8)
    out = []
    for k in range(n):
        kind = rng.choice(["parallel", "bay90", "bay60", "bay45"])
        back = bool(rng.integers(2))
        h0 = float(rng.uniform(-0.5, 0.5)) + (math.pi if rng.random() < 0.25 else 0.0)
        if kind == "parallel":
            ratio = float(rng.uniform(1.2, 1.6))
            c = parallel_case(f"s{k}-parallel-{ratio:.2f}", robot, ln, wd, rear, ratio, res)
            lane_y = c.start[1]
            c = Case(
                c.name, c.grid, robot, (c.start[0] - float(rng.uniform(0, 3)), lane_y, h0), c.goal
            )
        else:
            angle = {"bay90": 90.0, "bay60": 60.0, "bay45": 45.0}[kind] * math.pi / 180.0
            ratio = float(rng.uniform(1.15, 1.4))
            aisle = float(rng.uniform(4.0, 7.0))
            start = (18.0 - float(rng.uniform(4.0, 9.0)), 0.5 * aisle, h0)
            tag = "back" if back else "fwd"
            c = angled_case(
                f"s{k}-{kind}-{ratio:.2f}-a{aisle:.1f}-{tag}", robot, ln, wd, rear, ratio,
                aisle, angle, res, back, start,
            )  # fmt: skip
        out.append(c)
    return out


def cases() -> list[Case]:
    """The benchmark's cases (module docstring)."""
    out = []
    body = (0.6, 0.3, 0.1, 0.6)
    small = (0.88, 0.4, 0.18, 0.5)
    for tag, (ln, wd, rear, rad) in (("body", body), ("small", small)):
        robot = car(ln, wd, rear, rad)
        for ratio in (1.25, 1.3, 1.4, 1.5):
            out.append(
                parallel_case(f"{tag}-parallel-{ratio:g}", robot, ln, wd, rear, ratio, 0.025)
            )
    full = car(4.69, 1.94, 0.96, 3.0, wheelbase=2.8)
    out.append(parallel_case("full-parallel-1.3", full, 4.69, 1.94, 0.96, 1.3, 0.1))
    for backwards in (True, False):
        tag = "back" if backwards else "fwd"
        out.append(
            bay_case(f"full-bay-1.3-{tag}", full, 4.69, 1.94, 0.96, 1.3, 5.5, 0.1, backwards)
        )
    return out


def to_cells(grid: astar.OccupancyGrid, pose) -> tuple[float, float, float]:
    """A world pose (m, m, rad) in the search's cell units."""
    return (
        (pose[0] - grid.origin[0]) / grid.resolution - 0.5,
        (pose[1] - grid.origin[1]) / grid.resolution - 0.5,
        pose[2],
    )


def run_search(case: Case, factor: float, budget: float) -> dict:
    """The car planner's first search try on ``case`` (module docstring)."""
    grid, robot = case.grid, case.robot
    sgrid = _car_tries.car_search_grid(robot, grid, margin=True)
    kw = _car_tries.exact_clearance(robot, grid, True)
    t0 = time.perf_counter()
    try:
        path = astar.find_pose_path(
            sgrid,
            to_cells(grid, case.start),
            to_cells(grid, case.goal),
            turning_radius=factor * robot.drive.min_turning_radius / grid.resolution,
            time_budget=budget,
            **kw,
        )
    except astar.NoPosePathError as exc:
        return {"ok": False, "s": time.perf_counter() - t0, "why": exc.reason, **exc.stats}
    except astar.InvalidInputError as exc:
        return {"ok": False, "s": time.perf_counter() - t0, "why": f"refused: {exc}"}
    return {"ok": True, "s": time.perf_counter() - t0, "cusps": path.cusps, **path.stats}


def run_plan(case: Case) -> dict:
    """``trajopt.plan`` on ``case``: success, seconds, cusps, tries."""
    t0 = time.perf_counter()
    try:
        traj = trajopt.plan(
            case.grid,
            case.start[:2],
            case.goal[:2],
            case.robot,
            start_heading=case.start[2],
            goal_heading=case.goal[2],
        )
    except Exception as exc:  # noqa: BLE001 - a benchmark reports every failure by its type
        return {"ok": False, "s": time.perf_counter() - t0, "why": type(exc).__name__}
    car_stats = traj.stats["car"]
    return {
        "ok": True,
        "s": time.perf_counter() - t0,
        "cusps": car_stats["cusps"],
        "tries": len(car_stats["tries"]),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", help="substrings of case names to run")
    ap.add_argument("--no-plan", action="store_true", help="the search alone")
    ap.add_argument("--factor", type=float, default=1.15, help="search radius / R")
    ap.add_argument("--budget", type=float, default=2.0, help="search time budget (s)")
    ap.add_argument("--suite", type=int, default=0, help="random full-size cases instead")
    ap.add_argument("--seed", type=int, default=0, help="seed of --suite")
    ap.add_argument("--res", type=float, default=0.1, help="cell size of --suite (m)")
    args = ap.parse_args(argv)
    todo = suite(args.suite, args.seed, args.res) if args.suite else cases()
    todo = [c for c in todo if not args.only or any(o in c.name for o in args.only)]
    # pay numba's compilation (and the cache load) before timing
    warm = parallel_case("warm", car(0.6, 0.3, 0.1, 0.6), 0.6, 0.3, 0.1, 2.5, 0.05)
    run_search(warm, 1.15, 2.0)
    print(f"{'case':24s} {'search':>22s} {'exp':>7s} {'cusps':>5s}   {'plan':>16s}")
    rows = []
    for case in todo:
        s = run_search(case, args.factor, args.budget)
        line = f"{case.name[:24]:24s} "
        line += f"{'ok' if s['ok'] else s['why'][:12]:>12s} {s['s'] * 1e3:7.0f} ms "
        line += f"{s.get('expanded', 0):7d} {s.get('cusps', '-')!s:>5s}"
        p = None
        if not args.no_plan and not str(s.get("why", "")).startswith("refused"):
            p = run_plan(case)
            line += f"   {'ok' if p['ok'] else p['why'][:12]:>12s} {p['s'] * 1e3:6.0f} ms"
            if p["ok"]:
                line += f" cusps {p['cusps']} tries {p['tries']}"
        print(line, flush=True)
        rows.append((s, p))
    done = [r for r in rows if not str(r[0].get("why", "")).startswith("refused")]
    for col, name in ((0, "search"), (1, "plan")):
        got = [r[col] for r in done if r[col] is not None]
        if got:
            ok = [g["s"] for g in got if g["ok"]]
            q = np.percentile(ok, [50, 95]) * 1e3 if ok else [math.nan] * 2
            print(
                f"{name}: {len(ok)} of {len(got)} ok (refused end poses: {len(rows) - len(done)}); "
                f"median {q[0]:.0f} ms, p95 {q[1]:.0f} ms"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
