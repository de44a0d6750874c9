"""Small hand-made scenarios with holding arcs, shared by the tracker's and the harness's
tests."""

from fractions import Fraction

from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.schedule import JobAssignment, Schedule


def held_then_followed() -> tuple[Problem, Schedule]:
    """T, held into L by its holder (2 each), is followed by M (1); no travel. The plan: A
    does T (0-2) and L (2-4), C does M (2-3); B, another holder, is idle."""
    problem = Problem(
        operation_types={1: 'hold', 3: 'mount'},
        robot_types={'Holder': {1: Fraction(2)}, 'Mounter': {3: Fraction(1)}},
        robots=(Robot('A', 'Holder'), Robot('B', 'Holder'), Robot('C', 'Mounter')),
        jobs=(Job('T', 'x', ((1,),)), Job('L', 'x', ((1,),)), Job('M', 'x', ((3,),))),
        precedence=(('T', 'M'),), holding=(('T', 'L', 1),))
    plan = Schedule({'T': JobAssignment('T', 0, Fraction(0), Fraction(2), {'A': 1}),
                     'L': JobAssignment('L', 0, Fraction(2), Fraction(4), {'A': 1}),
                     'M': JobAssignment('M', 0, Fraction(2), Fraction(3), {'C': 3})},
                    {'A': ('T', 'L'), 'B': (), 'C': ('M',)})
    return problem, plan
