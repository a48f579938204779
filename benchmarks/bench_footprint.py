"""Rectangular robots: collisions, door passages and smoothing time, same run.

Two parts:

1. **Maps.** On the shared ROS maps (disc radius 0.2 m) and Moving AI maps (2.5 cells),
   seeded random queries are planned for two rectangles with the disc's diameter ``D``:
   ``1.6 D x 1.0 D`` and ``2:1`` (``1.6 D x 0.8 D``), rotation centre in the middle. Every
   returned trajectory is checked for collisions by an independent test: points filling
   the footprint at 1500 poses along it, against the occupied squares and the outside of
   the map. Reported: solved, why the others were refused (no path even for the inscribed
   disc, an end where the footprint stands at no heading, no certified curve), collisions,
   the rung of the radius ladder used, the share that needed footprint rounds (a pinned
   end heading or the footprint SCP), and the median and p95 of the accepted rung's
   smoothing stage (footprint certificates and rounds included) and of its footprint
   certificates alone. One warm-up plan runs first (compilation is not measured).
   The same queries are then planned again without the footprint rounds (the smoother
   only certifies the footprint; the ladder of discs does the rest), as the previous
   design, and the solved counts and smoothing p95 are printed side by side.
2. **Doors.** A wall with one door whose width lies between the footprint's width plus two
   cells and its circumscribed diameter (so the circumscribed disc cannot pass), with
   several widths, wall thicknesses and offsets; the query crosses the door. Reported:
   the share solved with the footprint (and, as the reference, with the circumscribed
   disc, which must be 0), and collisions.

Run from the repository root (the shared maps: ``$TRAJOPT_DATA`` or ``../shared/data``)::

    python benchmarks/bench_footprint.py
    python benchmarks/bench_footprint.py --per-map 10
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import astar  # noqa: E402
import trajopt  # noqa: E402
from trajopt.errors import TrajoptError

ROS = ("turtlebot3_world", "smoothers_world", "depot")
MOVINGAI = ("den312d", "Berlin_0_256", "arena")


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def collides(grid, fp, x, y, theta) -> bool:
    """Independent check: points filling the posed footprint vs occupied squares."""
    v = fp.vertices
    n = 10
    edges = [
        v[i] + np.linspace(0, 1, n)[:, None] * (v[(i + 1) % len(v)] - v[i]) for i in range(len(v))
    ]
    lo, hi = v.min(axis=0), v.max(axis=0)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n))
    pts = np.vstack(edges + [np.column_stack([gx.ravel(), gy.ravel()])])
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    wx = x[:, None] + c * pts[None, :, 0] - s * pts[None, :, 1]
    wy = y[:, None] + s * pts[None, :, 0] + c * pts[None, :, 1]
    ix = np.floor((wx - grid.origin[0]) / grid.resolution).astype(int).ravel()
    iy = np.floor((wy - grid.origin[1]) / grid.resolution).astype(int).ravel()
    ny, nx = grid.shape
    if np.any((ix < 0) | (iy < 0) | (ix >= nx) | (iy >= ny)):
        return True
    return bool(grid.occupied[iy, ix].any())


def queries(grid, r_free, n, rng):
    free = np.argwhere(
        ~astar.inflate(grid, r_free, metric="square", outside_occupied=True).occupied
    )
    out = []
    for _ in range(40 * n):
        if len(out) == n or len(free) < 2:
            break
        a, b = free[rng.integers(len(free), size=2)]
        p0, p1 = grid.cell_to_world(a[::-1]), grid.cell_to_world(b[::-1])
        if math.dist(p0, p1) > 20 * grid.resolution:
            out.append((tuple(p0), tuple(p1)))
    return out


@contextlib.contextmanager
def without_footprint_rounds():
    """The previous design, for comparison in the same run: the fit only certifies."""
    import trajopt.smoother._attempts as attempts
    from trajopt.smoother._footprint_rounds import FootprintRounds

    saved = attempts.footprint_scp, FootprintRounds.pin
    attempts.footprint_scp = lambda *a, **k: None
    FootprintRounds.pin = lambda *a, **k: False
    try:
        yield
    finally:
        attempts.footprint_scp, FootprintRounds.pin = saved


def run_maps(args, rng, quiet: bool = False) -> tuple[int, int, list[float]]:
    """Plan the map queries; return (solved, queries, smoothing times in ms)."""
    say = (lambda *a, **k: None) if quiet else print
    say(
        f"{'map':18s} {'shape':>9s} {'solved':>7s} {'no path':>7s} {'no pose':>7s} "
        f"{'no curve':>8s} {'collide':>7s} {'rungs':>9s} {'rounds':>6s} "
        f"{'smooth med/p95 ms':>18s} {'cert med/p95 ms':>16s}"
    )
    d = data_dir()
    maps = [(n, d / "ros" / f"{n}.yaml", None) for n in ROS]
    maps += [(n, d / "movingai" / "maps" / f"{n}.map", 2.5) for n in MOVINGAI]
    all_smooth: list[float] = []
    total_solved = total_queries = 0
    trajopt.warm_up(trajopt.Planner(astar.load_map(maps[0][1]), trajopt.Robot.rectangle(0.64, 0.4)))
    for name, path, r_cells in maps:
        grid = astar.load_map(path)
        diam = 2 * (0.2 if r_cells is None else r_cells * grid.resolution)
        for shape, (ln, wd) in (
            ("1.6x1.0", (1.6 * diam, 1.0 * diam)),
            ("2:1", (1.6 * diam, 0.8 * diam)),
        ):
            robot = trajopt.Robot.rectangle(ln, wd)
            planner = trajopt.Planner(grid, robot)
            qs = queries(grid, robot.inscribed_radius + grid.resolution, args.per_map, rng)
            solved = collided = with_rounds = 0
            refused = {"no path": 0, "no pose": 0, "no curve": 0}
            rungs: dict[int, int] = {}
            smooth, cert = [], []
            for p0, p1 in qs:
                try:
                    traj = planner.plan(p0, p1)
                except trajopt.NoPathError:
                    refused["no path"] += 1
                    continue
                except trajopt.InvalidInputError:
                    refused["no pose"] += 1
                    continue
                except TrajoptError:
                    refused["no curve"] += 1
                    continue
                solved += 1
                smp = traj.sample(np.linspace(0.0, traj.duration, 1500))
                collided += collides(grid, robot.footprint, smp.x, smp.y, smp.theta)
                fst = traj.stats["footprint"]
                k = fst["ladder_m"].index(fst["disc_radius_m"])
                rungs[k] = rungs.get(k, 0) + 1
                with_rounds += fst["rounds"] > 0
                smooth.append(1e3 * traj.stats["stages_s"].get("smooth", float("nan")))
                cert.append(1e3 * fst["certificate_s"])

            def mp(v):
                return f"{statistics.median(v):.1f}/{np.percentile(v, 95):.1f}" if v else "-"

            rung_s = ",".join(f"{rungs.get(i, 0)}" for i in range(3))
            total_solved += solved
            total_queries += len(qs)
            say(
                f"{name:18s} {shape:>9s} {solved:3d}/{len(qs):<3d} {refused['no path']:7d} "
                f"{refused['no pose']:7d} {refused['no curve']:8d} {collided:7d} {rung_s:>9s} "
                f"{with_rounds:6d} {mp(smooth):>18s} {mp(cert):>16s}"
            )
            all_smooth.extend(smooth)
    if all_smooth:
        say(
            f"smoothing stage over all solved queries: median {statistics.median(all_smooth):.1f} "
            f"ms, p95 {np.percentile(all_smooth, 95):.1f} ms, max {max(all_smooth):.1f} ms "
            f"({len(all_smooth)} plans)"
        )
    return total_solved, total_queries, all_smooth


def door_grid(width_m, wall_cells, offset_cells, res=0.02):
    occ = np.zeros((150, 220), bool)
    x0 = 100
    occ[:, x0 : x0 + wall_cells] = True
    c = 75 + offset_cells
    half = int(round(width_m / res / 2))
    occ[c - half : c + half, x0 : x0 + wall_cells] = False
    return astar.OccupancyGrid(occ, res), (0.8, (c) * res), (3.6, (c) * res)


def run_doors(args) -> None:
    robot = trajopt.Robot.rectangle(0.7, 0.4, track_width=0.3, wheel_v_max=0.6)
    disc = trajopt.Robot(radius=robot.circumscribed_radius)
    lo = float(np.ptp(robot.footprint.vertices[:, 1])) + 2 * 0.02 + 0.02
    hi = 2 * robot.circumscribed_radius - 0.02
    cases = [(w, t, o) for w in np.linspace(lo, hi, 5) for t in (2, 4, 8) for o in (-10, 0, 10)]
    ok = ok_disc = collided = 0
    for w, t, o in cases:
        grid, s, g = door_grid(float(w), t, o)
        try:
            traj = trajopt.plan(grid, s, g, robot)
            ok += 1
            smp = traj.sample(np.linspace(0.0, traj.duration, 1500))
            collided += collides(grid, robot.footprint, smp.x, smp.y, smp.theta)
        except TrajoptError:
            pass
        try:
            trajopt.plan(grid, s, g, disc)
            ok_disc += 1
        except TrajoptError:
            pass
    print(
        f"doors ({len(cases)}: widths {lo:.2f}-{hi:.2f} m, walls 2-8 cells, 3 offsets; "
        f"footprint 0.7 x 0.4 m, circumscribed diameter {2 * robot.circumscribed_radius:.3f} m)"
    )
    print(
        f"  solved with the footprint {ok}/{len(cases)} ({100 * ok / len(cases):.0f} %), "
        f"collisions {collided}; with the circumscribed disc {ok_disc}/{len(cases)}"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-map", type=int, default=6)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    if not (data_dir() / "ros").is_dir():
        print(f"shared data not found at {data_dir()} (set TRAJOPT_DATA)")
        return 1
    ok, n, smooth = run_maps(args, np.random.default_rng(args.seed))
    with without_footprint_rounds():
        ok0, n0, smooth0 = run_maps(args, np.random.default_rng(args.seed), quiet=True)
    print(
        f"the same queries without the footprint rounds (no pinned end heading, no footprint "
        f"SCP; the ladder only): solved {ok0}/{n0}, smoothing p95 "
        f"{np.percentile(smooth0, 95):.1f} ms; with them: {ok}/{n}, "
        f"{np.percentile(smooth, 95):.1f} ms"
    )
    run_doors(args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
