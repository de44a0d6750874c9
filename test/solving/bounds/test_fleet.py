"""Bounds for any scenario (`bounds.fleet`) and the CP-SAT cut that counts each robot's work
and travel: each checked by hand on small cases, then against optima proven independently."""

from fractions import Fraction

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.schedule import Status
from fjsp_planner.solving.bounds.fleet import _Facts, fleet_bound, static_bound
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


@pytest.mark.slow
@pytest.mark.parametrize('seed', range(400, 408))
def test_cpsat_and_the_mip_prove_the_same_optimum_above_the_static_bound(seed):
    """The MIP shares nothing with the CP-SAT model and its cuts: the same optimum from both
    says no cut removed an optimal schedule, and the static bound stays below it."""
    problem = parse_scenario(random_scenario(seed, Shape(jobs=5, robots=3, robot_types=2)))
    mip = solve(problem, solver='mip', time_limit=60)
    cpsat = solve(problem, time_limit=30)
    assert mip.status == cpsat.status == Status.OPTIMAL
    assert mip.makespan == cpsat.makespan
    assert static_bound(problem) <= cpsat.makespan


@pytest.mark.slow
def test_the_static_bound_stays_below_proven_optima_of_generated_scenarios():
    for seed in range(300, 330):
        problem = parse_scenario(random_scenario(seed, Shape(jobs=7, robots=4, robot_types=3)))
        result = solve(problem, time_limit=20)
        if result.status == Status.OPTIMAL:
            assert static_bound(problem) <= result.makespan, f'seed {seed}'
