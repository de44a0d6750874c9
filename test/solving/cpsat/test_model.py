"""The CP-SAT model's hints: a schedule given to the model sets every variable it decides."""

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.solving.cpsat.model import CpsatModel
from fjsp_planner.solving.greedy import greedy_schedule


def test_a_schedule_hints_every_variable_of_a_routed_model():
    """CP-SAT takes a hint as its first solution at once only when the hint sets every
    variable; otherwise it must complete it by search first. Every variable the model
    declares, the places each robot works at included, follows from the schedule."""
    problem = parse_scenario(random_scenario(11, Shape(jobs=15, robots=5, robot_types=3)))
    schedule = greedy_schedule(problem)
    model = CpsatModel(problem, schedule)
    model.add_hint(schedule)
    proto = model.model.proto
    hinted = set(proto.solution_hint.vars)
    unhinted = [variable.name for index, variable in enumerate(proto.variables)
                if index not in hinted and min(variable.domain) != max(variable.domain)]
    assert unhinted == []
