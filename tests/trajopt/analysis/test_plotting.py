"""Figures: footprints (or discs) drawn along a timed trajectory."""

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
