"""The fleet load bound (`bounds.assignment`), by hand on small cases; against optima proven
independently: `test_known_optima.py`."""

import dataclasses
from fractions import Fraction

from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.schedule import Status
from fjsp_planner.solving.bounds.assignment import fleet_load_bound
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.cpsat import solve_cpsat
from fjsp_planner.solving.routed import LOAD_BOUND_WORK
from fjsp_planner.solving.solve import solve


def welders(robots, jobs) -> Problem:
    """Welders (weld 2, move 1 per unit of distance) at sites a, b 5 apart, a base 10 from
    both."""
    distances = {}
    for x, y, d in (('a', 'b', 5), ('a', 'base', 10), ('b', 'base', 10)):
        distances[x, y] = distances[y, x] = Fraction(d)
    return Problem(operation_types={1: 'weld', 2: 'move'},
                   robot_types={'Welder': {1: Fraction(2), 2: Fraction(1)}},
                   robots=tuple(robots), jobs=tuple(Job(n, at, ((1,),)) for n, at in jobs),
                   distances=distances, locomote=2)


def test_a_robot_taking_a_job_elsewhere_travels_there():
    """W1 at a, W2 at b; three jobs at a, one at b. Any split but W1 on a and W2 on b has a
    robot cross (5): W1 welds three at a, 6, the optimum. Shared work alone gives 8 / 2."""
    problem = welders([Robot('W1', 'Welder', start_location='a'),
                       Robot('W2', 'Welder', start_location='b')],
                      [('x1', 'a'), ('x2', 'a'), ('x3', 'a'), ('y', 'b')])
    assert fleet_load_bound(problem, 5) == 6 == solve(problem).makespan
    assert static_bound(problem) < 6


def test_the_first_place_is_entered_from_the_start_location():
    """W1 starts at the base (10 from a), W2 at b: W1 would weld x1 at a from 10 to 12, so
    W2 welds y, crosses (5) and welds x1: 9, the optimum. Counting only the least leg into
    a (5, from b), W1 could weld x1 by 7."""
    problem = welders([Robot('W1', 'Welder', start_location='base'),
                       Robot('W2', 'Welder', start_location='b')],
                      [('x1', 'a'), ('y', 'b')])
    assert fleet_load_bound(problem, 5) == 9 == solve(problem).makespan


def test_release_time_and_an_incumbent_cap_it():
    """W released at 3 at a welds both jobs at a: 3 + 4 = 7; an incumbent of 6, which no
    schedule can reach, caps it (as the incumbent is a makespan found, it is never less)."""
    problem = welders([Robot('W', 'Welder', start_location='a', release_time=Fraction(3))],
                      [('x1', 'a'), ('x2', 'a')])
    assert fleet_load_bound(problem, 5) == 7 == solve(problem).makespan
    assert fleet_load_bound(problem, 5, incumbent=Fraction(6)) == 6


def test_a_robot_that_may_start_anywhere_enters_its_first_place_for_free():
    """W without a start location welds at a, then crosses to b: 2 + 5 + 2 = 9."""
    problem = welders([Robot('W', 'Welder')], [('x', 'a'), ('y', 'b')])
    assert fleet_load_bound(problem, 5) == 9 == solve(problem).makespan


def test_the_work_given_beside_the_routed_search_proves_small_cases():
    """Beside the routed search the bound stops after `LOAD_BOUND_WORK` of CP-SAT's
    deterministic time, not after a share of wall time: enough for the three-jobs-at-a case
    (6), whatever else runs on the machine."""
    problem = welders([Robot('W1', 'Welder', start_location='a'),
                       Robot('W2', 'Welder', start_location='b')],
                      [('x1', 'a'), ('x2', 'a'), ('x3', 'a'), ('y', 'b')])
    assert fleet_load_bound(problem, 5, work=LOAD_BOUND_WORK) == 6


def test_running_jobs_get_none():
    problem = welders([Robot('W', 'Welder')], [('x', 'a'), ('y', 'a')])
    running = dataclasses.replace(problem, fixed={
        'x': FixedJob(0, Fraction(0), Fraction(2), {'W': 1})})
    assert fleet_load_bound(running, 5) is None


def test_cpsat_given_the_bound_stops_when_a_schedule_meets_it():
    """The three-jobs-at-a case, the fleet load bound 6 given: CP-SAT's schedule of 6 is
    proven optimal, the bound kept as the model's floor (a floor above the optimum would
    make the model infeasible, one rounded wrongly a bound of 6 - 1 tick)."""
    problem = welders([Robot('W1', 'Welder', start_location='a'),
                       Robot('W2', 'Welder', start_location='b')],
                      [('x1', 'a'), ('x2', 'a'), ('x3', 'a'), ('y', 'b')])
    result = solve_cpsat(problem, 5, 1, lower_bound=fleet_load_bound(problem, 5))
    assert result.status == Status.OPTIMAL and result.makespan == result.lower_bound == 6


def test_a_robot_goes_from_one_place_to_the_next():
    """W starts at a hub 5 from each of three sites, the sites 10 apart: whatever the
    order, after the first site (5) it goes on to the next two (10 each): with 3 welds of 2,
    31, the optimum. One least leg into each site counts only 5 per site (from the hub):
    21."""
    distances = {}
    for site in 'xyz':
        distances['hub', site] = distances[site, 'hub'] = Fraction(5)
        for other in 'xyz':
            if other != site:
                distances[site, other] = Fraction(10)
    problem = Problem(operation_types={1: 'weld', 2: 'move'},
                      robot_types={'Welder': {1: Fraction(2), 2: Fraction(1)}},
                      robots=(Robot('W', 'Welder', start_location='hub'),),
                      jobs=tuple(Job(site, site, ((1,),)) for site in 'xyz'),
                      distances=distances, locomote=2)
    assert fleet_load_bound(problem, 5) == 31 == solve(problem).makespan
    assert fleet_load_bound(problem, 5, routes=False) == 21


def test_a_robot_goes_back_and_forth_along_precedence():
    """W welds x1 at a, y at b, then x2 at a; between y and x2 a carrier C, already at b,
    carries at b (1). W makes its way a -> b -> a (10): 6 of welds + 10 = 16, the optimum
    (W goes back while C carries). Its route visits b once: 11; the precedence of y before
    x2 runs through C's job, so its chains of jobs are read through any job."""
    distances = {('a', 'b'): Fraction(5), ('b', 'a'): Fraction(5)}
    problem = Problem(operation_types={1: 'weld', 2: 'move', 3: 'carry'},
                      robot_types={'Welder': {1: Fraction(2), 2: Fraction(1)},
                                   'Carrier': {3: Fraction(1), 2: Fraction(1)}},
                      robots=(Robot('W', 'Welder', start_location='a'),
                              Robot('C', 'Carrier', start_location='b')),
                      jobs=(Job('x1', 'a', ((1,),)), Job('y', 'b', ((1,),)),
                            Job('carry', 'b', ((3,),)), Job('x2', 'a', ((1,),))),
                      precedence=(('x1', 'y'), ('y', 'carry'), ('carry', 'x2')),
                      distances=distances, locomote=2)
    assert fleet_load_bound(problem, 5) == 11
    assert fleet_load_bound(problem, 5, chains=True) == 16 == solve(problem).makespan
