"""Tests of trajopt.planning: the budgets of a car's tries (``trajopt/planning/_car_tries.py``).

Expansion counts decide a car's plan, the wall-clock limits are only safety nets: on a
suite case whose plan takes three searches (full-parallel-forwards-3 of
``bench_parking.py``, the full-size car at 0.1 m), the plan is the same with the safety nets
a million seconds long; a cap on the plan's expansions exactly at what the plan spent
keeps it, 100 expansions left for the last search (which found its first path after
thousands) stop it by its count (``max_expansions``, not
the clock) and no further try starts. A safety net that fires (made 1 ns long: every search
checks its clock after 128 expansions) stops the plan with an error that says so, instead
of going on to another try. No test here times anything.
"""

from __future__ import annotations

import numpy as np
import pytest

import astar
import trajopt
import trajopt.planning._car_tries as car_tries
from benchmarks import parking_cases as pc

FULL = pc.CARS["full"]


def plan_case():
    case = pc.make_case(FULL, "parallel", "forwards", 0, 3)
    return trajopt.plan(
        case.grid(0.1),
        case.start[:2],
        case.goal[:2],
        FULL.robot(),
        start_heading=case.start[2],
        goal_heading=case.goal[2],
    )


@pytest.fixture(scope="module")
def default_plan():
    return plan_case()


def same_plan(a, b) -> None:
    assert a.stats["car"]["tries"] == b.stats["car"]["tries"]
    assert a.stats["car"]["expansions"] == b.stats["car"]["expansions"]
    assert a.stats["car"]["cusps"] == b.stats["car"]["cusps"]
    assert a.duration == b.duration
    t = np.linspace(0.0, a.duration, 257)
    sa, sb = a.sample(t), b.sample(t)
    for field in ("x", "y", "theta", "v"):
        np.testing.assert_array_equal(getattr(sa, field), getattr(sb, field))


def test_the_case_takes_several_searches(default_plan):
    tries = default_plan.stats["car"]["tries"]
    assert len(tries) >= 3 and tries[-1].endswith("parking costs: planned")
    assert "no path (max_expansions)" in "; ".join(tries)  # the default costs' count cap
    search = default_plan.stats["car"]["search"]
    # the expansions of every search of the plan, the last one's included
    assert default_plan.stats["car"]["expansions"] > search["expanded"] > 0
    assert all(s["stop"] != "time_budget" for s in search["searches"])


def test_safety_nets_far_longer_change_nothing(default_plan, monkeypatch):
    monkeypatch.setattr(car_tries, "SEARCH_SAFETY_S", 1e6)
    monkeypatch.setattr(car_tries, "CAR_BUDGET_S", 1e6)
    same_plan(plan_case(), default_plan)


def test_the_plans_expansion_cap_decides(default_plan, monkeypatch):
    spent = default_plan.stats["car"]["expansions"]
    assert spent < car_tries.FOOTPRINT_CAR_EXPANSIONS
    monkeypatch.setattr(car_tries, "FOOTPRINT_CAR_EXPANSIONS", spent)
    same_plan(plan_case(), default_plan)
    # the last search found its first path after at least (expanded - 100) / 2 expansions
    # (it polishes for at most as many again plus 100: astar.find_pose_path): 100 left for
    # it stop it by its count
    last = default_plan.stats["car"]["search"]["expanded"]
    assert (last - 100) / 2 > 100
    monkeypatch.setattr(car_tries, "FOOTPRINT_CAR_EXPANSIONS", spent - last + 100)
    with pytest.raises(trajopt.NoPathError, match=r"max_expansions") as err:
        plan_case()
    tries = str(err.value).split("(tries: ")[-1].split(")) ")[0].split("; ")
    n = len(default_plan.stats["car"]["tries"])
    # the same tries up to the last, which stopped by its count; none after it
    assert tries[: n - 1] == default_plan.stats["car"]["tries"][:-1]
    assert len(tries) == n and tries[-1].endswith("parking costs: no path (max_expansions")


def test_a_search_safety_net_that_fires_stops_the_plan_and_says_so(monkeypatch):
    monkeypatch.setattr(car_tries, "SEARCH_SAFETY_S", 1e-9)
    with pytest.raises(trajopt.NoPathError, match="wall-clock safety net of 1e-09 s") as err:
        plan_case()
    assert "the expansion caps decide the plan" in str(err.value)


def test_the_plans_safety_net_stops_before_a_try_and_says_so(monkeypatch):
    monkeypatch.setattr(car_tries, "CAR_BUDGET_S", -1.0)
    with pytest.raises(
        trajopt.NoPathError, match=r"safety net of -1 s fired before the try"
    ) as err:
        plan_case()
    assert "(tries: none)" in str(err.value)


def test_expansion_caps_by_kind_of_robot():
    disc = trajopt.Robot(radius=0.3, drive="ackermann", min_turning_radius=1.0)
    assert car_tries.expansion_caps(disc) == (
        car_tries.SEARCH_EXPANSIONS,
        car_tries.CAR_EXPANSIONS,
    )
    assert car_tries.expansion_caps(FULL.robot()) == (
        car_tries.FOOTPRINT_SEARCH_EXPANSIONS,
        car_tries.FOOTPRINT_CAR_EXPANSIONS,
    )
    for search, plan in (car_tries.expansion_caps(disc), car_tries.expansion_caps(FULL.robot())):
        assert car_tries.FOOTPRINT_DEFAULT_EXPANSIONS < search < plan


def boxed_goal_grid(play: float):
    """A goal pose whose body keeps ``play`` (m) from four walls round it (the small car)."""
    b = pc.CARS["small"].body()
    gx, gy = 3.0, 2.0
    xl, xh, yl, yh = gx + b[:, 0].min(), gx + b[:, 0].max(), gy + b[:, 1].min(), gy + b[:, 1].max()

    def box(x0, y0, x1, y1):
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)

    walls = [
        box(xl - 0.1, yh + play, xh + 0.1, yh + play + 0.1),
        box(xl - 0.1, yl - play - 0.1, xh + 0.1, yl - play),
        box(xh + play, yl - 0.1, xh + play + 0.1, yh + 0.1),
        box(xl - play - 0.1, yl - 0.1, xl - play, yh + 0.1),
    ]
    return astar.OccupancyGrid.from_polygons(walls, 0.05, (0.0, 0.0, 6.0, 4.0)), (gx, gy)


def test_a_boxed_in_goal_ends_in_the_escapes_typed_error():
    # every search fails, the escape (the last try) runs from the goal and finds nothing
    grid, goal = boxed_goal_grid(0.01)
    with pytest.raises(trajopt.NoPathError, match=r"escape .* found nothing \(exhausted, \d+ exp"):
        trajopt.plan(
            grid, (1.0, 0.7), goal, pc.CARS["small"].robot(), start_heading=0.0, goal_heading=0.0
        )


def test_the_escape_try_runs_only_after_every_other_try_failed(default_plan):
    tries = default_plan.stats["car"]["tries"]
    assert not any("escape" in t for t in tries)
