"""Loading scenarios: the paper's numbers, panels, and every kind of bad input named."""

import copy
from fractions import Fraction
from pathlib import Path

import pytest
import yaml

from fjsp_planner.core.problem import ProblemError
from fjsp_planner.core.scenario import ScenarioError, load_scenario, parse_scenario

PAPER = Path(__file__).resolve().parents[2] / 'config' / 'scenarios' / 'solar_panel.yaml'


@pytest.fixture(scope='module')
def paper_data():
    return yaml.safe_load(PAPER.read_text())


def test_paper_instance_numbers():
    problem = load_scenario(PAPER)
    assert [r.name for r in problem.robots] == ['Assembler', 'LSMS', 'MARC1', 'MARC2']
    assert len(problem.jobs) == 12
    assert problem.job('Aa').plans == ((0, 0, 2),)
    assert problem.duration('Assembler', 2) == 5
    assert problem.duration('LSMS', 3) == 1
    # Travel = distance * locomote efficiency / speed (paper §VI).
    assert problem.travel('Assembler', 'M1', 'Ja') == Fraction(43 * 100, 30)
    assert problem.travel('MARC2', 'M1', 'Ja') == Fraction(43 * 5, 25)
    assert problem.travel('LSMS', 'Ab', 'Md') == Fraction(58, 30)
    assert problem.distance('Jd', 'M1') == problem.distance('M1', 'Jd') == 56
    assert ('Jd', 'Ad', 1) in problem.holding
    assert len(problem.precedence) == 13


def test_panels_repeat_jobs_and_shift_distances():
    problem = load_scenario(PAPER, panels=3, shift=60)
    assert len(problem.jobs) == 36
    assert problem.distance('Ja_p1', 'Ja_p2') == 60
    assert problem.distance('M1_p1', 'Ja_p3') == 43 + 120
    assert ('Ja_p2', 'Aa_p2', 0) in problem.holding
    assert ('Ja_p1', 'Aa_p2', 0) not in problem.holding
    assert len(problem.precedence) == 39
    assert problem.panels[1][0] == 'M1_p2'


def test_file_panels_section_is_the_default(tmp_path, paper_data):
    data = copy.deepcopy(paper_data)
    data['panels'] = {'count': 2, 'shift': 10}
    path = tmp_path / 'two.yaml'
    path.write_text(yaml.safe_dump(data))
    problem = load_scenario(path)
    assert len(problem.jobs) == 24
    assert problem.distance('Ja_p1', 'Ja_p2') == 10


def test_sparse_pairs_operation_names_and_fractions():
    problem = parse_scenario({
        'operation_types': {0: 'grip', 1: 'drive'},
        'locomote': 'drive',
        'robot_types': {'rover': {'grip': '5/2', 'drive': 2}},
        'robots': [{'name': 'r1', 'type': 'rover', 'speed': 3, 'start_location': 'base',
                    'release_time': 1.5}],
        'jobs': [{'name': 'a', 'location': 'site', 'plans': [['grip']]}],
        'distances': {'pairs': [['base', 'site', 9]]},
    })
    assert problem.duration('r1', 0) == Fraction(5, 2)
    assert problem.travel('r1', 'site', 'base') == 6
    assert problem.robot('r1').release_time == Fraction(3, 2)


def _edit(data, path, value):
    target = data
    for key in path[:-1]:
        target = target[key]
    if value is DELETE:
        del target[path[-1]]
    else:
        target[path[-1]] = value


DELETE = object()

INVALID = [
    ('unknown robot type', ('robots', 0, 'type'), 'Walker', "unknown robot type 'Walker'"),
    ('duplicate robot', ('robots', 1, 'name'), 'Assembler', "robot 'Assembler' is defined 2"),
    ('duplicate job', ('jobs', 1, 'name'), 'M1', "job 'M1' is defined 2 times"),
    ('unknown job in precedence', ('precedence', 0), ['M1', 'Zz'], "unknown job 'Zz'"),
    ('precedence cycle', ('precedence', 12), ['Ad', 'M1'], 'precedence cycle: '),
    ('holding type missing at one end', ('holding', 0), ['Ja', 'Aa', 1],
     "needs operation type 1 but job 'Ja' has no such operation"),
    ('unknown operation in a plan', ('jobs', 0, 'plans'), [[7]], 'unknown operation type 7'),
    ('job needs more robots than exist', ('jobs', 4, 'plans'), [[0, 0, 2, 2, 2]],
     "job 'Aa' cannot be staffed: plan 0 [0, 0, 2, 2, 2] needs 5 distinct robots"),
    ('negative distance', ('distances', 'table', 'rows', 0, 2), -4, 'is negative'),
    ('asymmetric distance', ('distances', 'table', 'rows', 0, 2), 44, 'not symmetric'),
    ('missing distances', ('distances',), DELETE, "no distance between locations 'Aa' and"),
    ('non-number speed', ('robots', 0, 'speed'), 'fast', "robot 'Assembler' speed: expected"),
    ('zero speed', ('robots', 0, 'speed'), 0, 'speed must be positive'),
    ('missing jobs', ('jobs',), DELETE, "missing 'jobs'"),
    ('unknown section', ('robotz',), [], "unknown section 'robotz'"),
    ('robot type cannot travel', ('robot_types', 'LSMS', 'locomote'), DELETE,
     "robot type 'LSMS' has no efficiency for the locomote"),
    ('holding into two jobs', ('holding', 1), ['Ja', 'Ab', 0], 'cannot go directly to both'),
]


@pytest.mark.parametrize('name, path, value, expected', INVALID, ids=[r[0] for r in INVALID])
def test_invalid_scenarios_name_the_offending_item(paper_data, name, path, value, expected):
    data = copy.deepcopy(paper_data)
    _edit(data, path, value)
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    assert any(expected in p for p in caught.value.problems), caught.value.problems


def test_a_job_no_robot_can_do():
    data = yaml.safe_load(PAPER.read_text())
    data['operation_types'][4] = 'solder'
    data['jobs'][0]['plans'] = [[4]]
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    assert "job 'M1' cannot be staffed: plan 0 [4] needs 1 distinct robots" in str(caught.value)


def test_every_problem_is_reported_at_once(paper_data):
    data = copy.deepcopy(paper_data)
    data['robots'][0]['type'] = 'Walker'
    data['precedence'].append(['M1', 'Nope'])
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    assert len(caught.value.problems) >= 2


def test_yaml_syntax_error_names_the_line(tmp_path):
    path = tmp_path / 'broken.yaml'
    path.write_text('name: x\nrobots: [\n  {name: a, type: b\njobs: []\n')
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert 'YAML syntax error at line' in str(caught.value)
    assert str(path) in str(caught.value)


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(ScenarioError, match='cannot read scenario'):
        load_scenario(tmp_path / 'absent.yaml')


def test_bad_panel_count(tmp_path):
    with pytest.raises(ScenarioError, match='panels must be at least 1'):
        load_scenario(PAPER, panels=0)
