"""Tests of trajopt.plotting.animate (trajopt.analysis.animation): the robot and movers over time.

The frames are checked against positions computed here independently: the trajectory's
state at the frame time (``state_at``), the movers' reference points interpolated from
their waypoints with ``np.interp`` and their shapes rotated here; the fallback to the HTML
player is checked with the encoder hidden.
"""

from __future__ import annotations

import gc
import math
import warnings

import matplotlib
import numpy as np
import pytest

import trajopt
from trajopt.errors import InvalidInputError
from trajopt.geometry import PolylineCurve

matplotlib.use("Agg")
# animations built only to check their arguments or artists are never rendered
pytestmark = pytest.mark.filterwarnings("ignore:Animation was deleted without rendering")

BOX = [[-0.3, -0.15], [0.3, -0.15], [0.3, 0.15], [-0.3, 0.15]]


@pytest.fixture(autouse=True, scope="module")
def _collect_animations():
    """Collect the module's unrendered animations once, at its end, their warning filtered.

    One collection for the module, not one after every test: each full ``gc.collect``
    walks every object not frozen (tests/conftest.py freezes the heap as a module starts).
    """
    yield
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Animation was deleted without rendering")
        gc.collect()


@pytest.fixture(scope="module")
def line():
    """A disc robot's 4 m straight drive along y = 0 (a real timed Trajectory)."""
    return trajopt.time_parameterize(
        PolylineCurve(np.array([[0.0, 0.0], [4.0, 0.0]])), trajopt.Robot(radius=0.2)
    )


@pytest.fixture(scope="module")
def movers(line):
    walker = trajopt.MovingObstacle.from_waypoints(
        [0.0, 3.0, 7.0], [(2.0, -2.0), (2.0, -0.9), (2.5, 1.5)], radius=0.2, name="walker"
    )
    cart = trajopt.MovingObstacle.constant_velocity(
        (3.0, 1.5), (-0.1, 0.05), radius=0.05, growth=0.02, horizon=line.duration + 2.0,
        heading=0.4, vertices=BOX, name="cart",
    )  # fmt: skip
    return [walker, cart]


def _ref_pose(m, t):
    """The mover's reference point and heading at t, interpolated here from its waypoints."""
    c = np.array([np.interp(t, m.times, m.positions[:, i]) for i in (0, 1)])
    return c, float(np.interp(t, m.times, m.headings))


def _dist_to_convex(p, w):
    """Distance from points p (n, 2) to the convex CCW polygon w (m, 2); 0 inside."""
    best = np.full(len(p), np.inf)
    inside = np.ones(len(p), dtype=bool)
    for a, b in zip(w, np.roll(w, -1, axis=0), strict=True):
        e, q = b - a, p - a
        lam = np.clip(q @ e / (e @ e), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(q - lam[:, None] * e).T))
        inside &= e[0] * q[:, 1] - e[1] * q[:, 0] >= 0.0
    return np.where(inside, 0.0, best)


def test_frames_show_the_robot_and_movers_where_they_are(line, movers):
    fps, speed = 2.0, 2.0
    anim = trajopt.plotting.animate(
        line, None, movers, fps=fps, speed=speed, dpi=20.0, figsize=(2.0, 2.0)
    )
    end = max(line.duration, movers[1].times[-1])
    t = anim.times
    assert t[0] == 0.0 and t[-1] == pytest.approx(end)
    assert np.allclose(np.diff(t[:-1]), speed / fps) and 0.0 < t[-1] - t[-2] <= speed / fps
    walker, cart = movers
    for k in range(len(t)):
        anim.seek(k)
        st = line.state_at(min(t[k], line.duration))  # stands at its goal after its end
        assert anim.robot.center == pytest.approx((st.x, st.y), abs=1e-12)
        assert anim.robot.radius == pytest.approx(0.2)
        hx, hy = anim.heading.get_data()
        assert math.atan2(hy[1] - hy[0], hx[1] - hx[0]) == pytest.approx(st.theta, abs=1e-9)
        # the walker: a disc of radius 0.2 about its interpolated point
        c, _ = _ref_pose(walker, t[k])
        assert np.allclose(np.hypot(*(anim.movers[0].get_xy() - c).T), 0.2, atol=1e-9)
        assert np.allclose(np.ravel(anim.centres[0].get_data()), c)
        # the cart: its box turned by its heading about its point, rounded by radius + growth t
        c, h = _ref_pose(cart, t[k])
        rot = np.array([[math.cos(h), -math.sin(h)], [math.sin(h), math.cos(h)]])
        box = c + np.asarray(BOX) @ rot.T
        rad = 0.05 + 0.02 * min(t[k], cart.times[-1])
        assert np.allclose(_dist_to_convex(anim.movers[1].get_xy(), box), rad, atol=1e-9)
        assert anim.clock.get_text() == f"t = {t[k]:.2f} s"
    assert anim.path is None and anim.format == "html"


def test_a_footprint_robot_is_its_polygon_at_the_pose(line):
    robot = trajopt.Robot.rectangle(0.5, 0.3)
    timed = trajopt.time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [1.0, 1.0]])), robot)
    anim = trajopt.plotting.animate(timed, None, fps=2.0, t_end=timed.duration)
    for k in (0, len(anim.times) // 2, len(anim.times) - 1):
        anim.seek(k)
        st = timed.state_at(anim.times[k])
        c, s = math.cos(st.theta), math.sin(st.theta)
        v = np.asarray(robot.footprint.vertices)
        expect = np.column_stack(
            [st.x + c * v[:, 0] - s * v[:, 1], st.y + s * v[:, 0] + c * v[:, 1]]
        )
        assert np.allclose(anim.robot.get_xy()[: len(v)], expect, atol=1e-12)


def test_saved_as_gif_or_the_html_player_when_the_encoder_is_missing(line, tmp_path, monkeypatch):
    from matplotlib import animation as mpl_animation

    few = dict(fps=1.0, speed=4.0, dpi=20.0, figsize=(2.0, 2.0))
    unsaved = trajopt.plotting.animate(line, None, fps=1.0, t_end=1.0, dpi=20.0, figsize=(2, 2))
    assert unsaved.path is None and "<script" in unsaved._repr_html_()  # the HTML player
    if mpl_animation.writers.is_available("pillow"):
        anim = trajopt.plotting.animate(line, None, path=tmp_path / "a.gif", **few)
        assert anim.path == tmp_path / "a.gif" and anim.format == "gif"
        from PIL import Image

        with Image.open(anim.path) as img:
            assert img.format == "GIF" and img.n_frames == len(anim.times)
        assert anim._repr_html_().startswith('<img src="data:image/gif;base64,')
    monkeypatch.setattr(mpl_animation.writers, "is_available", lambda name: False)
    for suffix in (".gif", ".mp4"):
        with pytest.warns(UserWarning, match="encoder"):
            anim = trajopt.plotting.animate(line, None, path=tmp_path / f"b{suffix}", **few)
        assert anim.path == tmp_path / "b.html" and anim.format == "html"
        assert not (tmp_path / f"b{suffix}").exists()
        text = anim.path.read_text()
        assert "<script" in text and text == anim._repr_html_()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # .html needs no encoder: no warning
        anim = trajopt.plotting.animate(line, None, path=tmp_path / "c.html", **few)
    assert anim.path.read_text() == anim.to_html()


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"fps": 0.0}, "fps"),
        ({"fps": "fast"}, "fps"),
        ({"speed": -1.0}, "speed"),
        ({"t_end": math.nan}, "t_end"),
        ({"dpi": 0}, "dpi"),
        ({"path": "clip.avi"}, "path"),
        ({"fps": 1000.0}, "MAX_FRAMES"),
        ({"movers": [(1.0, 2.0)]}, "MovingObstacle"),
        ({"figsize": (0.0, 2.0)}, "figsize"),
    ],
)
def test_bad_arguments_raise_typed_errors(line, kwargs, field):
    with pytest.raises(InvalidInputError, match=field):
        trajopt.plotting.animate(line, None, **kwargs)
    with pytest.raises(InvalidInputError, match="frame"):
        trajopt.plotting.animate(line, None, fps=0.5, t_end=2.0).seek(99)
