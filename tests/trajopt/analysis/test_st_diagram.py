"""Tests of trajopt.analysis (plotting.plot_st): the movers' forbidden (s, t) cells and s(t).

The path is a straight line along y = 0, so the robot's centre at arc length ``s`` is
``(s, 0)`` here, independently of the library; the movers' centres are interpolated from
their waypoints with ``np.interp``.
"""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

import trajopt
from trajopt.errors import InvalidInputError
from trajopt.geometry import PolylineCurve

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def crossing():
    """A 4 m straight drive re-timed so that a walker crossing its middle passes first."""
    line = trajopt.time_parameterize(
        PolylineCurve(np.array([[0.0, 0.0], [4.0, 0.0]])), trajopt.Robot(radius=0.2)
    )
    t_mid = float(np.interp(2.0, line.sample(np.linspace(0, line.duration, 2001)).s,
                            np.linspace(0, line.duration, 2001)))  # fmt: skip
    walker = trajopt.MovingObstacle.from_waypoints(
        [t_mid - 5.0, t_mid + 5.0], [(2.0, -2.5), (2.0, 2.5)], radius=0.25, name="walker"
    )
    assert not trajopt.certify_movers(line, [walker], margin=0.05).ok
    out = trajopt.moving.retime_for_movers(line, [walker], margin=0.05)
    assert trajopt.certify_movers(out, [walker], margin=0.05).ok and out.duration > line.duration
    return out, walker


def _artist(ax, gid):
    found = [a for a in [*ax.collections, *ax.lines] if a.get_gid() == gid]
    assert len(found) == 1, gid
    return found[0]


def test_the_profile_passes_no_forbidden_cell(crossing):
    traj, walker = crossing
    import matplotlib.pyplot as plt

    fig, ax = trajopt.plotting.plot_st(traj, [walker], margin=0.05, ds=0.02, dt=0.05)
    try:
        mesh = _artist(ax, "forbidden")
        line = _artist(ax, "profile")
        corners = mesh.get_coordinates()  # (n + 1, K + 1, 2): x = t, y = s
        t_c = 0.5 * (corners[0, :-1, 0] + corners[0, 1:, 0])  # cell centres: the grid times
        s_lo, s_hi = corners[:-1, 0, 1], corners[1:, 0, 1]
        s_c = 0.5 * (s_lo + s_hi)
        blocked = ~np.ma.getmaskarray(mesh.get_array()).reshape(len(s_c), len(t_c))
        assert blocked.sum() > 50
        # the cells are the necessary ones: forbidden for every s within ds/2 at that time
        c = np.stack([np.interp(t_c, walker.times, walker.positions[:, i]) for i in (0, 1)], -1)
        d = np.hypot(s_c[:, None] - c[None, :, 0], 0.0 - c[None, :, 1])  # (n, K)
        half = 0.5 * (s_hi - s_lo)[:, None]
        need = 0.2 + 0.25 + 0.05 - half  # robot + walker + margin, less the half cell
        clear = np.abs(d - need) > 1e-9  # away from ties
        assert np.array_equal(blocked[clear], (d < need)[clear])
        # the profile at each grid time lies outside every forbidden cell of that time
        lt, ls = line.get_data()
        assert np.all(np.diff(ls) >= -1e-12) and ls[-1] == pytest.approx(4.0)
        s_at = np.interp(t_c, lt, ls)
        inside = (s_at[None, :] >= s_lo[:, None]) & (s_at[None, :] <= s_hi[:, None])
        assert not np.any(inside & blocked)
        # and it waited: at some grid time the walker's cells lie just ahead of it
        assert np.any(blocked & (s_c[:, None] > s_at[None, :]))
        assert ax.get_xlabel() == "time t [s]" and ax.get_ylabel() == "arc length s [m]"
        assert "walker" in [t.get_text() for t in ax.get_legend().get_texts()]
    finally:
        plt.close(fig)


def test_a_footprint_robot(crossing):
    import matplotlib.pyplot as plt

    _, walker = crossing
    robot = trajopt.Robot.rectangle(0.5, 0.3)
    line = trajopt.time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [4.0, 0.0]])), robot)
    fig, ax = trajopt.plotting.plot_st(line, [walker], ds=0.05, dt=0.1)
    try:
        mesh = _artist(ax, "forbidden")
        corners = mesh.get_coordinates()
        t_c = 0.5 * (corners[0, :-1, 0] + corners[0, 1:, 0])
        s_lo, s_hi = corners[:-1, 0, 1], corners[1:, 0, 1]
        blocked = ~np.ma.getmaskarray(mesh.get_array()).reshape(len(s_lo), len(t_c))
        assert blocked.any()
        # a blocked cell: the box (heading 0 on this line) is closer than 0.25 m to the walker
        # for every s of the cell; check the cell's centre with the box written out here
        for i, k in zip(*np.nonzero(blocked), strict=True):
            s = 0.5 * (s_lo[i] + s_hi[i])
            c = np.array([np.interp(t_c[k], walker.times, walker.positions[:, j]) for j in (0, 1)])
            dx = max(abs(c[0] - s) - 0.25, 0.0)
            dy = max(abs(c[1]) - 0.15, 0.0)
            assert np.hypot(dx, dy) < 0.25
    finally:
        plt.close(fig)


def test_a_chain_with_a_turn_in_place_rests_at_s_zero(crossing):
    import matplotlib.pyplot as plt

    _, walker = crossing
    robot = trajopt.Robot(radius=0.2)
    line = trajopt.time_parameterize(PolylineCurve(np.array([[0.0, 0.0], [4.0, 0.0]])), robot)
    turn = trajopt.timing.turn_in_place((0.0, 0.0), np.pi / 2, 0.0, robot)
    chain = trajopt.TrajectoryChain((turn, line), robot)
    fig, ax = trajopt.plotting.plot_st(chain, [walker], ds=0.05, dt=0.1)
    try:
        t, s = _artist(ax, "profile").get_data()
        assert turn.duration > 0.5
        assert np.all(s[t <= turn.duration] == 0.0) and np.all(s[t > turn.duration + 0.1] > 0)
        assert s[-1] == pytest.approx(4.0)
    finally:
        plt.close(fig)
    on = trajopt.time_parameterize(PolylineCurve(np.array([[4.0, 0.0], [6.0, 0.0]])), robot)
    with pytest.raises(InvalidInputError, match="one path"):
        trajopt.plotting.plot_st(trajopt.TrajectoryChain((line, on), robot), [walker])


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"margin": -0.1}, "margin"),
        ({"ds": 0.0}, "ds"),
        ({"dt": float("inf")}, "dt"),
        ({"t_end": -1.0}, "t_end"),
        ({"ds": 1e-5, "dt": 1e-4}, "ST_MAX_NODES"),
    ],
)
def test_bad_arguments_raise_typed_errors(crossing, kwargs, field):
    traj, walker = crossing
    with pytest.raises(InvalidInputError, match=field):
        trajopt.plotting.plot_st(traj, [walker], **kwargs)


def test_not_one_path_is_refused(crossing):
    _, walker = crossing
    with pytest.raises(InvalidInputError, match="trajectory"):
        trajopt.plotting.plot_st(object(), [walker])
    with pytest.raises(InvalidInputError, match="MovingObstacle"):
        trajopt.plotting.plot_st(crossing[0], ["walker"])
