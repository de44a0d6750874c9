"""The local search in a process of its own: its schedule comes back valid, and a child
that fails leaves the first run's schedule and a note saying why, never an error."""

import subprocess
import sys
import time

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving import local_process
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.local_process import LocalSearchProcess, local_searches

# Each waits for a search of one to a few seconds in a child process.
pytestmark = pytest.mark.slow


def scenario():
    problem = parse_scenario(random_scenario(5, Shape(jobs=40, robots=6)))
    return problem, greedy_schedule(problem)


def fake_child(tmp_path, monkeypatch, body: str):
    """A child that reads the request and then runs `body` instead of the search."""
    script = tmp_path / 'child'
    script.write_text(f'#!{sys.executable}\nimport pickle, sys\n'
                      f'problem, start, deadline, seed = pickle.load(sys.stdin.buffer)\n{body}\n')
    script.chmod(0o755)
    monkeypatch.setattr(local_process.sys, 'executable', str(script))


def test_the_search_in_a_child_process_returns_a_valid_shorter_schedule():
    problem, greedy = scenario()
    found = LocalSearchProcess(problem, greedy, time.monotonic() + 2, seed=1).result()
    assert found is not None
    schedule, found_at = found
    assert validate(problem, schedule) == []
    assert schedule.makespan < greedy.makespan
    assert found_at <= time.monotonic()


def test_two_runs_give_the_better_schedule_and_no_note():
    problem, greedy = scenario()
    best, _, notes = local_searches(problem, greedy, time.monotonic() + 2.5, runs=2)
    assert notes == ()
    assert validate(problem, best) == []
    assert best.makespan < greedy.makespan


def test_a_child_that_fails_leaves_the_first_runs_schedule_and_its_message(
        tmp_path, monkeypatch):
    fake_child(tmp_path, monkeypatch, "sys.exit('out of memory, say')")
    problem, greedy = scenario()
    best, _, notes = local_searches(problem, greedy, time.monotonic() + 2.5, runs=2)
    assert validate(problem, best) == []
    assert len(notes) == 1
    assert 'exit code 1' in notes[0] and 'out of memory, say' in notes[0]


def test_an_invalid_schedule_from_the_child_is_refused(tmp_path, monkeypatch):
    """A job moved to start before time 0, ahead of everything it waits for."""
    fake_child(tmp_path, monkeypatch, (
        'import dataclasses\n'
        'name, job = next(iter(start.jobs.items()))\n'
        'early = dataclasses.replace(job, start=job.start - 1000, end=job.end - 1000)\n'
        'bad = dataclasses.replace(start, jobs={**start.jobs, name: early})\n'
        'sys.stdout.buffer.write(pickle.dumps((bad, 0.0)))'))
    problem, greedy = scenario()
    process = LocalSearchProcess(problem, greedy, time.monotonic() + 1, seed=1)
    assert process.result() is None
    assert process.failure == 'sent a schedule that is not valid'


def test_a_child_past_its_deadline_is_killed(tmp_path, monkeypatch):
    fake_child(tmp_path, monkeypatch, 'import time\ntime.sleep(60)')
    monkeypatch.setattr(local_process, 'GRACE', 0.5)
    problem, greedy = scenario()
    began = time.monotonic()
    process = LocalSearchProcess(problem, greedy, began + 0.5, seed=1)
    assert process.result() is None
    assert 'within 0.5 s' in process.failure
    assert time.monotonic() - began < 10


def test_a_child_stops_when_its_parent_ends():
    """A parent killed mid-search leaves no search running to its deadline."""
    parent = subprocess.run([sys.executable, '-c', (
        'import os, sys, time\n'
        f'sys.path[:0] = {sys.path!r}\n'
        'from fjsp_planner.model.generator import Shape, random_scenario\n'
        'from fjsp_planner.model.scenario import parse_scenario\n'
        'from fjsp_planner.solving.greedy import greedy_schedule\n'
        'from fjsp_planner.solving.local_process import LocalSearchProcess\n'
        'problem = parse_scenario(random_scenario(5, Shape(jobs=40, robots=6)))\n'
        'process = LocalSearchProcess(problem, greedy_schedule(problem),\n'
        '                             time.monotonic() + 120, seed=1)\n'
        'time.sleep(1)\n'
        'print(process._child.pid, flush=True)\n'
        'os._exit(0)\n')], capture_output=True, text=True, timeout=60, check=True)
    child = int(parent.stdout.split()[-1])
    waited = time.monotonic()
    while _running(child) and time.monotonic() - waited < 20:
        time.sleep(0.1)
    assert not _running(child)


def _running(pid: int) -> bool:
    """Whether the process runs (a zombie, ended but not yet reaped by init, does not)."""
    try:
        with open(f'/proc/{pid}/stat') as stat:
            return stat.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except FileNotFoundError:
        return False


def test_a_problem_that_cannot_be_sent_leaves_a_note(monkeypatch):
    def refuse(*args):
        raise TypeError('cannot pickle this')
    monkeypatch.setattr(local_process.pickle, 'dump', refuse)
    problem, greedy = scenario()
    best, _, notes = local_searches(problem, greedy, time.monotonic() + 2.5, runs=2)
    assert validate(problem, best) == []
    assert notes == ('the local search in a second process could not start: cannot pickle this',)
