"""fjsp-solve as a user runs it: exit codes, printed table, JSON shape, Gantt file."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO / 'config' / 'scenarios' / 'solar_panel.yaml'


def fjsp_solve(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(REPO / 'src' / 'fjsp_planner'))
    return subprocess.run([sys.executable, '-m', 'fjsp_planner.cli', *map(str, args)],
                          capture_output=True, text=True, env=env, cwd=cwd, timeout=120)


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


def test_greedy_solver_and_panels(tmp_path):
    out = tmp_path / 'plan.json'
    run = fjsp_solve(PAPER, '--solver', 'greedy', '--panels', 2, '--shift', 30, '--json', out)
    assert run.returncode == 0, run.stderr
    data = json.loads(out.read_text())
    assert data['status'] == 'feasible' and len(data['jobs']) == 24


@pytest.mark.parametrize('args, message', [
    (['missing.yaml'], 'no such file'),
    ([PAPER, '--panels', '0'], 'must be a positive integer'),
    ([PAPER, '--time-limit', 'soon'], 'not a number'),
    ([PAPER, '--solver', 'gurobi'], 'invalid choice'),
    ([PAPER, '--shift', '-1'], 'must not be negative'),
    ([PAPER, '--workers', '999999'], "must be at most 64, got '999999'"),
], ids=['missing file', 'zero panels', 'bad time limit', 'unknown solver', 'negative shift',
        'too many workers'])
def test_bad_arguments_exit_2_with_a_message(args, message):
    run = fjsp_solve(*args)
    assert run.returncode == 2
    assert message in run.stderr
    assert 'Traceback' not in run.stderr


def test_invalid_scenario_lists_every_problem(tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text(PAPER.read_text().replace('type: MARC, speed: 25', 'type: Rover, speed: 25')
                   .replace('- [Jd, Ad]', '- [Jd, Zz]'))
    run = fjsp_solve(bad)
    assert run.returncode == 2
    assert "unknown robot type 'Rover'" in run.stderr
    assert "unknown job 'Zz'" in run.stderr
    assert 'Traceback' not in run.stderr
