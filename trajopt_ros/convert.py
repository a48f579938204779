"""Between ROS 2 messages and trajopt values: maps, poses, paths and timed trajectories.

Inputs are checked here (a malformed map, a NaN or non-unit quaternion, a pose in another
frame raise :class:`~trajopt_ros.errors.RequestError` with its reason); outputs are built
from NumPy arrays sampled once (one vectorised ``sample`` call per message), leaving only
the per-pose object creation that ROS message sequences require.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion, Transform, Twist, Vector3
from nav_msgs.msg import OccupancyGrid as GridMsg
from nav_msgs.msg import Path
from std_msgs.msg import Header
from trajectory_msgs.msg import MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint

import astar
from trajopt_ros.errors import RequestError

__all__ = [
    "grid_from_msg",
    "pose_from_msg",
    "path_from_msg",
    "path_msg",
    "trajectory_msg",
    "to_time",
    "to_duration",
    "from_time",
    "QUATERNION_TOLERANCE",
]

#: Largest accepted ``| |q| - 1 |`` of an orientation quaternion.
QUATERNION_TOLERANCE = 1e-3


def to_time(seconds: float) -> Time:
    """Make a ``builtin_interfaces/Time`` from seconds since the epoch (ROS clock)."""
    ns = int(round(seconds * 1e9))
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def to_duration(seconds: float) -> Duration:
    """Make a ``builtin_interfaces/Duration`` from seconds (>= 0)."""
    ns = max(0, int(round(seconds * 1e9)))
    return Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def from_time(stamp: Any) -> float:
    """Seconds of a ``Time`` or ``Duration``."""
    return stamp.sec + stamp.nanosec * 1e-9


def grid_from_msg(
    msg: GridMsg, *, mode: str, threshold: int, unknown_occupied: bool
) -> astar.OccupancyGrid | astar.Costmap:
    """Read the map a ``nav_msgs/OccupancyGrid`` holds.

    Parameters
    ----------
    msg : nav_msgs.msg.OccupancyGrid
        Values ``-1`` (unknown) or ``0..100``, row 0 at the bottom.
    mode : {"auto", "occupancy", "costmap"}
        ``"occupancy"``: a cell is occupied when its value is ``>= threshold``;
        ``"costmap"``: values are a Nav2 costmap (:func:`astar.from_costmap`, convention
        ``"occupancy_grid"``: 100 lethal, 1..98 graded cost); ``"auto"``: costmap when any
        value lies in ``1..99``, occupancy otherwise.
    threshold : int
        Occupancy threshold (1..100).
    unknown_occupied : bool
        Whether ``-1`` cells are obstacles.

    Returns
    -------
    astar.OccupancyGrid or astar.Costmap

    Raises
    ------
    RequestError
        ``"invalid_map"``: an empty map, ``width * height != len(data)``, a resolution not
        finite and > 0, a non-finite origin, a rotated origin, values outside -1..100.
    """
    w, h, res = int(msg.info.width), int(msg.info.height), float(msg.info.resolution)
    n = len(msg.data)
    if w <= 0 or h <= 0:
        raise RequestError("invalid_map", f"map is empty: width {w} x height {h} cells")
    if w * h != n:
        raise RequestError(
            "invalid_map", f"map data has {n} values, width {w} x height {h} = {w * h} needed"
        )
    if not (math.isfinite(res) and res > 0):
        raise RequestError("invalid_map", f"map resolution must be finite and > 0 m, got {res}")
    o = msg.info.origin
    ox, oy = float(o.position.x), float(o.position.y)
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise RequestError("invalid_map", f"map origin must be finite, got ({ox}, {oy})")
    q = o.orientation
    if abs(q.x) > 1e-6 or abs(q.y) > 1e-6 or abs(q.z) > 1e-6 or abs(abs(q.w) - 1.0) > 1e-6:
        raise RequestError(
            "invalid_map",
            f"map origin must not be rotated (quaternion (0, 0, 0, 1)), got "
            f"({q.x}, {q.y}, {q.z}, {q.w})",
        )
    values = np.frombuffer(msg.data, dtype=np.int8) if not isinstance(msg.data, list) else None
    if values is None:
        values = np.asarray(msg.data, dtype=np.int16)
    values = values.reshape(h, w)
    if values.min() < -1 or values.max() > 100:
        bad = np.argwhere((values < -1) | (values > 100))[0]
        raise RequestError(
            "invalid_map",
            f"map value {int(values[bad[0], bad[1]])} at cell ({bad[1]}, {bad[0]}) is outside "
            "-1..100",
        )
    graded = bool(np.any((values >= 1) & (values <= 99)))
    if mode == "costmap" or (mode == "auto" and graded):
        return astar.from_costmap(
            values,
            res,
            (ox, oy),
            convention="occupancy_grid",
            unknown_occupied=unknown_occupied,
        )
    occ = values >= threshold
    if unknown_occupied:
        occ |= values < 0
    return astar.OccupancyGrid(occ, resolution=res, origin=(ox, oy))


def pose_from_msg(
    msg: PoseStamped,
    frame: str,
    what: str,
    odom: tuple[str, tuple[float, float, float]] | None = None,
) -> tuple[float, float, float]:
    """``(x, y, yaw)`` (m, m, rad) of a ``PoseStamped`` in the planning frame.

    Parameters
    ----------
    msg : geometry_msgs.msg.PoseStamped
    frame : str
        The planning frame; an empty ``frame_id`` is read as it.
    what : str
        ``"start"`` or ``"goal"`` (named in the messages).
    odom : tuple, optional
        ``(frame_id, (x, y, yaw))``: another frame accepted, with its fixed transform into
        the planning frame.

    Raises
    ------
    RequestError
        ``"frame_mismatch"``: another frame; ``"invalid_pose"``: a non-finite coordinate,
        a quaternion whose norm is off 1 by more than :data:`QUATERNION_TOLERANCE`, or one
        tilted out of the plane.
    """
    return _pose(msg.header.frame_id, msg.pose, frame, what, odom)


def _pose(
    frame_id: str,
    pose: Pose,
    frame: str,
    what: str,
    odom: tuple[str, tuple[float, float, float]] | None,
) -> tuple[float, float, float]:
    p, q = pose.position, pose.orientation
    vals = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
    if not all(math.isfinite(v) for v in vals):
        raise RequestError("invalid_pose", f"{what} pose has a non-finite value: {vals}")
    norm = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise RequestError(
            "invalid_pose",
            f"{what} orientation must be a unit quaternion (norm within "
            f"{QUATERNION_TOLERANCE} of 1), got norm {norm:.6g}",
        )
    if math.hypot(q.x, q.y) > 1e-3 * max(norm, 1.0) * 10:
        raise RequestError(
            "invalid_pose",
            f"{what} orientation must be a rotation about z (planar), got x={q.x}, y={q.y}",
        )
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    x, y = float(p.x), float(p.y)
    fid = frame_id.lstrip("/")
    if fid in ("", frame.lstrip("/")):
        return (x, y, yaw)
    if odom is not None and fid == odom[0].lstrip("/"):
        tx, ty, tyaw = odom[1]
        c, s = math.cos(tyaw), math.sin(tyaw)
        return (tx + c * x - s * y, ty + s * x + c * y, yaw + tyaw)
    raise RequestError(
        "frame_mismatch",
        f"{what} is in frame {frame_id!r}, the planning frame is {frame!r} (tf2 is not "
        "available; send poses in the planning frame or set odom.frame_id / odom.to_map)",
    )


def path_from_msg(msg: Path, frame: str) -> np.ndarray:
    """Read the poses of a ``nav_msgs/Path`` as an array ``(n, 3)`` of ``x, y, yaw``.

    Raises
    ------
    RequestError
        ``"invalid_pose"`` for fewer than 2 poses or a bad pose, ``"frame_mismatch"`` for
        a path or pose in another frame than ``frame``.
    """
    if len(msg.poses) < 2:
        raise RequestError("invalid_pose", f"path has {len(msg.poses)} poses, at least 2 needed")
    out = np.empty((len(msg.poses), 3))
    for i, ps in enumerate(msg.poses):
        fid = ps.header.frame_id or msg.header.frame_id
        out[i] = _pose(fid, ps.pose, frame, f"path pose {i}", None)
    return out


def _sample(traj: Any, dt: float) -> Any:
    return traj.sample_uniform(dt)


_new = object.__new__


def _pose_stamped(
    sec: int, nsec: int, frame: str, x: float, y: float, qz: float, qw: float
) -> PoseStamped:
    """Make a ``PoseStamped`` without the generated constructors (a sixth of their time).

    The generated message classes keep each field ``f`` in the slot ``_f`` and check
    values only when ``_check_fields`` is set; the constructors import and build every
    nested default, which dominates a long path. Values here are already of the right
    types (Python ints and floats from NumPy's ``tolist``).
    """
    stamp = _new(Time)
    stamp._check_fields, stamp._sec, stamp._nanosec = False, sec, nsec
    header = _new(Header)
    header._check_fields, header._stamp, header._frame_id = False, stamp, frame
    point = _new(Point)
    point._check_fields, point._x, point._y, point._z = False, x, y, 0.0
    quat = _new(Quaternion)
    quat._check_fields, quat._x, quat._y, quat._z, quat._w = False, 0.0, 0.0, qz, qw
    pose = _new(Pose)
    pose._check_fields, pose._position, pose._orientation = False, point, quat
    out = _new(PoseStamped)
    out._check_fields, out._header, out._pose = False, header, pose
    return out


def path_msg(traj: Any, start_time: float, frame: str, dt: float, samples: Any = None) -> Path:
    """Build a ``nav_msgs/Path`` along ``traj``: a pose every ``dt`` s and at its end.

    Parameters
    ----------
    traj : trajopt trajectory
        Anything with ``sample_uniform``.
    start_time : float
        Absolute time (s, ROS clock) of the trajectory's ``t = 0``: each pose is stamped
        ``start_time + t``.
    frame : str
        The frame of the poses.
    dt : float
        Sampling interval (s).
    samples : TrajectorySample, optional
        Samples already taken (then ``traj`` and ``dt`` are not used).
    """
    smp = samples if samples is not None else _sample(traj, dt)
    t = np.asarray(smp.t, dtype=float)
    half = 0.5 * np.asarray(smp.theta, dtype=float)
    ns = np.round((start_time + t) * 1e9).astype(np.int64)
    cols = zip(
        (ns // 1_000_000_000).tolist(),
        (ns % 1_000_000_000).tolist(),
        np.asarray(smp.x, dtype=float).tolist(),
        np.asarray(smp.y, dtype=float).tolist(),
        np.sin(half).tolist(),
        np.cos(half).tolist(),
        strict=True,
    )
    poses = [_pose_stamped(sec, nsec, frame, x, y, qz, qw) for sec, nsec, x, y, qz, qw in cols]
    out = Path()
    out.header.frame_id = frame
    out.header.stamp = to_time(start_time)
    out.poses = poses
    return out


def trajectory_msg(
    traj: Any, start_time: float, frame: str, dt: float, samples: Any = None
) -> MultiDOFJointTrajectory:
    """Build a ``trajectory_msgs/MultiDOFJointTrajectory`` of one joint ``base`` along ``traj``.

    Each point holds the pose (``transforms``: translation x, y and the heading as a
    quaternion about z), the body-frame velocity (``velocities``: ``linear.x`` the speed
    ``v`` in m/s, ``angular.z`` the yaw rate in rad/s) and acceleration (``accelerations``:
    ``linear.x`` the tangential, ``linear.y`` the lateral acceleration in m/s^2) at
    ``time_from_start``; ``header.stamp`` is the absolute time of ``t = 0``.
    """
    smp = samples if samples is not None else _sample(traj, dt)
    half = 0.5 * np.asarray(smp.theta, dtype=float)
    a_lat = getattr(smp, "a_lat", None)
    a_lat = np.zeros_like(half) if a_lat is None else np.asarray(a_lat, dtype=float)
    cols = zip(
        np.asarray(smp.t, dtype=float).tolist(),
        np.asarray(smp.x, dtype=float).tolist(),
        np.asarray(smp.y, dtype=float).tolist(),
        np.sin(half).tolist(),
        np.cos(half).tolist(),
        np.asarray(smp.v, dtype=float).tolist(),
        np.asarray(smp.omega, dtype=float).tolist(),
        np.asarray(smp.a, dtype=float).tolist(),
        a_lat.tolist(),
        strict=True,
    )
    points = []
    for t, x, y, qz, qw, v, om, a, al in cols:
        points.append(
            MultiDOFJointTrajectoryPoint(
                transforms=[
                    Transform(translation=Vector3(x=x, y=y), rotation=Quaternion(z=qz, w=qw))
                ],
                velocities=[Twist(linear=Vector3(x=v), angular=Vector3(z=om))],
                accelerations=[Twist(linear=Vector3(x=a, y=al))],
                time_from_start=to_duration(t),
            )
        )
    out = MultiDOFJointTrajectory()
    out.header.frame_id = frame
    out.header.stamp = to_time(start_time)
    out.joint_names = ["base"]
    out.points = points
    return out


def reference(traj: Any, t: float) -> tuple[Pose, Twist]:
    """Return the pose and body-frame twist of ``traj`` at time ``t`` (s)."""
    smp = traj.sample(np.array([min(max(t, 0.0), float(traj.duration))]))
    th = float(smp.theta[0])
    pose = Pose(
        position=Point(x=float(smp.x[0]), y=float(smp.y[0])),
        orientation=Quaternion(z=math.sin(th / 2), w=math.cos(th / 2)),
    )
    twist = Twist(linear=Vector3(x=float(smp.v[0])), angular=Vector3(z=float(smp.omega[0])))
    return pose, twist
