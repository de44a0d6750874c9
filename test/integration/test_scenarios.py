"""Fleets that are not the paper's run to completion on the node network: the scenarios'
own robot types played by the generic agent, robots leaving from their start locations no
earlier than their release times, alternative plans, precedence and holding arcs, within one
place and across two (holders carry the part along their leg)."""


import pytest

from fjsp_msgs.msg import TaskEvent

from repo_paths import SCENARIOS

PAPER_TYPES = {'Assembler', 'MARC', 'LSMS'}


@pytest.mark.parametrize('scenario', ['truss.yaml', 'antenna.yaml', 'habitat.yaml',
                                      'yard.yaml'])
def test_scenario_runs_to_completion(fjsp_fleet, scenario):
    fleet = fjsp_fleet(SCENARIOS / scenario, time_scale=0.05, planner={'time_limit': 10.0})
    problem = fleet.problem
    assert not {r.type for r in problem.robots} & PAPER_TYPES
    fleet.start()
    executed = fleet.check_mission_complete(timeout=90)
    observer = fleet.observer
    # Each agent played the type the scenario gives its robot.
    assert {r: s.robot_type for r, s in observer.robots.items()} == {
        r.name: r.type for r in problem.robots}
    first_plan = observer.plans[0]
    assert observer.latest_revision() == 1, 'nothing went wrong, so nothing was re-planned'
    for robot_plan in first_plan.robots:
        robot = problem.robot(robot_plan.robot)
        if not robot_plan.tasks:
            continue
        first = robot_plan.tasks[0]
        # The first leg starts where the scenario puts the robot, once it is released.
        assert first.travel_start >= float(robot.release_time), robot.name
        assert first.arrival - first.travel_start == pytest.approx(
            float(problem.travel(robot.name, robot.start_location, first.location))), robot.name
        started = [e.time for e in observer.events
                   if e.robot == robot.name and e.kind == TaskEvent.KIND_STARTED]
        assert min(started) >= float(robot.release_time), robot.name
    # A holding arc's holders went straight on to the job they hold into.
    for held_from, held_to, q in problem.holding:
        holders = [r for r, op in executed.jobs[held_from].robots.items() if op == q]
        for robot in holders:
            sequence = executed.sequences[robot]
            assert sequence.index(held_to) == sequence.index(held_from) + 1, (robot, sequence)
    assert float(executed.makespan) == pytest.approx(first_plan.makespan, rel=0.01)
