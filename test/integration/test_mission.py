"""A whole mission over real processes: planner + the paper's four robots, via `ros2 run`."""

import pytest
from harness import ROBOTS, SCENARIO, Launcher, Observer, executed_timeline, private_domain

from fjsp_msgs.msg import MissionStatus, TaskEvent
from fjsp_planner.core.scenario import load_scenario
from fjsp_planner.core.validate import validate

MAKESPAN_TOLERANCE = 0.01
"""Executed makespan may exceed the plan by 1 %: agents keep logical time, so the only slack
is the rounding-up of reported ends (1e-6 units per leg or operation)."""


@pytest.fixture(scope='module')
def mission(tmp_path_factory):
    """One mission shared by this module's tests (each check reads the same run)."""
    with private_domain() as domain:
        yield from _mission(domain, tmp_path_factory)


def _mission(domain, tmp_path_factory):
    launcher = Launcher(domain, tmp_path_factory.mktemp('mission'))
    observer = Observer(domain)
    try:
        launcher.start_planner()
        for robot, _ in ROBOTS:
            launcher.start_agent(robot)
        observer.wait_for(lambda o: o.complete(), 60, 'the mission to complete')
        # The last job-done event and the status saying complete may land in either order.
        observer.wait_for(lambda o: sum(e.kind == TaskEvent.KIND_JOB_DONE
                                        for e in o.events) >= 12, 5, 'every job-done event')
        # Each agent's event history reaches this observer when its writer is discovered.
        parts = {(r.robot, t.job) for r in observer.plans[-1].robots for t in r.tasks}
        observer.wait_for(lambda o: parts <= {(e.robot, e.job) for e in o.events
                                              if e.kind == TaskEvent.KIND_OPERATION_DONE},
                          10, "every robot's events")
        yield launcher, observer
    finally:
        launcher.stop()
        observer.close()


def test_every_job_is_done_exactly_once(mission):
    _, observer = mission
    done = [e.job for e in observer.events if e.kind == TaskEvent.KIND_JOB_DONE]
    problem = load_scenario(SCENARIO)
    assert sorted(done) == sorted(j.name for j in problem.jobs)
    status = observer.status
    assert (status.jobs_done, status.jobs_total, status.jobs_running) == (12, 12, 0)
    assert status.ignored_stale + status.ignored_duplicate + status.ignored_unknown == 0
    ids = [e.event_id for e in observer.events]
    assert len(ids) == len(set(ids))


def test_executed_timeline_respects_the_problem(mission):
    _, observer = mission
    problem = load_scenario(SCENARIO)
    executed = executed_timeline(problem, observer.plans, observer.events)
    assert validate(problem, executed) == []
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


def test_nodes_exit_cleanly_on_interrupt(mission):
    launcher, observer = mission
    assert observer.status.state == MissionStatus.STATE_COMPLETE
    codes = launcher.stop()
    assert codes == {name: 0 for name in codes}, codes
    for name in codes:
        assert 'Traceback' not in launcher.log(name), name
