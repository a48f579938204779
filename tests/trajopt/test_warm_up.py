"""Tests of trajopt.warmup: the first plan after it loads no compiled kernel, for every planner kind.

``warm_up()`` without a planner loads every kernel: then no planner kind loads one.
(``tests/trajopt/test_kernel_cache.py`` checks that it compiles and reaches every kernel.)
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import astar
from tests.processes import Queued, module_processes, selected_params
from tests.reference import point_square_distance
from trajopt import Planner, Robot, Smoother, warm_up
from trajopt.analysis.scenes import warm_up_map
from trajopt.errors import InvalidInputError


def _free_grid() -> astar.OccupancyGrid:
    return astar.OccupancyGrid(np.zeros((50, 50), dtype=bool), 0.05)


def _costmap() -> astar.Costmap:
    values = np.zeros((50, 50), dtype=np.uint8)
    values[20:30, 20:30] = 254
    return astar.from_costmap(values, 0.05, convention="costmap_2d")


PLANNERS = {
    "default": lambda: Planner(_free_grid()),
    "rectangle": lambda: Planner(_free_grid(), Robot.rectangle(0.6, 0.3, 0.15)),
    "kappa": lambda: Planner(_free_grid(), Robot(radius=0.1), smoother=Smoother(kappa_max=2.0)),
    "boxes": lambda: Planner(_free_grid(), corridor="boxes"),
    "paper": lambda: Planner(_free_grid(), Robot(radius=0.1), inflation="paper"),
    "shortest": lambda: Planner(_free_grid(), search="shortest"),
    "fallback": lambda: Planner(_free_grid(), fallback="stop_and_turn"),
    "costmap": lambda: Planner(_costmap(), Robot(radius=0.1)),
}


@pytest.mark.parametrize("kind", sorted(PLANNERS))
def test_warm_up_plans_with_the_planners_settings(kind):
    planner = PLANNERS[kind]()
    seconds = warm_up(planner)
    assert seconds > 0.0
    assert planner.latency_s == 0.0  # the planner itself ran no query


@pytest.mark.parametrize("kind", ["default", "rectangle", "kappa", "paper"])
def test_warm_up_map_leaves_room_for_the_robot(kind):
    planner = PLANNERS[kind]()
    grid, start, goal = warm_up_map(planner)
    need = planner.robot.radius * (3.0 if planner.inflation == "paper" else 1.0)
    for p in (start, goal):
        assert point_square_distance(np.asarray(p), grid) >= need
    assert grid.occupied[:, grid.occupied.shape[1] // 2].any()  # a wall between them


FIRST_PLANS = ["disc", "costmap", "rectangle", "all"]

#: A fresh process: after warm_up(planner), the paper scene's four queries load or compile no
#: numba kernel (counted at numba's own cache and dispatcher entry points); after warm_up()
#: with no planner, neither do those of every planner kind nor a comparison.
FIRST_PLANS_SCRIPT = textwrap.dedent(
    """
        import sys
        import numpy as np
        import numba.core.caching as caching
        from numba.core.dispatcher import Dispatcher
        import astar, trajopt
        kind = sys.argv[1]
        scene = trajopt.scenes.paper()
        grid, robot = scene.grid, trajopt.Robot(radius=scene.robot_radius)
        if kind == "costmap":
            values = np.where(grid.occupied, 254, 0).astype(np.uint8)
            grid = astar.from_costmap(values, grid.resolution, grid.origin,
                                      convention="costmap_2d")
        elif kind == "rectangle":
            robot = trajopt.Robot.rectangle(2.2 * scene.robot_radius, 1.4 * scene.robot_radius)
        planners = [trajopt.Planner(grid, robot)]
        if kind == "all":
            values = np.where(grid.occupied, 254, 0).astype(np.uint8)
            r = scene.robot_radius
            costmap = astar.from_costmap(values, grid.resolution, grid.origin,
                                         convention="costmap_2d")
            planners += [
                trajopt.Planner(grid, trajopt.Robot.rectangle(2.2 * r, 1.4 * r)),
                trajopt.Planner(costmap, robot),
                trajopt.Planner(costmap, robot, landmarks=4),
                trajopt.Planner(grid, robot, corridor="boxes"),
                trajopt.Planner(grid, robot, smoother=trajopt.Smoother(kappa_max=1 / (2 * r))),
                trajopt.Planner(grid, robot, inflation="paper"),
                trajopt.Planner(grid, robot, search="shortest"),
            ]
            trajopt.warm_up()
        else:
            trajopt.warm_up(planners[0])
        events = []
        load, compile_ = caching.Cache.load_overload, Dispatcher.compile
        def counting_load(self, *a, **k):
            events.append("load")
            return load(self, *a, **k)
        def counting_compile(self, sig):
            n = len(self.overloads)
            out = compile_(self, sig)
            if len(self.overloads) > n:
                events.append(self.py_func.__name__)
            return out
        caching.Cache.load_overload = counting_load
        Dispatcher.compile = counting_compile
        for planner in planners:
            for name in scene.target_names:
                planner.plan(scene.start, scene.goal(name))
        if kind == "all":
            trajopt.compare(grid, scene.start, scene.goal("A"), robot_radius=scene.robot_radius,
                            w_cells=scene.w_cells)
        print("EVENTS", events)
        """
)


def early_processes(items) -> dict[str, Queued]:
    """A fresh process for each selected kind, queued when collection ends (tests/processes.py)."""
    kinds = selected_params(items, "test_first_plans_after_warm_up_load_no_kernel", "kind")
    return {kind: Queued(FIRST_PLANS_SCRIPT, kind) for kind in kinds}


@pytest.fixture(scope="module")
def first_plan_runs(request):
    """The fresh processes of the selected kinds (:func:`early_processes`)."""
    return module_processes(request)


@pytest.mark.parametrize("kind", FIRST_PLANS)
def test_first_plans_after_warm_up_load_no_kernel(kind, first_plan_runs):
    # each kind in its own fresh process (FIRST_PLANS_SCRIPT), queued when collection ended
    out = first_plan_runs[kind].result()
    assert out.returncode == 0, out.stderr[-2000:]
    assert "EVENTS []" in out.stdout, out.stdout + out.stderr[-2000:]


def test_warm_up_rejects_a_non_planner():
    with pytest.raises(InvalidInputError, match="planner must be a trajopt.Planner"):
        warm_up("planner")
