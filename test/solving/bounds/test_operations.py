"""The operation set bound (`bounds.operations`), by hand on a small case; against optima
proven independently: `test_known_optima.py`."""

import dataclasses
from fractions import Fraction

from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.solving.bounds import chains
from fjsp_planner.solving.bounds.assignment import fleet_load_bound
from fjsp_planner.solving.bounds.chains import chain_bound
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.bounds.operations import operation_bound
from fjsp_planner.solving.solve import solve


def welds_between_a_carry():
    """One welder F at a, one carrier M at b, 5 apart (1 per unit). F welds x1 at a, M
    carries at b for 4, then F welds x2 at a; F also welds y at b. F welds x1 (0-1), waits
    for the carry (1-5), welds x2 (5-6) and crosses to weld y (11-12): the optimum is 12
    (crossing to y between the welds at a costs a second crossing: 13)."""
    return Problem(
        operation_types={1: 'weld', 2: 'carry', 3: 'move'},
        robot_types={'Welder': {1: Fraction(1), 3: Fraction(1)},
                     'Carrier': {2: Fraction(4), 3: Fraction(1)}},
        robots=(Robot('F', 'Welder', start_location='a'),
                Robot('M', 'Carrier', start_location='b')),
        jobs=(Job('x1', 'a', ((1,),)), Job('m', 'b', ((2,),)), Job('x2', 'a', ((1,),)),
              Job('y', 'b', ((1,),))),
        precedence=(('x1', 'm'), ('m', 'x2')),
        distances={('a', 'b'): Fraction(5), ('b', 'a'): Fraction(5)}, locomote=3)


def test_the_jobs_of_a_scarce_operation_weigh_its_robot_s_ways_with_their_windows(
        monkeypatch):
    """The welds alone, x2 held back to 5 by the carry and x1 followed by it, need F at a
    twice or y last: 12, the optimum. The fleet load and static bounds route F through a and
    b once (3 welds + 5: 8); the chain x1 -> m -> x2 alone ends at 6."""
    problem = welds_between_a_carry()
    assert operation_bound(problem, 5) == 12 == solve(problem).makespan
    assert fleet_load_bound(problem, 5) == static_bound(problem) == 8
    monkeypatch.setattr(chains, 'PAIRED_CHAINS', 0)
    assert chain_bound(problem, 5) == 6


def test_running_jobs_get_no_bound_from_any_set_of_jobs():
    """Like those of `fleet`, the bounds of `restricted` hold only without running jobs."""
    running = dataclasses.replace(welds_between_a_carry(), fixed={
        'x1': FixedJob(0, Fraction(0), Fraction(1), {'F': 1})})
    assert operation_bound(running, 5) is None and chain_bound(running, 5) is None


def test_no_two_jobs_needing_one_type_get_none():
    problem = welds_between_a_carry()
    one_weld = dataclasses.replace(problem, jobs=problem.jobs[:2], precedence=(('x1', 'm'),))
    assert operation_bound(one_weld, 5) is None
