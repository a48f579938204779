"""The node's parameters: names, types, defaults, descriptions, and their validation.

:data:`PARAMETERS` lists every parameter (declared by the node with its description);
:func:`build_config` turns a full set of values into a :class:`NodeConfig`, building the
:class:`trajopt.Robot` and :class:`trajopt.PlannerOptions` they describe, or raises
:class:`~trajopt_ros.errors.ParameterError` naming the parameter, its value and the rule.
The node validates the whole set on start-up and on every ``set_parameters`` call, so an
invalid change is refused whole and a valid one applies whole. No ROS import here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

import trajopt
from trajopt_ros.errors import ParameterError

__all__ = ["Parameter", "PARAMETERS", "NodeConfig", "build_config", "defaults"]


@dataclass(frozen=True, slots=True)
class Parameter:
    """One node parameter.

    Attributes
    ----------
    name : str
        Its ROS name (dots group: ``robot.radius``).
    default : bool, int, float, str or list of float
        Its default; the type of the default is the parameter's type.
    description : str
        What it means, with its unit.
    """

    name: str
    default: Any
    description: str


PARAMETERS: tuple[Parameter, ...] = (
    Parameter(
        "frame_id", "map", "the planning frame: the map's frame; poses in another are refused"
    ),
    Parameter("robot.radius", 0.165, "radius of a disc robot (m); ignored with a footprint"),
    Parameter(
        "robot.footprint",
        [0.0],
        "convex footprint polygon as a flat list x0, y0, x1, y1, ... (m, robot frame, x "
        "forward); [0.0] or [] for none (a disc of robot.radius)",
    ),
    Parameter("robot.drive", "differential", "differential, omni or ackermann"),
    Parameter("robot.v_max", 0.5, "maximum forward speed (m/s)"),
    Parameter("robot.a_max", 0.5, "maximum tangential acceleration and deceleration (m/s^2)"),
    Parameter("robot.j_max", 2.0, "maximum tangential jerk (m/s^3)"),
    Parameter("robot.a_lat_max", 0.5, "maximum lateral acceleration (m/s^2)"),
    Parameter("robot.omega_max", 1.5, "maximum yaw rate (rad/s)"),
    Parameter(
        "robot.min_turning_radius",
        0.0,
        "minimum turning radius of a car-like robot (m, > 0 with drive ackermann, 0 otherwise)",
    ),
    Parameter("robot.reverse", True, "whether a car-like robot may reverse"),
    Parameter("planner.corridor", "polygons", "polygons or boxes"),
    Parameter(
        "planner.search",
        "",
        "A* cost: clearance, shortest, costmap, costmap+clearance; '' picks per map type",
    ),
    Parameter("planner.costmap_weight", 2.0, "weight of a costmap's graded cost (>= 0)"),
    Parameter("planner.fallback", "", "'' (none) or stop_and_turn"),
    Parameter("planner.timing_dt", 0.02, "step of the timing's forward pass (s)"),
    Parameter("planner.search_mode", "auto", "auto, exact or coarse"),
    Parameter(
        "map.mode",
        "auto",
        "how /map values read: occupancy (threshold), costmap (0-100 graded cost), or auto "
        "(costmap when any value lies in 1..99)",
    ),
    Parameter("map.occupied_threshold", 65, "occupancy mode: a value >= this is occupied (1-100)"),
    Parameter("map.unknown_occupied", True, "whether unknown cells (-1) are obstacles"),
    Parameter(
        "odom.frame_id", "", "odometry frame if not the planning frame ('' = planning frame)"
    ),
    Parameter(
        "odom.to_map",
        [0.0, 0.0, 0.0],
        "fixed transform x, y (m), yaw (rad) of the odometry frame in the planning frame",
    ),
    Parameter("topics.map", "map", "OccupancyGrid input (transient local)"),
    Parameter("topics.odom", "odom", "Odometry input"),
    Parameter("topics.goal", "goal_pose", "PoseStamped goals"),
    Parameter("topics.plan", "plan", "Path output (poses stamped with absolute times)"),
    Parameter("topics.trajectory", "trajectory", "MultiDOFJointTrajectory output"),
    Parameter("topics.markers", "corridor_markers", "MarkerArray of corridor and footprint"),
    Parameter("replan.rate", 2.0, "highest re-plan rate (Hz, > 0)"),
    Parameter("plan.sample_interval", 0.1, "time between the poses of /plan (s, > 0)"),
    Parameter("feedback.rate", 10.0, "action feedback rate while a trajectory runs (Hz, > 0)"),
)


def defaults() -> dict[str, Any]:
    """Every parameter's default value by name."""
    return {p.name: p.default for p in PARAMETERS}


@dataclass(frozen=True, slots=True)
class NodeConfig:
    """A validated parameter set.

    Attributes
    ----------
    values : dict
        The raw values by parameter name.
    robot : trajopt.Robot
    options : trajopt.PlannerOptions
        The planner settings (robot included), except the map-dependent ``search`` default.
    planner_kwargs : dict
        Keyword arguments for :class:`trajopt.Planner` besides the map and robot.
    odom_to_map : tuple of float
        ``(x, y, yaw)`` (m, m, rad).
    """

    values: dict[str, Any]
    robot: trajopt.Robot
    options: trajopt.PlannerOptions
    planner_kwargs: dict[str, Any]
    odom_to_map: tuple[float, float, float]

    def __getitem__(self, name: str) -> Any:
        return self.values[name]


def _fail(name: str, value: Any, rule: str) -> ParameterError:
    return ParameterError(f"parameter {name} = {value!r}: {rule}")


def _positive(values: dict[str, Any], name: str) -> float:
    v = values[name]
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or v <= 0:
        raise _fail(name, v, "must be a finite number > 0")
    return float(v)


def _choice(values: dict[str, Any], name: str, allowed: tuple[str, ...]) -> str:
    v = values[name]
    if not isinstance(v, str) or v not in allowed:
        raise _fail(name, v, f"must be one of {', '.join(repr(a) for a in allowed)}")
    return v


def _name(values: dict[str, Any], name: str) -> str:
    v = values[name]
    ok = isinstance(v, str) and v != "" and all(c.isalnum() or c in "_/~" for c in v)
    if not ok or v[0].isdigit():
        raise _fail(
            name, v, "must be a ROS name: letters, digits, _ and /, not starting with a digit"
        )
    return v


def build_config(values: dict[str, Any]) -> NodeConfig:
    """Validate a full parameter set and build what it describes.

    Parameters
    ----------
    values : dict
        Every name of :data:`PARAMETERS` with its value; unknown names are refused.

    Returns
    -------
    NodeConfig

    Raises
    ------
    ParameterError
        The first parameter that breaks a rule: its name, value and the rule.
    """
    known = {p.name for p in PARAMETERS}
    for name in values:
        if name not in known:
            raise _fail(name, values[name], "is not a parameter of the node")
    vals = defaults() | dict(values)
    for name in ("frame_id", "topics.map", "topics.odom", "topics.goal", "topics.plan"):
        _name(vals, name)
    for name in ("topics.trajectory", "topics.markers"):
        _name(vals, name)
    drive = _choice(vals, "robot.drive", ("differential", "omni", "ackermann"))
    limits = {
        k: _positive(vals, f"robot.{k}")
        for k in ("v_max", "a_max", "j_max", "a_lat_max", "omega_max")
    }
    robot_kw: dict[str, Any] = dict(limits, drive=drive)
    fp = vals["robot.footprint"]
    if not isinstance(fp, list | tuple) or not all(
        isinstance(x, int | float) and not isinstance(x, bool) for x in fp
    ):
        raise _fail("robot.footprint", fp, "must be a list of numbers x0, y0, x1, y1, ...")
    if len(fp) > 1:
        if len(fp) % 2 or len(fp) < 6:
            raise _fail(
                "robot.footprint", fp, "needs an even count of numbers, at least 3 vertices"
            )
        robot_kw["footprint"] = np.reshape(np.asarray(fp, dtype=float), (-1, 2))
    else:
        robot_kw["radius"] = _positive(vals, "robot.radius")
    r_min = vals["robot.min_turning_radius"]
    if isinstance(r_min, bool) or not isinstance(r_min, int | float) or not math.isfinite(r_min):
        raise _fail("robot.min_turning_radius", r_min, "must be a finite number (m)")
    if drive == "ackermann":
        if r_min <= 0:
            raise _fail("robot.min_turning_radius", r_min, "must be > 0 with robot.drive ackermann")
        robot_kw["min_turning_radius"] = float(r_min)
        if not isinstance(vals["robot.reverse"], bool):
            raise _fail("robot.reverse", vals["robot.reverse"], "must be a bool")
        robot_kw["reverse"] = vals["robot.reverse"]
    elif r_min != 0:
        raise _fail("robot.min_turning_radius", r_min, f"must be 0 with robot.drive {drive}")
    try:
        robot = trajopt.Robot(**robot_kw)
    except trajopt.InvalidInputError as exc:
        field = next((k for k in robot_kw if k in str(exc)), "footprint")
        name = f"robot.{field}"
        raise _fail(name, vals.get(name, robot_kw.get(field)), str(exc)) from exc

    corridor = _choice(vals, "planner.corridor", ("polygons", "boxes"))
    search = _choice(
        vals, "planner.search", ("", "clearance", "shortest", "costmap", "costmap+clearance")
    )
    w = vals["planner.costmap_weight"]
    if isinstance(w, bool) or not isinstance(w, int | float) or not math.isfinite(w) or w < 0:
        raise _fail("planner.costmap_weight", w, "must be a finite number >= 0")
    fallback = _choice(vals, "planner.fallback", ("", "stop_and_turn"))
    kwargs: dict[str, Any] = {
        "corridor": corridor,
        "search": search or None,
        "costmap_weight": float(w),
        "fallback": fallback or None,
        "timing_dt": _positive(vals, "planner.timing_dt"),
        "search_mode": _choice(vals, "planner.search_mode", ("auto", "exact", "coarse")),
    }
    try:
        options = trajopt.PlannerOptions(robot=robot, **{k: v for k, v in kwargs.items()})
    except trajopt.InvalidInputError as exc:
        field = next((k for k in kwargs if k in str(exc)), "search")
        raise _fail(f"planner.{field}", vals[f"planner.{field}"], str(exc)) from exc

    _choice(vals, "map.mode", ("auto", "occupancy", "costmap"))
    thr = vals["map.occupied_threshold"]
    if isinstance(thr, bool) or not isinstance(thr, int) or not 1 <= thr <= 100:
        raise _fail("map.occupied_threshold", thr, "must be an integer in 1..100")
    if not isinstance(vals["map.unknown_occupied"], bool):
        raise _fail("map.unknown_occupied", vals["map.unknown_occupied"], "must be a bool")
    if vals["odom.frame_id"] != "":
        _name(vals, "odom.frame_id")
    tf = vals["odom.to_map"]
    if (
        not isinstance(tf, list | tuple)
        or len(tf) != 3
        or not all(isinstance(x, int | float) and math.isfinite(x) for x in tf)
    ):
        raise _fail("odom.to_map", tf, "must be three finite numbers x (m), y (m), yaw (rad)")
    for name in ("replan.rate", "plan.sample_interval", "feedback.rate"):
        _positive(vals, name)
    return NodeConfig(
        values=vals,
        robot=robot,
        options=options,
        planner_kwargs=kwargs,
        odom_to_map=(float(tf[0]), float(tf[1]), float(tf[2])),
    )
