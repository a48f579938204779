"""Tests of trajopt_ros: maps and ``plan`` publications ordered, no plan of a replaced map sent.

The node runs in this process (no executor: its callbacks are called directly, from two
threads where a race is staged), so that a map update can be delivered at the exact moment
that would publish a stale plan: while the library plans, and between the plan and its
publication. Each publication on ``plan`` is recorded with the map generation current at
that moment; the published paths are checked against the maps by brute-force clearance.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

pytest.importorskip("rclpy", reason="the ROS 2 wheels are not installed (pip install -e '.[ros2]')")

from tests.trajopt_ros import helpers as h  # noqa: E402

TOL = 1e-6
START, GOAL = (1.0, 1.0), (5.0, 1.0)


def gap_below_map() -> np.ndarray:
    """The wall at x = 3 m moved up: from y = 1.4 m to the top, the gap below it."""
    v = np.zeros((h.NY, h.NX), np.int8)
    v[int(1.4 / h.RES) :, int(3.0 / h.RES) : int(3.2 / h.RES)] = 100
    return v


class Recorder:
    """Stands in for the node's ``plan`` publisher.

    Records each message with the newest map's generation at that moment and the generation
    of the map the published trajectory was made on.
    """

    def __init__(self, node):
        self.node, self.sent = node, []

    def publish(self, msg):
        run = self.node._running
        self.sent.append((self.node._map_gen, run.map_gen if run else None, msg))


@pytest.fixture
def node(ros_env, interfaces):
    import rclpy
    from nav_msgs.msg import Odometry
    from rclpy.parameter import Parameter

    from trajopt_ros.node import PlannerNode

    context = rclpy.context.Context()
    rclpy.init(context=context)
    overrides = [
        Parameter("robot.radius", value=h.RADIUS),
        Parameter("robot.v_max", value=0.8),
        Parameter("replan.rate", value=50.0),
    ]
    node = PlannerNode("trajopt_planner_order", context=context, parameter_overrides=overrides)
    node._plan_pub = Recorder(node)
    node._on_map(h.grid_msg(h.wall_map()))
    odom = Odometry()
    odom.header.frame_id = "map"
    odom.pose.pose = h.pose(*START).pose
    node._on_odom(odom)
    yield node
    node.destroy_node()
    rclpy.shutdown(context=context)


def clear_on(path, values) -> bool:
    return h.clearance(h.path_xy(path), values).min() >= h.RADIUS - TOL


def test_map_arriving_between_plan_and_publication_is_planned_again(node):
    """The plan returns, a map replaces it before publication: the plan is made again."""
    new_map = gap_below_map()
    real_plan = node._plan
    made = []

    def plan_then_map_update(start, goal):
        out = real_plan(start, goal)
        made.append(out)
        if len(made) == 1:
            node._on_map(h.grid_msg(new_map))  # the map callback's thread, at the worst moment
        return out

    node._plan = plan_then_map_update
    node._on_goal(h.pose(*GOAL))
    first = made[0].traj.sample_uniform(0.05)
    old_xy = np.column_stack([first.x, first.y])
    assert h.clearance(old_xy, new_map).min() < h.RADIUS  # the first plan hits the new wall
    # one publication: the plan made again on map 2, not the one made on map 1
    ((newest, made_on, path),) = node._plan_pub.sent
    assert newest == made_on == 2 and node._running.map_gen == 2
    assert [m.map_gen for m in made] == [1, 2]
    np.testing.assert_allclose(h.path_xy(path)[[0, -1]], [START, GOAL], atol=TOL)
    assert clear_on(path, new_map)


def test_map_arriving_during_a_plan_reaches_plan_after_it(node):
    """A map update during the library's plan waits for it; its re-plan is published last."""
    new_map = gap_below_map()
    planner = node._planner
    real = planner.plan
    in_plan, update_started = threading.Event(), threading.Event()

    def slow_plan(*args, **kwargs):
        in_plan.set()
        update_started.wait(10.0)
        return real(*args, **kwargs)

    planner.plan = slow_plan
    goal_thread = threading.Thread(target=node._on_goal, args=(h.pose(*GOAL),))
    goal_thread.start()
    assert in_plan.wait(30.0)

    def update():
        update_started.set()
        node._on_map(h.grid_msg(new_map))

    map_thread = threading.Thread(target=update)
    map_thread.start()
    goal_thread.join(60.0)
    map_thread.join(60.0)
    planner.plan = real
    sent = node._plan_pub.sent
    # Two orders are right, depending on which thread takes the lock when the plan ends:
    # the plan on map 1 published, then the update's re-plan on map 2; or the map applied
    # first and the plan made again on map 2. Never a plan published after a newer map.
    assert sent and all(newest == made_on for newest, made_on, _ in sent), sent
    assert [made_on for _, made_on, _ in sent] in ([1, 2], [2])
    maps = {1: h.wall_map(), 2: new_map}
    assert all(clear_on(path, maps[made_on]) for _, made_on, path in sent)
    final = sent[-1][2]
    assert node._running.map_gen == 2
    np.testing.assert_allclose(h.path_xy(final)[-1], GOAL, atol=TOL)
    assert clear_on(final, new_map)


def test_rate_limited_replan_runs_once_when_the_limit_allows(node):
    """A re-plan the rate limit defers runs on the one-shot timer, not before 1 / rate."""
    import time

    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    assert node.set_parameters([Parameter("replan.rate", value=2.0)])[0].successful
    node._on_goal(h.pose(*GOAL))
    t_first = time.monotonic()
    node._maybe_replan("map changed")  # the first re-plan runs at once
    assert node._running.replans == 1
    node._maybe_replan("map changed")  # the next within 1 / rate = 0.5 s is deferred
    assert node._replan_due == "map changed" and node._running.replans == 1
    node._maybe_replan("new goal")  # a second request while one waits: still one re-plan
    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    try:
        while node._running.replans == 1:
            assert time.monotonic() - t_first < 10.0, "the deferred re-plan never ran"
            executor.spin_once(timeout_sec=0.1)
        t_replan = time.monotonic()
        for _ in range(10):  # nothing more is due: the timer stays cancelled
            executor.spin_once(timeout_sec=0.1)
    finally:
        executor.remove_node(node)
        executor.shutdown()
    assert t_replan - t_first >= 0.5
    assert node._running.replans == 2 and node._replan_due == ""
    assert len(node._plan_pub.sent) == 3
