"""Tests of trajopt_ros: the managed node (``trajopt-ros --managed``) through its transitions.

One node process, started with a bad parameter: ``configure`` fails with the reason logged
and the node stays unconfigured; the parameter set right, ``configure`` and ``activate``
bring up ``get_plan`` (a plan on a published map, checked by brute-force clearance);
``deactivate`` takes it off the graph, ``cleanup`` returns to unconfigured, SIGINT ends the
process cleanly. The states are read with ``~/get_state``; no fixed sleeps.

A service drops its answer to a client whose reply reader it has not matched yet (Fast DDS
waits about 100 ms for that match, then rclpy warns "failed to send response (timeout):
client will not receive response"), and ``wait_for_service`` returns as soon as the *client*
sees the server, so under heavy load the first call of a client may get no answer at all.
Each client's first call is therefore one that changes nothing, repeated until it is answered
(:func:`tests.trajopt_ros.helpers.answered`); ``change_state`` is primed with a transition label the node does not
know (refused, no transition); only then does a call that changes the node go out once.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("rclpy", reason="the ROS 2 wheels are not installed (pip install -e '.[ros2]')")

from tests.trajopt_ros import helpers as h  # noqa: E402
from tests.trajopt_ros.conftest import NodeProcess  # noqa: E402

NS, NAME = "/managed", "trajopt_managed"


def test_managed_node_lifecycle(ros_env, interfaces, client):
    from lifecycle_msgs.msg import State, Transition
    from lifecycle_msgs.srv import ChangeState, GetState
    from nav_msgs.msg import OccupancyGrid
    from nav_msgs.srv import GetPlan
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParameters
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    node = NodeProcess(
        ros_env,
        "-r",
        f"__ns:={NS}",
        "-p",
        "robot.drive:=tank",
        "-p",
        f"robot.radius:={h.RADIUS}",
        name=NAME,
        cli_args=("--managed",),
    )
    base = f"{NS}/{NAME}"
    change = client.create_client(ChangeState, f"{base}/change_state")
    get = client.create_client(GetState, f"{base}/get_state")
    put = client.create_client(SetParameters, f"{base}/set_parameters")
    for srv in (change, get, put):
        assert srv.wait_for_service(timeout_sec=30.0), node.output()
    unknown = ChangeState.Request()
    unknown.transition.label = "no_such_transition"  # refused: no transition, no side effect
    assert not h.answered(change, unknown, "change_state primed").success, node.output()
    assert not h.answered(put, SetParameters.Request(), "set_parameters primed").results

    def state() -> int:
        return h.answered(get, GetState.Request(), "get_state").current_state.id

    def step(transition: int) -> bool:
        req = ChangeState.Request()
        req.transition.id = transition
        return h.call(change, req, 120.0).success  # configure warms the library up

    assert state() == State.PRIMARY_STATE_UNCONFIGURED
    # a bad parameter: configure fails with its reason, the node stays unconfigured
    assert not step(Transition.TRANSITION_CONFIGURE)
    assert "configure failed" in node.output() and "robot.drive" in node.output()
    assert state() == State.PRIMARY_STATE_UNCONFIGURED
    fixed = Parameter(
        name="robot.drive",
        value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="differential"),
    )
    assert h.call(put, SetParameters.Request(parameters=[fixed])).results[0].successful
    assert step(Transition.TRANSITION_CONFIGURE), node.output()
    assert state() == State.PRIMARY_STATE_INACTIVE
    get_plan = client.create_client(GetPlan, f"{NS}/get_plan")
    assert not get_plan.service_is_ready()  # inactive: configured, not serving

    assert step(Transition.TRANSITION_ACTIVATE), node.output()
    assert state() == State.PRIMARY_STATE_ACTIVE
    assert get_plan.wait_for_service(timeout_sec=30.0), node.output()
    qos = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    values = h.wall_map()
    client.create_publisher(OccupancyGrid, f"{NS}/map", qos).publish(h.grid_msg(values))
    req = GetPlan.Request(start=h.pose(1.0, 1.0), goal=h.pose(5.0, 1.0))
    path = h.wait_for(
        lambda: (p := h.answered(get_plan, req, "get_plan").plan) and len(p.poses) > 0 and p,
        30.0,
        "a plan from the activated node",
    )
    xy = h.path_xy(path)
    np.testing.assert_allclose(xy[[0, -1]], [[1.0, 1.0], [5.0, 1.0]], atol=1e-6)
    assert h.clearance(xy, values).min() >= h.RADIUS - 1e-6

    assert step(Transition.TRANSITION_DEACTIVATE), node.output()
    assert state() == State.PRIMARY_STATE_INACTIVE
    # no server behind get_plan any more (the graph still lists it: this client uses it)
    h.wait_for(lambda: not get_plan.service_is_ready(), 30.0, "get_plan gone after deactivate")
    assert step(Transition.TRANSITION_CLEANUP), node.output()
    assert state() == State.PRIMARY_STATE_UNCONFIGURED
    code, _ = node.stop()
    assert code == 0, node.output()
    assert "Traceback" not in node.output()
