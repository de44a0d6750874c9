"""Plans no robot can staff: a scenario may list one, and a re-plan poses one whenever the
only robots able to do an operation have failed. The solvers leave them out and the schedule
names plans as the problem does."""

from fractions import Fraction

import pytest

from fjsp_planner.execution.replan import ExecutionState, RobotSituation, replan
from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.solve import solve
from fjsp_planner.solving.staffable import staffable

GRIP, WELD, PAINT, LOCOMOTE = range(4)


def beam(*robots: Robot) -> Problem:
    """Lift (paint, or grip) then Join (grip and weld, or paint and weld) at the site, 5 from
    the dock: a crane drives there in 10, the welder in 1."""
    return Problem(
        operation_types={GRIP: 'grip', WELD: 'weld', PAINT: 'paint', LOCOMOTE: 'locomote'},
        robot_types={'Crane': {GRIP: Fraction(2), LOCOMOTE: Fraction(10)},
                     'Welder': {GRIP: Fraction(4), WELD: Fraction(3), LOCOMOTE: Fraction(2)},
                     'Painter': {PAINT: Fraction(1), LOCOMOTE: Fraction(1)}},
        robots=robots,
        jobs=(Job('Lift', 'site', ((PAINT,), (GRIP,))),
              Job('Join', 'site', ((GRIP, WELD), (PAINT, WELD)))),
        distances={('dock', 'site'): Fraction(5), ('site', 'dock'): Fraction(5)},
        precedence=(('Lift', 'Join'),), locomote=LOCOMOTE, name='beam')


CRANE = Robot('C1', 'Crane', speed=Fraction(5), start_location='dock')
WELDER = Robot('W1', 'Welder', speed=Fraction(10), start_location='dock')
PAINTER = Robot('P1', 'Painter', speed=Fraction(5), start_location='dock')


@pytest.mark.parametrize('solver', ['cpsat', 'greedy', 'mip'])
def test_a_plan_no_robot_can_staff_is_never_chosen(solver):
    """Without a painter: the welder grips Lift at [1, 5]; Join needs both robots, and the
    crane is at the site at 10: [10, 13]."""
    problem = beam(CRANE, WELDER)
    result = solve(problem, solver=solver, time_limit=10)
    assert validate(problem, result.schedule) == []
    assert result.schedule.jobs['Lift'].plan == 1 and result.schedule.jobs['Join'].plan == 0
    if solver != 'greedy':
        assert result.makespan == 13


def test_every_plan_staffable_is_solved_as_posed():
    assert staffable(beam(CRANE, WELDER, PAINTER)) is None


def test_a_re_plan_after_the_only_painter_failed_goes_on_without_its_plans():
    problem = beam(CRANE, WELDER, PAINTER)
    state = ExecutionState(Fraction(0), frozenset(), {}, {
        'C1': RobotSituation('C1', True, 'dock', Fraction(0)),
        'W1': RobotSituation('W1', True, 'dock', Fraction(0)),
        'P1': RobotSituation('P1', False, 'dock', Fraction(0))})
    planned = solve(problem, time_limit=5).schedule
    outcome = replan(problem, planned, state, time_limit=5)
    assert outcome.problems == []
    assert validate(outcome.residual.problem, outcome.schedule) == []
    assert 'P1' not in outcome.schedule.sequences and outcome.result.makespan == 13
