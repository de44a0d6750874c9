"""The scenario generator: the same seed gives the same scenario, every scenario loads from
the YAML a user would write, and together the scenarios cover what the format allows."""

import pytest
import yaml

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import scenario_from_text

SEEDS = range(60)


def loaded(seed, shape=None):
    text = yaml.safe_dump(random_scenario(seed, shape or Shape()), sort_keys=False)
    return scenario_from_text(text, name=f'generated-{seed}')


def test_a_seed_always_gives_the_same_scenario():
    assert random_scenario(7) == random_scenario(7)
    assert random_scenario(7) != random_scenario(8)


@pytest.mark.parametrize('shape', [Shape(jobs=40, robots=6, robot_types=3, places=5),
                                   Shape(jobs=3, robots=3, robot_types=2, places=2)])
def test_the_shape_asked_for_is_the_shape_drawn(shape):
    problem = loaded(3, shape)
    assert len(problem.jobs) == shape.jobs
    assert len(problem.robots) == shape.robots
    assert len({r.type for r in problem.robots}) == shape.robot_types
    assert len({j.location for j in problem.jobs}) <= shape.places


def test_generated_scenarios_cover_what_the_format_allows():
    problems = [loaded(seed) for seed in SEEDS]
    travel = {p.operation_types[p.locomote] for p in problems}
    assert 'locomote' not in travel and len(travel) > 1
    assert {len({r.type for r in p.robots}) for p in problems} >= {2, 3, 4, 5}
    assert min(len(p.robots) for p in problems) == 3 and max(len(p.robots) for p in problems) == 10
    robots = [r for p in problems for r in p.robots]
    assert any(r.start_location is None for r in robots)
    assert any(r.release_time > 0 for r in robots)
    assert any(p.time_overrides for p in problems)
    assert any(t.denominator != 1 for p in problems for times in p.robot_types.values()
               for t in times.values())
    jobs = [j for p in problems for j in p.jobs]
    assert any(len(plan) == 3 for j in jobs for plan in j.plans)
    assert any(len(j.plans) > 1 for j in jobs)
    assert all(len({tuple(sorted(plan)) for plan in j.plans}) == len(j.plans) for j in jobs)
    holds = [(p.job(a).location == p.job(b).location) for p in problems for a, b, _ in p.holding]
    assert holds.count(True) >= 5 and holds.count(False) >= 5
    assert any(len(p.precedence) > len(p.jobs) // 2 for p in problems)


@pytest.mark.parametrize('seed', SEEDS)
def test_with_each_holding_arc_as_one_job_the_precedence_graph_has_no_cycle(seed):
    """A cycle through merged arcs means robots holding in two arcs could do neither arc
    first (and a path around one arc, a holder waiting for a job that needs it)."""
    problem = loaded(seed)
    node = {held: first for first, held, _ in problem.holding}
    successors = {}
    for before, after in problem.precedence:
        before, after = node.get(before, before), node.get(after, after)
        if before != after:
            successors.setdefault(before, set()).add(after)
    for start in successors:
        assert start not in _descendants(successors, start), (seed, start)


def _descendants(successors, job):
    seen, todo = set(), [job]
    while todo:
        for nxt in successors.get(todo.pop(), ()):
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen
