"""Bounds for any scenario (`bounds.fleet`) and the CP-SAT cut that counts each robot's work
and travel, checked by hand on small cases. Against optima proven independently (generated
scenarios the MIP and CP-SAT both prove): `test_known_optima.py`."""

from fractions import Fraction

from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.solving.bounds.fleet import _Facts, fleet_bound
from fjsp_planner.solving.solve import solve

OPS = {0: 'hold', 1: 'weld', 2: 'move'}


def two_sites(robots, jobs, precedence=()):
    """Sites a, b 5 apart, a base 10 from both; every robot moves a unit of distance in 1."""
    distances = {}
    for x, y, d in (('a', 'b', 5), ('a', 'base', 10), ('b', 'base', 10)):
        distances[x, y] = distances[y, x] = Fraction(d)
    types = {'Welder': {1: Fraction(2), 2: Fraction(1)},
             'Holder': {0: Fraction(3), 2: Fraction(1)}}
    return Problem(operation_types=OPS, robot_types=types, robots=tuple(robots),
                   jobs=tuple(jobs), distances=distances, precedence=tuple(precedence),
                   locomote=2)


def test_a_robot_alone_does_its_jobs_and_enters_each_of_their_places():
    """Only W welds: released at 1 at a, it welds x at a (2), goes to b (5), welds y (2):
    1 + 2 + 5 + 2 = 10, the optimum."""
    problem = two_sites([Robot('W', 'Welder', start_location='a', release_time=Fraction(1))],
                        [Job('x', 'a', ((1,),)), Job('y', 'b', ((1,),))])
    assert _Facts(problem).robot_bound() == 10
    assert solve(problem).makespan == 10


def test_jobs_needing_two_holders_share_the_holders_time():
    """Four jobs each held by both holders for 3: 4 x 2 x 3 = 24 units of holding over two
    robots, 12, the optimum; the longest chain is one job, 3."""
    problem = two_sites([Robot('H1', 'Holder'), Robot('H2', 'Holder')],
                        [Job(f'j{k}', 'a', ((0, 0),)) for k in range(4)])
    facts = _Facts(problem)
    assert facts.chain_bound() == 3
    assert facts.energy_bound() == 12 == fleet_bound(problem)
    assert solve(problem).makespan == 12


def test_a_job_starts_no_earlier_than_its_robots_can_arrive():
    """H starts at the base, 10 from b: x at b holds 3 from 10, then y welds 2: 15."""
    problem = two_sites([Robot('H', 'Holder', start_location='base'), Robot('W', 'Welder')],
                        [Job('x', 'b', ((0,),)), Job('y', 'b', ((1,),))], [('x', 'y')])
    assert _Facts(problem).chain_bound() == 15
    assert solve(problem).makespan == 15


def test_a_robot_may_reach_a_job_sooner_through_other_places():
    """a to b is 20 direct, 10 through c (distances need not obey the triangle inequality):
    W welds x at a (2), z at c from 7, y at b from 14: 16, the optimum. A head taking the
    direct leg from a would hold y back to 20."""
    distances = {}
    for x, y, d in (('a', 'b', 20), ('a', 'c', 5), ('c', 'b', 5)):
        distances[x, y] = distances[y, x] = Fraction(d)
    problem = Problem(operation_types=OPS, robot_types={'Welder': {1: Fraction(2),
                                                                   2: Fraction(1)}},
                      robots=(Robot('W', 'Welder', start_location='a'),),
                      jobs=(Job('x', 'a', ((1,),)), Job('y', 'b', ((1,),)),
                            Job('z', 'c', ((1,),))),
                      distances=distances, precedence=(('x', 'y'),), locomote=2)
    assert solve(problem).makespan == 16
    assert _Facts(problem).chain_bound() == 12
    assert fleet_bound(problem) <= 16
