"""The ROS 2 node's own costs, over Fast DDS between two processes (issue #44's numbers).

    python benchmarks/bench_ros.py [--requests 1000] [--repeats 30] [--parts start,map,...]

Measures, on a 400 x 400 map (0.05 m cells, 20 m x 20 m, walls with doors):

1. ``start``: node start to ``get_plan`` found, with a warm kernel cache (a fresh process);
2. ``map``: map publish to planner ready (the node's log: planner built, inflation done;
   time since the message's stamp, one machine clock), after an untimed smaller map (the
   first sample of a new publisher waits for discovery);
3. ``share``: the node's share of a ``get_plan`` round trip for paths of about 100 and 500
   poses, per request: the round trip minus the library's plan time the node logged for
   that request minus the time this client takes to deserialise that response
   (``rclpy.serialization``; median of ``--repeats``); the median of those shares, beside
   the node's callback time (plan + path message) and the floor (a trivial service of the
   same node);
4. ``update``: a map update while a trajectory runs to the re-planned ``/plan`` received
   here, minus the re-plan's own wall time; split by the node's log (wall clock, one
   machine) into the map's delivery, the node's own work around the re-plan, and the
   ``/plan`` delivery including this client's deserialisation;
5. ``soak``: ``--requests`` ``get_plan`` calls in a row, every third one bad (cycling
   through a goal outside the map, on a wall, NaN, another frame): every good one answered
   with a path, every bad one with an empty path, and the node's resident memory before
   and after (``/proc/PID/status``); then the shutdown on SIGINT.

The node runs with ``--log-level trajopt_planner:=debug``: it logs each ``get_plan``'s
library time (wall and CPU) and when its callback began. Network hygiene as in the tests:
LOCALHOST discovery, a domain id held by a file lock, a temporary log folder.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.trajopt_ros import helpers as h  # noqa: E402
from tests.trajopt_ros.conftest import NodeProcess, _hold_domain_id  # noqa: E402

RES, N = 0.05, 400


def big_map() -> np.ndarray:
    v = np.zeros((N, N), np.int8)
    for k in (100, 200, 300):  # walls along x and y, each with two doors
        v[k : k + 4, :] = 100
        v[:, k : k + 4] = 100
        for d in (50, 250):
            v[k : k + 4, d : d + 30] = 0
            v[d : d + 30, k : k + 4] = 0
    return v


def grid_msg(values):
    msg = h.grid_msg(values)
    msg.info.resolution = RES
    return msg


def rss_kib(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=30)
    ap.add_argument(
        "--parts",
        default="start,map,share,update,soak",
        help="comma-separated subset of start, map, share, update, soak",
    )
    args = ap.parse_args()
    parts = set(args.parts.split(","))
    env = {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_DOMAIN_ID": str(_hold_domain_id()),
        "ROS_LOG_DIR": tempfile.mkdtemp(prefix="trajopt-ros-bench-log-"),
        "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
    }
    os.environ.update(env)
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import OccupancyGrid, Odometry
    from nav_msgs.msg import Path as PathMsg
    from nav_msgs.srv import GetPlan
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import GetParameters, SetParameters
    from rclpy.executors import MultiThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rclpy.serialization import deserialize_message, serialize_message

    from trajopt_ros.build import ensure_interfaces
    from trajopt_ros.convert import to_time

    ensure_interfaces()
    rclpy.init()
    client = rclpy.create_node("trajopt_bench")
    ex = MultiThreadedExecutor(num_threads=2)
    ex.add_node(client)
    spinner = threading.Thread(target=ex.spin, daemon=True)
    spinner.start()
    out: dict[str, object] = {}

    # 1. start to services ready (the kernel cache is warm after the first start)
    starts = []
    node = None
    for _ in range(3 if "start" in parts else 1):
        if node is not None:  # stopped, and gone from this client's graph
            node.stop()
            h.wait_for(
                lambda: "/get_plan" not in dict(client.get_service_names_and_types()),
                30.0,
                "the stopped node's get_plan gone from the graph",
            )
        t0 = time.perf_counter()
        # debug level: the node logs each get_plan's library time (its share counts the log)
        node = NodeProcess(env, "--log-level", "trajopt_planner:=debug")
        srv = client.create_client(GetPlan, "get_plan")
        assert srv.wait_for_service(timeout_sec=60.0), node.output()
        starts.append(time.perf_counter() - t0)
        client.destroy_client(srv)
    out["start_to_ready_s"] = starts
    print("start to ready (s):", [round(x, 2) for x in starts], flush=True)
    get_plan = client.create_client(GetPlan, "get_plan")
    assert get_plan.wait_for_service(timeout_sec=30.0)

    # 2. map publish to planner ready
    qos = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    map_pub = client.create_publisher(OccupancyGrid, "map", qos)
    # matched first: a map published before would wait for discovery (transient local)
    h.wait_for(lambda: map_pub.get_subscription_count() > 0, 30.0, "the node's map subscription")
    values = big_map()
    # an untimed first map of another size: the first sample of a new writer can wait for
    # the node's side of discovery and a heartbeat (about 100 ms here), which is DDS's, not
    # the node's; the 400 x 400 map after it still builds a new planner (another shape)
    n_logs = node.output().count(") ready: planner in")
    map_pub.publish(grid_msg(values[:200, :200].copy()))
    h.wait_for(lambda: node.output().count(") ready: planner in") > n_logs, 30.0, "map ready")
    lags = []
    for k in range(5 if "map" in parts else 1):
        v = values.copy()
        v[5, 5 + k] = 100  # a new map each time (same shape: update_map after the first)
        msg = grid_msg(v)
        msg.header.stamp = client.get_clock().now().to_msg()
        n_logs = node.output().count(") ready: planner in")
        map_pub.publish(msg)
        h.wait_for(
            lambda n=n_logs: node.output().count(") ready: planner in") > n, 30.0, "map ready"
        )
        lags.append(float(re.findall(r"ready ([0-9.]+) ms after its stamp", node.output())[-1]))
    out["map_to_ready_ms (first: new planner; then update_map)"] = lags
    print("map to ready (ms):", lags, flush=True)
    values = v

    def call(start, goal):
        start.header.stamp = to_time(time.time())  # the node logs when its callback began
        t0 = time.perf_counter()
        res = h.call(get_plan, GetPlan.Request(start=start, goal=goal), 30.0)
        return time.perf_counter() - t0, res

    def cpu_s(pid: int) -> float:  # user + system CPU time of a process (s)
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    # 3. node share of a get_plan round trip, from the library time the node logs per request
    put = client.create_client(SetParameters, "/trajopt_planner/set_parameters")
    assert put.wait_for_service(timeout_sec=10.0)
    params = client.create_client(GetParameters, "/trajopt_planner/get_parameters")
    assert params.wait_for_service(timeout_sec=10.0)

    def set_param(name, value):
        p = Parameter(
            name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value)
        )
        assert h.call(put, SetParameters.Request(parameters=[p])).results[0].successful

    start, goal = (2.0, 2.0, 0.0), (2.0, 8.0, 0.0)  # through a door: a path of some 20 s
    logged = re.compile(
        r"get_plan: (\d+) poses on map \d+, library plan ([0-9.]+) ms \(CPU ([0-9.]+) ms\), "
        r"callback ([0-9.]+) ms \(from ([0-9.]+)\)"
    )
    if "share" in parts:
        floor = []
        c0 = cpu_s(node.proc.pid)
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            h.call(params, GetParameters.Request(names=["robot.radius"]))
            floor.append(time.perf_counter() - t0)
        floor_cpu = (cpu_s(node.proc.pid) - c0) / args.repeats
        out["floor: get_parameters round trip (ms)"] = {
            "trip": round(1e3 * statistics.median(floor), 2),
            "node CPU per request": round(1e3 * floor_cpu, 2),
        }
        print("floor: get_parameters (ms):", out["floor: get_parameters round trip (ms)"])
    for interval in (0.15, 0.03) if "share" in parts else ():
        set_param("plan.sample_interval", interval)
        # the first plan of a size is not timed; its answer is what the client deserialises
        raw = serialize_message(call(h.pose(*start), h.pose(*goal))[1])
        n_logged = len(logged.findall(node.output()))
        trips, deser, sent, back = [], [], [], []
        c0 = cpu_s(node.proc.pid)
        for _ in range(args.repeats):  # each round trip with this client's deserialisation
            sent.append(time.time())
            dt, res = call(h.pose(*start), h.pose(*goal))
            back.append(time.time())
            assert len(res.plan.poses) > 0
            trips.append(dt)
            t0 = time.perf_counter()
            deserialize_message(raw, GetPlan.Response)
            deser.append(time.perf_counter() - t0)
        node_cpu = (cpu_s(node.proc.pid) - c0) / args.repeats
        want = len(trips)
        rows = h.wait_for(
            lambda n=n_logged, want=want: (
                (r := logged.findall(node.output())[n:]) and len(r) == want and r
            ),
            10.0,
            "the node's get_plan log lines",
        )
        lib = [1e-3 * float(r[1]) for r in rows]
        lib_cpu = [1e-3 * float(r[2]) for r in rows]
        cb = [1e-3 * float(r[3]) for r in rows]
        began = [float(r[4]) for r in rows]
        share = [t - lib_t - d for t, lib_t, d in zip(trips, lib, deser, strict=True)]
        med = {
            k: round(1e3 * statistics.median(x), 2)
            for k, x in (
                ("trip", trips),
                ("library (node-logged)", lib),
                ("client deser", deser),
                ("node share", share),
                ("request to callback", [b - s for b, s in zip(began, sent, strict=True)]),
                ("node callback", cb),
                ("callback besides the plan", [c - x for c, x in zip(cb, lib, strict=True)]),
                (
                    "callback end to answer here",
                    [e - b - c for e, b, c in zip(back, began, cb, strict=True)],
                ),
            )
        }
        med["node CPU per request"] = round(1e3 * node_cpu, 2)
        med["node CPU besides the plan"] = round(1e3 * (node_cpu - statistics.mean(lib_cpu)), 2)
        key = f"get_plan {len(res.plan.poses)} poses (ms)"
        out[key] = med
        print(key, med, flush=True)

    # 4. map update while a trajectory runs -> re-planned /plan (rate limit lifted to 50 Hz,
    # /plan sampled at the default 0.1 s)
    set_param("replan.rate", 50.0)
    set_param("plan.sample_interval", 0.1)
    plans: list = []
    got = threading.Event()

    def on_plan(m):
        plans.append((time.time(), m))
        got.set()

    client.create_subscription(PathMsg, "plan", on_plan, qos)
    odom_pub = client.create_publisher(Odometry, "odom", 10)
    goal_pub = client.create_publisher(PoseStamped, "goal_pose", 10)
    h.wait_for(lambda: goal_pub.get_subscription_count() > 0, 10.0, "goal_pose subscriber")
    replanned = re.compile(
        r"re-planned \(map changed[^)]*\) on map (\d+) in ([0-9.]+) ms, published in "
        r"([0-9.]+) ms \(stamp ([0-9.]+), published at ([0-9.]+)\)"
    )
    ready = re.compile(r"map (\d+) \(.*\) ready: .* \(received at ([0-9.]+)\)")
    extra = []
    for k in range(5 if "update" in parts else 0):
        odom = Odometry()
        odom.header.frame_id = "map"
        odom.pose.pose = h.pose(2.0, 2.0 + 0.2 * k).pose
        n0 = len(plans)
        deadline = time.monotonic() + 20.0
        while len(plans) == n0:
            if time.monotonic() > deadline:
                raise TimeoutError("no plan for goal_pose:\n" + node.output()[-3000:])
            odom_pub.publish(odom)
            goal_pub.publish(h.pose(18.0, 11.0 + 0.2 * k))
            got.wait(2.0)
            got.clear()
        v = values.copy()
        v[150 + k, 60:70] = 100  # a change in the route's first room
        msg = grid_msg(v)  # built before the clock starts: the client's cost, not the node's
        n_logs = len(replanned.findall(node.output()))
        t_pub = time.time()
        msg.header.stamp = to_time(t_pub)
        map_pub.publish(msg)
        row = h.wait_for(
            lambda n=n_logs: (r := replanned.findall(node.output())) and len(r) > n and r[-1],
            10.0,
            "the node's re-plan log line",
        )
        gen, replan_ms, pub_ms, stamp, published = (float(x) for x in row)
        received = {int(g): float(t) for g, t in ready.findall(node.output())}[int(gen)]

        def plan_of(stamp=stamp):  # the /plan message of that re-plan (its stamp is its t0)
            for t, m in plans:
                if abs(m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec - stamp) < 2e-6:
                    return t, m
            return None

        t_recv, m = h.wait_for(plan_of, 10.0, "the re-planned /plan")
        raw = serialize_message(m)
        deser = []
        for _ in range(5):  # a median: one collection or preemption here is not the node's
            t0 = time.perf_counter()
            deserialize_message(raw, PathMsg)
            deser.append(time.perf_counter() - t0)
        deser_ms = 1e3 * statistics.median(deser)
        total = 1e3 * (t_recv - t_pub)
        extra.append(
            {
                "total": round(total, 1),
                "re-plan": replan_ms,
                "beyond": round(total - replan_ms, 1),
                "beyond, less client deser": round(total - replan_ms - deser_ms, 1),
                "map delivery": round(1e3 * (received - t_pub), 1),
                "node besides re-plan": round(1e3 * (published - received) - replan_ms, 1),
                "of which publish": pub_ms,
                "/plan delivery": round(1e3 * (t_recv - published), 1),
                "of which client deser": round(deser_ms, 1),
                "poses": len(m.poses),
            }
        )
        print("map update to /plan (ms):", extra[-1], flush=True)
    out["map update to /plan beyond the re-plan (ms)"] = extra

    # 5. soak
    bad_goals = [
        lambda: h.pose(30.0, 5.0),
        lambda: h.pose(7.0, 5.1),  # on a wall
        lambda: h.pose(float("nan"), 2.0),
        lambda: h.pose(2.0, 8.0, frame="odom"),
    ]
    if "soak" not in parts:
        code, secs = node.stop()
        print("shutdown by SIGINT:", {"exit code": code, "seconds": round(secs, 2)})
        _stop_client(ex, spinner, client)
        return 0
    for _ in range(30):
        call(h.pose(*start), h.pose(*goal))
    rss0 = rss_kib(node.proc.pid)
    good_ok = bad_ok = n_good = n_bad = 0
    t0 = time.perf_counter()
    for i in range(args.requests):
        if i % 3 == 2:
            n_bad += 1
            _, res = call(h.pose(*start), bad_goals[(i // 3) % len(bad_goals)]())
            bad_ok += len(res.plan.poses) == 0
        else:
            n_good += 1
            gy = 7.0 + 0.4 * (i % 5)
            _, res = call(h.pose(*start), h.pose(2.0, gy))
            good_ok += len(res.plan.poses) > 0
    rss1 = rss_kib(node.proc.pid)
    out["soak"] = {
        "requests": args.requests,
        "good answered": f"{good_ok}/{n_good}",
        "bad refused": f"{bad_ok}/{n_bad}",
        "alive": node.proc.poll() is None,
        "rss_MiB before, after": (round(rss0 / 1024, 1), round(rss1 / 1024, 1)),
        "rss growth %": round(100.0 * (rss1 - rss0) / max(rss0, 1), 2),
        "seconds": round(time.perf_counter() - t0, 1),
    }
    code, secs = node.stop()
    out["shutdown by SIGINT"] = {"exit code": code, "seconds": round(secs, 2)}
    print("soak:", out["soak"])
    print("shutdown by SIGINT:", out["shutdown by SIGINT"])
    _stop_client(ex, spinner, client)
    return 0


def _stop_client(ex: Any, spinner: threading.Thread, client: Any) -> None:
    """Stop the client's executor, wait for its spinning thread, then shut rclpy down.

    The thread is joined before the interpreter exits: a thread still inside rclpy's C++ code
    at exit aborts the process (``terminate called without an active exception``).
    """
    import rclpy

    ex.shutdown()
    spinner.join(timeout=5.0)
    client.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
