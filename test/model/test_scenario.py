"""Loading scenarios: the paper's numbers, panels, and every kind of bad input named."""

import copy
import os
import time
from fractions import Fraction

import pytest
import yaml

from fjsp_planner.model.problem import ProblemError
from fjsp_planner.model.scenario import (
    ScenarioError,
    load_scenario,
    parse_scenario,
    scenario_warnings,
)
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate

from repo_paths import PAPER


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
HOLD = "'hold frame link' (0)"

# (why the scenario is wrong, where it is edited, the new value, what the message must say)
INVALID = [
    ('unknown robot type', ('robots', 0, 'type'), 'Walker', "unknown robot type 'Walker'"),
    ('robot without a type', ('robots', 0, 'type'), DELETE, "robot 'Assembler': missing 'type'"),
    ('duplicate robot', ('robots', 1, 'name'), 'Assembler', "robot 'Assembler' is defined 2"),
    ('duplicate job', ('jobs', 1, 'name'), 'M1', "job 'M1' is defined 2 times"),
    ('unknown job in precedence', ('precedence', 0), ['M1', 'Zz'], "unknown job 'Zz'"),
    ('precedence cycle', ('precedence', 12), ['Ad', 'M1'], 'precedence cycle: '),
    ('holding type missing at one end', ('holding', 0), ['Ja', 'Aa', 1],
     "needs operation type 'hold solar cell sheet' (1) but job 'Ja' has no such operation"),
    ('holding into two jobs', ('holding', 1), ['Ja', 'Ab', 0],
     f"holding arc ('Ja', 'Ab', {HOLD}): job 'Ja' already holds operation type {HOLD} into "
     "'Aa'; a robot cannot go directly to both"),
    ('unknown operation in a plan', ('jobs', 0, 'plans'), [[7]], 'unknown operation type 7'),
    ('unknown operation name in a plan', ('jobs', 0, 'plans'), [['weld']],
     "job 'M1': unknown operation type 'weld'"),
    ('job needs more robots than exist', ('jobs', 4, 'plans'), [[0, 0, 2, 2, 2]],
     f"job 'Aa' cannot be staffed: plan 0 [{HOLD} x2, 'weld connection point' (2) x3] "
     'needs 5 distinct robots'),
    ('negative distance', ('distances', 'table', 'rows', 0, 2), -4,
     "distance 'M1'-'Ja': -4 is outside [0, 1e+06]"),
    ('asymmetric distance', ('distances', 'table', 'rows', 0, 2), 44, 'not symmetric'),
    ('missing distances', ('distances',), DELETE,
     "no distances are given, but robots travel (operation type 'locomote' (3)) between 12 "
     "locations: 'distances' must give one between every two of them"),
    ('non-number speed', ('robots', 0, 'speed'), 'fast',
     "robot 'Assembler' speed: expected a finite number, got 'fast'"),
    ('zero speed', ('robots', 0, 'speed'), 0,
     "robot 'Assembler' speed: 0 is outside [1e-06, 1e+06]"),
    ('missing jobs', ('jobs',), DELETE, "missing 'jobs'"),
    ('unknown section', ('robotz',), [], "scenario: unknown key 'robotz' (allowed: name, "
                                         'operation_types'),
    ('robot type cannot travel', ('robot_types', 'LSMS', 'locomote'), DELETE,
     "robot type 'LSMS' has no efficiency for the locomote operation type 'locomote' (3)"),
    # A misspelt key would otherwise be ignored, and the robot silently given speed 1.
    ('misspelt robot key', ('robots', 3, 'sped'), 25,
     "robot 'MARC2': unknown key 'sped' (allowed: name, type, speed, start_location, "
     "release_time); did you mean 'speed'?"),
    ('misspelt job key', ('jobs', 0, 'plan'), [[3]], "job 'M1': unknown key 'plan'"),
    ('misspelt override key', ('time_overrides',),
     [{'robot': 'MARC1', 'operation': 2, 'time': 1, 'tme': 2}],
     "time override for 'MARC1': unknown key 'tme'"),
    ('misspelt panels key', ('panels', 'cuont'), 2, "panels: unknown key 'cuont'"),
    ('misspelt distances key', ('distances', 'pair'), [], "distances: unknown key 'pair'"),
    ('misspelt table key', ('distances', 'table', 'name'), [],
     "distances table: unknown key 'name'"),
    # Magnitudes that used to overflow CP-SAT's 64-bit arithmetic.
    ('efficiency of 1e300', ('robot_types', 'MARC', 'weld connection point'), 1e300,
     "robot type 'MARC', operation 'weld connection point': 1e+300 is outside [0, 1e+06]"),
    ('speed of 1e-300', ('robots', 2, 'speed'), 1e-300,
     "robot 'MARC1' speed: 1e-300 is outside [1e-06, 1e+06]"),
    ('distance of 1e30', ('distances', 'table', 'rows', 0, 2), 1e30,
     "distance 'M1'-'Ja': 1e+30 is outside [0, 1e+06]"),
    ('release time of 1e300', ('robots', 1, 'release_time'), 1e300,
     "robot 'LSMS' release_time: 1e+300 is outside [0, 1e+06]"),
    ('NaN time', ('robot_types', 'LSMS', 'locomote'), float('nan'),
     "robot type 'LSMS', operation 'locomote': expected a finite number, got nan"),
    ('infinite speed', ('robots', 0, 'speed'), float('inf'),
     "robot 'Assembler' speed: expected a finite number, got inf"),
    ('huge exponent written as text', ('robots', 0, 'speed'), '1e-999999999',
     "robot 'Assembler' speed: expected a finite number, got '1e-999999999'"),
    ('too precise', ('robots', 0, 'release_time'), '0.0000001',
     "robot 'Assembler' release_time: '0.0000001' is too precise: at most 6 decimal places"),
    ('fraction dividing by zero', ('robots', 0, 'speed'), '1/0',
     "robot 'Assembler' speed: '1/0' divides by zero"),
    ('derived travel too long', ('robot_types', 'Assembler', 'locomote'), 10**6,
     "robot 'Assembler': travelling from 'Ab' to 'Md' would take 1933333.333 units "
     '(distance 58 x locomote efficiency 1e+06 / speed 30), more than the limit of 1e+06'),
    # Names and sizes a file can make enormous cheaply.
    ('name that is a list', ('jobs', 0, 'name'), ['M', 1],
     "job #1: a name must be a string, got ['M', 1]"),
    ('empty name', ('robots', 0, 'name'), '', 'robot #1: a name must not be empty'),
    ('long name', ('robots', 0, 'name'), 'R' * 1000,
     "robot #1: name 'RRRRRRRRRRRRRRRRRRRRRRRRRRR...RRRRRRRRRRRRRRRRRRRRRRRRRRRR' is longer "
     'than 100 characters'),
    ('too many plans', ('jobs', 0, 'plans'), [[3]] * 21,
     "job 'M1': plans: 21 is more than the limit of 20"),
    ('too many robots', ('robots',), [{'name': f'R{i}', 'type': 'MARC'} for i in range(101)],
     "scenario: 'robots' entries: 101 is more than the limit of 100"),
    ('too many panels', ('panels', 'count'), 51, 'panels count: 51 is more than the limit of 50'),
    ('panels too large for the jobs', ('panels', 'count'), 50,
     'jobs (12 x 50 panels): 600 is more than'),
]


@pytest.mark.parametrize('why, path, value, expected', INVALID, ids=[r[0] for r in INVALID])
def test_invalid_scenarios_name_the_offending_item(paper_data, why, path, value, expected):
    data = copy.deepcopy(paper_data)
    if why == 'panels too large for the jobs':
        data['jobs'] += [{'name': f'X{i}', 'location': 'M1', 'plans': [[3]]}
                         for i in range(72)]
        expected = 'jobs (84 x 50 panels): 4200 is more than the limit of 1000'
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
    assert caught.value.problems == [
        "job 'M1' cannot be staffed: plan 0 ['solder' (4)] needs a robot able to do it; no "
        'robot can']


def two_holds(extra_robots=()) -> dict:
    """Two holding arcs, each held job waiting for the other arc's first job: J1 -> H1
    holding grip, J2 -> H2 holding torque, with J1 before H2 and J2 before H1."""
    return {
        'operation_types': {0: 'grip', 1: 'torque', 2: 'drive'},
        'robot_types': {'Gripper': {'grip': 2, 'drive': 1}, 'Both': {'grip': 3, 'torque': 3,
                                                                    'drive': 1},
                        'Turner': {'torque': 2, 'drive': 1}},
        'robots': [{'name': 'A', 'type': 'Gripper'}, {'name': 'B', 'type': 'Both'},
                   {'name': 'C', 'type': 'Turner'}, *extra_robots],
        'jobs': [{'name': name, 'location': 'yard', 'plans': [[op, op]]}
                 for name, op in (('J1', 'grip'), ('J2', 'torque'), ('H1', 'grip'),
                                  ('H2', 'torque'))],
        'precedence': [['J1', 'H2'], ['J2', 'H1']],
        'holding': [['J1', 'H1', 'grip'], ['J2', 'H2', 'torque']],
    }


def test_two_holding_arcs_that_must_share_a_holder_and_wait_for_each_other_are_refused():
    """B is the only robot able to do both: two grip and two torque holders among three
    robots put it in both arcs, and it could do neither arc first."""
    with pytest.raises(ProblemError) as caught:
        parse_scenario(two_holds())
    assert caught.value.problems == [
        "holding arcs ('J1', 'H1', 'grip' (0)) and ('J2', 'H2', 'torque' (1)) cannot both be "
        "held: 'H1' waits for 'J2' and 'H2' for 'J1', and 4 holders among the 3 robots able "
        "to do 'grip' (0) or 'torque' (1) put one in both arcs, which it could do neither of "
        'first']


def test_two_holding_arcs_waiting_for_each_other_with_holders_enough_are_kept():
    """With a second robot able to do both, A and D hold the grip and B and C the torque."""
    problem = parse_scenario(two_holds([{'name': 'D', 'type': 'Both'}]))
    grip, torque = {'A': 0, 'D': 0}, {'B': 1, 'C': 1}
    schedule = Schedule(
        {'J1': JobAssignment('J1', 0, 0, 3, grip), 'J2': JobAssignment('J2', 0, 0, 3, torque),
         'H1': JobAssignment('H1', 0, 3, 6, grip), 'H2': JobAssignment('H2', 0, 3, 6, torque)},
        {'A': ('J1', 'H1'), 'D': ('J1', 'H1'), 'B': ('J2', 'H2'), 'C': ('J2', 'H2')})
    assert validate(problem, schedule) == []


def test_every_problem_is_reported_at_once(paper_data):
    """Problems found by reading the file, by checking ids and by checking the structure they
    make (cycles, holding arcs, staffing) all come in one pass, each named once."""
    data = copy.deepcopy(paper_data)
    data['robots'][0]['type'] = 'Walker'                       # unknown robot type
    data['distances']['pairs'] = [['Ja', 'depot', 4]]          # 'depot' is a start location
    data['robots'][1]['start_location'] = 'depot'              # far from all but Ja
    data['holding'][0] = ['Ja', 'Aa', 1]                       # Ja holds no solar cell sheet
    data['precedence'].append(['Ad', 'M1'])                    # closes a cycle
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    problems = caught.value.problems
    expected = ["robot 'Assembler': unknown robot type 'Walker'",
                "no distance between locations 'Aa' and 'depot'",
                "holding arc ('Ja', 'Aa', 'hold solar cell sheet' (1)) needs operation type "
                "'hold solar cell sheet' (1) but job 'Ja' has no such operation",
                'precedence cycle: ']
    for text in expected:
        assert any(text in p for p in problems), (text, problems)
    assert len(problems) == len(set(problems))


def test_reading_errors_and_model_errors_come_together(paper_data):
    """A value the reader refuses does not hide what the model check finds elsewhere."""
    data = copy.deepcopy(paper_data)
    data['robots'][2]['speed'] = 'fast'
    data['holding'].append(['Ja', 'Aa', 'weld'])                # unknown operation name
    data['precedence'].append(['Ad', 'M1'])
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    text = '\n'.join(caught.value.problems)
    assert "robot 'MARC1' speed: expected a finite number, got 'fast'" in text
    assert "unknown operation type 'weld'" in text
    assert 'precedence cycle: ' in text


def test_a_malformed_entry_hides_only_its_own_consequences(paper_data):
    data = copy.deepcopy(paper_data)
    data['jobs'][4]['plans'] = 5
    data['jobs'].append({'name': 'Aa', 'plans': [[0, 0, 2]]})   # a second 'Aa': said too
    data['distances']['table']['rows'][0][2] = 'far'
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    assert sorted(caught.value.problems) == sorted([
        "job 'Aa': plans must be a list of lists of operation types",
        "job 'Aa' is defined 2 times",
        "distance 'M1'-'Ja': expected a finite number, got 'far'"])


def test_a_malformed_entry_is_reported_once(paper_data):
    """A job whose plans cannot be read is not also an 'unknown job' in every arc naming it."""
    data = copy.deepcopy(paper_data)
    data['jobs'][4]['plans'] = 5
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    assert caught.value.problems == [
        "job 'Aa': plans must be a list of lists of operation types"]


def test_yaml_syntax_error_names_the_line(tmp_path):
    path = tmp_path / 'broken.yaml'
    path.write_text('name: x\nrobots: [\n  {name: a, type: b\njobs: []\n')
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert 'YAML syntax error at line' in str(caught.value)
    assert str(path) in str(caught.value)


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(ScenarioError, match='absent.yaml: no such file'):
        load_scenario(tmp_path / 'absent.yaml')


def test_bad_panel_count(tmp_path):
    with pytest.raises(ScenarioError, match='panels must be at least 1'):
        load_scenario(PAPER, panels=0)


def test_panels_beyond_the_limit_are_refused_before_anything_is_built():
    """`panels:=100000` used to build 10^10 distance entries until the machine ran out of
    memory; it is refused at once, before the file is even read."""
    began = time.monotonic()
    with pytest.raises(ScenarioError) as caught:
        load_scenario(PAPER, panels=100000)
    assert caught.value.problems == [
        f'{PAPER}: panels: 100000 is more than the limit of 50']
    assert time.monotonic() - began < 5      # generous: it builds nothing


def test_shift_override_is_checked():
    with pytest.raises(ScenarioError, match=r'shift: 1e\+30 is outside \[0, 1e\+06\]'):
        load_scenario(PAPER, panels=2, shift=1e30)


def test_panels_that_make_travel_too_long(tmp_path):
    """Each panel is `shift` further away: 50 panels 30000 apart put the last one 1.47e6
    away, beyond what any robot may travel."""
    with pytest.raises(ScenarioError) as caught:
        load_scenario(PAPER, panels=50, shift=30000)
    assert any("robot 'Assembler': travelling from 'Ab' of panel 1 to 'Md' of panel 50 would "
               'take 4900193.333 units (distance 1.47006e+06 x locomote efficiency 100 / '
               'speed 30), more than the limit of 1e+06' in p
               for p in caught.value.problems), caught.value.problems


@pytest.mark.parametrize(('content', 'message'), [
    (b'name: caf\xe9\n', 'not UTF-8 text (byte 0xe9 at offset 9)'),
    (b'operation_types: {0: ' + b'9' * 5000 + b'}\n', 'YAML value that cannot be read'),
    (b'jobs: ' + b'[' * 5000 + b']' * 5000 + b'\n',
     'YAML nesting deeper than 64 levels at line 1, column 70'),
    (b'a: &a [x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a]\n'
     b'c: &c [*b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c]\n'
     b'name: *d\n', 'name: a name must be a string, got [[[...], [...], [...], [...], ...]'),
], ids=['latin-1 byte', 'integer of 5000 digits', 'nested 5000 deep', 'alias bomb as name'])
def test_unreadable_content_is_one_clear_error(tmp_path, content, message):
    path = tmp_path / 'bad.yaml'
    path.write_bytes(content)
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert any(message in p for p in caught.value.problems), caught.value.problems
    assert all(len(p) < 500 for p in caught.value.problems)


def test_a_directory_is_not_a_missing_file(tmp_path):
    with pytest.raises(ScenarioError, match='is a directory, not a scenario file'):
        load_scenario(tmp_path)


def test_a_pipe_is_refused_rather_than_read_forever(tmp_path):
    fifo = tmp_path / 'pipe.yaml'
    os.mkfifo(fifo)
    with pytest.raises(ScenarioError, match='is not a regular file'):
        load_scenario(fifo)


def test_a_file_larger_than_the_limit(tmp_path):
    path = tmp_path / 'huge.yaml'
    path.write_bytes(b'#' * (4 * 2**20 + 1))
    with pytest.raises(ScenarioError, match='larger than the limit of 4194304 bytes'):
        load_scenario(path)


# --- checks that help: what to write instead ---------------------------------------------

BEAM = {
    'name': 'beam',
    'operation_types': {0: 'grip', 1: 'weld', 2: 'locomote'},
    'robot_types': {'Crane': {'grip': 2, 'locomote': 10},
                    'Welder': {'grip': 4, 'weld': 3, 'locomote': 2}},
    'robots': [{'name': 'C1', 'type': 'Crane', 'speed': 5, 'start_location': 'dock'},
               {'name': 'W1', 'type': 'Welder', 'speed': 10, 'start_location': 'dock',
                'release_time': 1}],
    'jobs': [{'name': 'Lift', 'location': 'site', 'plans': [['grip']]},
             {'name': 'Join', 'location': 'site', 'plans': [['grip', 'weld']]},
             {'name': 'Check', 'location': 'yard', 'plans': [['weld']]}],
    'distances': {'pairs': [['dock', 'site', 5], ['dock', 'yard', 3], ['site', 'yard', 2]]},
    'precedence': [['Lift', 'Join']],
    'holding': [['Lift', 'Join', 'grip']],
}

# (what is wrong, where it is edited, the new value, every problem said, in order)
UNHELPFUL = [
    ('misspelt robot type', ('robots', 0, 'type'), 'Crain',
     ["robot 'C1': unknown robot type 'Crain'; did you mean 'Crane'?",
      "job 'Join' cannot be staffed: plan 0 ['grip' (0), 'weld' (1)] needs 2 distinct robots "
      "able to do its operations; 1 can (not counting 'C1', of unknown type)"]),
    ('misspelt operation type in a plan', ('jobs', 0, 'plans'), [['grp']],
     ["job 'Lift': unknown operation type 'grp'; did you mean 'grip'?"]),
    ('misspelt operation type of a holding arc', ('holding', 0), ['Lift', 'Join', 'gripp'],
     ["holding arc ('Lift', 'Join'): unknown operation type 'gripp'; did you mean 'grip'?"]),
    ('misspelt efficiency', ('robot_types', 'Crane', 'wled'), 3,
     ["robot type 'Crane': unknown operation type 'wled'; did you mean 'weld'?"]),
    ('misspelt locomote', ('locomote',), 'locomot',
     ["locomote: unknown operation type 'locomot'; did you mean 'locomote'?"]),
    ('misspelt job in precedence', ('precedence', 0), ['Lift', 'Jion'],
     ["precedence arc ('Lift', 'Jion') names unknown job 'Jion'; did you mean 'Join'?"]),
    ('misspelt job in a holding arc', ('holding', 0), ['Lfit', 'Join', 'grip'],
     ["holding arc ('Lfit', 'Join', 'grip' (0)) names unknown job 'Lfit'; did you mean "
      "'Lift'?"]),
    ('misspelt robot of an override', ('time_overrides',),
     [{'robot': 'w1', 'operation': 'weld', 'time': 2}],
     ["time override names unknown robot 'w1'; did you mean 'W1'?"]),
    ('unknown start location, named once', ('robots', 0, 'start_location'), 'dok',
     ["location 'dok' (start of robot 'C1') has no distance to any other location; did you "
      "mean 'dock'?"]),
    ('misspelt job location', ('jobs', 2, 'location'), 'yrd',
     ["location 'yrd' (job 'Check') has no distance to any other location; did you mean "
      "'yard'?"]),
    ('no distances at all', ('distances',), DELETE,
     ["no distances are given, but robots travel (operation type 'locomote' (2)) between 3 "
      "locations: 'distances' must give one between every two of them"]),
    ('one distance missing', ('distances', 'pairs'), [['dock', 'site', 5], ['dock', 'yard', 3]],
     ["no distance between locations 'site' and 'yard'"]),
    ('a distance given twice', ('distances', 'pairs'),
     [['dock', 'site', 5], ['dock', 'yard', 3], ['site', 'yard', 2], ['yard', 'dock', 2.5]],
     ["distance 'yard'-'dock' is given twice: 3 and 2.500"]),
    ('a job one robot short', ('jobs', 1, 'plans'), [['weld', 'weld']],
     ["holding arc ('Lift', 'Join', 'grip' (0)) needs operation type 'grip' (0) but job "
      "'Join' has no such operation", "job 'Join' cannot be staffed: plan 0 ['weld' (1) x2] "
      'needs 2 distinct robots able to do its operations; 1 can']),
    ('a job no robot can do', ('operation_types', 3), 'paint', None),
]


@pytest.mark.parametrize('why, path, value, expected', UNHELPFUL,
                         ids=[row[0] for row in UNHELPFUL])
def test_problems_say_what_to_write_instead(why, path, value, expected):
    data = copy.deepcopy(BEAM)
    _edit(data, path, value)
    if why == 'a job no robot can do':
        data['jobs'][2]['plans'] = [['paint']]
        expected = ["job 'Check' cannot be staffed: plan 0 ['paint' (3)] needs a robot able "
                    'to do it; no robot can']
    with pytest.raises(ProblemError) as caught:
        parse_scenario(data)
    assert caught.value.problems == expected


def test_the_beam_is_fine():
    problem = parse_scenario(copy.deepcopy(BEAM))
    assert scenario_warnings(problem) == []


TRAVEL_FREE = ("are given, but no operation type is the travel type (none is called "
               "'locomote', and no 'locomote:' names one): travel takes no time")

# (what is written, the warning)
UNMEANT = [
    ('travel type called drive', {
        'operation_types': {0: 'grip', 1: 'weld', 2: 'drive'},
        'robot_types': {'Crane': {'grip': 2, 'drive': 10},
                        'Welder': {'grip': 4, 'weld': 3, 'drive': 2}}},
     f"distances and the start locations of robots 'C1', 'W1' {TRAVEL_FREE}; did you mean "
     "'locomote: drive'?"),
    ('no travel type, distances only', {
        'operation_types': {0: 'grip', 1: 'weld'},
        'robot_types': {'Crane': {'grip': 2}, 'Welder': {'grip': 4, 'weld': 3}},
        'robots': [{'name': 'C1', 'type': 'Crane'}, {'name': 'W1', 'type': 'Welder'}]},
     f"distances {TRAVEL_FREE}; name it with 'locomote: <operation type>', or call it "
     "'locomote'"),
    ('no travel type, one start location only', {
        'operation_types': {0: 'grip', 1: 'weld', 2: 'fly'},
        'robot_types': {'Crane': {'grip': 2, 'fly': 1}, 'Welder': {'grip': 4, 'weld': 3}},
        'robots': [{'name': 'C1', 'type': 'Crane', 'start_location': 'site'},
                   {'name': 'W1', 'type': 'Welder'}],
        'distances': None},
     f"the start location of robot 'C1' {TRAVEL_FREE}; did you mean 'locomote: fly'?"),
]


@pytest.mark.parametrize('why, changes, warning', UNMEANT, ids=[row[0] for row in UNMEANT])
def test_what_probably_is_not_meant_is_a_warning(why, changes, warning):
    data = {**copy.deepcopy(BEAM), **changes}
    data = {key: value for key, value in data.items() if value is not None}
    assert scenario_warnings(parse_scenario(data)) == [warning]
