"""The ``trajopt_planner`` ROS 2 node: maps, odometry and goals in; plans, trajectories out.

Interfaces (all names relative, so ``--ros-args -r __ns:=/robot1`` namespaces them; the
topic names are parameters ``topics.*``):

* subscriptions: ``map`` (``nav_msgs/OccupancyGrid``, reliable + transient local, depth 1),
  ``odom`` (``nav_msgs/Odometry``), ``goal_pose`` (``geometry_msgs/PoseStamped``);
* publications: ``plan`` (``nav_msgs/Path``, each pose stamped with the absolute time the
  robot should be there), ``trajectory`` (``trajectory_msgs/MultiDOFJointTrajectory``) and
  ``corridor_markers`` (``visualization_msgs/MarkerArray``), the last two built only while
  someone subscribes;
* service ``get_plan`` (``nav_msgs/srv/GetPlan``);
* actions ``plan_trajectory`` (``trajopt_ros_interfaces/action/PlanTrajectory``),
  ``compute_path_to_pose`` (``nav2_msgs/action/ComputePathToPose``) and ``smooth_path``
  (``nav2_msgs/action/SmoothPath``).

A *running* trajectory (started by ``goal_pose`` or by ``plan_trajectory`` with
``execute``) is re-planned with :meth:`trajopt.Planner.replan` when the map or its goal
changes, at most ``replan.rate`` times a second; a re-plan is published only when an
independent clearance check (:func:`trajopt_ros.check.collides`) passes on the newest map.
"""

from __future__ import annotations

import dataclasses
import gc
import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import rclpy
from geometry_msgs.msg import Point, PoseStamped
from nav_msgs.msg import OccupancyGrid as GridMsg
from nav_msgs.msg import Odometry, Path
from nav_msgs.srv import GetPlan
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.lifecycle import LifecycleNodeMixin, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from trajectory_msgs.msg import MultiDOFJointTrajectory
from visualization_msgs.msg import Marker, MarkerArray

import astar
import trajopt
from trajopt_ros import codes
from trajopt_ros.check import collides
from trajopt_ros.convert import (
    from_time,
    grid_from_msg,
    path_from_msg,
    path_msg,
    pose_from_msg,
    reference,
    to_duration,
    trajectory_msg,
)
from trajopt_ros.errors import ParameterError, RequestError
from trajopt_ros.params import PARAMETERS, NodeConfig, build_config

__all__ = ["PlannerNode", "ManagedPlannerNode", "NODE_NAME"]

#: Default node name.
NODE_NAME = "trajopt_planner"


class _Planned(NamedTuple):
    """A plan of the node: the trajectory, the library's wall and CPU time (s), the map."""

    traj: Any
    seconds: float
    cpu_seconds: float
    map_gen: int


@dataclass
class _Running:
    """The trajectory being driven: ``traj`` started at ROS time ``t0`` (s)."""

    traj: Any
    t0: float
    goal: tuple[float, float, float]
    map_gen: int
    goal_handle: Any = None
    replans: int = 0
    ended: str = ""  # why it stopped early: a reason of trajopt_ros.codes
    message: str = ""
    wake: threading.Event = field(default_factory=threading.Event)


class PlannerNode(Node):
    """The planner node (module docstring); start-up warms the library first.

    Parameters
    ----------
    node_name : str, optional
        Default ``trajopt_planner``.
    freeze_gc : bool, optional
        After the warm-up, before any service or subscription exists, collect garbage and
        move every object then alive out of the cyclic collector's reach (``gc.freeze``):
        the library's modules, kernels and solvers live as long as the process, and a full
        collection scanning them took 70-180 ms, every few dozen requests. For a process
        that runs this node (the ``trajopt-ros`` command); default False.
    **kwargs
        Passed to :class:`rclpy.node.Node` (e.g. ``parameter_overrides``).

    Raises
    ------
    ParameterError
        A parameter breaks its rule (the message names it, its value and the rule).
    """

    def __init__(
        self, node_name: str = NODE_NAME, *, freeze_gc: bool = False, **kwargs: Any
    ) -> None:
        super().__init__(node_name, **kwargs)
        self._declare()
        self._configure(freeze_gc)
        self._create_interfaces()

    # ------------------------------------------------------------ set-up
    def _declare(self) -> None:
        """Declare the parameters and set the state of a node without a map."""
        for p in PARAMETERS:
            self.declare_parameter(
                p.name,
                p.default,
                ParameterDescriptor(
                    description=p.description, read_only=p.name.startswith("topics.")
                ),
            )
        self._config: NodeConfig | None = None
        self._lock = threading.RLock()
        self._interfaces: list[tuple[str, Any]] = []  # (kind, entity) while they exist
        self._reset_state()
        self.add_on_set_parameters_callback(self._on_set_parameters)

    def _reset_state(self) -> None:
        self._planner: trajopt.Planner | None = None
        self._grid: astar.OccupancyGrid | astar.Costmap | None = None
        self._odom: tuple[float, float, float, float, float] | None = None
        self._running: _Running | None = None
        self._map_gen = 0  # +1 per accepted map; a plan carries the generation it was made on
        self._last_replan = -math.inf
        self._replan_due = ""  # why a deferred re-plan is due ('' = none)

    def _configure(self, freeze_gc: bool) -> None:
        """Check the parameters (:class:`ParameterError`) and warm the library up."""
        self._config = build_config(self._values())
        self.warm_up_s = self._warm_up()
        if freeze_gc:
            gc.collect()
            gc.freeze()

    def _create_interfaces(self) -> None:
        """Create the subscriptions, publishers, timer, actions and ``get_plan`` (last)."""
        cfg = self._config
        self._subs_group = MutuallyExclusiveCallbackGroup()
        self._serve_group = ReentrantCallbackGroup()
        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        made = self._interfaces
        for kind, topic, cb, qos in (
            (GridMsg, cfg["topics.map"], self._on_map, latched),
            (Odometry, cfg["topics.odom"], self._on_odom, 10),
            (PoseStamped, cfg["topics.goal"], self._on_goal, 10),
        ):
            sub = self.create_subscription(kind, topic, cb, qos, callback_group=self._subs_group)
            made.append(("subscription", sub))
        self._plan_pub = self.create_publisher(Path, cfg["topics.plan"], latched)
        self._traj_pub = self.create_publisher(
            MultiDOFJointTrajectory, cfg["topics.trajectory"], 10
        )
        self._marker_pub = self.create_publisher(MarkerArray, cfg["topics.markers"], latched)
        made += [("publisher", self._plan_pub), ("publisher", self._traj_pub)]
        made.append(("publisher", self._marker_pub))
        # a one-shot timer (cancelled while idle) for a re-plan the rate limit defers
        self._timer = self.create_timer(
            1.0 / cfg["replan.rate"], self._on_replan_timer, callback_group=self._subs_group
        )
        self._timer.cancel()
        made.append(("timer", self._timer))
        made += [("action", a) for a in self._create_actions()]
        # last, the service clients wait for (the actions' set-up takes 0.1-0.2 s: a client
        # that found get_plan earlier sent its first map before the node could spin)
        srv = self.create_service(
            GetPlan, "get_plan", self._on_get_plan, callback_group=self._serve_group
        )
        made.append(("service", srv))
        self.get_logger().info(
            f"ready: warm-up {self.warm_up_s:.2f} s, robot {cfg.robot.drive} "
            f"radius {cfg.robot.radius} m, frame {cfg['frame_id']!r}"
        )

    def _destroy_interfaces(self) -> None:
        """Stop a running trajectory and destroy the interfaces, ``get_plan`` first."""
        if self._interfaces:
            self._stop_running("canceled", "the node stops serving")
        destroy = {
            "subscription": self.destroy_subscription,
            "publisher": self.destroy_publisher,
            "timer": self.destroy_timer,
            "service": self.destroy_service,
            "action": lambda a: a.destroy(),
        }
        while self._interfaces:
            kind, entity = self._interfaces.pop()
            destroy[kind](entity)

    def _values(self) -> dict[str, Any]:
        return {p.name: self.get_parameter(p.name).value for p in PARAMETERS}

    def _warm_up(self) -> float:
        """Load kernels and build solvers on a small free map with the configured robot."""
        t0 = time.perf_counter()
        r = self._config.robot.radius
        res = max(r / 4.0, 0.01)
        n = int(math.ceil(12.0 * r / res)) + 8
        grid = astar.OccupancyGrid(np.zeros((n, n), bool), resolution=res)
        planner = trajopt.Planner(grid, self._config.robot, **self._planner_kwargs(grid))
        trajopt.warm_up(planner)
        return time.perf_counter() - t0

    def _planner_kwargs(self, grid: Any) -> dict[str, Any]:
        kw = dict(self._config.planner_kwargs)
        if (
            kw["search"] is not None
            and kw["search"].startswith("costmap")
            and not isinstance(grid, astar.Costmap)
        ):
            kw["search"] = None  # a costmap search needs a costmap; plain maps take the default
        return kw

    def _create_actions(self) -> list[ActionServer]:
        from trajopt_ros.build import ensure_interfaces

        ensure_interfaces()
        from trajopt_ros_interfaces.action import PlanTrajectory

        out = [
            ActionServer(
                self,
                PlanTrajectory,
                "plan_trajectory",
                execute_callback=self._execute_plan_trajectory,
                goal_callback=lambda _g: GoalResponse.ACCEPT,
                cancel_callback=lambda _g: CancelResponse.ACCEPT,
                callback_group=self._serve_group,
            )
        ]
        self._PlanTrajectory = PlanTrajectory
        try:
            from nav2_msgs.action import ComputePathToPose, SmoothPath
        except ImportError:  # pragma: no cover - the build provides a copy
            self.get_logger().warning("nav2_msgs not importable: no Nav2 actions")
            return out
        self._ComputePathToPose, self._SmoothPath = ComputePathToPose, SmoothPath
        for kind, name, cb in (
            (ComputePathToPose, "compute_path_to_pose", self._execute_compute_path),
            (SmoothPath, "smooth_path", self._execute_smooth_path),
        ):
            out.append(
                ActionServer(
                    self, kind, name, execute_callback=cb, callback_group=self._serve_group
                )
            )
        return out

    def _on_set_parameters(self, params: list[Any]) -> SetParametersResult:
        values = self._values() | {p.name: p.value for p in params}
        try:
            cfg = build_config(values)
        except ParameterError as exc:
            self.get_logger().warning(f"parameters refused: {exc}")
            return SetParametersResult(successful=False, reason=str(exc))
        with self._lock:
            old = self._config
            self._config = cfg
            if old is None:  # a managed node not configured yet: checked, kept for later
                return SetParametersResult(successful=True)
            if (cfg.robot, cfg.planner_kwargs) != (old.robot, old.planner_kwargs) and self._grid:
                self._planner = trajopt.Planner(
                    self._grid, cfg.robot, **self._planner_kwargs(self._grid)
                )
        return SetParametersResult(successful=True)

    # ------------------------------------------------------------ time and inputs
    def now_s(self) -> float:
        """Return the node's clock (s)."""
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_map(self, msg: GridMsg) -> None:
        t_received = time.time()
        cfg = self._config
        if msg.header.frame_id.lstrip("/") not in ("", cfg["frame_id"].lstrip("/")):
            self.get_logger().error(
                f"map refused: frame {msg.header.frame_id!r}, the planning frame is "
                f"{cfg['frame_id']!r}"
            )
            return
        try:
            grid = grid_from_msg(
                msg,
                mode=cfg["map.mode"],
                threshold=cfg["map.occupied_threshold"],
                unknown_occupied=cfg["map.unknown_occupied"],
            )
        except (RequestError, astar.InvalidInputError) as exc:
            self.get_logger().error(f"map refused, keeping the previous one: {exc}")
            return
        t_build = time.perf_counter()
        with self._lock:
            old = self._grid
            same = (
                self._planner is not None
                and isinstance(grid, astar.OccupancyGrid)
                and isinstance(old, astar.OccupancyGrid)
                and (old.shape, old.resolution, old.origin)
                == (grid.shape, grid.resolution, grid.origin)
            )
            if same:
                self._planner.update_map(grid)
            else:
                self._planner = trajopt.Planner(grid, cfg.robot, **self._planner_kwargs(grid))
            self._planner.inflated_grid  # noqa: B018 - compute the inflation now, not at the first query
            self._grid = grid
            self._map_gen += 1
            gen = self._map_gen
            due = self._running is not None
        build_ms = 1e3 * (time.perf_counter() - t_build)
        stamp = from_time(msg.header.stamp)
        lag = (
            f", received {1e3 * (t_received - stamp):.1f} ms and ready "
            f"{1e3 * (time.time() - stamp):.1f} ms after its stamp"
            if stamp > 0
            else ""
        )
        self.get_logger().info(
            f"map {gen} ({grid.shape[1]} x {grid.shape[0]} cells) ready: planner in "
            f"{build_ms:.1f} ms{lag} (received at {t_received:.6f})"
        )
        if due:
            self._maybe_replan("map changed")

    def _on_odom(self, msg: Odometry) -> None:
        cfg = self._config
        odom = (cfg["odom.frame_id"], cfg.odom_to_map) if cfg["odom.frame_id"] else None
        try:
            x, y, yaw = pose_from_msg(
                PoseStamped(header=msg.header, pose=msg.pose.pose),
                cfg["frame_id"],
                "odometry",
                odom,
            )
        except RequestError as exc:
            self.get_logger().warning(f"odometry ignored: {exc}", throttle_duration_sec=5.0)
            return
        tw = msg.twist.twist
        self._odom = (x, y, yaw, float(tw.linear.x), float(tw.angular.z))

    def _on_goal(self, msg: PoseStamped) -> None:
        try:
            goal = pose_from_msg(msg, self._config["frame_id"], "goal")
            with self._lock:
                running = self._active_running()
                if running is not None:
                    running.goal = goal
            if running is not None:
                self._maybe_replan("new goal")
                return
            start = self._start_from_odom()
            planned = self._plan(start, goal)
            self._start_running(planned.traj, planned.map_gen, start, goal, None)
        except Exception as exc:  # noqa: BLE001 - every failure is logged and the node serves on
            self.get_logger().error(f"goal refused ({codes.reason_of(exc)}): {exc}")

    # ------------------------------------------------------------ planning
    def _start_from_odom(self) -> tuple[float, float, float]:
        if self._odom is None:
            raise RequestError("no_odometry", "no odometry received yet: the start is unknown")
        return self._odom[:3]

    def _check_end(self, planner: trajopt.Planner, xy: tuple[float, float], what: str) -> None:
        grid = planner.grid
        ix = math.floor((xy[0] - grid.origin[0]) / grid.resolution)
        iy = math.floor((xy[1] - grid.origin[1]) / grid.resolution)
        if not (0 <= ix < grid.nx and 0 <= iy < grid.ny):
            raise RequestError(
                f"{what}_outside_map",
                f"{what} ({xy[0]:.3f}, {xy[1]:.3f}) m is outside the map "
                f"[{grid.origin[0]}, {grid.origin[0] + grid.width}] x "
                f"[{grid.origin[1]}, {grid.origin[1] + grid.height}] m",
            )
        if grid.occupied[iy, ix] or planner.inflated_grid.occupied[iy, ix]:
            raise RequestError(
                f"{what}_occupied",
                f"{what} ({xy[0]:.3f}, {xy[1]:.3f}) m is in cell ({ix}, {iy}), occupied or "
                f"within the robot radius {planner.robot.radius} m of an obstacle",
            )

    def _plan(
        self, start: tuple[float, float, float], goal: tuple[float, float, float]
    ) -> _Planned:
        """Plan ``start`` -> ``goal`` (x, y, yaw) on the newest map.

        The plan holds the node's lock: no map replaces the planner's meanwhile.
        """
        with self._lock:
            planner = self._planner
            if planner is None:
                raise RequestError("no_map", "no valid map received yet")
            self._check_end(planner, start[:2], "start")
            self._check_end(planner, goal[:2], "goal")
            t0, c0 = time.perf_counter(), time.thread_time()
            traj = planner.plan(start[:2], goal[:2], start_heading=start[2], goal_heading=goal[2])
            wall, cpu = time.perf_counter() - t0, time.thread_time() - c0
            return _Planned(traj, wall, cpu, self._map_gen)

    def _fail(self, where: str, exc: BaseException) -> tuple[str, str]:
        reason = codes.reason_of(exc)
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        msg = f"{type(exc).__name__}: {msg}"
        self.get_logger().warning(f"{where} refused ({reason}): {msg}")
        return reason, msg

    # ------------------------------------------------------------ running trajectory
    def _active_running(self) -> _Running | None:
        run = self._running
        if run is None or self.now_s() - run.t0 >= float(run.traj.duration):
            return None
        return run

    def _start_running(
        self,
        traj: Any,
        gen: int,
        start: tuple[float, float, float],
        goal: tuple[float, float, float],
        handle: Any,
    ) -> _Running:
        """Drive ``traj`` (made on map generation ``gen``) from now and publish it.

        All of it under the node's lock, as every publication on ``plan``: plans reach
        ``plan`` in the order of the maps they were made on. A trajectory made on a map that
        has been replaced since is planned again on the newest one before it is published.
        """
        with self._lock:
            if gen != self._map_gen:
                self.get_logger().info(
                    f"plan made on map {gen}, map {self._map_gen} arrived meanwhile: planning again"
                )
                again = self._plan(start, goal)
                traj, gen = again.traj, again.map_gen
            old = self._running
            if old is not None and old.goal_handle is not None and old.goal_handle is not handle:
                old.ended, old.message = "preempted", "replaced by a newer goal"
                old.wake.set()
            run = _Running(traj=traj, t0=self.now_s(), goal=goal, map_gen=gen, goal_handle=handle)
            self._running = run
            self._publish(run)
        return run

    def _stop_running(self, reason: str, message: str) -> None:
        with self._lock:
            run, self._running = self._running, None
            if run is not None:
                run.ended, run.message = reason, message
                run.wake.set()
                empty = Path()
                empty.header.frame_id = self._config["frame_id"]
                empty.header.stamp = self.get_clock().now().to_msg()
                self._plan_pub.publish(empty)

    def _on_replan_timer(self) -> None:
        self._timer.cancel()
        if self._replan_due:
            self._maybe_replan(f"{self._replan_due}, deferred by replan.rate")

    def _maybe_replan(self, why: str) -> None:
        """Re-plan the running trajectory now, or when the rate limit ``replan.rate`` allows.

        A deferred re-plan runs on a one-shot timer at the earliest time the limit allows.
        The re-plan and its publication hold the node's lock (ordered with map updates).
        """
        with self._lock:
            wait = self._last_replan + 1.0 / self._config["replan.rate"] - time.monotonic()
            if wait > 0:
                if not self._replan_due:
                    self._timer.timer_period_ns = max(int(wait * 1e9), 1_000_000)
                    self._timer.reset()
                self._replan_due = why.split(",")[0]
                return
            self._replan_due = ""
            run = self._active_running()
            planner = self._planner
            if run is None or planner is None:
                return
            self._last_replan = time.monotonic()
            t = self.now_s() - run.t0
            duration = float(run.traj.duration)
            latency = max(planner.latency_s, 0.02)
            if t + latency >= duration:
                return
            gx, gy, gyaw = run.goal
            t_replan = time.perf_counter()
            try:
                new = planner.replan(run.traj, t, goal=(gx, gy), goal_heading=gyaw, latency=latency)
            except Exception as exc:  # noqa: BLE001 - the old trajectory stays if still clear
                reason, msg = self._fail(f"re-plan ({why})", exc)
                if collides(run.traj, self._grid, self._config.robot, t):
                    self._stop_running(
                        reason, f"re-plan failed and the old trajectory collides: {msg}"
                    )
                return
            if collides(new, self._grid, self._config.robot, 0.0):
                self.get_logger().error(f"re-plan ({why}) collides with the newest map: not used")
                if collides(run.traj, self._grid, self._config.robot, t):
                    self._stop_running("unknown", "old and re-planned trajectories collide")
                return
            run.t0 += float(new.stats.get("splice_time_s", t + latency))
            run.traj = new
            run.map_gen = self._map_gen
            run.replans += 1
            run.wake.set()
            replan_ms = 1e3 * (time.perf_counter() - t_replan)
            t_pub = time.perf_counter()
            self._publish(run)
            pub_ms = 1e3 * (time.perf_counter() - t_pub)
            published = time.time()
        self.get_logger().info(
            f"re-planned ({why}) on map {run.map_gen} in {replan_ms:.1f} ms, published in "
            f"{pub_ms:.1f} ms (stamp {run.t0:.6f}, published at {published:.6f}): "
            f"{new.stats.get('replan', '')}"
        )

    # ------------------------------------------------------------ outputs
    def _publish(self, run: _Running) -> None:
        cfg = self._config
        dt = cfg["plan.sample_interval"]
        smp = run.traj.sample_uniform(dt)
        self._plan_pub.publish(path_msg(run.traj, run.t0, cfg["frame_id"], dt, smp))
        if self._traj_pub.get_subscription_count() > 0:
            self._traj_pub.publish(trajectory_msg(run.traj, run.t0, cfg["frame_id"], dt, smp))
        if self._marker_pub.get_subscription_count() > 0:
            self._marker_pub.publish(self._markers(run.traj, smp))

    def _markers(self, traj: Any, smp: Any) -> MarkerArray:
        frame, stamp = self._config["frame_id"], self.get_clock().now().to_msg()
        out = MarkerArray(markers=[Marker(action=Marker.DELETEALL, ns="corridor")])
        steps = getattr(traj, "steps", None)
        regions = getattr(getattr(steps, "corridor", None), "regions", None) or ()
        for k, region in enumerate(regions):
            verts = getattr(region, "vertices", None)
            if verts is None:
                continue
            m = Marker(ns="corridor", id=k, type=Marker.LINE_STRIP, action=Marker.ADD)
            m.header.frame_id, m.header.stamp = frame, stamp
            m.scale.x = 0.02
            m.color.g, m.color.b, m.color.a = 0.6, 1.0, 0.8
            m.pose.orientation.w = 1.0
            v = np.asarray(verts, dtype=float)
            m.points = [Point(x=float(x), y=float(y)) for x, y in np.vstack([v, v[:1]])]
            out.markers.append(m)
        robot = self._config.robot
        fp = robot.footprint
        ring = (
            np.asarray(fp.vertices, dtype=float)
            if fp is not None
            else robot.radius
            * np.column_stack(
                [np.cos(np.linspace(0, 2 * np.pi, 25)), np.sin(np.linspace(0, 2 * np.pi, 25))]
            )
        )
        x0, y0, th = float(smp.x[0]), float(smp.y[0]), float(smp.theta[0])
        c, s = math.cos(th), math.sin(th)
        m = Marker(ns="footprint", id=0, type=Marker.LINE_STRIP, action=Marker.ADD)
        m.header.frame_id, m.header.stamp = frame, stamp
        m.scale.x = 0.02
        m.color.r, m.color.a = 1.0, 1.0
        m.pose.orientation.w = 1.0
        pts = np.vstack([ring, ring[:1]])
        m.points = [
            Point(x=x0 + c * px - s * py, y=y0 + s * px + c * py) for px, py in pts.tolist()
        ]
        out.markers.append(m)
        return out

    # ------------------------------------------------------------ GetPlan
    def _on_get_plan(
        self, request: GetPlan.Request, response: GetPlan.Response
    ) -> GetPlan.Response:
        t_in, wall_in = time.perf_counter(), time.time()
        frame = self._config["frame_id"]
        response.plan.header.frame_id = frame
        try:
            start = pose_from_msg(request.start, frame, "start")
            goal = pose_from_msg(request.goal, frame, "goal")
            planned = self._plan(start, goal)
        except Exception as exc:  # noqa: BLE001 - answered with an empty path and a logged reason
            self._fail("get_plan", exc)
            response.plan.header.stamp = self.get_clock().now().to_msg()
            return response
        response.plan = path_msg(
            planned.traj, self.now_s(), frame, self._config["plan.sample_interval"]
        )
        total_ms = 1e3 * (time.perf_counter() - t_in)
        self.get_logger().debug(  # per request, as Nav2's planner server: debug level
            f"get_plan: {len(response.plan.poses)} poses on map {planned.map_gen}, library plan "
            f"{1e3 * planned.seconds:.3f} ms (CPU {1e3 * planned.cpu_seconds:.3f} ms), callback "
            f"{total_ms:.3f} ms (from {wall_in:.6f})"
        )
        return response

    # ------------------------------------------------------------ PlanTrajectory
    def _execute_plan_trajectory(self, handle: Any) -> Any:
        kind = self._PlanTrajectory
        req = handle.request
        result = kind.Result()
        frame = self._config["frame_id"]
        result.path.header.frame_id = frame
        try:
            goal = pose_from_msg(req.goal, frame, "goal")
            start = (
                pose_from_msg(req.start, frame, "start")
                if req.use_start
                else self._start_from_odom()
            )
            traj, planning_s, _, gen = self._plan(start, goal)
        except Exception as exc:  # noqa: BLE001 - every failure becomes a coded result
            reason, msg = self._fail("plan_trajectory", exc)
            result.error_code, result.error_msg = codes.code_for(codes.PLAN_TRAJECTORY, reason), msg
            handle.abort()
            return result
        result.planning_time = to_duration(planning_s)
        fb = kind.Feedback(planning_time=result.planning_time)
        if not req.execute:
            self._fill_result(result, traj, self.now_s())
            handle.publish_feedback(fb)
            handle.succeed()
            return result
        try:
            run = self._start_running(traj, gen, start, goal, handle)
        except Exception as exc:  # noqa: BLE001 - a plan again on a newer map can fail too
            reason, msg = self._fail("plan_trajectory", exc)
            result.error_code, result.error_msg = codes.code_for(codes.PLAN_TRAJECTORY, reason), msg
            handle.abort()
            return result
        period = 1.0 / self._config["feedback.rate"]
        while True:
            if handle.is_cancel_requested:
                self._stop_running("canceled", "cancelled by the client")
                self._fill_result(result, run.traj, run.t0, run.replans)
                result.error_code = codes.PLAN_TRAJECTORY["canceled"]
                result.error_msg = "cancelled by the client"
                handle.canceled()
                return result
            if run.ended:
                self._fill_result(result, run.traj, run.t0, run.replans)
                result.error_code = codes.code_for(codes.PLAN_TRAJECTORY, run.ended)
                result.error_msg = run.message
                handle.abort()
                return result
            t = self.now_s() - run.t0
            duration = float(run.traj.duration)
            if t >= duration:
                with self._lock:
                    if self._running is run:
                        self._running = None
                self._fill_result(result, run.traj, run.t0, run.replans)
                handle.succeed()
                return result
            fb.time_from_start = to_duration(t)
            fb.time_remaining = to_duration(duration - t)
            fb.reference_pose, fb.reference_twist = reference(run.traj, t)
            fb.replans = run.replans
            handle.publish_feedback(fb)
            run.wake.wait(min(period, max(duration - t, 0.001)))
            run.wake.clear()

    def _fill_result(self, result: Any, traj: Any, t0: float, replans: int = 0) -> None:
        frame, dt = self._config["frame_id"], self._config["plan.sample_interval"]
        smp = traj.sample_uniform(dt)
        result.path = path_msg(traj, t0, frame, dt, smp)
        result.trajectory = trajectory_msg(traj, t0, frame, dt, smp)
        result.duration = to_duration(float(traj.duration))
        result.replans = replans

    # ------------------------------------------------------------ Nav2 actions
    def _execute_compute_path(self, handle: Any) -> Any:
        req = handle.request
        result = self._ComputePathToPose.Result()
        frame = self._config["frame_id"]
        result.path.header.frame_id = frame
        try:
            if req.planner_id not in ("", "trajopt"):
                raise RequestError(
                    "invalid_planner", f"planner_id {req.planner_id!r}: this server has 'trajopt'"
                )
            goal = pose_from_msg(req.goal, frame, "goal")
            start = (
                pose_from_msg(req.start, frame, "start")
                if req.use_start
                else self._start_from_odom()
            )
            traj, planning_s, _, _ = self._plan(start, goal)
        except Exception as exc:  # noqa: BLE001 - every failure becomes Nav2's code
            reason, msg = self._fail("compute_path_to_pose", exc)
            result.error_code = codes.code_for(codes.COMPUTE_PATH_TO_POSE, reason)
            result.error_msg = msg
            handle.abort()
            return result
        result.path = path_msg(traj, self.now_s(), frame, self._config["plan.sample_interval"])
        result.planning_time = to_duration(planning_s)
        handle.succeed()
        return result

    def _execute_smooth_path(self, handle: Any) -> Any:
        req = handle.request
        result = self._SmoothPath.Result()
        frame = self._config["frame_id"]
        result.path.header.frame_id = frame
        t0 = time.perf_counter()
        try:
            if req.smoother_id not in ("", "trajopt"):
                raise RequestError(
                    "invalid_smoother",
                    f"smoother_id {req.smoother_id!r}: this server has 'trajopt'",
                )
            poses = path_from_msg(req.path, frame)
            budget = from_time(req.max_smoothing_duration)
            traj = self._smooth(poses, t0 + budget if budget > 0 else None)
            if req.check_for_collisions and collides(traj, self._grid, self._config.robot, 0.0):
                raise RequestError("in_collision", "the smoothed path collides with the map")
        except Exception as exc:  # noqa: BLE001 - every failure becomes Nav2's code
            reason, msg = self._fail("smooth_path", exc)
            result.error_code = codes.code_for(codes.SMOOTH_PATH, reason)
            result.error_msg = msg
            result.smoothing_duration = to_duration(time.perf_counter() - t0)
            handle.abort()
            return result
        result.smoothing_duration = to_duration(time.perf_counter() - t0)
        result.was_completed = True
        result.path = path_msg(traj, self.now_s(), frame, self._config["plan.sample_interval"])
        handle.succeed()
        return result

    def _smooth(self, poses: np.ndarray, deadline: float | None = None) -> Any:
        """Time a certified curve along a given path: its corridor, the smoother, the timing.

        ``deadline`` (``time.perf_counter`` seconds, or None) bounds the fit: the smoother's
        ``time_budget_s`` becomes the time left, and a fit that fails at or after the
        deadline, or no time left before it, raises ``RequestError("timeout")``.
        """
        with self._lock:  # no map update meanwhile, as for a plan
            return self._smooth_locked(poses, deadline)

    def _smooth_locked(self, poses: np.ndarray, deadline: float | None) -> Any:
        planner = self._planner
        if planner is None:
            raise RequestError("no_map", "no valid map received yet")
        self._check_end(planner, tuple(poses[0, :2]), "start")
        self._check_end(planner, tuple(poses[-1, :2]), "goal")
        robot = planner.robot
        pts = poses[:, :2]
        keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9])
        pts = pts[keep]
        corridor = trajopt.build_polygon_corridor(planner.grid, pts, robot.radius)
        smoother = planner.smoother
        if deadline is not None:
            left = deadline - time.perf_counter()
            if left <= 0:
                raise RequestError(
                    "timeout", "max_smoothing_duration passed before the fit could start"
                )
            smoother = dataclasses.replace(
                smoother, time_budget_s=min(smoother.time_budget_s, left)
            )
        try:
            smooth = smoother.fit(
                pts,
                corridor,
                raw_grid=planner.grid,
                radius=robot.radius,
                start=pts[0],
                goal=pts[-1],
            )
        except trajopt.SmoothingError as exc:
            if deadline is not None and time.perf_counter() >= deadline:
                raise RequestError(
                    "timeout", f"the fit stopped at max_smoothing_duration: {exc}"
                ) from exc
            raise
        return trajopt.time_parameterize(smooth, robot, dt=self._config["planner.timing_dt"])


class ManagedPlannerNode(LifecycleNodeMixin, PlannerNode):
    """The planner node as a managed (lifecycle) node: the same interfaces, made by transitions.

    Created *unconfigured*, with its parameters declared and the lifecycle services
    (``~/change_state``, ``~/get_state``, ...) only. ``configure`` checks the parameters
    (a bad one fails the transition with its reason logged) and warms the library up;
    ``activate`` creates the subscriptions, publishers, actions and ``get_plan``;
    ``deactivate`` stops a running trajectory (an empty ``plan``) and destroys them;
    ``cleanup`` forgets the map, the odometry and the planner; ``shutdown`` does all of it.

    Parameters
    ----------
    node_name : str, optional
        Default ``trajopt_planner``.
    freeze_gc : bool, optional
        As :class:`PlannerNode`, at the end of ``configure``.
    **kwargs
        Passed to :class:`rclpy.node.Node`.
    """

    def __init__(
        self, node_name: str = NODE_NAME, *, freeze_gc: bool = False, **kwargs: Any
    ) -> None:
        Node.__init__(self, node_name, **kwargs)
        LifecycleNodeMixin.__init__(self, enable_communication_interface=True)
        self._freeze_gc = freeze_gc
        self._declare()

    def on_configure(self, state: Any) -> TransitionCallbackReturn:
        """Check the parameters and warm the library up (FAILURE with a bad one)."""
        try:
            self._configure(self._freeze_gc)
        except ParameterError as exc:
            self.get_logger().error(f"configure failed: {exc}")
            return TransitionCallbackReturn.FAILURE
        self.get_logger().info(f"configured: warm-up {self.warm_up_s:.2f} s")
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: Any) -> TransitionCallbackReturn:
        """Create the interfaces, ``get_plan`` last."""
        self._create_interfaces()
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: Any) -> TransitionCallbackReturn:
        """Stop a running trajectory and destroy the interfaces."""
        self._destroy_interfaces()
        self.get_logger().info("deactivated: no interfaces")
        return TransitionCallbackReturn.SUCCESS

    def on_cleanup(self, state: Any) -> TransitionCallbackReturn:
        """Forget the map, the odometry, the planner and the running trajectory."""
        with self._lock:
            self._reset_state()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: Any) -> TransitionCallbackReturn:
        """Deactivate (if active) and clean up."""
        self._destroy_interfaces()
        with self._lock:
            self._reset_state()
        return TransitionCallbackReturn.SUCCESS


def spin(node: PlannerNode, executor: Any = None) -> None:
    """Spin ``node`` until shutdown (SIGINT/SIGTERM), then destroy it.

    Parameters
    ----------
    node : PlannerNode
    executor : rclpy.executors.Executor, optional
        Default a :class:`~rclpy.executors.MultiThreadedExecutor` of 4 threads (services
        and actions run beside the map and odometry callbacks).
    """
    from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor

    try:
        if executor is None:
            executor = MultiThreadedExecutor(num_threads=4)
        executor.add_node(node)
        # waits of at most 0.5 s rather than spin()'s unbounded one: with nothing else due,
        # a SIGTERM's shutdown sometimes left the executor waiting (seen in about 3 of 10
        # runs of the shutdown test); each wait's end checks the context again
        while node.context.ok():
            executor.spin_once(timeout_sec=0.5)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except Exception:  # a signal between start-up and spin leaves an invalid context
        if rclpy.ok():
            raise
    finally:
        if executor is not None:
            executor.shutdown(timeout_sec=0.5)
        node.destroy_node()
        rclpy.try_shutdown()
