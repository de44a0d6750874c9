"""fjsp-solve as a user runs it: exit codes, printed table, JSON shape, Gantt file."""

import ctypes
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fjsp_common.decimals import decimals

from repo_paths import DATA, FRAGMENTS, PAPER, REPO


def fjsp_solve(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        str(REPO / 'src' / package) for package in ('fjsp_planner', 'fjsp_common')))
    return subprocess.run([sys.executable, '-m', 'fjsp_planner.cli', *map(str, args)],
                          capture_output=True, text=True, env=env, cwd=cwd, timeout=120)


@pytest.mark.integration
def test_paper_instance_json_and_gantt(tmp_path):
    out, png = tmp_path / 'plan.json', tmp_path / 'plan.png'
    run = fjsp_solve(PAPER, '--time-limit', 20, '--json', out, '--gantt', png)
    assert run.returncode == 0, run.stderr
    assert 'status optimal' in run.stdout and 'makespan 32' in run.stdout
    for robot in ('Assembler', 'LSMS', 'MARC1', 'MARC2'):
        assert robot in run.stdout
    data = json.loads(out.read_text())
    assert data['status'] == 'optimal'
    assert data['makespan'] == 32 and data['lower_bound'] == 32 and data['gap'] == 0
    assert isinstance(data['solve_seconds'], float)
    assert sorted(j['name'] for j in data['jobs']) == sorted(
        ['M1', 'M2', 'Ja', 'Jb', 'Aa', 'Ab', 'M3', 'Jc', 'Ac', 'Md', 'Jd', 'Ad'])
    aa = next(j for j in data['jobs'] if j['name'] == 'Aa')
    assert sorted(aa['robots'].values()) == [0, 0, 2]
    assert set(aa) == {'name', 'plan', 'start', 'end', 'robots'}
    assert set(data['robots']) == {'Assembler', 'LSMS', 'MARC1', 'MARC2'}
    visits = [v for route in data['robots'].values() for v in route]
    assert len(visits) == sum(len(j['robots']) for j in data['jobs'])
    assert all(v['travel_start'] <= v['arrival'] <= v['start'] < v['end'] for v in visits)
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


@pytest.mark.integration
def test_greedy_solver_and_panels(tmp_path):
    out = tmp_path / 'plan.json'
    run = fjsp_solve(PAPER, '--solver', 'greedy', '--panels', 2, '--shift', 30, '--json', out)
    assert run.returncode == 0, run.stderr
    data = json.loads(out.read_text())
    assert data['status'] == 'feasible' and len(data['jobs']) == 24


@pytest.mark.integration
@pytest.mark.parametrize('args, message', [
    (['missing.yaml'], 'missing.yaml: no such file'),
    (['.'], '.: is a directory, not a scenario file'),
    ([PAPER, '--panels', '0'], 'must be a positive integer'),
    ([PAPER, '--panels', '100000'], 'panels: 100000 is more than the limit of 50'),
    ([PAPER, '--time-limit', 'soon'], 'not a number'),
    ([PAPER, '--time-limit', 'inf'], 'must be a finite number > 0'),
    ([PAPER, '--solver', 'gurobi'], 'invalid choice'),
    ([PAPER, '--shift', '-1'], "shift: '-1' is outside [0, 1e+06]"),
    ([PAPER, '--shift', '1e-999999999'], 'shift: expected a finite number'),
    ([PAPER, '--workers', '999999'], 'must be at most 64'),
], ids=['missing file', 'directory', 'zero panels', 'too many panels', 'bad time limit',
        'infinite time limit', 'unknown solver', 'negative shift', 'huge exponent',
        'too many workers'])
def test_bad_arguments_exit_2_with_a_message(args, message):
    run = fjsp_solve(*args)
    assert run.returncode == 2
    assert message in run.stderr
    assert 'Traceback' not in run.stderr


@pytest.mark.integration
@pytest.mark.parametrize('option', ['--json', '--gantt'])
def test_an_output_that_cannot_be_written_exits_2(tmp_path, option):
    run = fjsp_solve(PAPER, '--solver', 'greedy', option, tmp_path / 'no' / 'such' / 'out')
    assert (run.returncode, 'Traceback' in run.stderr) == (2, False), run.stderr
    assert run.stderr.startswith('fjsp-solve: cannot write ') and 'No such file' in run.stderr


@pytest.mark.integration
@pytest.mark.parametrize('old, new, message', [
    ('{name: MARC2, type: MARC, speed: 25}', '{name: MARC2, type: MARC, sped: 25}',
     "robot 'MARC2': unknown key 'sped'"),
    ('weld connection point: 1, locomote: 5}', 'weld connection point: 1e300, locomote: 5}',
     "robot type 'MARC', operation 'weld connection point': '1e300' is outside"),
    ('{name: MARC2, type: MARC, speed: 25}', '{name: MARC2, type: MARC, speed: 1e-300}',
     "robot 'MARC2' speed: '1e-300' is outside [1e-06, 1e+06]"),
    ('- [0, 0, 43,', '- [0, 0, 1e30,', "distance 'M1'-'Ja': '1e30' is outside"),
    ('{name: LSMS, type: LSMS, speed: 30}', '{name: LSMS, type: LSMS, speed: 30, '
     'release_time: 1e300}', "robot 'LSMS' release_time: '1e300' is outside"),
], ids=['misspelt key', 'efficiency 1e300', 'speed 1e-300', 'distance 1e30',
        'release time 1e300'])
def test_values_that_used_to_crash_the_solver_exit_2(tmp_path, old, new, message):
    bad = tmp_path / 'bad.yaml'
    text = PAPER.read_text()
    assert old in text
    bad.write_text(text.replace(old, new, 1))
    run = fjsp_solve(bad)
    assert (run.returncode, 'Traceback' in run.stderr) == (2, False), run.stderr
    assert message in run.stderr
    assert len(run.stderr.splitlines()) == 2, run.stderr        # the heading and the reason


@pytest.mark.integration
@pytest.mark.parametrize('name, content, message', [
    ('latin.yaml', b'name: caf\xe9\n', 'not UTF-8 text (byte 0xe9 at offset 9)'),
    ('big.fjs', b'1 2\n1 1 1 1e23\n', "time on machine 1: '1e23' is outside [0, 1e+06]"),
], ids=['non-UTF-8 YAML', '.fjs time 1e23'])
def test_unreadable_files_exit_2(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    run = fjsp_solve(path)
    assert (run.returncode, 'Traceback' in run.stderr) == (2, False), run.stderr
    assert message in run.stderr


@pytest.mark.integration
def test_invalid_scenario_lists_every_problem(tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text(PAPER.read_text().replace('type: MARC, speed: 25', 'type: Rover, speed: 25')
                   .replace('- [Jd, Ad]', '- [Jd, Zz]'))
    run = fjsp_solve(bad)
    assert run.returncode == 2
    assert "unknown robot type 'Rover'" in run.stderr
    assert "unknown job 'Zz'" in run.stderr
    assert 'Traceback' not in run.stderr


def _status(pid) -> dict[str, str]:
    try:
        lines = Path(f'/proc/{pid}/status').read_text().splitlines()
    except OSError:
        return {}
    return dict(line.split(':\t', 1) for line in lines if ':\t' in line)


def _wait_for(process, condition, what, timeout=60):
    """Poll the child's /proc status until `condition(status)` (bounded)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert process.poll() is None, f'fjsp-solve ended before {what}'
        if condition(_status(process.pid)):
            return
        time.sleep(0.02)
    pytest.fail(f'fjsp-solve never got to {what} within {timeout} s')


def _handles_sigterm(status):
    return int(status.get('SigCgt', '0'), 16) & (1 << (signal.SIGTERM - 1))


def _threads(status):
    return int(status.get('Threads', '0'))


def _signal_a_thread_other_than_the_main_one(pid, signum):
    others = sorted(int(t) for t in os.listdir(f'/proc/{pid}/task') if int(t) != pid)
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.tgkill(pid, others[-1], signum) != 0:
        raise OSError(ctypes.get_errno(), 'tgkill failed')


# Each case: the stage at which the signal lands, recognised from outside through /proc.
# The main thread installs the handlers, then imports OR-Tools (which starts one thread of its
# own), then starts the worker (3 threads): it loads the scenario (for seconds at 50 panels),
# solves greedily, then CP-SAT adds its 2 search threads.
@pytest.mark.integration
@pytest.mark.skipif(not Path('/proc/self/status').exists(), reason='needs Linux /proc')
@pytest.mark.parametrize('signum, panels, ready, stage, to_thread', [
    (signal.SIGINT, 10, _handles_sigterm, None, False),
    (signal.SIGTERM, 50, lambda s: _threads(s) >= 3, 'loading the scenario', False),
    (signal.SIGINT, 10, lambda s: _threads(s) >= 5, 'solving', False),
    (signal.SIGTERM, 10, lambda s: _threads(s) >= 5, 'solving', False),
    (signal.SIGTERM, 10, lambda s: _threads(s) >= 5, 'solving', True),
], ids=['SIGINT at start', 'SIGTERM while loading', 'SIGINT while solving',
        'SIGTERM while solving', 'SIGTERM landing on a CP-SAT thread'])
def test_signals_stop_it_at_once_with_one_line(signum, panels, ready, stage, to_thread):
    """The kernel hands a signal sent to the process to any thread not blocking it, mostly
    the main one; when it chose another, fjsp-solve went on for its whole time limit."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        str(REPO / 'src' / package) for package in ('fjsp_planner', 'fjsp_common')))
    process = subprocess.Popen(
        [sys.executable, '-m', 'fjsp_planner.cli', PAPER, '--panels', str(panels),
         '--time-limit', '120'], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=env)
    try:
        _wait_for(process, ready, stage or 'installing its signal handlers')
        if to_thread:
            _signal_a_thread_other_than_the_main_one(process.pid, signum)
        else:
            process.send_signal(signum)
        sent = time.monotonic()
        _, stderr = process.communicate(timeout=30)
        waited = time.monotonic() - sent
    finally:
        process.kill()
        process.wait()
    name = signal.Signals(signum).name
    assert process.returncode == 128 + signum, stderr
    assert stderr.startswith(f'fjsp-solve: stopped by {name} while '), stderr
    assert len(stderr.splitlines()) == 1, stderr
    if stage is not None:
        assert stderr.strip().endswith(stage), stderr
    assert waited < 10, f'took {waited:.1f} s to stop'   # the time limit is 120 s


LONG = 'x' * 24
LONG_NAMES = f"""
name: long names
operation_types: {{0: grip and hold the {LONG}, 1: travel}}
robot_types:
  Crane: {{grip and hold the {LONG}: 2, travel: 10}}
robots:
  - {{name: crane_number_one_of_the_{LONG[:6]}, type: Crane, speed: 5, start_location: dock}}
  - {{name: C2, type: Crane, speed: 5, start_location: dock}}
jobs:
  - {{name: lift_the_first_truss_{LONG[:9]}, location: site, plans: [[grip and hold the {LONG}]]}}
  - {{name: J2, location: site, plans: [[grip and hold the {LONG}, grip and hold the {LONG}]]}}
distances: {{pairs: [[dock, site, 5]]}}
precedence: [[lift_the_first_truss_{LONG[:9]}, J2]]
"""


def table_of(problem):
    from fjsp_planner.cli import format_table
    from fjsp_planner.solving.solve import solve

    result = solve(problem, time_limit=1)
    return result, format_table(problem, result).splitlines()


def check_columns(problem, result, lines):
    """Each row's names start where the header's titles do (left-aligned columns), its
    numbers end where theirs end, and neighbouring cells never touch."""
    header = lines[0]
    starts = [header.index(title) for title in ('robot', 'job', 'operation')]
    ends = [header.index(title) + len(title) for title in ('travel', 'start', 'end')]
    rows = iter(lines[1:])
    for robot in problem.robots:
        for visit in result.schedule.visits(problem, robot.name):
            line = next(rows)
            operation = problem.operation_types[
                result.schedule.jobs[visit.job].robots[robot.name]]
            for text, start in zip((robot.name, visit.job, operation), starts, strict=True):
                assert line[start:start + len(text) + 1] == text + ' ', (header, line)
            left, arrival, start, end = decimals(visit.travel_start, visit.arrival,
                                                 visit.start, visit.end)
            travel = f'{left}-{arrival}' if visit.arrival > visit.travel_start else '-'
            numbers = (travel, start, end)
            for text, end in zip(numbers, ends, strict=True):
                assert line[end - len(text) - 1:end] == ' ' + text, (header, line)
            assert len(line) == ends[-1], (header, line)
        if not result.schedule.sequences[robot.name]:
            assert next(rows) == f'{robot.name:<{starts[1]}}(no jobs)'


def test_table_columns_fit_names_of_any_length():
    from fjsp_planner.model.scenario import scenario_from_text

    problem = scenario_from_text(LONG_NAMES, name='long')
    assert max(len(r.name) for r in problem.robots) == 30
    assert max(len(j.name) for j in problem.jobs) == 30
    assert max(len(n) for n in problem.operation_types.values()) == 42
    result, lines = table_of(problem)
    check_columns(problem, result, lines)


@pytest.mark.parametrize('seed', range(8))
def test_table_columns_line_up_for_generated_scenarios(seed):
    import yaml

    from fjsp_planner.model.generator import random_scenario
    from fjsp_planner.model.scenario import scenario_from_text

    problem = scenario_from_text(yaml.safe_dump(random_scenario(seed)), name=f'gen-{seed}')
    result, lines = table_of(problem)
    check_columns(problem, result, lines)


# --- checking a file without solving -----------------------------------------------------

BEAM = (DATA / 'beam_drive.yaml').read_text()

FRAGMENT = FRAGMENTS / 'solar_panel_second_panel.yaml'


@pytest.mark.integration
def test_check_says_a_scenario_is_fine_and_solves_nothing():
    run = fjsp_solve('--check', PAPER)
    assert (run.returncode, run.stderr) == (0, '')
    assert run.stdout == f'{PAPER}: fine: 12 jobs, 4 robots, 12 locations\n'


@pytest.mark.integration
def test_check_names_every_problem(tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text(BEAM.replace('type: Crane, speed', 'type: Crain, speed')
                   .replace('start_location: dock, release', 'start_location: dok, release')
                   + 'locomote: drive\n')
    run = fjsp_solve('--check', bad)
    assert (run.returncode, run.stdout) == (2, '')
    assert run.stderr.splitlines()[1:] == [
        f"  - {bad}: robot 'C1': unknown robot type 'Crain'; did you mean 'Crane'?",
        f"  - {bad}: location 'dok' (start of robot 'W1') has no distance to any other "
        "location; did you mean 'dock'?",
        f"  - {bad}: job 'Join' cannot be staffed: plan 0 ['grip' (0), 'weld' (1)] needs 2 "
        "distinct robots able to do its operations; 1 can (not counting 'C1', of unknown "
        "type)"]


@pytest.mark.integration
def test_warnings_are_printed_and_the_plan_goes_on(tmp_path):
    """The travel type is called `drive` and nothing says so: travel is free, so said."""
    beam = tmp_path / 'beam.yaml'
    beam.write_text(BEAM)
    warning = ("fjsp-solve: warning: distances and the start locations of robots 'C1', 'W1' "
               'are given, but no operation type is the travel type')
    for args in (('--check',), ('--solver', 'greedy')):
        run = fjsp_solve(*args, beam)
        assert run.returncode == 0, run.stderr
        assert run.stderr.startswith(warning) and "did you mean 'locomote: drive'?" in run.stderr
    beam.write_text(BEAM + 'locomote: drive\n')
    assert fjsp_solve('--check', beam).stderr == ''


@pytest.mark.integration
def test_a_fragment_is_checked_against_its_scenario(tmp_path):
    run = fjsp_solve('--check', FRAGMENT, '--fragment-of', PAPER)
    assert (run.returncode, run.stderr) == (0, ''), run.stderr
    assert run.stdout == (f"{FRAGMENT}: fine: adds 12 jobs ('M1_p2', 'M2_p2', 'Ja_p2' and 9 "
                          f'more) to {PAPER}\n')
    bad = tmp_path / 'more.yaml'
    bad.write_text('jobs: [{name: Ja, location: far, plans: [[0]]}]\n'
                   'precedence: [[Ad, Xx]]\n')
    run = fjsp_solve('--check', bad, '--fragment-of', PAPER)
    assert (run.returncode, run.stdout) == (2, '')
    assert run.stderr.splitlines() == [
        'fjsp-solve: invalid fragment:',
        "  - job 'Ja' is defined 2 times",
        "  - location 'far' (job 'Ja') has no distance to any other location",
        "  - precedence arc ('Ad', 'Xx') names unknown job 'Xx'"]


@pytest.mark.integration
def test_fragment_of_goes_with_check():
    run = fjsp_solve(FRAGMENT, '--fragment-of', PAPER)
    assert run.returncode == 2 and '--fragment-of goes with --check' in run.stderr
