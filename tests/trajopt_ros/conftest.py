"""Fixtures of the ROS 2 node tests: network hygiene, one node process, one client node.

* Every ROS process of a test run gets ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, a
  ``ROS_DOMAIN_ID`` held for the run by an ``fcntl`` lock file (the first free id of
  0..101, so parallel runs on one machine never share a domain) and a temporary
  ``ROS_LOG_DIR``.
* The node under test runs in its own OS process (``python -m trajopt_ros.cli``), started
  once per session; the tests talk to it from this process over Fast DDS and wait on the
  graph (``wait_for_service`` / ``wait_for_server`` with >= 10 s timeouts), never a fixed
  sleep.
* Without the ROS 2 wheels (``pip install -e '.[ros2]'``) every test here is skipped with
  that reason.
"""

from __future__ import annotations

import atexit
import fcntl
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

try:  # the wheels' bootstrapper sets the library path at interpreter start
    import rclpy  # noqa: F401

    HAVE_ROS = True
except ImportError:  # pragma: no cover - depends on the install
    HAVE_ROS = False

_HELD: list = []


def _hold_domain_id() -> int:
    """Lock the first free ROS domain id of 0..101 for this process's life."""
    folder = Path(tempfile.gettempdir()) / "trajopt-ros-domain-locks"
    folder.mkdir(exist_ok=True)
    for domain in range(102):
        fh = open(folder / f"{domain}.lock", "w")  # noqa: SIM115 - held until exit
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            fh.close()
            continue
        _HELD.append(fh)
        return domain
    raise RuntimeError("no free ROS domain id in 0..101 (all locked by other runs)")


@pytest.fixture(scope="session")
def ros_env() -> dict[str, str]:
    """The ROS environment of this run (also set in this process's ``os.environ``)."""
    if not HAVE_ROS:
        pytest.skip("the ROS 2 wheels are not installed (pip install -e '.[ros2]')")
    domain = os.environ.get("TRAJOPT_ROS_TEST_DOMAIN_ID")
    env = {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_DOMAIN_ID": domain if domain is not None else str(_hold_domain_id()),
        "ROS_LOG_DIR": tempfile.mkdtemp(prefix="trajopt-ros-log-"),
        "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
    }
    os.environ.update(env)
    return env


def node_env(ros_env: dict[str, str]) -> dict[str, str]:
    """Environment of a node process: this one's, the ROS settings, the worktree first."""
    env = dict(os.environ, **ros_env)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), env.get("PYTHONPATH", "")])
    return env


@pytest.fixture(scope="session")
def interfaces(ros_env):
    """The interface packages, built (or loaded from the cache) and importable here."""
    from trajopt_ros.build import ensure_interfaces

    return ensure_interfaces()


class NodeProcess:
    """``trajopt-ros`` in its own process, with its output in a temporary file."""

    def __init__(
        self,
        ros_env: dict[str, str],
        *ros_args: str,
        name: str = "trajopt_planner",
        cli_args: tuple[str, ...] = (),
    ):
        self.log = tempfile.NamedTemporaryFile("w+", prefix="trajopt-ros-node-", suffix=".log")
        args = [*cli_args, "--ros-args", "-r", f"__node:={name}", *ros_args]
        # the child inherits the domain id's lock: the id stays taken while any node lives
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "trajopt_ros.cli", *args],
            stdout=self.log,
            stderr=subprocess.STDOUT,
            env=node_env(ros_env),
            cwd=str(REPO),
            pass_fds=[fh.fileno() for fh in _HELD],
        )
        atexit.register(self.stop)

    def output(self) -> str:
        self.log.flush()
        with open(self.log.name) as fh:
            return fh.read()

    def stop(self, sig: int | None = None, timeout: float = 10.0) -> tuple[int, float]:
        """Send ``sig`` (default SIGINT) and wait; returns the exit code and the seconds taken."""
        import signal

        t0 = time.perf_counter()
        if self.proc.poll() is not None:
            return self.proc.returncode, 0.0
        self.proc.send_signal(signal.SIGINT if sig is None else sig)
        try:
            code = self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        return code, time.perf_counter() - t0


@pytest.fixture(scope="session")
def node_process(ros_env, interfaces, tmp_path_factory):
    """The node under test, started once for the session with a YAML parameter file."""
    params = tmp_path_factory.mktemp("params") / "robot.yaml"
    params.write_text(
        "trajopt_planner:\n"
        "  ros__parameters:\n"
        "    robot:\n"
        "      radius: 0.2\n"
        "      v_max: 0.8\n"
        "    plan:\n"
        "      sample_interval: 0.1\n"
        "    replan:\n"
        "      rate: 50.0\n"
    )
    node = NodeProcess(ros_env, "--params-file", str(params))
    yield node
    node.stop()


@pytest.fixture(scope="session")
def client(ros_env, interfaces):
    """A client node in this process, spun by a background executor."""
    import threading

    import rclpy
    from rclpy.executors import MultiThreadedExecutor

    context = rclpy.context.Context()
    rclpy.init(context=context)
    node = rclpy.create_node("trajopt_test_client", context=context)
    executor = MultiThreadedExecutor(num_threads=2, context=context)
    executor.add_node(node)
    thread = threading.Thread(target=executor.spin, daemon=True)
    thread.start()
    yield node
    executor.shutdown(timeout_sec=1.0)
    node.destroy_node()
    rclpy.shutdown(context=context)
