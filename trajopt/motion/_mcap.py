"""ROS 2 MCAP files of a planned trajectory: what RViz and Foxglove open.

:func:`write_mcap` (and :meth:`Trajectory.to_mcap`) writes an MCAP file with the ``ros2``
profile: each topic carries a standard ROS 2 message type whose definition is stored in the
file (``ros2msg`` schema encoding), and each message is serialised in CDR (the ROS 2 wire
format, little-endian), so any ROS 2 MCAP reader decodes it without this library:

==================  ================================  =============================================
topic               type                              content
==================  ================================  =============================================
``/map``            ``nav_msgs/msg/OccupancyGrid``    the raw map (100 occupied, 0 free)
``/map_inflated``   ``nav_msgs/msg/OccupancyGrid``    the grid the robot centre moved in
``/plan``           ``nav_msgs/msg/Path``             the samples' poses (heading quaternions)
``/corridor``       ``visualization_msgs/msg/MarkerArray``  one closed ``LINE_STRIP`` per region
``/pose``           ``geometry_msgs/msg/PoseStamped`` one per sample, stamped at its time
``/twist``          ``geometry_msgs/msg/TwistStamped`` ``linear.x = v``, ``angular.z = omega``
``/movers``         ``visualization_msgs/msg/MarkerArray``  each mover's shape at each time (below)
``/movers/predicted`` ``visualization_msgs/msg/MarkerArray``  each mover's predicted track
==================  ================================  =============================================

The maps and the corridor come from ``trajectory.steps`` (a trajectory returned by
:func:`trajopt.plan`); a trajectory timed by hand has only ``/plan``, ``/pose`` and
``/twist``. Poses are in ``frame_id`` (default ``"map"``), twists in ``child_frame_id``
(default ``"base_link"``, the robot frame: ``v`` forward, ``omega`` counter-clockwise; an
omnidirectional base's twist is its body-frame velocity ``linear.x = v_body_x``,
``linear.y = v_body_y`` and its orientation rate).
Every message is logged at its header stamp: ``start_time`` (s since the Unix epoch,
default 0) plus the sample time; the map, path and corridor at ``start_time``.

With ``movers`` (:class:`trajopt.MovingObstacle`), two more topics: ``/movers/predicted``
once at ``start_time``, one ``LINE_STRIP`` per mover (namespace ``"predicted"``, id its
index, ``text`` its name) through its waypoints in ``frame_id``; and ``/movers`` every
``movers_dt`` (default ``dt``) from ``t = 0`` to the later of the trajectory's end and the
last prediction time (the end included), one closed ``LINE_STRIP`` per mover (namespace ``"movers"``, id its
index, ``text`` its name) whose ``pose`` is the mover's reference point and heading at that
time and whose ``points`` are its shape's outline in its own frame: the convex polygon (or
the point of a disc) rounded by ``radius_at(t)``
(:func:`trajopt.geometry.rounded_polygon`). Without movers the file is the same, byte for
byte, as before they existed.

The file is written atomically (a temporary file beside it, then a rename): a failure
leaves no partial file. :func:`read_mcap` reads such a file back.

Needs the ``mcap`` and ``mcap-ros2-support`` packages (``pip install trajopt[ros]``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from astar.files import atomic_write
from astar.grid import OccupancyGrid
from trajopt.errors import InvalidInputError, TrajoptError
from trajopt.motion._cdr import (
    CdrWriter,
    MoverFrames,
    encode_grid,
    encode_markers,
    encode_movers_at,
    encode_path,
    encode_pose_stamped,
    encode_predicted,
)

#: Topic -> ROS 2 message type written by :func:`write_mcap`.
TOPICS: dict[str, str] = {
    "/map": "nav_msgs/msg/OccupancyGrid",
    "/map_inflated": "nav_msgs/msg/OccupancyGrid",
    "/plan": "nav_msgs/msg/Path",
    "/corridor": "visualization_msgs/msg/MarkerArray",
    "/pose": "geometry_msgs/msg/PoseStamped",
    "/twist": "geometry_msgs/msg/TwistStamped",
}
#: Topic -> ROS 2 message type added by :func:`write_mcap` when it is given movers.
MOVER_TOPICS: dict[str, str] = {
    "/movers": "visualization_msgs/msg/MarkerArray",
    "/movers/predicted": "visualization_msgs/msg/MarkerArray",
}


class McapExportError(TrajoptError, OSError):
    """The MCAP file cannot be written or read (the message names the file and the cause)."""


# ============================================================== message definitions
# The standard ROS 2 interface definitions (fields only), one block per type; a schema is
# its type's block followed by the blocks of every type it uses.
_DEFS: dict[str, str] = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "builtin_interfaces/Duration": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "std_msgs/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    "geometry_msgs/PoseStamped": "std_msgs/Header header\ngeometry_msgs/Pose pose",
    "geometry_msgs/Twist": "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    "geometry_msgs/TwistStamped": "std_msgs/Header header\ngeometry_msgs/Twist twist",
    "nav_msgs/MapMetaData": (
        "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\n"
        "uint32 height\ngeometry_msgs/Pose origin"
    ),
    "nav_msgs/OccupancyGrid": "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data",
    "nav_msgs/Path": "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses",
    "sensor_msgs/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data",
    "visualization_msgs/UVCoordinate": "float32 u\nfloat32 v",
    "visualization_msgs/MeshFile": "string filename\nuint8[] data",
    "visualization_msgs/Marker": (
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n"
        "int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n"
        "int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n"
        "int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n"
        "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
        "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
        "builtin_interfaces/Duration lifetime\nbool frame_locked\n"
        "geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring texture_resource\n"
        "sensor_msgs/CompressedImage texture\n"
        "visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n"
        "visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials"
    ),
    "visualization_msgs/MarkerArray": "visualization_msgs/Marker[] markers",
}
_SEP = "=" * 80


def _uses(name: str) -> list[str]:
    """Types used by ``name``, depth first, each once."""
    out: list[str] = []

    def visit(t: str) -> None:
        for line in _DEFS[t].splitlines():
            ftype = line.split()[0].removesuffix("[]")
            if "/" in ftype and ftype not in out:
                visit(ftype)
                out.append(ftype)

    visit(name)
    return out


def message_definition(datatype: str) -> str:
    """Return the ``ros2msg`` schema text of ``datatype`` (e.g. ``"nav_msgs/msg/Path"``)."""
    short = datatype.replace("/msg/", "/")
    parts = [_DEFS[short]]
    for dep in _uses(short):
        parts.append(f"{_SEP}\nMSG: {dep}\n{_DEFS[dep]}")
    return "\n".join(parts) + "\n"


def _check_movers(movers: Any) -> tuple[Any, ...]:
    """Return the movers as a tuple; each must be a :class:`trajopt.MovingObstacle` (its interface)."""
    if movers is None:
        return ()
    try:
        out = tuple(movers)
    except TypeError:
        raise InvalidInputError(
            f"movers must be a sequence of trajopt.MovingObstacle, got {type(movers).__name__}"
        ) from None
    need = ("pose_at", "radius_at", "shape_vertices", "positions", "t_last", "name")
    for i, m in enumerate(out):
        if not all(hasattr(m, a) for a in need):
            raise InvalidInputError(
                f"movers[{i}] must be a trajopt.MovingObstacle, got {type(m).__name__}"
            )
    return out


# ============================================================== write
def write_mcap(
    trajectory: Any,
    path: str | os.PathLike[str],
    *,
    dt: float = 0.01,
    frame_id: str = "map",
    child_frame_id: str = "base_link",
    start_time: float = 0.0,
    movers: Any = None,
    movers_dt: float | None = None,
) -> Path:
    """Write a timed trajectory (and its map, corridor and movers) as a ROS 2 MCAP file.

    Parameters
    ----------
    trajectory : Trajectory or StopAndTurnTrajectory
        The motion; its ``steps`` (when present) give the maps and the corridor.
    path : str or os.PathLike
        Output file (``.mcap``); its folder is created if needed.
    dt : float, optional
        Sample spacing (s) of ``/pose``, ``/twist`` and ``/plan`` (the end time is always
        included).
    frame_id, child_frame_id : str, optional
        The fixed frame of poses, maps and markers, and the robot frame of the twists.
    start_time : float, optional
        Stamp of ``t = 0`` in seconds since the Unix epoch (finite, ``>= 0``).
    movers : sequence of MovingObstacle, optional
        Predicted moving obstacles (the trajectory's clock): ``/movers`` and
        ``/movers/predicted`` (module docstring). ``None`` or empty: neither topic.
    movers_dt : float, optional
        Spacing (s, > 0) of the ``/movers`` messages; default ``dt``. A viewer shows each
        mover's latest marker until the next, so 0.05-0.1 s is smooth enough and keeps the
        file small (the markers of 10 movers every 10 ms take several times the space of
        the robot's topics).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InvalidInputError
        A bad ``dt``, ``start_time``, frame name or mover.
    McapExportError
        The file cannot be written (the message names it and the cause), or the ``mcap``
        package is missing.
    """
    for name, value in (("frame_id", frame_id), ("child_frame_id", child_frame_id)):
        if not isinstance(value, str) or not value:
            raise InvalidInputError(f"{name} must be a non-empty string, got {value!r}")
    if isinstance(start_time, bool) or not isinstance(start_time, int | float):
        raise InvalidInputError(f"start_time must be a number of seconds, got {start_time!r}")
    if not (math.isfinite(start_time) and 0.0 <= start_time < 2.0**31):
        raise InvalidInputError(
            f"start_time must be finite and in [0, 2^31) s since the epoch, got {start_time!r}"
        )
    try:
        from mcap.writer import CompressionType, Writer
    except ImportError:  # pragma: no cover - the ros extra is part of dev
        raise McapExportError(
            "writing MCAP needs the 'mcap' package: pip install 'trajopt[ros]'"
        ) from None
    movers = _check_movers(movers)
    step_m = float(dt) if movers_dt is None else movers_dt
    if (
        isinstance(step_m, bool)
        or not isinstance(step_m, int | float)
        or not (math.isfinite(step_m) and step_m > 0.0)
    ):
        raise InvalidInputError(f"movers_dt must be a finite number > 0 (s), got {movers_dt!r}")
    smp = trajectory.sample_uniform(dt)
    whole = math.floor(start_time)
    ns0 = int(whole) * 1_000_000_000 + int(round((start_time - whole) * 1e9))
    stamps = ns0 + np.rint(np.asarray(smp.t) * 1e9).astype(np.int64)
    x = np.asarray(smp.x, dtype=float)
    y = np.asarray(smp.y, dtype=float)
    half = 0.5 * np.asarray(smp.theta, dtype=float)
    qz, qw = np.sin(half), np.cos(half)
    v = np.asarray(smp.v, dtype=float)
    vy = np.zeros_like(v)  # a differential drive moves along its heading
    if hasattr(smp, "v_body_x"):  # an omnidirectional base: its body-frame velocity
        v = np.asarray(smp.v_body_x, dtype=float)
        vy = np.asarray(smp.v_body_y, dtype=float)
    om = np.asarray(smp.omega, dtype=float)
    steps = getattr(trajectory, "steps", None)
    m_times = np.zeros(0)
    if movers:  # every dt until the later of the trajectory's end and the last prediction
        m_end = max([float(trajectory.duration)] + [float(m.t_last) for m in movers])
        m_times = step_m * np.arange(int(math.floor(m_end / step_m + 1e-9)) + 1)
        if m_end - m_times[-1] > 1e-9 * max(1.0, m_end):
            m_times = np.append(m_times, m_end)
    m_stamps = ns0 + np.rint(m_times * 1e9).astype(np.int64)
    m_frames = [MoverFrames.of(m, m_times) for m in movers]

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as f:
            mw = Writer(f, compression=CompressionType.ZSTD)
            mw.start(profile="ros2", library="trajopt")
            schema_ids: dict[str, int] = {}
            channels: dict[str, int] = {}

            def channel(topic: str) -> int:
                dtype = TOPICS[topic] if topic in TOPICS else MOVER_TOPICS[topic]
                if dtype not in schema_ids:
                    schema_ids[dtype] = mw.register_schema(
                        name=dtype,
                        encoding="ros2msg",
                        data=message_definition(dtype).encode("utf-8"),
                    )
                channels[topic] = mw.register_channel(
                    topic=topic, message_encoding="cdr", schema_id=schema_ids[dtype]
                )
                return channels[topic]

            if steps is not None:
                for topic, grid in (
                    ("/map", steps.raw_grid),
                    ("/map_inflated", steps.inflated_grid),
                ):
                    mw.add_message(
                        channel(topic),
                        log_time=ns0,
                        publish_time=ns0,
                        data=encode_grid(grid, ns0, frame_id),
                    )
            mw.add_message(
                channel("/plan"),
                log_time=ns0,
                publish_time=ns0,
                data=encode_path(ns0, stamps, frame_id, x, y, qz, qw),
            )
            if steps is not None and steps.corridor is not None:
                polys = _corridor_polygons(steps.corridor)
                mw.add_message(
                    channel("/corridor"),
                    log_time=ns0,
                    publish_time=ns0,
                    data=encode_markers(polys, ns0, frame_id),
                )
            if movers:
                mw.add_message(
                    channel("/movers/predicted"),
                    log_time=ns0,
                    publish_time=ns0,
                    data=encode_predicted(movers, ns0, frame_id),
                )
            done = 0  # mover frames written, in time order with the poses

            def movers_until(ns_last: int) -> None:
                nonlocal done
                while done < len(m_stamps) and m_stamps[done] <= ns_last:
                    ns = int(m_stamps[done])
                    data = encode_movers_at(m_frames, done, ns, frame_id)
                    c = channels["/movers"] if "/movers" in channels else channel("/movers")
                    mw.add_message(c, log_time=ns, publish_time=ns, data=data, sequence=done)
                    done += 1

            c_pose, c_twist = channel("/pose"), channel("/twist")
            for k in range(len(stamps)):
                ns = int(stamps[k])
                movers_until(ns)
                w = CdrWriter()
                encode_pose_stamped(w, ns, frame_id, x[k], y[k], qz[k], qw[k])
                mw.add_message(c_pose, log_time=ns, publish_time=ns, data=w.data(), sequence=k)
                w = CdrWriter()
                w.header(ns, child_frame_id)
                w.pack("6d", 8, v[k], vy[k], 0.0, 0.0, 0.0, om[k])
                mw.add_message(c_twist, log_time=ns, publish_time=ns, data=w.data(), sequence=k)
            movers_until(int(m_stamps[-1]) if len(m_stamps) else ns0)
            mw.finish()

    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        return atomic_write(target, write)
    except OSError as exc:
        raise McapExportError(f"{target}: cannot write the MCAP file: {exc}") from exc


def _corridor_polygons(corridor: Any) -> list[np.ndarray]:
    regions = getattr(corridor, "regions", None)
    if regions is None:
        regions = getattr(corridor, "boxes", ())
    out = []
    for r in regions:
        verts = r.vertices() if callable(r.vertices) else r.vertices
        out.append(np.asarray(verts, dtype=float).reshape(-1, 2))
    return out


# ============================================================== read
@dataclass(frozen=True)
class McapContents:
    """What :func:`read_mcap` found in a file written by :func:`write_mcap`.

    Attributes
    ----------
    stamps_ns : ndarray of int64, shape (n,)
        Header stamps of the ``/pose`` messages (ns since the epoch).
    t : ndarray, shape (n,)
        Time since the first pose (s).
    x, y, theta : ndarray, shape (n,)
        Poses (m, m, rad; ``theta`` from the quaternion, unwrapped).
    v, omega : ndarray, shape (n,)
        ``/twist`` ``linear.x`` (m/s) and ``angular.z`` (rad/s).
    path : ndarray, shape (m, 3)
        ``/plan`` poses ``(x, y, theta)``.
    maps : dict of str to OccupancyGrid
        ``/map`` and ``/map_inflated`` when present (occupied = value 100). The message
        stores the resolution as float32; it is read back as the shortest decimal that
        rounds to that float32 (so 0.05 stays 0.05).
    corridor : list of ndarray, shape (k, 2) each
        The corridor regions' closed outlines from ``/corridor``.
    frame_id, child_frame_id : str
        Frames of the poses and of the twists.
    movers : dict of str to ndarray, shape (n, 3) each
        Per mover name, from ``/movers``: its marker poses ``(t, x, y)`` (``t`` in s since
        the first pose's stamp; x, y in m).
    predicted : dict of str to ndarray, shape (k, 2) each
        Per mover name, its predicted track from ``/movers/predicted`` (m).
    """

    stamps_ns: np.ndarray
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    path: np.ndarray
    maps: dict[str, OccupancyGrid] = field(default_factory=dict)
    corridor: list[np.ndarray] = field(default_factory=list)
    frame_id: str = ""
    child_frame_id: str = ""
    movers: dict[str, np.ndarray] = field(default_factory=dict)
    predicted: dict[str, np.ndarray] = field(default_factory=dict)


def read_mcap(path: str | os.PathLike[str]) -> McapContents:
    """Read back a file written by :func:`write_mcap` (decoded by ``mcap-ros2-support``).

    Parameters
    ----------
    path : str or os.PathLike
        The MCAP file.

    Returns
    -------
    McapContents

    Raises
    ------
    McapExportError
        The file is missing, not MCAP, or lacks the ``/pose`` and ``/twist`` topics.
    """
    p = Path(path)
    try:
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory
    except ImportError:  # pragma: no cover
        raise McapExportError(
            "reading MCAP needs 'mcap' and 'mcap-ros2-support': pip install 'trajopt[ros]'"
        ) from None
    poses: list[tuple[int, float, float, float, float]] = []
    twists: list[tuple[float, float]] = []
    path_rows: list[tuple[float, float, float]] = []
    maps: dict[str, OccupancyGrid] = {}
    corridor: list[np.ndarray] = []
    mover_rows: dict[str, list[tuple[int, float, float]]] = {}
    predicted: dict[str, np.ndarray] = {}
    frames = {"frame_id": "", "child_frame_id": ""}
    try:
        with open(p, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            for _schema, channel, _msg, ros in reader.iter_decoded_messages():
                topic = channel.topic
                if topic == "/pose":
                    st = ros.header.stamp
                    o = ros.pose.orientation
                    poses.append(
                        (
                            st.sec * 1_000_000_000 + st.nanosec,
                            ros.pose.position.x,
                            ros.pose.position.y,
                            o.z,
                            o.w,
                        )
                    )
                    frames["frame_id"] = ros.header.frame_id
                elif topic == "/twist":
                    twists.append((ros.twist.linear.x, ros.twist.angular.z))
                    frames["child_frame_id"] = ros.header.frame_id
                elif topic == "/plan":
                    for ps in ros.poses:
                        o = ps.pose.orientation
                        path_rows.append(
                            (ps.pose.position.x, ps.pose.position.y, 2.0 * math.atan2(o.z, o.w))
                        )
                elif topic in ("/map", "/map_inflated"):
                    info = ros.info
                    data = (
                        np.frombuffer(bytes(ros.data), dtype=np.int8)
                        if isinstance(ros.data, bytes | bytearray)
                        else np.asarray(ros.data, dtype=np.int8)
                    )
                    occ = data.reshape(info.height, info.width) == 100
                    # MapMetaData.resolution is float32: take the shortest decimal that
                    # rounds to it (0.03 for float32(0.03)), the value a map YAML gave
                    res = float(np.format_float_positional(np.float32(info.resolution)))
                    maps[topic] = OccupancyGrid(
                        occ,
                        res,
                        (info.origin.position.x, info.origin.position.y),
                    )
                elif topic == "/corridor":
                    for m in ros.markers:
                        corridor.append(np.array([[q.x, q.y] for q in m.points], dtype=float))
                elif topic == "/movers":
                    for m in ros.markers:
                        st = m.header.stamp
                        mover_rows.setdefault(m.text, []).append(
                            (
                                st.sec * 1_000_000_000 + st.nanosec,
                                m.pose.position.x,
                                m.pose.position.y,
                            )
                        )
                elif topic == "/movers/predicted":
                    for m in ros.markers:
                        predicted[m.text] = np.array([[q.x, q.y] for q in m.points], dtype=float)
    except OSError as exc:
        raise McapExportError(f"{p}: cannot read the MCAP file: {exc}") from exc
    except Exception as exc:  # the mcap reader raises its own types on malformed files
        raise McapExportError(
            f"{p}: not a readable MCAP file ({type(exc).__name__}: {exc})"
        ) from exc
    if not poses or len(twists) != len(poses):
        raise McapExportError(
            f"{p}: expected /pose and /twist messages of equal count (a file written by "
            f"trajopt.write_mcap), found {len(poses)} and {len(twists)}"
        )
    arr = np.array(poses, dtype=object)
    stamps = np.array([r[0] for r in poses], dtype=np.int64)
    xyq = np.array([r[1:] for r in poses], dtype=float)
    del arr
    theta = np.unwrap(2.0 * np.arctan2(xyq[:, 2], xyq[:, 3]))
    tw = np.array(twists, dtype=float)
    movers = {}
    for name, rows in mover_rows.items():
        rows.sort()
        ns = np.array([r[0] for r in rows], dtype=np.int64)
        xy = np.array([r[1:] for r in rows], dtype=float)
        movers[name] = np.column_stack([(ns - stamps[0]) / 1e9, xy])
    return McapContents(
        stamps_ns=stamps,
        t=(stamps - stamps[0]) / 1e9,
        x=xyq[:, 0],
        y=xyq[:, 1],
        theta=theta,
        v=tw[:, 0],
        omega=tw[:, 1],
        path=np.array(path_rows, dtype=float).reshape(-1, 3),
        maps=maps,
        corridor=corridor,
        frame_id=frames["frame_id"],
        child_frame_id=frames["child_frame_id"],
        movers=movers,
        predicted=predicted,
    )
