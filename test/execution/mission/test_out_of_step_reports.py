"""Defects found by running fleets across real network links and by the soak test
(test/integration/test_network_links.py, test_soak.py), each reproduced here by hand through
the planner's ROS-free core.

Reports arrive out of step after a network partition: when a link comes back, each robot's
state arrives at once (it is republished every heartbeat) but each robot's task-event history
only when its writer resends it (Fast DDS: at the writer's next heartbeat, up to 3 s later),
one robot's before another's. In between, the planner knows that a job started but not that
its robots' previous job ended: the state it would re-plan from has a robot on two jobs at
once.
"""

import math

import pytest

from fjsp_common.vocabulary import EventKind, MissionState, RobotMode
from fjsp_planner.execution.journal import PlanRecord
from fjsp_planner.execution.mission.controller import MissionController
from fjsp_planner.execution.mission.effects import PublishPlan, Solve, SolveKind
from fjsp_planner.execution.mission.liveness import FLEET_SILENCE
from fjsp_planner.execution.mission.reports import EventReport, RobotReport
from fjsp_planner.execution.mission.settings import Settings
from fjsp_planner.execution.replan import replan
from fjsp_planner.execution.tracking import MissionTracker
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.solving.solve import solve

from repo_paths import SCENARIOS

SCENARIO = SCENARIOS / 'solar_panel.yaml'
ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')
FLEET_SILENT = FLEET_SILENCE * 1.0 + 0.5
"""Seconds of no robot heard at all after which every robot is offline (timeout 1 s)."""
SETTINGS = Settings(time_limit=5.0, replan_time_limit=2.0, heartbeat_timeout=1.0,
                    robot_wait_timeout=3.0, start_delay=0.0, time_scale=1.0)


class Planner:
    """The controller, a wall clock (= schedule units here) and the node's way of solving."""

    def __init__(self):
        self.controller = MissionController(SETTINGS)
        self.wall = 1000.0
        self.modes = dict.fromkeys(ROBOTS, RobotMode.IDLE)
        self.failures = dict.fromkeys(ROBOTS, 0)
        self.count = 0
        self.published = []
        self.solves = []

    def carry_out(self, effects):
        for effect in effects:
            if isinstance(effect, Solve):
                self.solves.append(effect)
            elif isinstance(effect, PublishPlan):
                self.published.append(effect)

    def tick(self, seconds=0.1, heard=ROBOTS):
        for _ in range(max(1, round(seconds / 0.1))):
            self.wall += 0.1
            for robot in heard:
                self.carry_out(self.controller.robot_state(RobotReport(
                    robot, self.modes[robot], incarnation=1, failures=self.failures[robot],
                    mission_id='m1', revision=self.following), self.wall))
            self.carry_out(self.controller.tick(self.wall))

    def solve_pending(self):
        """Run the solves asked for, as the node does: a ValueError is the outcome."""
        pending, self.solves = self.solves, []
        for request in pending:
            try:
                if request.kind == SolveKind.PLAN:
                    outcome = solve(request.problem, time_limit=request.time_limit)
                else:
                    outcome = replan(request.problem, request.previous, request.state,
                                     time_limit=request.time_limit)
            except ValueError as error:
                outcome = error
            self.carry_out(self.controller.solved(request.token, outcome, self.wall))

    def event(self, kind, robot, job, time, revision=1):
        self.count += 1
        effects, _ = self.controller.task_event(
            EventReport(f'{robot}/{self.count}', 'm1', kind, robot, job, revision, time),
            self.wall)
        self.carry_out(effects)

    @property
    def following(self) -> int:
        """The revision every robot follows: the latest published."""
        return self.published[-1].revision if self.published else 0

    @property
    def mission(self):
        return self.controller.mission


@pytest.fixture
def planner():
    planner = Planner()
    planner.carry_out(planner.controller.start(load_scenario(SCENARIO), 'm1', planner.wall))
    planner.tick()
    planner.solve_pending()
    assert [p.revision for p in planner.published] == [1]
    return planner


def test_a_replan_on_a_half_arrived_history_is_retried_once_it_has_arrived(planner):
    plan, problem = planner.mission.schedule, planner.mission.problem
    # Ja holds into Aa: Ja's two robots go straight on to Aa, where a third joins them.
    crew, newcomer = plan.jobs['Ja'].robots, next(
        r for r in plan.jobs['Aa'].robots if r not in plan.jobs['Ja'].robots)
    start, held_start = float(plan.jobs['Ja'].start), float(plan.jobs['Aa'].start)
    for robot in crew:
        planner.event(EventKind.STARTED, robot, 'Ja', start)
    # The link is cut. On the other side Ja is finished, Aa begun, and a robot of Ja fails.
    planner.tick(FLEET_SILENT, heard=())
    planner.solve_pending()
    assert planner.mission.state == MissionState.BLOCKED  # nobody left to do anything
    failing = next(iter(crew))
    planner.modes[failing], planner.failures[failing] = RobotMode.FAILED, 1
    # The link is back: states at once, the newcomer's history first, then a re-plan.
    planner.tick(0.5)
    planner.event(EventKind.STARTED, newcomer, 'Aa', held_start)
    planner.tick(0.8)
    assert planner.solves, 'no re-plan once the robots were back'
    planner.solve_pending()
    # The histories of Ja's robots arrive: Ja ended, they began Aa, one failed on it.
    for robot, operation in crew.items():
        end = start + float(problem.duration(robot, operation))
        planner.event(EventKind.OPERATION_DONE, robot, 'Ja', end)
    assert 'Ja' in planner.mission.tracker.done
    for robot in crew:
        planner.event(EventKind.STARTED, robot, 'Aa', held_start)
    planner.event(EventKind.ABORTED, failing, 'Aa', held_start + 1)
    for _ in range(20):
        planner.tick()
        planner.solve_pending()
    # Re-planned from the whole history: Aa redone without the failed robot.
    assert planner.mission.state == MissionState.EXECUTING, planner.mission.blocked
    latest = planner.published[-1]
    assert latest.revision > 1
    assert failing not in latest.result.schedule.jobs['Aa'].robots


def test_a_robot_not_yet_departed_is_replanned_from_its_start_and_release_time():
    """The truss's D2 starts at the depot, released at 3. Its agent reports no location
    until it first moves (it is placed by its first leg), and is idle meanwhile: a re-plan
    at t=1 must still start it at the depot no earlier than 3, not anywhere at once."""
    problem = load_scenario(SCENARIOS / 'truss.yaml')
    tracker = MissionTracker(problem)
    tracker.set_plan(solve(problem, time_limit=5).schedule, 1)
    for robot in problem.robots:
        tracker.record_robot_state(robot.name, RobotMode.IDLE, '', '', math.nan, at=1.0)
    d2 = tracker.execution_state(1.0).robots['D2']
    assert (d2.location, d2.free_at) == ('depot', 3)


def test_a_mission_completed_while_blocked_no_longer_says_it_is_blocked(planner):
    """The planner cut off from every robot blocks the mission (nobody to staff anything);
    the robots, unaware, finish the plan they have, and their reports complete it. Its
    status said COMPLETE with the reasons of the old block (soak and network tests)."""
    planner.tick(FLEET_SILENT, heard=())
    planner.solve_pending()
    assert planner.mission.state == MissionState.BLOCKED
    plan, problem = planner.mission.schedule, planner.mission.problem
    for name, a in sorted(plan.jobs.items(), key=lambda kv: kv[1].start):
        for robot in a.robots:
            planner.event(EventKind.STARTED, robot, name, float(a.start))
        for robot, operation in a.robots.items():
            end = a.start + problem.duration(robot, operation)
            planner.event(EventKind.OPERATION_DONE, robot, name, float(end))
    status = planner.controller.status(planner.wall)
    assert status.state == MissionState.COMPLETE
    assert status.blocked == ()


def test_a_resumed_mission_is_judged_from_where_its_robots_started():
    """A mission after another one starts each robot where the last left it, and is judged
    from there. A planner restarted mid-mission rebuilt the mission from its journal with
    the scenario's start locations instead: the truss's gantry, which began at bay1, was
    'first at the depot', 16 units of travel from its first job, and the mission FAILED on
    a violation that never happened (soak: every truss mission whose planner was killed)."""
    problem = load_scenario(SCENARIOS / 'truss.yaml')
    here = {r.name: 'bay1' for r in problem.robots}
    first = MissionController(SETTINGS)
    wall = 1000.0
    first.start(problem, 'm2', wall)
    for name, place in here.items():
        first.robot_state(RobotReport(name, RobotMode.IDLE, incarnation=1, location=place),
                          wall)
    (request,) = [e for e in first.tick(wall + 0.1) if isinstance(e, Solve)]
    assert {r.start_location for r in request.problem.robots} == {'bay1'}
    outcome = solve(request.problem, time_limit=5)
    (published,) = [e for e in first.solved(request.token, outcome, wall + 0.2)
                    if isinstance(e, PublishPlan)]
    schedule = published.result.schedule
    # The planner is killed; a new one resumes the mission from its journal.
    resumed = MissionController(SETTINGS)
    resumed.resume('m2', problem, SETTINGS, wall,
                   [PlanRecord(1, published.mission_start, schedule, frozenset(), (),
                               published.starts)],
                   wall + 1)
    # It judges the mission's execution against the problem it started from.
    starts = {r.name: r.start_location for r in resumed.mission.problem.robots}
    assert starts == here


def test_a_job_completed_before_its_robot_failed_is_not_done_again(planner):
    """Seen on a generated scenario (FJSP_SEED=11, seed 11402): a robot finished its operation
    of a two-robot job, then failed. Its FAILED state reached the planner before its
    operation-done event (robot states and task events travel on different topics), so the
    re-plan was posed with the job running on a failed robot: aborted, to be redone. The job's
    completion arrived while it was solved, and the new revision had the job done again."""
    plan, problem = planner.mission.schedule, planner.mission.problem
    held = {a for a, _, _ in problem.holding}
    job = min((name for name, a in plan.jobs.items()
               if len(a.robots) > 1 and name not in held), key=lambda n: plan.jobs[n].start)
    before = sorted((n for n, a in plan.jobs.items() if a.end <= plan.jobs[job].start),
                    key=lambda n: plan.jobs[n].start)
    end = float(plan.jobs[job].end)
    planner.tick(end + 0.5)  # wall = schedule time here: past the job's end
    for name in before + [job]:
        for robot in plan.jobs[name].robots:
            planner.event(EventKind.STARTED, robot, name, float(plan.jobs[name].start))
    for name in before:
        for robot, operation in plan.jobs[name].robots.items():
            done = plan.jobs[name].start + problem.duration(robot, operation)
            planner.event(EventKind.OPERATION_DONE, robot, name, float(done))
    failing = next(iter(plan.jobs[job].robots))
    planner.modes[failing], planner.failures[failing] = RobotMode.FAILED, 1
    planner.tick()
    assert planner.solves, 'no re-plan for the failure'
    # The job's operation-done events arrive while the re-plan is solved.
    for robot, operation in plan.jobs[job].robots.items():
        done = plan.jobs[job].start + problem.duration(robot, operation)
        planner.event(EventKind.OPERATION_DONE, robot, job, float(done))
    assert job in planner.mission.tracker.done
    for _ in range(20):
        planner.solve_pending()
        planner.tick()
    latest = planner.published[-1]
    assert latest.revision > 1, (planner.mission.state, planner.mission.blocked, job, failing)
    assert job not in latest.result.schedule.jobs, f"job '{job}' is planned again"
