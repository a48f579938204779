"""Tests of trajopt_ros: the node in its own process, driven from this one over Fast DDS (conftest: hygiene)."""

from __future__ import annotations

import itertools
import math
import signal
import threading

import numpy as np
import pytest

pytest.importorskip("rclpy", reason="the ROS 2 wheels are not installed (pip install -e '.[ros2]')")

from tests.trajopt_ros import helpers as h  # noqa: E402
from tests.trajopt_ros.conftest import NodeProcess  # noqa: E402

TOL = 1e-6
#: The signals test_shutdown_by_signal stops a fresh node with, one node each
SIGNALS = (signal.SIGTERM,)


@pytest.fixture(scope="module", autouse=True)
def fresh_nodes(request, ros_env, tmp_path_factory):
    """The fresh nodes of the module's tests, started when the module starts, so that their
    start-up (seconds of imports) runs beside the session node's instead of inside each test;
    only those of the selected tests. ``("sig", signal)``: a node per signal of
    test_shutdown_by_signal (namespace ``/sig<number>``, no map published there); ``"bad"``:
    a node given a parameter file with a bad drive (test_bad_parameter_file_refused_at_start).
    Each still running is stopped at the end of the module."""
    selected = {
        getattr(i, "originalname", None)
        for i in request.session.items
        if getattr(i, "module", None) is request.module
    }
    nodes = {}
    if "test_shutdown_by_signal" in selected:
        for sig in SIGNALS:
            ns = f"__ns:=/sig{int(sig)}"
            nodes["sig", sig] = NodeProcess(ros_env, "-r", ns, name="trajopt_sig")
    if "test_bad_parameter_file_refused_at_start" in selected:
        params = tmp_path_factory.mktemp("bad_params") / "bad.yaml"
        params.write_text("trajopt_bad:\n  ros__parameters:\n    robot:\n      drive: tank\n")
        nodes["bad"] = NodeProcess(ros_env, "--params-file", str(params), name="trajopt_bad")
    yield nodes
    for node in nodes.values():
        node.stop()


@pytest.fixture(scope="module")
def served(node_process, client):
    """The session node with the wall map published (latched) and its services found."""
    from nav_msgs.msg import OccupancyGrid
    from nav_msgs.srv import GetPlan
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    qos = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    map_pub = client.create_publisher(OccupancyGrid, "map", qos)
    get_plan = client.create_client(GetPlan, "get_plan")
    assert get_plan.wait_for_service(timeout_sec=30.0), node_process.output()
    values = h.wall_map()
    map_pub.publish(h.grid_msg(values))

    def planned():
        req = GetPlan.Request(start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0))
        return len(h.call(get_plan, req).plan.poses) > 0

    h.wait_for(planned, 15.0, "a plan on the published map")
    return {"map_pub": map_pub, "get_plan": get_plan, "values": values}


def get_plan(served, start, goal):
    from nav_msgs.srv import GetPlan

    return h.call(served["get_plan"], GetPlan.Request(start=start, goal=goal)).plan


def test_get_plan_ends_clearance_stamps(served):
    start, goal = (1.0, 1.0, 0.5), (5.0, 1.0, -1.0)
    path = get_plan(served, h.pose(*start), h.pose(*goal))
    xy, yaw, t = h.path_xy(path), h.path_yaw(path), h.stamps(path)
    assert path.header.frame_id == "map" and all(p.header.frame_id == "map" for p in path.poses)
    np.testing.assert_allclose(xy[0], start[:2], atol=TOL)
    np.testing.assert_allclose(xy[-1], goal[:2], atol=TOL)
    # headings honoured at both ends (a differential drive turns in place where needed)
    assert abs(math.remainder(yaw[0] - start[2], 2 * math.pi)) < 1e-6
    assert abs(math.remainder(yaw[-1] - goal[2], 2 * math.pi)) < 1e-6
    assert np.all(np.diff(t) > 0)
    assert np.all(np.diff(t)[:-1] == pytest.approx(0.1, abs=1e-6))  # plan.sample_interval
    assert h.clearance(xy, served["values"]).min() >= h.RADIUS - TOL
    assert xy[:, 1].max() > 2.6  # it went round the wall


@pytest.mark.parametrize(
    ("goal", "why"),
    [
        (h.pose(9.0, 1.0), "outside the map"),
        (h.pose(3.1, 1.0), "occupied"),
        (h.pose(float("nan"), 1.0), "nan"),
        (h.pose(5.0, 1.0, frame="odom"), "frame"),
        (h.pose(5.0, 1.0), "quaternion"),
    ],
)
def test_get_plan_bad_goal_empty_path(served, node_process, goal, why):
    if why == "quaternion":
        goal.pose.orientation.w = 2.0
    path = get_plan(served, h.pose(1.0, 1.0), goal)
    assert len(path.poses) == 0
    log = node_process.output().lower()
    assert "get_plan refused" in log
    # and the node keeps serving
    assert len(get_plan(served, h.pose(1.0, 1.0), h.pose(5.0, 1.0)).poses) > 0


def test_error_code_tables_match_generated_constants(interfaces):
    from nav2_msgs.action import ComputePathToPose, SmoothPath
    from trajopt_ros_interfaces.action import PlanTrajectory

    from trajopt_ros import codes

    for reason, code in codes.PLAN_TRAJECTORY.items():
        assert getattr(PlanTrajectory.Result, reason.upper()) == code
    for reason, code in codes.COMPUTE_PATH_TO_POSE.items():
        name = {"frame_mismatch": "TF_ERROR", "no_path": "NO_VALID_PATH"}.get(reason)
        if name or hasattr(ComputePathToPose.Result, reason.upper()):
            assert getattr(ComputePathToPose.Result, name or reason.upper()) == code
    assert SmoothPath.Result.FAILED_TO_SMOOTH_PATH == codes.SMOOTH_PATH["smoothing_failed"]
    assert SmoothPath.Result.INVALID_PATH == codes.SMOOTH_PATH["invalid_pose"]
    assert SmoothPath.Result.TIMEOUT == codes.SMOOTH_PATH["timeout"]


_ACTION_NODES = itertools.count()


def _send(client_node, action_type, name, goal, feedback=None, timeout=20.0):
    """Send ``goal`` to the action ``name`` and wait until it is accepted.

    rclpy's ``ActionClient`` joins its node's waitables before it has made its lock, so one
    built on the spun client node can kill the executor's thread (an ``AttributeError`` on
    ``_lock``) and with it every later test: it is built on a node of its own, handed to the
    executor only once built.
    """
    import rclpy
    from rclpy.action import ActionClient

    node = rclpy.create_node(
        f"trajopt_test_action_{next(_ACTION_NODES)}", context=client_node.context
    )
    ac = ActionClient(node, action_type, name)
    client_node.executor.add_node(node)
    assert ac.wait_for_server(timeout_sec=15.0)
    fut = ac.send_goal_async(goal, feedback_callback=feedback)
    handle = h.wait_for(lambda: fut.done() and fut.result(), timeout, "goal accepted")
    return ac, handle


def _result(handle, timeout=30.0):
    fut = handle.get_result_async()
    return h.wait_for(lambda: fut.done() and fut.result(), timeout, "action result")


def test_plan_trajectory_result_and_codes(served, client):
    from trajopt_ros_interfaces.action import PlanTrajectory

    goal = PlanTrajectory.Goal(
        start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0), use_start=True, execute=False
    )
    _, handle = _send(client, PlanTrajectory, "plan_trajectory", goal)
    res = _result(handle).result
    assert res.error_code == PlanTrajectory.Result.NONE
    pts = res.trajectory.points
    assert res.trajectory.joint_names == ["base"] and len(pts) == len(res.path.poses)
    t = np.array([p.time_from_start.sec + 1e-9 * p.time_from_start.nanosec for p in pts])
    dur = res.duration.sec + 1e-9 * res.duration.nanosec
    assert t[-1] == pytest.approx(dur, abs=1e-6) and np.all(np.diff(t) > 0)
    v = np.array([p.velocities[0].linear.x for p in pts])
    assert v[0] == pytest.approx(0, abs=1e-6) and v[-1] == pytest.approx(0, abs=1e-6)
    assert v.max() <= 0.8 + 1e-6  # robot.v_max from the parameter file
    # a typed failure per bad goal
    for bad, code in (
        (h.pose(3.1, 1.0), PlanTrajectory.Result.GOAL_OCCUPIED),
        (h.pose(-1.0, 1.0), PlanTrajectory.Result.GOAL_OUTSIDE_MAP),
        (h.pose(5.0, 1.0, frame="odom"), PlanTrajectory.Result.FRAME_MISMATCH),
    ):
        goal.goal = bad
        _, handle = _send(client, PlanTrajectory, "plan_trajectory", goal)
        res = _result(handle).result
        assert res.error_code == code, res.error_msg
        assert res.error_msg and len(res.path.poses) == 0


def test_plan_trajectory_feedback_and_cancel(served, client):
    from trajopt_ros_interfaces.action import PlanTrajectory

    got = threading.Event()
    feedback = []

    def on_feedback(msg):
        feedback.append(msg.feedback)
        if len(feedback) >= 3:
            got.set()

    goal = PlanTrajectory.Goal(
        start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0), use_start=True, execute=True
    )
    _, handle = _send(client, PlanTrajectory, "plan_trajectory", goal, on_feedback)
    assert got.wait(10.0)
    fb = feedback[-1]
    assert fb.time_remaining.sec + fb.time_remaining.nanosec > 0
    fut = handle.cancel_goal_async()
    h.wait_for(lambda: fut.done(), 10.0, "cancel answer")
    res = _result(handle).result
    assert res.error_code == PlanTrajectory.Result.CANCELED
    assert res.duration.sec > 0 and len(res.path.poses) > 2


def test_nav2_compute_path_to_pose(served, client):
    from nav2_msgs.action import ComputePathToPose

    goal = ComputePathToPose.Goal(
        start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0), use_start=True, planner_id=""
    )
    _, handle = _send(client, ComputePathToPose, "compute_path_to_pose", goal)
    res = _result(handle).result
    assert res.error_code == ComputePathToPose.Result.NONE
    xy = h.path_xy(res.path)
    np.testing.assert_allclose(xy[[0, -1]], [[1.0, 1.0], [5.0, 1.0]], atol=TOL)
    assert h.clearance(xy, served["values"]).min() >= h.RADIUS - TOL
    for bad, code in (
        (dict(goal=h.pose(3.1, 1.0)), ComputePathToPose.Result.GOAL_OCCUPIED),
        (dict(start=h.pose(-2.0, 1.0)), ComputePathToPose.Result.START_OUTSIDE_MAP),
        (dict(goal=h.pose(5.0, 1.0, frame="odom")), ComputePathToPose.Result.TF_ERROR),
        (dict(planner_id="GridBased"), ComputePathToPose.Result.INVALID_PLANNER),
    ):
        g = ComputePathToPose.Goal(
            start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0), use_start=True, planner_id=""
        )
        for k, val in bad.items():
            setattr(g, k, val)
        _, handle = _send(client, ComputePathToPose, "compute_path_to_pose", g)
        res = _result(handle).result
        assert res.error_code == code, res.error_msg


def test_nav2_smooth_path(served, client):
    from builtin_interfaces.msg import Duration
    from nav2_msgs.action import SmoothPath
    from nav_msgs.msg import Path

    # a jagged path round the wall's end, clear of the wall by more than the radius
    pts = [(1.0, 1.0), (2.0, 2.0), (2.6, 3.1), (3.1, 3.3), (3.7, 3.1), (4.3, 2.0), (5.0, 1.0)]
    path = Path()
    path.header.frame_id = "map"
    path.poses = [h.pose(x, y) for x, y in pts]
    goal = SmoothPath.Goal(
        path=path,
        smoother_id="",
        check_for_collisions=True,
        max_smoothing_duration=Duration(sec=60),
    )
    _, handle = _send(client, SmoothPath, "smooth_path", goal)
    res = _result(handle).result
    assert res.error_code == SmoothPath.Result.NONE, res.error_msg
    assert res.was_completed
    xy = h.path_xy(res.path)
    np.testing.assert_allclose(xy[[0, -1]], [pts[0], pts[-1]], atol=TOL)
    assert h.clearance(xy, served["values"]).min() >= h.RADIUS - TOL
    yaw = np.unwrap(h.path_yaw(res.path))
    assert np.abs(np.diff(yaw)).max() < 0.5  # smooth: no corner of the input polyline
    # max_smoothing_duration is a cut-off: 1 ns cannot hold a fit, answered with Nav2's TIMEOUT
    goal.max_smoothing_duration = Duration(nanosec=1)
    _, handle = _send(client, SmoothPath, "smooth_path", goal)
    res = _result(handle).result
    assert res.error_code == SmoothPath.Result.TIMEOUT, res.error_msg
    assert not res.was_completed and "max_smoothing_duration" in res.error_msg
    # a path through the wall is refused with Nav2's code
    path.poses = [h.pose(2.0, 1.0), h.pose(4.0, 1.0)]
    _, handle = _send(client, SmoothPath, "smooth_path", SmoothPath.Goal(path=path))
    res = _result(handle).result
    assert res.error_code in (
        SmoothPath.Result.FAILED_TO_SMOOTH_PATH,
        SmoothPath.Result.INVALID_PATH,
    ), res.error_msg


def _params_client(client, node="trajopt_planner"):
    from rcl_interfaces.srv import GetParameters, SetParameters

    get = client.create_client(GetParameters, f"/{node}/get_parameters")
    put = client.create_client(SetParameters, f"/{node}/set_parameters")
    assert get.wait_for_service(timeout_sec=10.0) and put.wait_for_service(timeout_sec=10.0)
    return get, put


def test_parameters_from_yaml_and_refused_changes(served, client):
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import GetParameters, SetParameters

    get, put = _params_client(client)
    names = ["robot.radius", "robot.v_max", "robot.drive"]
    vals = h.call(get, GetParameters.Request(names=names)).values
    assert [vals[0].double_value, vals[1].double_value, vals[2].string_value] == [
        0.2,
        0.8,
        "differential",
    ]
    bad = [
        Parameter(
            name="robot.v_max",
            value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=-1.0),
        ),
        Parameter(
            name="robot.drive",
            value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="tank"),
        ),
    ]
    for p in bad:
        res = h.call(put, SetParameters.Request(parameters=[p])).results[0]
        assert not res.successful and p.name in res.reason
    # an atomic set: one bad value refuses the whole set, the good one is not half-applied
    good = Parameter(
        name="robot.a_max",
        value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=0.7),
    )
    from rcl_interfaces.srv import SetParametersAtomically

    atomic = client.create_client(
        SetParametersAtomically, "/trajopt_planner/set_parameters_atomically"
    )
    assert atomic.wait_for_service(timeout_sec=10.0)
    res = h.call(atomic, SetParametersAtomically.Request(parameters=[good, bad[0]])).result
    assert not res.successful
    vals = h.call(get, GetParameters.Request(names=["robot.a_max", "robot.v_max"])).values
    assert [vals[0].double_value, vals[1].double_value] == [0.5, 0.8]


def test_bad_parameter_file_refused_at_start(fresh_nodes):
    node = fresh_nodes["bad"]  # started with the module, its parameter file's drive "tank"
    code = node.proc.wait(60)
    assert code == 2
    out = node.output()
    assert "robot.drive" in out and "tank" in out


@pytest.mark.parametrize("sig", SIGNALS)
def test_shutdown_by_signal(fresh_nodes, client, sig):
    from nav_msgs.srv import GetPlan

    node, ns = fresh_nodes["sig", sig], f"/sig{int(sig)}"  # started with the module, no map
    srv = client.create_client(GetPlan, f"{ns}/get_plan")
    assert srv.wait_for_service(timeout_sec=30.0), node.output()
    # before any map: refused with its reason, and a malformed map is refused too
    req = GetPlan.Request(start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0))
    assert len(h.answered(srv, req, "get_plan before any map").plan.poses) == 0
    h.wait_for(lambda: "(no_map)" in node.output(), 30.0, "the refusal logged")
    from nav_msgs.msg import OccupancyGrid
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    qos = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    pub = client.create_publisher(OccupancyGrid, f"{ns}/map", qos)
    bad = h.grid_msg(h.wall_map())
    bad.data = bad.data[:-1]
    pub.publish(bad)
    h.wait_for(lambda: "map refused" in node.output(), 30.0, "the malformed map refused")
    assert "needed" in node.output() and len(h.call(srv, req).plan.poses) == 0
    # a clean exit (a node that hangs is killed after 10 s: code -9); the time it takes is
    # measured by benchmarks/bench_ros.py, not asserted here (the CPU may be shared)
    code, _ = node.stop(sig)
    assert code == 0, node.output()
    assert "Traceback" not in node.output()


def test_map_update_replans_running_trajectory(served, client, node_process):
    """Last: it leaves a new map. A goal on goal_pose runs; a map update re-plans it."""
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import Odometry, Path

    plans: list = []
    client.create_subscription(Path, "plan", plans.append, 10)
    odom_pub = client.create_publisher(Odometry, "odom", 10)
    goal_pub = client.create_publisher(PoseStamped, "goal_pose", 10)
    # every link matched first: a message sent before discovery is lost even with reliable QoS
    h.wait_for(
        lambda: (
            goal_pub.get_subscription_count() > 0
            and odom_pub.get_subscription_count() > 0
            and client.count_publishers("plan") > 0
        ),
        10.0,
        "the node's odom and goal_pose subscribers and its plan publisher",
    )
    odom = Odometry()
    odom.header.frame_id = "map"
    odom.pose.pose = h.pose(1.0, 1.0).pose

    # one goal that the node plans (reliable QoS): a second goal would re-plan on the old map
    # and could reach /plan after the map update below. Odometry and goal are two topics, so
    # the goal may be handled first; then the node refuses it (no_odometry), plans nothing,
    # and both are sent again
    refused = node_process.output().count("goal refused (no_odometry)")
    odom_pub.publish(odom)
    goal_pub.publish(h.pose(5.0, 1.0))

    def first_plan():
        nonlocal refused
        got = [p for p in plans if len(p.poses) > 0]
        if not got and node_process.output().count("goal refused (no_odometry)") > refused:
            refused += 1
            odom_pub.publish(odom)
            goal_pub.publish(h.pose(5.0, 1.0))
        return got

    first = h.wait_for(first_plan, 20.0, "a plan on /plan")[-1]
    n_before = len(plans)
    assert h.clearance(h.path_xy(first), served["values"]).min() >= h.RADIUS - TOL, (
        node_process.output()
    )
    old_xy, old_t = h.path_xy(first), h.stamps(first)
    # a block across the old route's last third
    k = int(0.7 * len(old_xy))
    cx, cy = old_xy[k]
    values = served["values"].copy()
    ix, iy = int(cx / h.RES), int(cy / h.RES)
    values[max(iy - 3, 0) : iy + 4, max(ix - 3, 0) : ix + 4] = 100
    assert h.clearance(old_xy, values).min() < h.RADIUS  # the old one now collides
    served["map_pub"].publish(h.grid_msg(values))
    new = h.wait_for(lambda: [p for p in plans[n_before:] if len(p.poses) > 0], 10.0, "a re-plan")[
        -1
    ]
    new_xy, new_t = h.path_xy(new), h.stamps(new)
    # it continues the old one: its first pose is where the old one is at that time
    assert old_t[0] <= new_t[0] <= old_t[-1]
    at = np.array([np.interp(new_t[0], old_t, old_xy[:, i]) for i in (0, 1)])
    assert np.hypot(*(new_xy[0] - at)) < 0.8 * 0.1 + 1e-3  # v_max x sample interval
    np.testing.assert_allclose(new_xy[-1], [5.0, 1.0], atol=TOL)
    assert h.clearance(new_xy, values).min() >= h.RADIUS - TOL
