"""What a revision's plan message tells the agents, built from the domain core's objects."""

import dataclasses
from fractions import Fraction

from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.nodes.conversions import cancel_msg, plan_msg
from fjsp_planner.solving.solve import solve

from repo_paths import PAPER, SCENARIOS


def test_a_revision_names_the_predecessors_done_before_it():
    """A re-plan once LSMS has moved M1 and M2 poses the rest without them; `Ja` may go on
    with its robots there since before M2 ended, so its task still names both: the agents
    start it no earlier than M2's reported end (a restarted planner's revision left M2 out
    and they started `Ja` at 2, before M2's end at 2.000002)."""
    scenario = load_scenario(PAPER)
    done = {'M1', 'M2'}
    posed = dataclasses.replace(
        scenario, jobs=tuple(j for j in scenario.jobs if j.name not in done),
        precedence=tuple((a, b) for a, b in scenario.precedence if a not in done))
    result = solve(posed, time_limit=2, workers=1)
    msg = plan_msg(scenario, posed, result.schedule, result, 'mission', 2, 0.0, 1.0, None)
    tasks = [t for robot in msg.robots for t in robot.tasks]
    assert {t.job for t in tasks} == {j.name for j in posed.jobs}
    assert all(sorted(t.predecessors) == ['M1', 'M2'] for t in tasks if t.job in ('Ja', 'Jb'))
    assert all(list(t.predecessors) == ['Ja'] for t in tasks if t.job == 'Aa')


def test_every_robot_is_placed_where_the_plan_starts_it():
    """A robot the plan gives no task still learns where it stands (the scenario's start, or
    where a re-plan has it); one the scenario may start anywhere, or one left out, gets no
    place."""
    scenario = load_scenario(PAPER)
    placed = dataclasses.replace(scenario, robots=tuple(
        dataclasses.replace(r, start_location='Jd') if r.name == 'MARC2' else r
        for r in scenario.robots))
    result = solve(placed, time_limit=2, workers=1)
    msg = plan_msg(placed, placed, result.schedule, result, 'mission', 1, 0.0, 1.0, None)
    assert {r.robot: r.start_location for r in msg.robots} == {
        'Assembler': '', 'LSMS': '', 'MARC1': '', 'MARC2': 'Jd'}
    without_marc2 = dataclasses.replace(placed, robots=tuple(
        dataclasses.replace(r, start_location='Aa') for r in placed.robots
        if r.name != 'MARC2'))
    result = solve(without_marc2, time_limit=2, workers=1)
    msg = plan_msg(placed, without_marc2, result.schedule, result, 'mission', 2, 0.0, 1.0, None)
    assert {r.robot: r.start_location for r in msg.robots} == {
        'Assembler': 'Aa', 'LSMS': 'Aa', 'MARC1': 'Aa', 'MARC2': ''}


def test_the_plan_carries_the_map_of_the_scenario():
    """Every located place with its coordinates (a 2-D one at z = 0), in every revision; a
    scenario of distances alone has no map."""
    yard = load_scenario(SCENARIOS / 'yard.yaml')
    result = solve(yard, time_limit=2, workers=1)
    msg = plan_msg(yard, yard, result.schedule, result, 'mission', 1, 0.0, 1.0, None)
    assert {p.name: (p.x, p.y, p.z) for p in msg.places} == {
        'depot': (0, 0, 0), 'gate': (30, 40, 0), 'mount': (60, 0, 0),
        'mast_head': (60, 0, 12), 'pad': (30, -40, 0)}
    flat = dataclasses.replace(yard, coordinates={'depot': (Fraction('0.5'), Fraction(-2))})
    assert [(p.name, p.x, p.y, p.z) for p in cancel_msg(flat, 'mission', 2, 0.0, 1.0,
                                                        None).places] == [
        ('depot', 0.5, -2.0, 0.0)]
    paper = load_scenario(PAPER)
    result = solve(paper, time_limit=2, workers=1)
    assert list(plan_msg(paper, paper, result.schedule, result, 'mission', 1, 0.0, 1.0,
                         None).places) == []
