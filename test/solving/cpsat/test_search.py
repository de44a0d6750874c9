"""The search's helpers: the time grid's guard, the guided and stitched starts, the quick pass.

Each produces schedules the validator checks; values are worked out in the docstrings.
"""

import time
from fractions import Fraction

from fjsp_planner.execution.replan import simulated_state
from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving import greedy
from fjsp_planner.solving.cpsat.grid import MAX_TICKS, choose_grid
from fjsp_planner.solving.greedy import guided_schedule
from fjsp_planner.solving.panels import stitched_schedule
from fjsp_planner.solving.solve import solve

from repo_paths import PAPER


def chain(times, robots=('r1', 'r2')) -> Problem:
    """Jobs j0 -> j1 -> ... in a chain, each one operation of type 0 any robot does."""
    return Problem(
        operation_types={0: 'work'},
        robot_types={'arm': {0: Fraction(1)}},
        robots=tuple(Robot(r, 'arm') for r in robots),
        jobs=tuple(Job(f'j{i}', 'here', ((0,),)) for i in range(len(times))),
        precedence=tuple((f'j{i}', f'j{i + 1}') for i in range(len(times) - 1)),
        time_overrides={(r, 0): Fraction(1) for r in robots})


def test_grid_stays_exact_for_the_paper():
    problem = load_scenario(PAPER)
    grid = choose_grid(problem, [problem.travel(r.name, 'Ja', 'M1') for r in problem.robots],
                       Fraction(200))
    assert grid.scale == 30 and grid.exact


def test_grid_coarsens_before_the_horizon_overflows():
    """Durations of 1e6 + 1/997 want a grid of 997 per unit. A horizon of 4e9 (about the
    most 1000 jobs of times up to 1e6 can need) leaves room for 2^40 / 4e9 = 274 units
    per unit: the grid falls to 274 and rounds durations up, and the horizon stays in range."""
    problem = Problem(operation_types={0: 'work'},
                      robot_types={'arm': {0: Fraction(10**6) + Fraction(1, 997)}},
                      robots=(Robot('r', 'arm'),), jobs=(Job('j', 'here', ((0,),)),))
    small = choose_grid(problem, [], Fraction(10**6))
    assert small.scale == 997 and small.exact
    huge = choose_grid(problem, [], Fraction(4 * 10**9))
    assert huge.scale == 274 and not huge.exact
    assert huge.ticks(Fraction(4 * 10**9)) <= MAX_TICKS < 2**63 // 1000


def test_large_durations_solve_to_a_valid_schedule():
    """Three jobs of 1e6 + 1/7 on one robot, in a chain: 3e6 + 3/7, exactly."""
    problem = Problem(operation_types={0: 'work'},
                      robot_types={'arm': {0: Fraction(10**6) + Fraction(1, 7)}},
                      robots=(Robot('r', 'arm'),),
                      jobs=tuple(Job(f'j{i}', 'here', ((0,),)) for i in range(3)),
                      precedence=(('j0', 'j1'), ('j1', 'j2')))
    result = solve(problem, time_limit=5)
    assert result.status == Status.OPTIMAL
    assert result.makespan == 3 * (Fraction(10**6) + Fraction(1, 7))
    assert validate(problem, result.schedule) == []


def test_guided_schedule_keeps_the_guides_staffing_and_order():
    """Two robots, four independent jobs of 1: the guide puts j0, j1 on r2 and j2, j3 on r1;
    following it gives the same assignment, makespan 2."""
    problem = Problem(operation_types={0: 'work'}, robot_types={'arm': {0: Fraction(1)}},
                      robots=(Robot('r1', 'arm'), Robot('r2', 'arm')),
                      jobs=tuple(Job(f'j{i}', 'here', ((0,),)) for i in range(4)))
    first = solve(problem, time_limit=5).schedule
    swapped = {'r1': 'r2', 'r2': 'r1'}
    guide = first.__class__(
        {j: a.__class__(j, a.plan, a.start, a.end, {swapped[r]: q for r, q in a.robots.items()})
         for j, a in first.jobs.items()}, {})
    followed = guided_schedule(problem, guide)
    assert validate(problem, followed) == []
    assert followed.makespan == 2
    assert {j: dict(a.robots) for j, a in followed.jobs.items()} == {
        j: dict(a.robots) for j, a in guide.jobs.items()}


def test_guided_schedule_reassigns_a_failed_robots_jobs():
    """The paper's optimal plan, MARC1 failing at 3: what remains is staffed without it."""
    problem = load_scenario(PAPER)
    plan = solve(problem, time_limit=10).schedule
    from fjsp_planner.execution.replan import residual_problem

    state = simulated_state(problem, plan, Fraction(3), {'MARC1'})
    residual = residual_problem(problem, state, plan).problem
    followed = guided_schedule(residual, plan)
    assert validate(residual, followed) == []
    assert all('MARC1' not in a.robots for a in followed.jobs.values())


def test_stitched_panels_are_valid_and_no_worse_than_sequential_panels():
    """Panel 1 with all four robots (32), panel 2 by LSMS and the MARCs (55 1/6), the robots
    crossing in between: valid, and at most 32 + 55 1/6 + the MARC2's crossing (12) + the
    slack the guided placement adds for travel inside the panel."""
    problem = load_scenario(PAPER, panels=2)
    schedule, bound = stitched_schedule(problem, Fraction(150), 10.0, 2)
    assert schedule is not None and validate(problem, schedule) == []
    assert bound == Fraction(331, 6)
    assert schedule.makespan <= 32 + Fraction(331, 6) + 12 + 10


def test_quick_pass_is_valid_on_thirty_panels():
    problem = load_scenario(PAPER, panels=30)
    began = time.monotonic()
    schedule = greedy._one_pass(problem, None, None, greedy.QUICK)
    assert validate(problem, schedule) == []
    assert time.monotonic() - began < 30


def test_three_panels_solve_is_valid_with_an_honest_bound():
    """Two panels: test_bounds.py, `test_solve_reports_panel_bounds_on_two_panels`."""
    problem = load_scenario(PAPER, panels=3)
    result = solve(problem, time_limit=3)
    assert validate(problem, result.schedule) == []
    assert result.lower_bound <= result.makespan
