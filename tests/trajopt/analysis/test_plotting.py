"""Tests of trajopt.analysis.plotting: figures of footprints (or discs) drawn along a timed trajectory."""

from __future__ import annotations

from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest

from trajopt.analysis.plotting import plot_footprints
from trajopt.robot._footprint import Footprint
from trajopt.robot._robot import Robot

matplotlib.use("Agg")


class _Line:
    """A 4 s drive along y = x at 0.5 m/s, heading pi/4 (stands in for a Trajectory)."""

    duration = 4.0

    def __init__(self, robot: Robot | None = None) -> None:
        self.robot = robot

    def sample(self, t):
        t = np.asarray(t, dtype=float)
        s = 0.5 * t / np.sqrt(2.0)
        return SimpleNamespace(t=t, x=s, y=s, theta=np.full_like(t, np.pi / 4))


@pytest.fixture()
def ax():
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    yield ax
    plt.close(fig)


def test_footprints_at_regular_times_with_the_end(ax):
    from matplotlib.patches import Polygon

    robot = Robot.rectangle(0.4, 0.2, rear_offset=0.1)
    patches = plot_footprints(ax, _Line(robot), every_s=1.5)  # t = 0, 1.5, 3, and 4
    assert len(patches) == 4 and len(ax.patches) == 4
    assert all(isinstance(p, Polygon) and not p.get_fill() for p in patches)
    s = 0.5 * 3.0 / np.sqrt(2.0)
    np.testing.assert_allclose(patches[2].get_xy()[:4], robot.footprint.at(s, s, np.pi / 4))
    assert [t.get_text() for t in ax.legend().get_texts()] == ["footprint"]  # one entry
    # an exact multiple of every_s does not draw the end twice
    assert len(plot_footprints(ax, _Line(robot), every_s=1.0)) == 5


def test_disc_robot_draws_circles_of_its_radius(ax):
    from matplotlib.patches import Circle

    patches = plot_footprints(ax, _Line(), Robot(radius=0.2), every_s=2.0, label="robot")
    assert len(patches) == 3
    assert all(isinstance(p, Circle) and p.radius == pytest.approx(0.2) for p in patches)
    np.testing.assert_allclose(patches[1].center, [1 / np.sqrt(2.0)] * 2)
    assert patches[0].get_label() == "robot"


def test_array_footprint_and_bad_arguments(ax):
    robot = Robot(footprint=[[-0.1, -0.1], [0.2, 0.0], [-0.1, 0.1]])
    assert isinstance(robot.footprint, Footprint)
    assert len(plot_footprints(ax, _Line(robot), every_s=4.0)) == 2
    with pytest.raises(ValueError, match="every_s must be finite and > 0"):
        plot_footprints(ax, _Line(robot), every_s=0.0)
    with pytest.raises(ValueError, match="every_s must be finite and > 0"):
        plot_footprints(ax, _Line(robot), every_s=float("nan"))
    with pytest.raises(ValueError, match="more than 10000"):
        plot_footprints(ax, _Line(robot), every_s=1e-4)
    with pytest.raises(ValueError, match="robot is required"):
        plot_footprints(ax, SimpleNamespace(duration=1.0, sample=None), every_s=1.0)


def test_path_points_of_a_timed_trajectory():
    from trajopt.analysis.plotting import path_points
    from trajopt.motion._trajectory import SampledExport

    class Timed(SampledExport, _Line):  # sample_uniform from SampledExport, motion from _Line
        pass

    pts = path_points(Timed())
    assert pts.shape == (401, 2)  # every 10 ms of 4 s, both ends
    assert np.allclose(pts[:, 0], pts[:, 1]) and pts[-1, 0] == pytest.approx(2.0 / np.sqrt(2.0))


# ------------------------------------------------------ heading arrows (issue 33, part 5)
def _turn_drive_turn():
    """A chain: turn in place at (0, 0) from pi to 0, drive 1 m along x, turn to pi / 2."""
    import trajopt
    from trajopt.geometry._curve import PolylineCurve
    from trajopt.motion import TrajectoryChain
    from trajopt.timing import time_parameterize, turn_in_place

    robot = trajopt.Robot()
    drive = time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [1.0, 0.0]])), robot)
    return TrajectoryChain(
        (
            turn_in_place((0.0, 0.0), np.pi, 0.0, robot),
            drive,
            turn_in_place((1.0, 0.0), 0.0, np.pi / 2, robot),
        ),
        robot,
    )


def test_heading_arrows_and_turns_in_place(ax):
    from matplotlib.quiver import Quiver

    from trajopt.analysis.plotting import plot_headings

    chain = _turn_drive_turn()
    quiver, marks = plot_headings(ax, chain, 9, length=0.2, color="tab:red")
    assert isinstance(quiver, Quiver) and quiver in ax.collections
    t = np.linspace(0.0, chain.duration, 9)
    smp = chain.sample(t)
    np.testing.assert_allclose(quiver.X, smp.x)
    np.testing.assert_allclose(quiver.Y, smp.y)
    np.testing.assert_allclose(quiver.U, 0.2 * np.cos(smp.theta), atol=1e-12)
    np.testing.assert_allclose(quiver.V, 0.2 * np.sin(smp.theta), atol=1e-12)
    assert abs(quiver.U[0] + 0.2) < 1e-9  # the first arrow faces the start heading, pi
    # both turns marked where they happen, with the angle turned
    np.testing.assert_allclose(marks.get_xdata(), [0.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(marks.get_ydata(), [0.0, 0.0], atol=1e-9)
    assert marks.get_label() == "turn in place"
    assert sorted(a.get_text() for a in ax.texts) == ["+1.57 rad", "-3.14 rad"]
    # a trajectory that only drives: arrows, no marks; bad arguments refused
    assert plot_headings(ax, _Line(), 3, turns=True)[1] is None
    for bad in (0, -1, 2.5, True):
        with pytest.raises(ValueError, match="n must|arrows must"):
            plot_headings(ax, chain, bad)
    with pytest.raises(ValueError, match="length must be finite"):
        plot_headings(ax, chain, 3, length=float("nan"))


def test_plot_paths_arrows_option(ax):
    from matplotlib.quiver import Quiver

    import astar
    from trajopt.analysis.plotting import plot_paths

    grid = astar.OccupancyGrid(np.zeros((30, 40), bool), 0.05)
    chain = _turn_drive_turn()
    curve = chain.pieces[1].path
    plot_paths(grid, {"curve": curve, "chain": chain}, arrows=12, ax=ax)
    (quiver,) = [c for c in ax.collections if isinstance(c, Quiver)]  # the timed entry only
    assert len(quiver.X) == 12
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert lines["chain"].get_linestyle() == "-" and lines["turn in place"].get_marker() == "o"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "curve",
        "chain",
        "turn in place",
    ]
    # default: no arrows
    ax.clear()
    plot_paths(grid, {"chain": chain}, ax=ax)
    assert not [c for c in ax.collections if isinstance(c, Quiver)]
    with pytest.raises(ValueError, match="arrows must"):
        plot_paths(grid, {"chain": chain}, arrows=-2, ax=ax)
