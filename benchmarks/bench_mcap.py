"""MCAP export speed: a 60 s trajectory at 100 Hz, with its map and corridor.

A trajectory on the shared Willow Garage map (0.1 m cells, 584 x 526) is planned once and
re-timed with a lower ``v_max`` until it lasts at least 60 s; it is then written with
:meth:`trajopt.Trajectory.to_mcap` at ``dt = 0.01`` (6001 ``PoseStamped`` + 6001
``TwistStamped``, one ``Path`` of 6001 poses, two ``OccupancyGrid`` and one ``MarkerArray``)
``--repeat`` times. For comparison the same samples are written, in the same run, with
``mcap_ros2.writer.Writer`` (the reference implementation's generic serialiser, from
dictionaries) for the ``/pose`` and ``/twist`` topics only. The target is < 0.5 s per file.
The same file with ``--movers`` predicted movers (default 10: discs and boxes, half of them
with a growing radius, crossing the map for 60 s) adds ``/movers`` (every 10 ms, and with
``movers_dt = 0.1``) and ``/movers/predicted``; their times are printed beside (no target).

Run from the repository root (needs the shared data, ``$TRAJOPT_DATA`` or ``../shared/data``)::

    python benchmarks/bench_mcap.py
    python benchmarks/bench_mcap.py --repeat 9
    python benchmarks/bench_mcap.py --movers 0
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import astar  # noqa: E402
import trajopt  # noqa: E402
from trajopt.motion._mcap import message_definition


def data_dir() -> Path:
    env = os.environ.get("TRAJOPT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "data"


def sixty_second_trajectory():
    """A planned trajectory, re-timed with a scaled ``v_max`` until it lasts 60-63 s."""
    grid = astar.load_map(data_dir() / "ros" / "willow-2010-02-18-0.10.yaml")
    robot = trajopt.Robot(radius=0.25)
    traj = trajopt.Planner(grid, robot).plan((10.25, 22.65), (49.85, 44.45))
    v = robot.v_max
    for _ in range(20):
        if 60.0 <= traj.duration <= 63.0:
            break
        v *= traj.duration / 61.5
        timed = trajopt.time_parameterize(
            traj.path, trajopt.Robot(radius=0.25, v_max=v, wheel_v_max=2 * v)
        )
        traj = dataclasses.replace(timed, steps=traj.steps)
    return traj


def write_reference(traj, path: Path, dt: float) -> None:
    from mcap_ros2.writer import Writer

    smp = traj.sample_uniform(dt)
    half = 0.5 * np.asarray(smp.theta)
    with open(path, "wb") as f:
        w = Writer(f)
        s_pose = w.register_msgdef(
            "geometry_msgs/msg/PoseStamped", message_definition("geometry_msgs/msg/PoseStamped")
        )
        s_tw = w.register_msgdef(
            "geometry_msgs/msg/TwistStamped", message_definition("geometry_msgs/msg/TwistStamped")
        )
        for k in range(len(smp.t)):
            ns = int(round(smp.t[k] * 1e9))
            stamp = {"sec": ns // 10**9, "nanosec": ns % 10**9}
            w.write_message(
                "/pose",
                s_pose,
                {
                    "header": {"stamp": stamp, "frame_id": "map"},
                    "pose": {
                        "position": {"x": smp.x[k], "y": smp.y[k], "z": 0.0},
                        "orientation": {
                            "x": 0.0,
                            "y": 0.0,
                            "z": np.sin(half[k]),
                            "w": np.cos(half[k]),
                        },
                    },
                },
                log_time=ns,
                publish_time=ns,
            )
            w.write_message(
                "/twist",
                s_tw,
                {
                    "header": {"stamp": stamp, "frame_id": "base_link"},
                    "twist": {
                        "linear": {"x": smp.v[k], "y": 0.0, "z": 0.0},
                        "angular": {"x": 0.0, "y": 0.0, "z": smp.omega[k]},
                    },
                },
                log_time=ns,
                publish_time=ns,
            )
        w.finish()


def some_movers(traj, count: int) -> list:
    """``count`` movers crossing the trajectory's bounding box for its duration."""
    smp = traj.sample_uniform(0.5)
    lo = np.array([np.min(smp.x), np.min(smp.y)])
    hi = np.array([np.max(smp.x), np.max(smp.y)])
    rng = np.random.default_rng(7)
    box = [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]
    out = []
    for j in range(count):
        a, b = lo + rng.random(2) * (hi - lo), lo + rng.random(2) * (hi - lo)
        out.append(
            trajopt.MovingObstacle.from_waypoints(
                [0.0, traj.duration],
                [a, b],
                radius=0.3 if j % 2 else 0.05,
                growth=0.01 if j % 4 < 2 else 0.0,
                vertices=None if j % 2 else box,
                name=f"mover{j}",
            )
        )
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--movers", type=int, default=10)
    args = ap.parse_args(argv)
    if not (data_dir() / "ros").is_dir():
        print(f"shared data not found at {data_dir()} (set TRAJOPT_DATA)")
        return 1
    traj = sixty_second_trajectory()
    n = len(traj.sample_uniform(0.01).t)
    print(
        f"trajectory: {traj.duration:.2f} s, {traj.length:.2f} m, {n} samples at 100 Hz, "
        f"corridor of {len(traj.steps.corridor.regions)} regions"
    )
    movers = some_movers(traj, args.movers)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "traj.mcap"
        ours, ref, with_movers, at_10hz = [], [], [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            traj.to_mcap(out, dt=0.01)
            ours.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            write_reference(traj, Path(tmp) / "ref.mcap", 0.01)
            ref.append(time.perf_counter() - t0)
            if movers:
                t0 = time.perf_counter()
                traj.to_mcap(Path(tmp) / "movers.mcap", dt=0.01, movers=movers)
                with_movers.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                traj.to_mcap(Path(tmp) / "m10.mcap", dt=0.01, movers=movers, movers_dt=0.1)
                at_10hz.append(time.perf_counter() - t0)
        size = out.stat().st_size
        size_movers = (Path(tmp) / "movers.mcap").stat().st_size if movers else 0
        size_10hz = (Path(tmp) / "m10.mcap").stat().st_size if movers else 0
    m_ours, m_ref = statistics.median(ours), statistics.median(ref)
    print(
        f"to_mcap (all topics):                 median {1e3 * m_ours:7.1f} ms "
        f"(best {1e3 * min(ours):.1f}), {size / 1e6:.2f} MB"
    )
    if movers:
        print(
            f"to_mcap with {len(movers)} movers:            median "
            f"{1e3 * statistics.median(with_movers):7.1f} ms, {size_movers / 1e6:.2f} MB"
        )
        print(
            f"  ... with movers_dt = 0.1 s:          median "
            f"{1e3 * statistics.median(at_10hz):7.1f} ms, {size_10hz / 1e6:.2f} MB"
        )
    print(f"mcap_ros2 Writer (/pose, /twist only): median {1e3 * m_ref:7.1f} ms")
    print(
        f"ratio to_mcap / mcap_ros2 writer: {m_ours / m_ref:.2f}; target < 500 ms: "
        f"{'met' if m_ours < 0.5 else 'NOT met'}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
