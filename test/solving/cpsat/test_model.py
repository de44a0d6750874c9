"""The CP-SAT model: a schedule given to the model hints every variable it decides; the
travel stated between every two jobs of a robot goes the least way."""

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.cpsat import solve_cpsat
from fjsp_planner.solving.cpsat.model import CpsatModel
from fjsp_planner.solving.greedy import greedy_schedule

from solver_instances import detour


@pytest.mark.parametrize('pairwise_travel', [False, True])
def test_a_schedule_hints_every_variable_of_a_routed_model(pairwise_travel):
    """CP-SAT takes a hint as its first solution at once only when the hint sets every
    variable; otherwise it must complete it by search first. Every variable the model
    declares, the places each robot works at and the order of every two of its jobs
    included, follows from the schedule."""
    problem = parse_scenario(random_scenario(11, Shape(jobs=15, robots=5, robot_types=3)))
    schedule = greedy_schedule(problem)
    model = CpsatModel(problem, schedule, pairwise_travel=pairwise_travel)
    model.add_hint(schedule)
    proto = model.model.proto
    hinted = set(proto.solution_hint.vars)
    unhinted = [variable.name for index, variable in enumerate(proto.variables)
                if index not in hinted and min(variable.domain) != max(variable.domain)]
    assert unhinted == []


def test_travel_between_every_two_jobs_goes_the_least_way_along_the_table():
    """`detour`: robot A does x at a, y at b, z at c (1 each), x before z; a and c are 10
    apart, b 1 from each. Going x, y, z through b takes 1 + 1 + 1 + 1 + 1 = 5. The travel
    stated between x and z must be the least way (2, through b), not the direct 10, which
    would push z to 11 and the makespan to 12."""
    problem = detour(1)
    result = solve_cpsat(problem, time_limit=10, workers=1, pairwise_travel=True)
    assert result.status == Status.OPTIMAL
    assert result.makespan == 5
    assert validate(problem, result.schedule) == []
