"""Maps, messages and independent checks shared by the node tests (a helper, not a test module)."""

from __future__ import annotations

import math
import threading
import time

import numpy as np

RES = 0.05  # m per cell
NX, NY = 120, 80  # 6 m x 4 m
RADIUS = 0.2  # the robot radius of the test parameter file (m)


def wall_map() -> np.ndarray:
    """``values[iy, ix]`` (int8): free, a wall at x = 3 m from y = 0 to 2.6 m."""
    v = np.zeros((NY, NX), np.int8)
    v[: int(2.6 / RES), int(3.0 / RES) : int(3.2 / RES)] = 100
    return v


def grid_msg(values: np.ndarray, frame: str = "map"):
    from nav_msgs.msg import OccupancyGrid

    msg = OccupancyGrid()
    msg.header.frame_id = frame
    msg.info.resolution = RES
    msg.info.height, msg.info.width = values.shape
    msg.info.origin.orientation.w = 1.0
    msg.data = values.astype(np.int8).ravel().tolist()
    return msg


def pose(x: float, y: float, yaw: float = 0.0, frame: str = "map"):
    from geometry_msgs.msg import PoseStamped

    p = PoseStamped()
    p.header.frame_id = frame
    p.pose.position.x, p.pose.position.y = float(x), float(y)
    p.pose.orientation.z, p.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return p


def path_xy(path) -> np.ndarray:
    return np.array([[p.pose.position.x, p.pose.position.y] for p in path.poses]).reshape(-1, 2)


def path_yaw(path) -> np.ndarray:
    return np.array(
        [2.0 * math.atan2(p.pose.orientation.z, p.pose.orientation.w) for p in path.poses]
    )


def stamps(path) -> np.ndarray:
    return np.array([p.header.stamp.sec + 1e-9 * p.header.stamp.nanosec for p in path.poses])


def clearance(xy: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Brute force: each point's distance (m) to the nearest occupied square or the map edge."""
    iy, ix = np.nonzero(values >= 50)
    cx, cy = (ix + 0.5) * RES, (iy + 0.5) * RES
    h = RES / 2
    out = np.empty(len(xy))
    for k, (x, y) in enumerate(xy):
        d = np.hypot(np.maximum(np.abs(x - cx) - h, 0), np.maximum(np.abs(y - cy) - h, 0))
        edge = min(x, y, NX * RES - x, NY * RES - y)
        out[k] = min(d.min() if len(d) else np.inf, edge)
    return out


def wait_for(predicate, timeout: float = 10.0, what: str = "condition"):
    """Poll ``predicate`` (a graph or message condition) until it is truthy; no fixed sleep."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise TimeoutError(f"{what} not met within {timeout} s")
        time.sleep(0.01)


def call(client, request, timeout: float = 30.0):
    """Call a service and wait for the answer (woken by the answer itself, not by polling)."""
    done = threading.Event()
    fut = client.call_async(request)
    fut.add_done_callback(lambda _f: done.set())
    if not done.wait(timeout):
        raise TimeoutError(f"service answer not met within {timeout} s")
    return fut.result()


def answered(client, request, what: str, timeout: float = 60.0, attempt: float = 5.0):
    """The answer to a request that changes nothing, sent again until one comes.

    A service drops its answer to a client whose reply reader it has not matched yet (Fast
    DDS waits about 100 ms for that match), and ``wait_for_service`` returns as soon as the
    *client* sees the server, so under heavy load a client's first call may get no answer at
    all: its first call is one that changes nothing, repeated every ``attempt`` seconds until
    answered (``timeout`` seconds in all).
    """
    deadline = time.monotonic() + timeout
    while True:
        try:
            return call(client, request, attempt)
        except TimeoutError:
            if time.monotonic() > deadline:
                raise TimeoutError(f"{what}: no answer within {timeout} s") from None
