"""Scenarios past the CP-SAT routing size, up to the 1000-job limit, are scheduled."""

import time

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.large import CPSAT_ROUTING_ARCS, routing_arcs, solve_large
from fjsp_planner.solving.solve import solve
from fjsp_planner.solving.start import Start


def test_a_scenario_of_500_jobs_and_20_robots_is_accepted():
    """Its routing model would have about 3 million arcs; the loader refused it."""
    problem = parse_scenario(random_scenario(101, Shape(jobs=500, robots=20, robot_types=4)))
    assert len(problem.jobs) == 500
    assert routing_arcs(problem) > CPSAT_ROUTING_ARCS


@pytest.mark.slow
@pytest.mark.parametrize('jobs', [500, 1000])
def test_scenarios_past_the_routing_size_get_a_valid_schedule(jobs):
    problem = parse_scenario(random_scenario(7, Shape(jobs=jobs, robots=20, robot_types=4)))
    result = solve(problem, time_limit=20)
    assert result.schedule is not None
    assert validate(problem, result.schedule) == []
    assert result.lower_bound <= result.makespan


def test_the_search_past_the_routing_size_shortens_its_start():
    """The local search runs from the greedy schedule (here of 40 jobs with travel and
    holding arcs, as if past the size): valid, and shorter than one greedy pass."""
    problem = parse_scenario(random_scenario(5, Shape(jobs=40, robots=6)))
    greedy = greedy_schedule(problem)
    result = solve_large(problem, Start(greedy, None), time.monotonic(), 2, workers=2)
    assert validate(problem, result.schedule) == []
    assert result.makespan < greedy.makespan
    assert result.lower_bound <= result.makespan
