"""Jobs added to a running mission: a fragment checked against the mission, every problem at
once, and arcs into started jobs refused."""


import pytest
import yaml

from fjsp_planner.model.extension import extend
from fjsp_planner.model.problem import ProblemError
from fjsp_planner.model.scenario import load_scenario, parse_scenario, problem_mapping
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.solve import solve

from repo_paths import PAPER


@pytest.fixture(scope='module')
def problem():
    return load_scenario(PAPER)


def fragment(**sections) -> str:
    return yaml.safe_dump(sections)


def test_problem_mapping_reads_back_to_the_same_problem(problem):
    for panels in (1, 2):
        original = load_scenario(PAPER, panels=panels)
        again = parse_scenario(problem_mapping(original), original.name)
        assert (again.jobs, again.robots, again.distances, again.precedence, again.holding,
                again.robot_types) == (original.jobs, original.robots, original.distances,
                                       original.precedence, original.holding,
                                       original.robot_types)


def test_a_job_after_the_panel_is_added_and_solvable(problem):
    text = fragment(jobs=[{'name': 'Inspect', 'location': 'Ad', 'plans': [['locomote']]}],
                    precedence=[['Ad', 'Inspect']])
    extended, added = extend(problem, text)
    assert added == ('Inspect',)
    assert ('Ad', 'Inspect') in extended.precedence
    result = solve(extended, time_limit=10)
    assert validate(extended, result.schedule) == []
    assert result.makespan > 32  # one more unit after the panel's last job, at least


def test_a_new_location_needs_its_distances(problem):
    text = fragment(jobs=[{'name': 'Far', 'location': 'Depot', 'plans': [['locomote']]}],
                    distances={'pairs': [['Depot', 'Ja', 10]]})
    with pytest.raises(ProblemError) as error:
        extend(problem, text)
    assert any("'Depot' and 'M1'" in p for p in error.value.problems), error.value.problems


def test_every_problem_of_a_fragment_at_once(problem):
    text = fragment(jobs=[{'name': 'Ja', 'plans': [['locomote']]},
                          {'name': 'X', 'location': 'Ad', 'plans': [['locomote']]}],
                    precedence=[['X', 'Nowhere'], ['X', 'M1']], colour='red')
    with pytest.raises(ProblemError) as error:
        extend(problem, text, started={'M1'})
    problems = '\n'.join(error.value.problems)
    assert "unknown section 'colour'" in problems
    assert "precedence arc ['X', 'M1']: job 'M1' has already started" in problems
    assert "job 'Ja' is defined 2 times" in problems
    assert "unknown job 'Nowhere'" in problems


def test_a_cycle_through_the_mission_is_refused(problem):
    text = fragment(jobs=[{'name': 'X', 'location': 'Ad', 'plans': [['locomote']]}],
                    precedence=[['Ad', 'X'], ['X', 'M1']])
    with pytest.raises(ProblemError, match='precedence cycle'):
        extend(problem, text)


@pytest.mark.parametrize(('text', 'reason'), [
    ('jobs: [', 'YAML syntax error'),
    ('[1, 2]', 'must be a mapping'),
    ('jobs: []', 'at least one job'),
    ("jobs: [{name: X, location: Ad, plans: [['weld connection point', "
     "'weld connection point', 'weld connection point', 'weld connection point', "
     "'weld connection point']]}]", "job 'X' cannot be staffed"),
])
def test_bad_fragments(problem, text, reason):
    with pytest.raises(ProblemError) as error:
        extend(problem, text)
    assert any(reason in p for p in error.value.problems), error.value.problems


def test_the_shipped_second_panel_fragment_makes_two_panels(problem):
    """config/fragments/solar_panel_second_panel.yaml: the README's `mission add` example."""
    fragment = PAPER.parents[1] / 'fragments' / 'solar_panel_second_panel.yaml'
    extended, added = extend(problem, fragment.read_text())
    two = load_scenario(PAPER, panels=2)
    assert len(added) == 12 and len(extended.jobs) == len(two.jobs) == 24
    # The same instance as two panels repeated, but for the first panel's names.
    assert sorted(extended.distances.values()) == sorted(two.distances.values())
