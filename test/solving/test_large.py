"""Scenarios past the CP-SAT routing size, up to the 1000-job limit, are scheduled."""

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.large import CPSAT_ROUTING_ARCS, routing_arcs
from fjsp_planner.solving.solve import solve


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
