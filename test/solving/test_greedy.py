"""The greedy schedule: valid whenever a schedule exists, on the generator's scenarios too."""

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import load_scenario, parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.solve import solve

from repo_paths import DATA


def test_two_holding_arcs_whose_held_jobs_wait_for_each_other_are_placed():
    """Arc Wire-1 -> Mount-4 (torque) and arc Join-2 -> Place-5 (clamp), with Join-2 before
    Mount-4 and Wire-1 before Place-5. Neither arc can be placed as one block, and only the
    two drones torque: Wire-1 takes both, Join-2 needs one. So Join-2 goes first, its clamps
    kept for Place-5, then Wire-1 with both drones, then Mount-4 and Place-5."""
    problem = load_scenario(DATA / 'holding_arcs_waiting_for_each_other.yaml')
    assert ('Wire-1', 'Mount-4', 2) in problem.holding
    assert ('Join-2', 'Place-5', 0) in problem.holding
    schedule = greedy_schedule(problem)
    assert validate(problem, schedule) == []
    jobs = schedule.jobs
    assert jobs['Join-2'].end <= jobs['Wire-1'].start


@pytest.mark.parametrize('name', ['interleaved_holding_arcs_17_jobs',
                                  'interleaved_holding_arcs_28_jobs'])
def test_interleaved_holding_arcs_of_larger_scenarios_are_placed(name):
    problem = load_scenario(DATA / f'{name}.yaml')
    assert validate(problem, greedy_schedule(problem)) == []


@pytest.mark.slow
def test_every_generated_scenario_gets_a_valid_greedy_schedule():
    """The generator makes only scenarios that have a schedule."""
    for seed in range(200):
        problem = parse_scenario(random_scenario(seed))
        assert validate(problem, greedy_schedule(problem, passes=4)) == [], f'seed {seed}'


def test_a_limit_too_short_for_a_greedy_pass_still_gives_a_valid_schedule():
    """29 jobs in 10 ms: no greedy pass ends within its share of the limit, so `solve`
    waits for one quick pass rather than return nothing."""
    problem = parse_scenario(random_scenario(3, Shape(jobs=29, robots=6, robot_types=3)))
    result = solve(problem, time_limit=0.01)
    assert result.schedule is not None
    assert validate(problem, result.schedule) == []
