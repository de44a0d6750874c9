"""The schedule charts stay readable however large the mission: `fjsp-solve --gantt`'s chart
and the monitor's whole-mission chart of generated 60- and 300-job scenarios are at most
MAX_PIXELS wide, no two job labels overlap, and the paper's chart still names every job."""

import struct

import pytest
import yaml

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import load_scenario, scenario_from_text
from fjsp_planner.observe.mission_chart import draw_mission
from fjsp_planner.observe.plan_chart import draw_gantt
from fjsp_planner.solving.greedy import quick_schedule
from fjsp_planner.solving.solve import solve

from repo_paths import PAPER

MAX_PIXELS = 3000


def png_size(path) -> tuple[int, int]:
    """(width, height) from the PNG's header."""
    data = path.read_bytes()
    assert data[:8] == b'\x89PNG\r\n\x1a\n'
    return struct.unpack('>II', data[16:24])


def generated(jobs: int):
    text = yaml.safe_dump(random_scenario(11, Shape(jobs=jobs, robots=8)))
    problem = scenario_from_text(text, name=f'generated-{jobs}')
    return problem, quick_schedule(problem)


def overlapping(labels) -> list:
    """Pairs of labels on one row whose extents meet."""
    by_row = {}
    for label in labels:
        by_row.setdefault(label.row, []).append(label)
    pairs = []
    for row in by_row.values():
        row.sort(key=lambda label: label.left)
        pairs += [(a, b) for a, b in zip(row, row[1:], strict=False) if b.left < a.right]
    return pairs


def test_the_paper_chart_names_every_job(tmp_path):
    problem = load_scenario(PAPER)
    schedule = solve(problem, time_limit=10).schedule
    drawn = draw_gantt(problem, schedule, tmp_path / 'paper.png')
    named = [label.text for label in drawn.labels]
    # One label per robot on each job: Aa is done by three robots.
    assert sorted(set(named)) == sorted(j.name for j in problem.jobs)
    assert len(named) == sum(len(a.robots) for a in schedule.jobs.values())
    assert not overlapping(drawn.labels)
    assert png_size(tmp_path / 'paper.png') == (drawn.width, drawn.height)


@pytest.mark.parametrize('jobs', [60, pytest.param(300, marks=pytest.mark.slow)])
def test_plan_charts_of_large_scenarios_stay_readable(tmp_path, jobs):
    problem, schedule = generated(jobs)
    drawn = draw_gantt(problem, schedule, tmp_path / 'plan.png')
    width, height = png_size(tmp_path / 'plan.png')
    assert width <= MAX_PIXELS, (width, float(schedule.makespan))
    assert height <= MAX_PIXELS
    assert not overlapping(drawn.labels)
    assert drawn.labels, 'a chart of this size still has room for some names'
    assert all(label.text in schedule.jobs or label.text.endswith('…') for label in drawn.labels)


def mission_timeline(problem, schedule) -> dict:
    """What `views.timeline` gives for a mission that ran `schedule` as planned, at its end."""
    tasks, work = [], []
    for robot in problem.robots:
        for visit in schedule.visits(problem, robot.name):
            a = schedule.jobs[visit.job]
            tasks.append({'robot': robot.name, 'job': visit.job,
                          'travel_start': float(visit.travel_start),
                          'arrival': float(visit.arrival), 'start': float(a.start),
                          'end': float(a.end), 'held': False, 'continued': False})
            work.append({'robot': robot.name, 'job': visit.job, 'attempt': 1,
                         'start': float(a.start), 'end': float(a.end), 'open': False,
                         'outcome': 'done', 'outcome_time': float(a.end), 'reason': ''})
    makespan = float(schedule.makespan)
    return {'robots': [r.name for r in problem.robots], 'now': makespan, 'end': makespan,
            'revisions': [{'number': 1, 'time': 0.0, 'reasons': [], 'makespan': makespan}],
            'plans': [{'revision': 1, 'makespan': makespan, 'tasks': tasks}],
            'work': work, 'activities': [], 'health': []}


@pytest.mark.parametrize('jobs', [60, pytest.param(300, marks=pytest.mark.slow)])
def test_mission_charts_of_large_missions_stay_readable(tmp_path, jobs):
    problem, schedule = generated(jobs)
    header = {'scenario': problem.name, 'mission_id': 'm-1', 'state': 'complete',
              'ended': True, 'agrees': True, 'status_jobs': [jobs, jobs], 'jobs_done': jobs,
              'jobs_total': jobs, 'revision': 1, 'first_makespan': float(schedule.makespan),
              'planned_makespan': float(schedule.makespan),
              'executed_makespan': float(schedule.makespan)}
    drawn = draw_mission(mission_timeline(problem, schedule), header, tmp_path / 'mission.png')
    width, height = png_size(tmp_path / 'mission.png')
    assert width <= MAX_PIXELS and height <= MAX_PIXELS
    assert (width, height) == (drawn.width, drawn.height)
    assert drawn.labels and not overlapping(drawn.labels)
