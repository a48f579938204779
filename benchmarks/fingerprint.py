"""A fingerprint of plans through the public API, to show a restructuring changes no result.

Plans a fixed set of queries for every drive (differential disc and footprint, pose to pose,
omni disc and rectangle, car forwards and with reversing, a car with a body), re-plans
(keep, plan, new goal), a costmap plan, a speed-zone plan, the stop-and-turn fallback and a
handful of refused inputs, and hashes what a user can read from each answer: the class, the
duration, 400 samples of every field, the number of pieces, and for refusals the error type
and message. Timings (``stats[...]["*_s"]``) are left out: they change from run to run.

Usage::

    python benchmarks/fingerprint.py --out /tmp/before.json
    python benchmarks/fingerprint.py --compare /tmp/before.json   # exit 1 on any difference
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
from collections.abc import Callable

import numpy as np

import astar
import trajopt


def walled(width: float, height: float, res: float) -> np.ndarray:
    occ = np.zeros((round(height / res), round(width / res)), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def door_grid() -> astar.OccupancyGrid:
    """60 x 40 cells of 5 cm: a wall at x = 1.5 m with a 0.6 m door, a block below."""
    occ = np.zeros((40, 60), bool)
    occ[:, 30] = True
    occ[16:28, 30] = False
    occ[5:12, 40:50] = True
    return astar.OccupancyGrid(occ, 0.05)


def zigzag_grid(gap: int = 5, legs: int = 6, leg: int = 6):
    """A staircase corridor the box corridor cannot smooth for a 0.12 m disc."""
    size = 2 * gap + legs * leg + 10
    occ = np.ones((size, size), bool)
    x = y = 3
    for k in range(legs):
        if k % 2 == 0:
            occ[y : y + gap, x : x + leg + gap] = False
            x += leg
        else:
            occ[y : y + leg + gap, x : x + gap] = False
            y += leg
    res = 0.05
    start = ((3 + gap / 2) * res + 0.004, (3 + gap / 2) * res + 0.003)
    goal = ((x + gap / 2) * res, (y + gap / 2) * res - 0.004)
    return astar.OccupancyGrid(occ, res), start, goal


def bay_grid() -> astar.OccupancyGrid:
    res = 0.05
    occ = walled(5.0, 3.0, res)
    occ[: round(1.0 / res), :] = True
    occ[round(0.1 / res) : round(1.0 / res), round(2.0 / res) : round(2.45 / res)] = False
    return astar.OccupancyGrid(occ, res)


def digest(result: object) -> dict[str, object]:
    """Everything a user reads from a plan, hashed (exact bits)."""
    h = hashlib.sha256()
    duration = float(result.duration)
    t = np.linspace(0.0, duration, 400)
    smp = result.sample(t)
    for key, value in smp.as_dict().items():
        h.update(key.encode())
        h.update(np.ascontiguousarray(np.asarray(value, dtype=float)).tobytes())
    for tq in (0.0, 0.37 * duration, duration):
        st = result.state_at(tq)
        h.update(repr(st).encode())
    pieces = getattr(result, "pieces", None)
    return {
        "type": type(result).__name__,
        "duration": duration.hex(),
        "pieces": None if pieces is None else [type(p).__name__ for p in pieces],
        "samples": h.hexdigest(),
    }


def refusal(fn: Callable[[], object]) -> dict[str, object]:
    try:
        result = fn()
    except Exception as exc:  # noqa: BLE001 - the error is the fingerprint
        return {"error": type(exc).__name__, "message": str(exc)}
    return {"error": None, **digest(result)}


def cases() -> dict[str, Callable[[], object]]:
    paper = trajopt.scenes.paper()
    grid = paper.grid
    sp, targets = paper.start, paper.targets
    door = door_grid()
    out: dict[str, Callable[[], object]] = {}
    disc = trajopt.Robot()
    for name, goal in targets.items():
        out[f"paper_{name}"] = lambda g=goal: trajopt.plan(grid, sp, g, disc)
    out["paper_boxes"] = lambda: trajopt.plan(grid, sp, targets["D"], disc, corridor="boxes")
    out["paper_kappa"] = lambda: trajopt.Planner(
        grid, disc, smoother=trajopt.Smoother(kappa_max=2.0)
    ).plan(sp, targets["C"])
    out["paper_pose"] = lambda: trajopt.plan(
        grid, sp, targets["B"], disc, start_heading=math.pi, goal_heading=-math.pi / 2
    )
    out["paper_pose_soft"] = lambda: trajopt.plan(
        grid, sp, targets["A"], disc, start_heading=0.3, goal_heading=0.2
    )
    rect = trajopt.Robot.rectangle(0.45, 0.2)
    out["door_rect"] = lambda: trajopt.plan(door, (0.4, 1.1), (2.6, 1.1), rect)
    out["door_rect_pose"] = lambda: trajopt.plan(
        door, (0.4, 1.1), (2.6, 1.1), rect, start_heading=math.pi / 2, goal_heading=0.0
    )
    omni = trajopt.Robot(drive="omni")
    out["door_omni_free"] = lambda: trajopt.plan(door, (0.4, 1.1), (2.6, 1.1), omni)
    out["door_omni_pose"] = lambda: trajopt.plan(
        door, (0.4, 1.1), (2.6, 1.1), omni, start_heading=math.pi, goal_heading=-math.pi / 2
    )
    omni_rect = trajopt.Robot.rectangle(0.45, 0.2, drive="omni")
    out["door_omni_rect"] = lambda: trajopt.plan(
        door, (0.4, 1.1), (2.6, 1.1), omni_rect, start_heading=math.pi / 2, goal_heading=math.pi / 2
    )
    room = astar.OccupancyGrid(walled(8.0, 4.0, 0.05), 0.05)
    car = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, v_max_reverse=0.3)
    out["car_behind"] = lambda: trajopt.plan(
        room, (4.0, 2.0), (2.5, 2.0), car, start_heading=0.0, goal_heading=0.0
    )
    dead_end = astar.OccupancyGrid(walled(4.1, 1.2, 0.05), 0.05)
    steer = trajopt.Robot(
        drive="ackermann", min_turning_radius=0.6, wheelbase=0.4, steer_rate_max=1.0
    )
    out["car_three_point"] = lambda: trajopt.plan(
        dead_end, (1.5, 0.6), (1.6, 0.6), steer, start_heading=0.0, goal_heading=math.pi
    )
    occ = walled(6.0, 4.0, 0.05)
    occ[34:46, :70] = True
    block = astar.OccupancyGrid(occ, 0.05)
    fwd = trajopt.Robot(drive="ackermann", min_turning_radius=0.5, reverse=False)
    out["car_uturn"] = lambda: trajopt.plan(
        block, (1.0, 1.0), (1.0, 3.0), fwd, start_heading=0.0, goal_heading=math.pi
    )
    body = trajopt.Robot.rectangle(
        0.6, 0.3, rear_offset=0.1, drive="ackermann", min_turning_radius=0.6, wheelbase=0.4
    )
    bay = bay_grid()
    out["car_body_bay"] = lambda: trajopt.plan(
        bay, (1.0, 2.0), (2.225, 0.3), body, start_heading=0.0, goal_heading=math.pi / 2
    )

    def replans() -> dict[str, object]:
        planner = trajopt.Planner(grid, disc)
        traj = planner.plan(sp, targets["D"])
        keep = planner.replan(traj, 0.3 * traj.duration, latency=0.0)
        moved = planner.replan(traj, 0.3 * traj.duration, goal=targets["C"], latency=0.0)
        back = planner.replan(traj, 0.5 * traj.duration, goal=sp, latency=0.0)
        return {"keep": keep, "moved": moved, "back": back}

    out["replan_keep"] = lambda: replans()["keep"]
    out["replan_goal"] = lambda: replans()["moved"]
    out["replan_back"] = lambda: replans()["back"]

    def car_replan() -> object:
        planner = trajopt.Planner(room, car)
        traj = planner.plan((4.0, 2.0), (2.5, 2.0), start_heading=0.0, goal_heading=0.0)
        return planner.replan(traj, traj.duration / 3, latency=0.0)

    out["replan_car"] = car_replan

    def omni_replan() -> object:
        planner = trajopt.Planner(door, omni)
        traj = planner.plan((0.4, 1.1), (2.6, 1.1), start_heading=math.pi, goal_heading=0.0)
        return planner.replan(traj, traj.duration / 3, goal=(2.6, 1.6), latency=0.0)

    out["replan_omni"] = omni_replan
    zz, zs, zg = zigzag_grid()
    small = trajopt.Robot(radius=0.12)
    out["fallback"] = lambda: trajopt.plan(
        zz, zs, zg, small, goal_heading=0.0, fallback="stop_and_turn", corridor="boxes"
    )
    # refusals
    out["bad_drive"] = lambda: trajopt.Robot(drive="tank")
    out["bad_car_radius"] = lambda: trajopt.Robot(drive="ackermann")
    out["bad_car_field"] = lambda: trajopt.Robot(wheelbase=0.3)
    out["bad_steer"] = lambda: trajopt.Robot(
        drive="ackermann", min_turning_radius=1.0, steer_rate_max=1.0
    )
    out["bad_reverse"] = lambda: trajopt.Robot(
        drive="ackermann", min_turning_radius=1.0, reverse="yes"
    )
    out["bad_start"] = lambda: trajopt.plan(grid, (-1.0, 0.0), targets["A"], disc)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="write the fingerprint (JSON) here")
    ap.add_argument("--compare", help="compare with a fingerprint written before")
    ap.add_argument("--only", nargs="*", help="case names to run")
    args = ap.parse_args(argv)
    results = {}
    for name, fn in cases().items():
        if args.only and name not in args.only:
            continue
        results[name] = refusal(fn)
        print(f"{name:18s} {json.dumps(results[name])[:110]}", flush=True)
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1, sort_keys=True)
    if args.compare:
        with open(args.compare) as f:
            before = json.load(f)
        differ = [k for k in results if before.get(k) != results[k]]
        missing = [k for k in before if k not in results and not args.only]
        for k in differ:
            print(f"DIFFERS {k}:\n  before {before.get(k)}\n  now    {results[k]}")
        print(f"{len(results) - len(differ)} of {len(results)} identical; missing {missing}")
        return 1 if differ or missing else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
