"""The §IV MIP on hand-checkable instances, one per correction of the printed model."""

from fractions import Fraction

import pytest

from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.mip import solve_mip


def problem(jobs, robots=(('R1', 1), ('R2', 3)), precedence=(), holding=(), distance=None,
            start=None, fixed=None):
    """Robots ('name', hold time) with travel efficiency 1; jobs at locations x and y."""
    types = {name: {0: Fraction(t), 1: Fraction(1)} for name, t in robots}
    fleet = [Robot(name, name, Fraction(1)) for name, _ in robots]
    if start is not None:
        fleet[0] = Robot(fleet[0].name, fleet[0].type, Fraction(1), *start)
    return Problem(
        operation_types={0: 'hold', 1: 'locomote'}, robot_types=types, robots=tuple(fleet),
        jobs=tuple(Job(name, where, plans) for name, where, plans in jobs),
        distances={('x', 'y'): Fraction(distance or 0), ('y', 'x'): Fraction(distance or 0)},
        precedence=tuple(precedence), holding=tuple(holding), locomote=1, fixed=fixed or {})


def solved(p, backend='SCIP', hint=None):
    result = solve_mip(p, time_limit=5.0, backend=backend, hint=hint)
    assert result.status == Status.OPTIMAL
    assert result.lower_bound == result.makespan
    assert validate(p, result.schedule) == []
    return result


@pytest.mark.parametrize('backend', ['SCIP', 'HIGHS'])
def test_every_operation_of_a_plan_gets_its_own_robot(backend):
    # Printed `x_jp = Σ_m Σ_o x_jpom` would staff one of the two holds; both robots must work.
    result = solved(problem([('j', 'x', ((0, 0),))]), backend)
    assert result.makespan == 3
    assert set(result.schedule.jobs['j'].robots) == {'R1', 'R2'}


def test_a_robot_may_stay_idle():
    # Printed `Σ_j x^start_jm = 1` would force the slow robot to work too.
    result = solved(problem([('j', 'x', ((0,),))]))
    assert result.makespan == 1
    assert result.schedule.sequences['R2'] == ()


def test_travel_is_charged_on_the_arc_into_the_later_job():
    # Only R1 is fast; a -> b with b 5 away: 1 + 5 + 1 beats using R2 (3) for b after a.
    p = problem([('a', 'x', ((0,),)), ('b', 'y', ((0,),))], precedence=[('a', 'b')],
                distance=5)
    assert solved(p).makespan == 4  # R1 does a [0, 1], R2 starts at y and does b [1, 4]
    p = problem([('a', 'x', ((0,),)), ('b', 'y', ((0,),))], robots=(('R1', 1),),
                precedence=[('a', 'b')], distance=5)
    assert solved(p).makespan == 7  # one robot: 1 + 5 travel + 1


def test_holding_keeps_the_robot_and_goes_directly():
    # R1 holds in a and must hold in b straight after; c cannot come between on R1.
    p = problem([('a', 'x', ((0,),)), ('b', 'x', ((0,),)), ('c', 'x', ((0,),))],
                robots=(('R1', 1), ('R2', 3)), holding=[('a', 'b', 0)])
    result = solved(p)
    sequence = result.schedule.sequences
    holder = next(iter(result.schedule.jobs['a'].robots))
    assert result.schedule.jobs['b'].robots == {holder: 0}
    assert ('a', 'b') in zip(sequence[holder], sequence[holder][1:], strict=False)
    assert result.makespan == 3  # R1: a, b = 2; R2: c = 3


def test_holding_with_unequal_type_counts_is_infeasible():
    p = problem([('a', 'x', ((0,),)), ('b', 'x', ((0, 0),))], holding=[('a', 'b', 0)])
    assert solve_mip(p, time_limit=5.0).status == Status.INFEASIBLE


def test_start_location_and_release_time_delay_the_first_job():
    p = problem([('a', 'x', ((0,),))], robots=(('R1', 1),), start=('y', Fraction(2)),
                distance=Fraction(7, 2))
    result = solved(p)
    assert result.makespan == Fraction(13, 2)  # released at 2, 7/2 travel, 1 work
    assert result.schedule.jobs['a'].start == Fraction(11, 2)


def test_a_running_job_stays_and_release_binds_the_next_job():
    # R1 is on a (running, [0, 1]) but only released at 3 (say, it reports back then).
    p = problem([('a', 'x', ((0,),)), ('b', 'x', ((0,),))], robots=(('R1', 1),),
                start=(None, Fraction(3)),
                fixed={'a': FixedJob(0, Fraction(0), Fraction(1), {'R1': 0})})
    result = solved(p)
    assert result.schedule.jobs['a'].start == 0
    assert result.schedule.jobs['b'].start == 3
    assert result.makespan == 4


@pytest.mark.parametrize('backend', ['SCIP', 'HIGHS'])
def test_a_greedy_hint_tightens_the_horizon_and_keeps_the_optimum(backend):
    p = problem([('a', 'x', ((0,),)), ('b', 'y', ((0, 0),)), ('c', 'x', ((0,),))],
                precedence=[('a', 'b')], distance=2)
    hint = greedy_schedule(p)
    assert solved(p, backend, hint=hint).makespan == solved(p, backend).makespan


def test_a_plan_of_another_problem_does_not_cap_the_makespan():
    # The hint (makespan 1) is a plan of a smaller problem, as before a re-plan.
    small = problem([('a', 'x', ((0,),))])
    large = problem([('a', 'x', ((0,),)), ('b', 'x', ((0,),))], precedence=[('a', 'b')])
    result = solved(large, hint=solved(small).schedule)
    assert result.makespan == 2
