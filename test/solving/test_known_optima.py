"""The scenarios shipped in config/scenarios/ besides the paper's: they load, and CP-SAT
proves their optimum (the values their files state) with a schedule the validator accepts.
The integration tests run them on the node network; this is where a broken file shows first.
"""

from fractions import Fraction

import pytest

from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.solve import solve

from repo_paths import SCENARIOS


@pytest.mark.parametrize(('scenario', 'optimum'), [
    ('truss.yaml', Fraction(23)),
    ('antenna.yaml', Fraction(88, 5)),
    ('habitat.yaml', Fraction(58)),
])
def test_shipped_scenario_is_proven_optimal(scenario, optimum):
    problem = load_scenario(SCENARIOS / scenario)
    assert any(r.start_location for r in problem.robots)
    assert any(r.release_time > 0 for r in problem.robots)
    assert any(len(j.plans) > 1 for j in problem.jobs) and problem.holding
    result = solve(problem, time_limit=60, workers=2)
    assert result.status == Status.OPTIMAL, result
    assert result.makespan == optimum
    assert validate(problem, result.schedule) == []


def test_the_yard_map_is_planned_to_its_optimum_on_the_solver_grid():
    """Its distances from coordinates are millionths, so CP-SAT rounds travel up onto its
    1/1000 grid: it proves 46.175 optimal there, which bounds the exact optimum above."""
    problem = load_scenario(SCENARIOS / 'yard.yaml')
    result = solve(problem, time_limit=60, workers=2)
    assert validate(problem, result.schedule) == []
    assert result.makespan <= Fraction('46.175'), result


def test_a_shipped_scenario_carries_a_held_part_between_two_places():
    problem = load_scenario(SCENARIOS / 'habitat.yaml')
    assert any(problem.job(a).location != problem.job(b).location
               for a, b, _ in problem.holding)
    assert problem.operation_types[problem.locomote] != 'locomote'
