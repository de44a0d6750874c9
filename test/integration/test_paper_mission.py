"""A whole mission over real processes: the planner and the paper's four robots, each played
by its type-pinning executable (`assembler_agent`, `lsms_agent`, `marc_agent`)."""


import pytest

from fjsp_msgs.msg import MissionStatus, TaskEvent
from fjsp_planner.testing import FleetHarness

from repo_paths import PAPER

PAPER_AGENTS = {'Assembler': 'assembler_agent', 'LSMS': 'lsms_agent', 'MARC1': 'marc_agent',
                'MARC2': 'marc_agent'}
MAKESPAN_TOLERANCE = 0.01
"""Executed makespan may exceed the plan by 1 %: agents keep logical time, so the only slack
is the rounding-up of reported ends (1e-6 units per leg or operation)."""


@pytest.fixture(scope='module')
def mission(tmp_path_factory):
    """One mission shared by this module's tests (each check reads the same run)."""
    with FleetHarness(PAPER, out=tmp_path_factory.mktemp('mission')) as fleet:
        fleet.start_planner()
        for robot, executable in PAPER_AGENTS.items():
            fleet.start_agent(robot, executable)
        executed = fleet.check_mission_complete(timeout=60)
        yield fleet, executed


def test_every_job_is_done_exactly_once(mission):
    fleet, _ = mission
    observer = fleet.observer
    done = [e.job for e in observer.events if e.kind == TaskEvent.KIND_JOB_DONE]
    assert sorted(done) == sorted(j.name for j in fleet.problem.jobs)
    status = observer.status
    assert (status.jobs_done, status.jobs_total, status.jobs_running) == (12, 12, 0)
    assert status.ignored_stale + status.ignored_duplicate + status.ignored_unknown == 0
    ids = [e.event_id for e in observer.events]
    assert len(ids) == len(set(ids))


def test_executed_timeline_respects_the_problem(mission):
    fleet, executed = mission
    observer, problem = fleet.observer, fleet.problem
    plan = observer.plans[-1]
    # Every robot of a job starts it at the same schedule time, and as planned: one robot each.
    for job in executed.jobs:
        starts = {e.robot: e.time for e in observer.events
                  if e.kind == TaskEvent.KIND_STARTED and e.job == job}
        planned = {r.robot for r in plan.robots for t in r.tasks if t.job == job}
        assert set(starts) == planned, job
        assert len(set(starts.values())) == 1, (job, starts)
    for before, after in problem.precedence:
        assert executed.jobs[after].start >= executed.jobs[before].end, (before, after)
    for held_from, held_to, q in problem.holding:
        holders = {r for r, op in executed.jobs[held_from].robots.items() if op == q}
        assert holders, held_from
        for robot in holders:
            assert executed.jobs[held_to].robots.get(robot) == q, (robot, held_to)
            sequence = executed.sequences[robot]
            assert sequence.index(held_to) == sequence.index(held_from) + 1, (robot, sequence)
    assert float(executed.makespan) <= plan.makespan * (1 + MAKESPAN_TOLERANCE)
    assert float(executed.makespan) >= plan.makespan - 1e-9
    assert observer.status.projected_makespan == pytest.approx(float(executed.makespan),
                                                               abs=1e-6)
    # The pinned executables played the paper's types.
    assert {r: s.robot_type for r, s in observer.robots.items()} == {
        'Assembler': 'Assembler', 'LSMS': 'LSMS', 'MARC1': 'MARC', 'MARC2': 'MARC'}


def test_nodes_exit_cleanly_on_interrupt(mission):
    fleet, _ = mission
    assert fleet.observer.status.state == MissionStatus.STATE_COMPLETE
    codes = fleet.stop()
    assert codes == {name: 0 for name in codes}, codes
    assert set(codes) == {'planner', 'agent_Assembler', 'agent_LSMS', 'agent_MARC1',
                          'agent_MARC2'}
    for name in codes:
        assert 'Traceback' not in fleet.log(name), name
