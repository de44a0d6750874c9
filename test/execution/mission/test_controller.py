"""The mission controller's decisions, driven by hand-made reports and a fake clock (no ROS).

The paper's instance: its optimum (32) is found in well under a second, so every solve the
controller asks for is run here for real, through the same functions the node calls. The
moves of mission state they make are recorded: together they are every move the state table
(`states.TRANSITIONS`) allows, which the last test checks.
"""

import re
from dataclasses import replace
from fractions import Fraction

import pytest

from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.execution.mission import controller
from fjsp_planner.execution.mission.continuation import DUE_GRACE
from fjsp_planner.execution.mission.controller import IMPROVE_REACH, MissionController
from fjsp_planner.execution.mission.effects import (
    JobDone,
    LeftQueue,
    Note,
    PublishPlan,
    ResendPlan,
    Solve,
    SolveKind,
)
from fjsp_planner.execution.mission.liveness import PLAN_RESEND_AFTER
from fjsp_planner.execution.mission.reports import EventReport, RobotReport
from fjsp_planner.execution.mission.settings import Settings
from fjsp_planner.execution.mission.states import TRANSITIONS, check_transition
from fjsp_planner.execution.replan import Improvement, Replan, improve, repair
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import Schedule
from fjsp_planner.solving.solve import solve

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')
SETTINGS = Settings(time_limit=5.0, replan_time_limit=2.0, heartbeat_timeout=1.0,
                    robot_wait_timeout=3.0, start_delay=0.0, time_scale=1.0)


MOVES: set[tuple[MissionState, MissionState]] = set()
"""Every move of a mission's state that this file's tests made (current, new)."""
RAN: set[str] = set()
"""The tests of this file that ran in this process."""


@pytest.fixture(autouse=True)
def record_moves(request, monkeypatch):
    def recording(current, new):
        MOVES.add((current, new))
        return check_transition(current, new)

    monkeypatch.setattr(controller, 'check_transition', recording)
    yield
    RAN.add(request.node.nodeid)


@pytest.fixture(scope='module')
def problem():
    return load_scenario(PAPER)


class Fleet:
    """A controller, a clock in wall seconds (= schedule units here) and the effects so far."""

    def __init__(self, problem, settings=SETTINGS):
        self.problem = problem
        self.controller = MissionController(settings)
        self.wall = 1000.0
        self.refused = 0
        self.effects = []
        self.failures = dict.fromkeys(ROBOTS, 0)
        self.incarnations = dict.fromkeys(ROBOTS, 1)
        self.modes = dict.fromkeys(ROBOTS, RobotMode.IDLE)
        self.refusals = dict.fromkeys(ROBOTS, '')
        self.following = {}
        """Fields every report of the robots repeats, e.g. the mission they follow."""
        self.deaf = set()
        """Robots whose agents take no plan any more: they report the last one they took."""
        self.taken = {}
        """Robot -> (mission, revision) of the latest plan its agent took."""
        self.events = 0

    def take(self, effects):
        self.effects += effects
        return effects

    def start(self, mission='m1'):
        return self.take(self.controller.start(self.problem, mission, self.wall))

    def report(self, robot, mode=None, **fields):
        if mode is not None:
            self.modes[robot] = mode
        mission = self.controller.mission
        if robot not in self.deaf and mission is not None and mission.tracker.revision:
            self.taken[robot] = (mission.id, mission.tracker.revision)
        mission_id, revision = self.taken.get(robot, ('', 0))
        report = RobotReport(robot, self.modes[robot], incarnation=self.incarnations[robot],
                             failures=self.failures[robot], refusal=self.refusals[robot],
                             **{'mission_id': mission_id, 'revision': revision,
                                **self.following, **fields})
        return self.take(self.controller.robot_state(report, self.wall))

    def heartbeat(self, robots=ROBOTS):
        for robot in robots:
            self.report(robot)

    def tick(self, advance=0.1, robots=ROBOTS, refused_per_second=0):
        """Advance the clock in heartbeat-sized steps, robots in `robots` reporting and the
        node refusing `refused_per_second` unauthenticated messages meanwhile."""
        effects = []
        steps = max(1, round(advance / 0.1))
        for _ in range(steps):
            self.wall += advance / steps
            self.refused += round(refused_per_second * advance / steps)
            self.heartbeat(robots)
            effects += self.take(self.controller.tick(self.wall, refused=self.refused))
        return effects

    def tick_until_solve(self, ticks=20):
        """Tick until the controller asks for one solve (at most `ticks` times); that request."""
        for _ in range(ticks):
            requests = kinds(self.tick(), Solve)
            if requests:
                (request,) = requests
                return request
        raise AssertionError(f'no solve requested within {ticks} ticks')

    def run_solves(self, effects=None, improve_too=False):
        """Carry out the pending solves as the node would (a search for a better plan only
        with `improve_too`); the effects of their outcomes."""
        out = []
        for effect in list(self.effects if effects is None else effects):
            if not isinstance(effect, Solve) or (effect.kind == SolveKind.IMPROVE
                                                 and not improve_too):
                continue
            if effect.kind == SolveKind.PLAN:
                outcome = solve(effect.problem, time_limit=effect.time_limit)
            elif effect.kind == SolveKind.REPAIR:
                outcome = repair(effect.problem, effect.previous, effect.state,
                                 time_limit=effect.time_limit)
            else:
                outcome = improve(effect.published, time_limit=effect.time_limit,
                                  frozen_until=effect.frozen_until, started=effect.started)
            out += self.take(self.controller.solved(effect.token, outcome, self.wall))
        return out

    def event(self, kind, robot, job, time, mission='m1', revision=None):
        self.events += 1
        revision = self.controller.mission.tracker.revision if revision is None else revision
        effects, why = self.controller.task_event(
            EventReport(f'{robot}/{self.events}', mission, kind, robot, job, revision, time),
            self.wall)
        self.take(effects)
        return effects, why

    def execute(self, until=None, without=''):
        """Report the current plan's jobs as executed to plan (those starting before
        `until`, and not involving robot `without`), in start order."""
        plan = self.controller.mission.schedule
        tracker = self.controller.mission.tracker
        for name, a in sorted(plan.jobs.items(), key=lambda kv: kv[1].start):
            if until is not None and a.start >= until:
                break
            if tracker.jobs[name].end is not None or without in a.robots:
                continue
            for robot in a.robots:
                if robot not in tracker.jobs[name].started:
                    self.event(EventKind.STARTED, robot, name, float(a.start))
            for robot, q in a.robots.items():
                end = a.start + self.problem.duration(robot, q)
                if until is None or end <= until:
                    self.event(EventKind.OPERATION_DONE, robot, name, float(end))

    def state(self):
        return self.controller.mission.state

    def status(self):
        return self.controller.status(self.wall)


def kinds(effects, kind):
    return [e for e in effects if isinstance(e, kind)]


def notes(effects, kind):
    return [e for e in effects if isinstance(e, Note) and e.kind == kind]


def executing(problem, settings=SETTINGS) -> Fleet:
    """A fleet whose four robots reported, with revision 1 published."""
    fleet = Fleet(problem, settings)
    fleet.start()
    fleet.heartbeat()
    fleet.tick()
    fleet.run_solves()
    assert fleet.state() == MissionState.EXECUTING
    return fleet


def test_first_plan_waits_for_every_robot_then_solves_the_scenario(problem):
    fleet = Fleet(problem)
    effects = fleet.start()
    assert notes(effects, MissionEventKind.MISSION_STARTED)
    assert fleet.state() == MissionState.WAITING_FOR_ROBOTS
    assert fleet.status().blocked == ("waiting for robot 'Assembler' to report",
                                      "waiting for robot 'LSMS' to report",
                                      "waiting for robot 'MARC1' to report",
                                      "waiting for robot 'MARC2' to report")
    fleet.heartbeat(ROBOTS[:3])
    assert not kinds(fleet.tick(robots=ROBOTS[:3]), Solve)
    fleet.heartbeat()
    (request,) = kinds(fleet.tick(), Solve)
    assert request.kind == SolveKind.PLAN and request.problem is problem  # nothing moved: as given
    assert fleet.state() == MissionState.PLANNING
    (published,) = kinds(fleet.run_solves(), PublishPlan)
    assert published.revision == 1 and published.result.makespan == 32
    assert fleet.state() == MissionState.EXECUTING


def test_a_robot_that_never_reports_is_planned_without_and_named(problem):
    fleet = Fleet(problem)
    fleet.start()
    fleet.tick(advance=3.5, robots=ROBOTS[:3])
    (request,) = kinds(fleet.effects, Solve)
    assert {r.name for r in request.problem.robots} == {'Assembler', 'LSMS', 'MARC1'}
    fleet.run_solves()
    assert fleet.state() == MissionState.EXECUTING
    assert any("robot 'MARC2' has not reported" in w for w in fleet.status().warnings)
    fleet.report('MARC2')
    replans = kinds(fleet.tick(), Solve)
    assert replans and "robot 'MARC2' available" in replans[0].reasons


def test_a_changed_robot_wait_applies_to_the_mission_waiting(problem):
    """`robot_wait_timeout` may be set at run time (`ros2 param set`) as
    `plan_uptake_timeout` and `heartbeat_timeout` may: a user lengthening it while a mission
    waits for a robot expects that mission to wait longer, not only the next one."""
    fleet = Fleet(problem)
    fleet.start()
    fleet.controller.settings = replace(SETTINGS, robot_wait_timeout=10.0)
    fleet.tick(advance=5.0, robots=ROBOTS[:3])
    assert not kinds(fleet.effects, Solve)
    fleet.tick(advance=5.5, robots=ROBOTS[:3])
    (request,) = kinds(fleet.effects, Solve)
    assert {r.name for r in request.problem.robots} == {'Assembler', 'LSMS', 'MARC1'}


def test_failure_replans_without_the_robot(problem):
    fleet = executing(problem)
    fleet.wall += 5
    fleet.execute(until=5)
    fleet.failures['MARC1'] += 1
    effects = fleet.report('MARC1', RobotMode.FAILED)
    assert notes(effects, MissionEventKind.ROBOT_FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    assert request.kind == SolveKind.REPAIR and "robot 'MARC1' failed" in request.reasons
    assert not request.state.robots['MARC1'].healthy
    (published,) = kinds(fleet.run_solves(), PublishPlan)
    assert published.revision == 2 and 'MARC1' not in published.result.schedule.sequences


def test_a_projected_makespan_drifting_past_the_threshold_replans(problem):
    """No robot reports starting anything: the plan slips with the clock. With a drift
    threshold of 10 %, the rest is re-planned once the projection passes 32 * 1.1 = 35.2,
    and not before; without one (the default), never."""
    fleet = executing(problem, replace(SETTINGS, drift_threshold=0.1))
    assert not kinds(fleet.tick(advance=2.0), Solve)
    requests = kinds(fleet.tick(advance=3.0), Solve)
    assert len(requests) == 1 and requests[0].kind == SolveKind.REPAIR
    (reason,) = requests[0].reasons
    assert reason.startswith('projected makespan 35.') and "past the plan's 32.00" in reason
    steady = executing(problem)
    assert not kinds(steady.tick(advance=5.0), Solve)


def test_failure_and_recovery_between_two_ticks_still_replans(problem):
    """The recovered agent dropped its tasks: it must be planned in again, though it looks
    as healthy as before."""
    fleet = executing(problem)
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    fleet.report('MARC1', RobotMode.IDLE)
    (request,) = kinds(fleet.tick(), Solve)
    assert "robot 'MARC1' failed and recovered" in request.reasons


def test_a_restarted_agent_is_replanned(problem):
    fleet = executing(problem)
    fleet.incarnations['LSMS'] = 2
    (request,) = kinds(fleet.tick(), Solve)
    assert "robot 'LSMS' restarted: its agent lost its tasks" in request.reasons


def test_a_refusing_agent_is_left_out_and_named(problem):
    fleet = executing(problem)
    fleet.refusals['MARC2'] = "plan revision 1 makes 'MARC2' a 'MARC' but this agent plays a " \
                              "'Gantry'; refusing the plan"
    effects = fleet.report('MARC2')
    (warning,) = notes(effects, MissionEventKind.WARNING)
    assert 'MARC2' in warning.reasons[0] and 'refuses its plan' in warning.reasons[0]
    (request,) = kinds(fleet.tick(), Solve)
    assert not request.state.robots['MARC2'].healthy
    fleet.run_solves()
    assert fleet.state() == MissionState.EXECUTING
    assert any('refuses its plan' in w for w in fleet.status().warnings)


def test_a_robot_that_does_not_take_the_plan_gets_it_again_then_is_planned_without(problem):
    """An agent that reports but stays on an older revision (its subscription never matched
    the plan's writer) would leave its jobs undone while it looks healthy."""
    fleet = Fleet(problem, replace(SETTINGS, plan_uptake_timeout=5.0))
    fleet.deaf.add('MARC2')
    fleet.start()
    fleet.tick()
    fleet.run_solves()
    assert fleet.state() == MissionState.EXECUTING
    assert not kinds(fleet.tick(advance=PLAN_RESEND_AFTER - 0.3), ResendPlan)
    effects = fleet.tick(advance=0.5)
    assert kinds(effects, ResendPlan) == [ResendPlan(1)]
    (warning,) = notes(effects, MissionEventKind.WARNING)
    assert warning.robot == 'MARC2' and 'has not taken plan revision 1' in warning.reasons[0]
    assert not kinds(fleet.tick(advance=1.0), ResendPlan)
    # Again every PLAN_RESEND_AFTER: a flood may push each copy out of the robot's reader.
    effects = fleet.tick(advance=1.1)
    assert kinds(effects, ResendPlan) == [ResendPlan(1)]
    assert not notes(effects, MissionEventKind.WARNING)
    assert not kinds(fleet.effects, Solve)[1:]
    (request,) = kinds(fleet.tick(advance=5.0 - PLAN_RESEND_AFTER - 2.1 + 0.2), Solve)
    assert "robot 'MARC2' has not taken plan revision 1 within 5 s" in request.reasons
    assert not request.state.robots['MARC2'].healthy
    (published,) = kinds(fleet.run_solves(), PublishPlan)
    assert 'MARC2' not in published.result.schedule.sequences
    # Left out until it takes a revision, however long that takes: no re-plan meanwhile.
    assert not kinds(fleet.tick(advance=12.0), Solve)
    assert any("'MARC2' has not taken plan revision 1" in w for w in fleet.status().warnings)
    fleet.deaf.discard('MARC2')
    (request,) = kinds(fleet.tick(), Solve)
    assert "robot 'MARC2' available" in request.reasons


def test_a_robot_back_from_an_offline_spell_has_time_to_take_the_plan(problem):
    """Offline, it could not take the revision published meanwhile: its lag counts from
    when it is heard again."""
    fleet = executing(problem)
    fleet.deaf.add('MARC2')
    fleet.tick(advance=1.5, robots=ROBOTS[:3])
    assert "robot 'MARC2' offline (heartbeat lost)" in kinds(fleet.effects, Solve)[-1].reasons
    (published,) = kinds(fleet.run_solves(), PublishPlan)
    fleet.tick(advance=PLAN_RESEND_AFTER + 1.0, robots=ROBOTS[:3])
    effects = fleet.tick(advance=PLAN_RESEND_AFTER - 0.5)  # back, on revision 1 at first
    assert not kinds(effects, ResendPlan) and not notes(effects, MissionEventKind.WARNING)
    fleet.deaf.discard('MARC2')
    fleet.tick(advance=2.0)
    assert not kinds(fleet.effects, ResendPlan)


def test_robots_that_take_every_plan_are_never_told_again(problem):
    fleet = executing(problem, replace(SETTINGS, plan_uptake_timeout=3.0))
    fleet.tick(advance=20.0)
    assert not kinds(fleet.effects, ResendPlan)
    assert not notes(fleet.effects, MissionEventKind.WARNING)
    assert len(kinds(fleet.effects, Solve)) == 1


def test_when_every_robot_refuses_the_mission_is_blocked_naming_them(problem):
    fleet = Fleet(problem)
    fleet.start()
    for robot in ROBOTS:
        fleet.refusals[robot] = f"plan revision 1 makes '{robot}' a 'X' but this agent plays " \
                                "a 'Gantry'"
    fleet.tick(advance=0.2)
    assert fleet.state() == MissionState.BLOCKED
    blocked = '\n'.join(fleet.status().blocked)
    assert "job 'M1' cannot be staffed" in blocked
    assert "robot 'MARC1' refuses its plan" in blocked


def test_unknown_agent_is_a_warning(problem):
    fleet = executing(problem)
    effects = fleet.take(fleet.controller.robot_state(RobotReport('R2D2', RobotMode.IDLE),
                                                      fleet.wall))
    (warning,) = notes(effects, MissionEventKind.WARNING)
    assert "'R2D2'" in warning.reasons[0]
    assert any("agent of robot 'R2D2' is running" in w for w in fleet.status().warnings)
    # Its heartbeats are one warning, not one per heartbeat.
    assert not fleet.controller.robot_state(RobotReport('R2D2', RobotMode.IDLE), fleet.wall)


def test_heartbeat_loss_then_back_after_a_full_timeout(problem):
    fleet = executing(problem)
    effects = fleet.tick(advance=1.5, robots=('Assembler', 'LSMS', 'MARC1'))
    assert notes(effects, MissionEventKind.ROBOT_OFFLINE)[0].robot == 'MARC2'
    (request,) = kinds(effects, Solve)
    assert "robot 'MARC2' offline (heartbeat lost)" in request.reasons
    fleet.run_solves()
    # One heartbeat is not enough to count again: it must keep reporting for a timeout.
    assert not kinds(fleet.tick(), Solve)
    assert not notes(fleet.tick(advance=0.5), MissionEventKind.ROBOT_BACK)
    effects = fleet.tick(advance=0.7)
    assert notes(effects, MissionEventKind.ROBOT_BACK)
    assert "robot 'MARC2' available" in kinds(effects, Solve)[0].reasons


def test_a_starved_executor_does_not_make_robots_offline(problem):
    fleet = executing(problem)
    fleet.wall += 2.0  # nothing processed for 2 s, then a tick comes first
    assert not notes(fleet.take(fleet.controller.tick(fleet.wall)),
                     MissionEventKind.ROBOT_OFFLINE)


def test_robots_heard_late_all_together_are_not_offline(problem):
    """Every robot's states stop arriving for 1.5 s while the planner ticks (a flood it reads
    behind, a core it waits for), then all come at once: the planner fell behind, no robot
    failed, and nothing is re-planned."""
    fleet = executing(problem)
    effects = fleet.tick(advance=1.5, robots=())
    effects += fleet.tick()
    assert not notes(effects, MissionEventKind.ROBOT_OFFLINE)
    assert not kinds(effects, Solve)


def test_a_robot_silent_while_the_others_are_heard_is_offline_after_the_timeout(problem):
    fleet = executing(problem)
    assert not notes(fleet.tick(advance=0.9, robots=ROBOTS[1:]), MissionEventKind.ROBOT_OFFLINE)
    effects = fleet.tick(advance=0.3, robots=ROBOTS[1:])
    assert [n.robot for n in notes(effects, MissionEventKind.ROBOT_OFFLINE)] == [ROBOTS[0]]


def test_under_a_flood_a_robot_is_offline_only_after_five_timeouts(problem):
    """A flood of unsigned messages makes the node's subscriptions drop what it cannot read,
    a robot's states among them: a robot unheard for a few timeouts then is no evidence."""
    fleet = executing(problem)
    flood = {'robots': ROBOTS[1:], 'refused_per_second': 8000}
    assert not notes(fleet.tick(advance=4.8, **flood), MissionEventKind.ROBOT_OFFLINE)
    (offline,) = notes(fleet.tick(advance=0.4, **flood), MissionEventKind.ROBOT_OFFLINE)
    assert offline.robot == ROBOTS[0]
    assert 'under a flood of 8,000 unauthenticated messages a second' in offline.reasons[0]


def test_a_flood_an_agent_reports_makes_the_planner_judge_slower_too(problem):
    """Forged plans flood the agents, not the planner: their states come late, and say so."""
    fleet = executing(problem)
    effects = []
    for step in range(1, 49):
        fleet.wall += 0.1
        for robot in ROBOTS[1:]:
            fleet.report(robot, refused=800 * step)
        effects += fleet.take(fleet.controller.tick(fleet.wall, refused=0))
    assert not notes(effects, MissionEventKind.ROBOT_OFFLINE)


def test_a_few_refused_messages_are_no_flood(problem):
    """An agent without the key sends a few states a second: no reason to judge slower."""
    fleet = executing(problem)
    effects = fleet.tick(advance=1.2, robots=ROBOTS[1:], refused_per_second=20)
    assert [n.robot for n in notes(effects, MissionEventKind.ROBOT_OFFLINE)] == [ROBOTS[0]]


def test_a_fleet_that_falls_silent_together_is_offline_after_three_timeouts(problem):
    """No robot heard at all: the planner cannot tell its own stall from the fleet's loss (a
    cut link), and waits longer before it plans without every robot. The robots, unaware,
    finish the plan they have: their reports complete the mission."""
    fleet = executing(problem)
    assert not notes(fleet.tick(advance=2.9, robots=()), MissionEventKind.ROBOT_OFFLINE)
    effects = fleet.tick(advance=0.3, robots=())
    assert sorted(n.robot for n in notes(effects, MissionEventKind.ROBOT_OFFLINE)) \
        == sorted(ROBOTS)
    fleet.run_solves()
    assert fleet.state() == MissionState.BLOCKED
    fleet.execute()
    assert fleet.state() == MissionState.COMPLETE


def test_a_fleet_heard_again_after_falling_silent_is_planned_back_in(problem):
    fleet = executing(problem)
    fleet.tick(advance=3.2, robots=())
    fleet.run_solves()
    assert fleet.state() == MissionState.BLOCKED
    fleet.tick(advance=1.2)
    fleet.run_solves()
    assert fleet.state() == MissionState.EXECUTING, fleet.status().blocked
    assert fleet.controller.mission.tracker.revision == 2


def test_executed_mission_completes(problem):
    fleet = executing(problem)
    fleet.execute()
    assert len(kinds(fleet.effects, JobDone)) == 12
    assert fleet.state() == MissionState.COMPLETE
    (complete,) = notes(fleet.effects, MissionEventKind.MISSION_COMPLETE)
    assert complete.reasons == ('executed makespan 32, planned 32',)


@pytest.mark.parametrize(('start', 'end', 'written'), [(0.0, 1.0, ('0', '1')),
                                                     (0.1, 1.1, ('0.100', '1.100'))])
def test_an_invalid_executed_timeline_fails_the_mission(problem, start, end, written):
    """Jobs reported done in an order that breaks precedence: not a success. The reason reads
    in decimals: agents report float times, exact as Fractions such as 0.1 =
    3602879701896397/36028797018963968."""
    fleet = executing(problem)
    plan = fleet.controller.mission.schedule
    for name, a in plan.jobs.items():
        for robot in a.robots:
            fleet.event(EventKind.STARTED, robot, name, start)
            fleet.event(EventKind.OPERATION_DONE, robot, name, end)
    reasons = fleet.status().blocked
    assert fleet.state() == MissionState.FAILED
    assert any(r.startswith('executed timeline: ') and f'starts at {written[0]} before' in r
               and f'completes at {written[1]}' in r for r in reasons), reasons
    assert not [r for r in reasons if re.search(r'\d/\d', r)], reasons


def test_events_of_another_mission_are_counted_once_logged(problem):
    fleet = executing(problem)
    _, why = fleet.event(EventKind.STARTED, 'MARC1', 'M1', 0.0, mission='old')
    assert "mission 'old'" in why
    _, again = fleet.event(EventKind.STARTED, 'MARC1', 'M2', 0.0, mission='old')
    assert again == ''
    assert fleet.status().ignored['stale'] == 2


def test_a_replan_outdated_by_the_fleet_is_discarded(problem):
    fleet = executing(problem)
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    fleet.report('MARC1', RobotMode.IDLE)  # recovered while the solve ran
    effects = fleet.run_solves([request])
    assert not kinds(effects, PublishPlan)
    assert fleet.state() == MissionState.EXECUTING
    assert kinds(fleet.tick(), Solve)  # and planned again


def test_jobs_done_while_replanning_are_not_redone(problem):
    fleet = executing(problem)
    fleet.wall += 2
    fleet.execute(until=2)
    # A robot that some job of the next 10 units can do without.
    window = [a for a in fleet.controller.mission.schedule.jobs.values()
              if 2 <= a.start and a.end <= 12]
    out = next(r for r in ROBOTS if any(r not in a.robots for a in window))
    fleet.failures[out] += 1
    fleet.report(out, RobotMode.FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    # Before the new plan arrives, the other robots finish more jobs of the old one.
    fleet.execute(until=12, without=out)
    done = set(fleet.controller.mission.tracker.done)
    assert done - set(request.state.done)
    effects = fleet.run_solves([request])
    published = kinds(effects, PublishPlan)
    if published:
        # It let what progressed go on as it is: nothing done is started afresh.
        (plan,) = published
        assert set(done) - set(request.state.done) <= plan.continued
        assert not (set(plan.result.schedule.jobs) - plan.continued) & done
        assert fleet.controller.mission.tracker.done >= done
    else:
        (warning,) = notes(effects, MissionEventKind.WARNING)
        assert 'progressed while it was solved' in warning.reasons[0]
        (again,) = kinds(fleet.tick(), Solve)
        assert set(again.state.done) >= done
        assert f"robot '{out}' failed" in again.reasons


def at_the_first_crew_job(problem):
    """A mission executed to plan until its first job of several robots, which have all
    reported arriving there; (the fleet, that job, its assignment)."""
    fleet = executing(problem)
    first = fleet.controller.mission.schedule
    job, assignment = min(((name, a) for name, a in first.jobs.items() if len(a.robots) > 1),
                          key=lambda kv: kv[1].start)
    fleet.wall += float(assignment.start)
    fleet.execute(until=assignment.start)
    for robot in assignment.robots:
        fleet.event(EventKind.ARRIVED, robot, job, float(assignment.start))
    return fleet, job, assignment


def kept_as_planned(fleet, request):
    """The outcome of the re-plan `request` asks for, its schedule made the current plan
    less the jobs done, plus the jobs the re-plan adds: a plan that leaves every job as it
    was, whatever the heuristics would have chosen."""
    current = fleet.controller.mission.schedule
    done = fleet.controller.mission.tracker.done
    outcome = repair(request.problem, request.previous, request.state)
    jobs = {name: a for name, a in current.jobs.items() if name not in done}
    sequences = {robot: tuple(j for j in sequence if j in jobs)
                 for robot, sequence in current.sequences.items()}
    for name, a in outcome.result.schedule.jobs.items():
        if name not in current.jobs:
            jobs[name] = a
            for robot in a.robots:
                sequences[robot] += (name,)
    return replace(outcome, result=replace(outcome.result, schedule=Schedule(jobs, sequences)))


def test_a_job_its_robots_reached_goes_on_when_the_new_plan_keeps_it(problem):
    """A re-plan published while the robots of a job start it, their reports still on the
    way: the job goes on under the new revision, so those reports count, rather than being
    voided and the job done twice."""
    from fjsp_planner.model.extension import extend

    fleet, job, assignment = at_the_first_crew_job(problem)
    tracker = fleet.controller.mission.tracker
    extended, added = extend(problem, 'jobs: [{name: Inspect, location: Ad, plans: '
                             '[[locomote]]}]\nprecedence: [[Ad, Inspect]]\n',
                             tracker.done | tracker.running)
    (request,) = kinds(fleet.controller.add_jobs(extended, added, fleet.wall), Solve)
    outcome = kept_as_planned(fleet, request)
    (published,) = kinds(fleet.controller.solved(request.token, outcome, fleet.wall),
                         PublishPlan)
    assert 'Inspect' in published.result.schedule.jobs
    assert job in published.continued
    assert published.revision == 2
    # An agent that missed revision 1 still knows which reports about each job count.
    assert published.restarted_in[job] == 1
    assert published.restarted_in['Inspect'] == 2
    assert all(published.restarted_in[name] == 2 for name in published.result.schedule.jobs
               if name not in published.continued)
    for robot in assignment.robots:
        _, ignored = fleet.event(EventKind.STARTED, robot, job, float(assignment.start),
                                 revision=1)
        assert ignored == ''
    assert set(tracker.jobs[job].started) == set(assignment.robots)
    fleet.execute()
    assert fleet.state() == MissionState.COMPLETE


def test_a_new_plan_that_moves_a_job_fallen_due_is_discarded(problem):
    """The robots of a job all arrived and its predecessors completed: they start it on
    those reports, so the planner that has not heard yet they did must not give it to others
    (they would do it twice); it plans again, and goes on once the starts are heard."""
    fleet, job, assignment = at_the_first_crew_job(problem)
    tracker = fleet.controller.mission.tracker
    assert tracker.due_start(job) == float(assignment.start)
    request, outcome = moved_by_a_replan(fleet, job, assignment)
    effects = fleet.take(fleet.controller.solved(request.token, outcome, fleet.wall))
    assert not kinds(effects, PublishPlan)
    (warning,) = notes(effects, MissionEventKind.WARNING)
    assert f"job '{job}'" in warning.reasons[0]
    for robot in assignment.robots:
        fleet.event(EventKind.STARTED, robot, job, float(assignment.start))
    (again,) = kinds(fleet.tick(), Solve)
    assert job in again.state.running


def test_a_job_fallen_due_long_ago_does_not_hold_a_new_plan_back(problem):
    """No start heard DUE_GRACE after the job fell due: a report is missing, not on its
    way, and the new plan is published as it is."""
    fleet, job, assignment = at_the_first_crew_job(problem)
    fleet.wall += 2 * DUE_GRACE / SETTINGS.time_scale
    request, outcome = moved_by_a_replan(fleet, job, assignment)
    effects = fleet.take(fleet.controller.solved(request.token, outcome, fleet.wall))
    (published,) = kinds(effects, PublishPlan)
    assert job not in published.continued


def moved_by_a_replan(fleet, job, assignment):
    """A robot outside the job's crew fails; the re-plan requested, and its outcome made to
    give the job to other robots."""
    out = next(r for r in ROBOTS if r not in assignment.robots)
    fleet.failures[out] += 1
    fleet.report(out, RobotMode.FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    outcome = repair(request.problem, request.previous, request.state)
    schedule = outcome.result.schedule
    others = dict(zip((r for r in ROBOTS if r not in assignment.robots and r != out),
                      assignment.robots.values(), strict=False))
    moved = replace(schedule, jobs={**schedule.jobs,
                                    job: replace(schedule.jobs[job], robots=others)})
    return request, replace(outcome, result=replace(outcome.result, schedule=moved))


def test_a_job_whose_robot_first_redoes_a_job_begun_starts_afresh(problem):
    """A robot at a job is sent first to redo a job begun elsewhere (its robot went offline
    on it): the job it waits at is no longer its next, so its arrival there must not let the
    others start it without it."""
    fleet = executing(problem)
    first = fleet.controller.mission.schedule
    job, assignment = min(((name, a) for name, a in first.jobs.items() if len(a.robots) > 1),
                          key=lambda kv: kv[1].start)
    begun, running = max(((name, a) for name, a in first.jobs.items()
                          if name in problem.predecessors(job)), key=lambda kv: kv[1].start)
    (lost,) = running.robots
    assert lost not in assignment.robots
    fleet.wall += float(running.start)
    fleet.execute(until=running.start + Fraction(1, 2))
    for robot in assignment.robots:
        fleet.event(EventKind.ARRIVED, robot, job, float(running.start))
    effects = fleet.tick(advance=1.5, robots=[r for r in ROBOTS if r != lost])
    (request,) = kinds(effects, Solve)
    outcome = kept_as_planned(fleet, request)
    # The plan as it was, but for the begun job, redone first by a robot of the job.
    helper = next(iter(assignment.robots))
    kept = outcome.result.schedule
    sequences = {robot: tuple(j for j in sequence if j != begun)
                 for robot, sequence in kept.sequences.items()}
    sequences[helper] = (begun, *sequences[helper])
    redone = Schedule({**kept.jobs, begun: replace(
        running, robots={helper: next(iter(running.robots.values()))})}, sequences)
    outcome = replace(outcome, result=replace(outcome.result, schedule=redone))
    (published,) = kinds(fleet.controller.solved(request.token, outcome, fleet.wall),
                         PublishPlan)
    assert begun not in published.continued
    assert job not in published.continued


def test_a_job_a_restarted_robot_had_reached_starts_afresh(problem):
    """The agent of a robot waiting at a job restarted: its new process does not know it
    waits there, so its arrival must not let the others start the job without it."""
    fleet, job, assignment = at_the_first_crew_job(problem)
    restarted = next(iter(assignment.robots))
    fleet.incarnations[restarted] += 1
    request = fleet.tick_until_solve()
    assert f"robot '{restarted}' restarted: its agent lost its tasks" in request.reasons
    outcome = kept_as_planned(fleet, request)
    (published,) = kinds(fleet.controller.solved(request.token, outcome, fleet.wall),
                         PublishPlan)
    assert job not in published.continued
    assert fleet.controller.mission.tracker.jobs[job].arrived == {}


def test_a_job_the_new_plan_gives_other_robots_starts_afresh(problem):
    """Going on is for jobs the new plan leaves as they were: one that a failed robot was
    waiting at is started afresh, its arrivals void."""
    fleet, job, assignment = at_the_first_crew_job(problem)
    out = next(r for r in assignment.robots if r != 'Assembler')
    fleet.failures[out] += 1
    fleet.report(out, RobotMode.FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    (published,) = kinds(fleet.run_solves([request]), PublishPlan)
    assert out not in published.result.schedule.jobs[job].robots
    assert job not in published.continued
    assert fleet.controller.mission.tracker.jobs[job].arrived == {}


def test_stale_solve_outcomes_are_dropped(problem):
    fleet = executing(problem)
    assert fleet.controller.solved(999, None, fleet.wall) == []


def test_cancel_publishes_a_cancelling_revision_and_frees_the_fleet(problem):
    fleet = executing(problem)
    with pytest.raises(ValueError, match='one mission per fleet'):
        fleet.controller.start(problem, 'm2', fleet.wall)
    effects = fleet.take(fleet.controller.cancel('m1', 'operator cancelled', fleet.wall))
    (cancelling,) = kinds(effects, PublishPlan)
    assert cancelling.cancelled and cancelling.revision == 2
    assert fleet.state() == MissionState.CANCELLED
    assert fleet.status().blocked == ('operator cancelled',)
    with pytest.raises(ValueError, match="mission 'm1' has ended: cancelled"):
        fleet.controller.cancel('m1', 'again', fleet.wall)
    fleet.controller.start(problem, 'm2', fleet.wall)
    assert fleet.controller.mission.id == 'm2'


def test_next_mission_starts_where_the_robots_are(problem):
    fleet = executing(problem)
    fleet.execute()
    for robot in ROBOTS:
        fleet.report(robot, location='Ad')
    (request,) = kinds(fleet.controller.start(problem, 'm2', fleet.wall), Solve)
    assert {r.start_location for r in request.problem.robots} == {'Ad'}


def test_blocked_for_longer_than_the_timeout_fails(problem):
    fleet = executing(problem, replace(SETTINGS, blocked_timeout=2.0))
    for robot in ('MARC1', 'MARC2'):
        fleet.failures[robot] += 1
        fleet.report(robot, RobotMode.FAILED)
    fleet.tick()
    fleet.run_solves()
    assert fleet.state() == MissionState.BLOCKED
    fleet.tick(advance=2.5)
    assert fleet.state() == MissionState.FAILED
    assert 'blocked for 2 s' in fleet.status().blocked[0]


def test_jobs_added_mid_mission_are_replanned_in(problem):
    from fjsp_planner.model.extension import extend

    fleet = executing(problem)
    fleet.wall += 5
    fleet.execute(until=5)
    tracker = fleet.controller.mission.tracker
    extended, added = extend(problem, 'jobs: [{name: Inspect, location: Ad, plans: '
                             '[[locomote]]}]\nprecedence: [[Ad, Inspect]]\n',
                             tracker.done | tracker.running)
    effects = fleet.take(fleet.controller.add_jobs(extended, added, fleet.wall))
    assert notes(effects, MissionEventKind.JOBS_ADDED)[0].job == 'Inspect'
    (request,) = kinds(effects, Solve)
    assert 'jobs added: Inspect' in request.reasons
    (published,) = kinds(fleet.run_solves([request]), PublishPlan)
    assert 'Inspect' in published.result.schedule.jobs
    fleet.execute()
    assert fleet.state() == MissionState.COMPLETE
    assert fleet.status().jobs_total == 13


def test_resume_rebuilds_the_mission_and_replans_above_what_robots_follow(problem):
    from fjsp_planner.execution.journal import DoneRecord, PlanRecord

    fleet = executing(problem)
    first = kinds(fleet.effects, PublishPlan)[0]
    fleet.wall += 8
    fleet.execute(until=8)
    mission = fleet.controller.mission
    done = [DoneRecord(mission.tracker.jobs[j].done_as, 1) for j in sorted(mission.tracker.done)]
    records = [PlanRecord(1, first.mission_start, first.result.schedule, frozenset(), ())]
    # A new planner process: a fresh controller, the journal, and the fleet's reports.
    restarted = Fleet(problem)
    restarted.wall = fleet.wall
    effects = restarted.take(restarted.controller.resume(
        'm1', problem, SETTINGS, fleet.wall, records + done[:-1], restarted.wall))
    assert 'resumed after a planner restart' in \
        notes(effects, MissionEventKind.MISSION_STARTED)[0].reasons[0]
    restarted.following = {'mission_id': 'm1', 'revision': 3}  # what the robots follow
    restarted.heartbeat()
    # The agents' event histories bring back the job whose done record was lost.
    last = done[-1].assignment
    for robot, q in last.robots.items():
        restarted.event(EventKind.STARTED, robot, last.job, float(last.start), revision=1)
        restarted.event(EventKind.OPERATION_DONE, robot, last.job,
                        float(last.start + problem.duration(robot, q)), revision=1)
    assert restarted.controller.mission.tracker.done == mission.tracker.done
    request = restarted.tick_until_solve()
    assert len(request.reasons) == 1 and 'planner restarted' in request.reasons[0]
    assert set(request.state.done) == set(mission.tracker.done)
    (published,) = kinds(restarted.run_solves([request]), PublishPlan)
    assert published.revision == 4
    # Done jobs are not redone (a done jig job may go on, continued, while its hold lasts).
    restarted_jobs = set(published.result.schedule.jobs) - published.continued
    assert not restarted_jobs & set(mission.tracker.done)


def test_a_resumed_mission_waits_for_each_robots_history_as_far_as_its_state_says(problem):
    """Under load, the agents' event histories reached a restarted planner later than the
    half second it used to wait after discovering their writers: it re-planned as if
    nothing had happened meanwhile, and the robots redid every job since the restart. Each
    robot's state names the latest event it published; the re-plan waits for it."""
    from fjsp_planner.execution.journal import PlanRecord

    fleet = executing(problem)
    first = kinds(fleet.effects, PublishPlan)[0]
    plan = first.result.schedule
    job = min(plan.jobs.values(), key=lambda a: a.start)
    records = [PlanRecord(1, first.mission_start, plan, frozenset(), (),
                          incarnations=dict(first.incarnations))]
    restarted = Fleet(problem)
    restarted.wall = fleet.wall + float(job.end) + 1
    restarted.take(restarted.controller.resume('m1', problem, SETTINGS, fleet.wall, records,
                                               restarted.wall))
    # Each robot of the job did its part while no planner ran; its state says so.
    last = {robot: f'{robot}/done-{job.job}' for robot in job.robots}
    restarted.following = {'mission_id': 'm1', 'revision': 1}

    def tick():
        restarted.wall += 0.1
        for robot in ROBOTS:
            restarted.report(robot, last_event=last.get(robot, ''))
        return restarted.take(restarted.controller.tick(restarted.wall))

    for _ in range(10):
        assert not kinds(tick(), Solve)
    for robot, q in job.robots.items():
        for kind, at, name in ((EventKind.STARTED, job.start, f'{robot}/start-{job.job}'),
                               (EventKind.OPERATION_DONE,
                                job.start + problem.duration(robot, q), last[robot])):
            restarted.controller.task_event(EventReport(name, 'm1', kind, robot, job.job, 1,
                                                        float(at)), restarted.wall)
    (request,) = kinds(tick() + tick(), Solve)
    assert job.job in request.state.done


def test_a_resumed_mission_waits_for_a_missing_history_no_longer_than_the_robot_wait(problem):
    from fjsp_planner.execution.journal import PlanRecord

    fleet = executing(problem)
    first = kinds(fleet.effects, PublishPlan)[0]
    records = [PlanRecord(1, first.mission_start, first.result.schedule, frozenset(), ())]
    restarted = Fleet(problem)
    restarted.wall = fleet.wall + 1
    restarted.take(restarted.controller.resume('m1', problem, SETTINGS, fleet.wall, records,
                                               restarted.wall))
    restarted.following = {'mission_id': 'm1', 'revision': 1, 'last_event': 'never/sent'}
    waited = []
    for _ in range(60):
        if kinds(restarted.tick(), Solve):
            break
        waited.append(restarted.wall)
    assert SETTINGS.robot_wait_timeout - 0.2 <= waited[-1] - (fleet.wall + 1) \
        <= SETTINGS.robot_wait_timeout + 0.1


def test_an_agent_restarted_while_the_planner_was_down_has_its_job_redone(problem):
    """Found by the soak (truss: R1 killed, the planner killed, R1 started again, then the
    planner): R2 had begun a job with R1, whose new process knew nothing of it. The resumed
    planner saw a healthy R1 and let the job go on, and R1 did its part alone 70 units later.
    The journal names the agent each plan was made for: the job is aborted and redone."""
    from fjsp_planner.execution.journal import DoneRecord, PlanRecord

    fleet = executing(problem)
    first = kinds(fleet.effects, PublishPlan)[0]
    assert first.incarnations == dict.fromkeys(ROBOTS, 1)
    plan = first.result.schedule
    job = min((a for a in plan.jobs.values() if len(a.robots) >= 2), key=lambda a: a.start)
    fleet.wall += float(job.start) + 0.1
    fleet.execute(until=float(job.start) + 0.1)
    tracker = fleet.controller.mission.tracker
    assert job.job in tracker.running
    done = [DoneRecord(tracker.jobs[j].done_as, 1) for j in sorted(tracker.done)]
    records = [PlanRecord(1, first.mission_start, plan, frozenset(), (),
                          incarnations=dict(first.incarnations))]
    # The planner dies; one robot of the job restarts; a new planner resumes.
    gone, stayed = sorted(job.robots)[:2]
    restarted = Fleet(problem)
    restarted.wall = fleet.wall + 1
    restarted.incarnations[gone] = 2
    restarted.take(restarted.controller.resume('m1', problem, SETTINGS, fleet.wall,
                                               records + done, restarted.wall))
    restarted.following = {'mission_id': 'm1', 'revision': 1}
    restarted.heartbeat()
    # The robot that stayed still has its history; the restarted one lost its own.
    restarted.event(EventKind.STARTED, stayed, job.job, float(job.start), revision=1)
    request = restarted.tick_until_solve()
    aborted = notes(restarted.effects, MissionEventKind.JOB_ABORTED)
    assert [n.job for n in aborted] == [job.job]
    assert f"robot '{gone}' restarted while the planner was down" in aborted[0].reasons[0]
    assert job.job not in request.state.running
    (published,) = kinds(restarted.run_solves([request]), PublishPlan)
    assert job.job in published.result.schedule.jobs
    assert job.job not in published.continued
    assert published.incarnations[gone] == 2


def repaired_after_a_failure(problem):
    """MARC1 fails at 2: (the fleet, the repaired plan published, the effects of the repair)."""
    fleet = executing(problem)
    fleet.wall += 2
    fleet.execute(until=2)
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    (repair_request,) = kinds(fleet.tick(), Solve)
    effects = fleet.run_solves([repair_request])
    (repaired,) = kinds(effects, PublishPlan)
    return fleet, repaired, effects


def test_a_repaired_plan_is_published_at_once_then_bettered(problem):
    fleet, repaired, effects = repaired_after_a_failure(problem)
    searches = [e for e in kinds(effects, Solve) if e.kind == SolveKind.IMPROVE]
    if repaired.result.status == 'optimal':
        assert not searches  # nothing to better
        return
    (search,) = searches
    # The robots go on with the repaired plan until the search's plan can reach them.
    assert search.frozen_until == pytest.approx(fleet.controller.now_units(
        fleet.wall + search.time_limit + IMPROVE_REACH))
    better = kinds(fleet.run_solves([search], improve_too=True), PublishPlan)
    for plan in better:
        assert plan.revision == repaired.revision + 1
        assert plan.result.makespan < repaired.result.makespan
        assert plan.reasons[0].startswith('a better plan: makespan')
        begun = {name for name, a in repaired.result.schedule.jobs.items()
                 if a.start < search.frozen_until}
        assert begun <= plan.continued


def test_a_better_plan_is_searched_from_again_until_a_search_finds_no_better(problem):
    """The searches' outcomes are made up (the repaired plan, said to be better), so that
    both turns are taken whatever CP-SAT would find."""
    fleet, repaired, effects = repaired_after_a_failure(problem)
    (search,) = [e for e in kinds(effects, Solve) if e.kind == SolveKind.IMPROVE]
    published = search.published
    effects = fleet.take(fleet.controller.solved(search.token, Improvement(published, True),
                                                 fleet.wall))
    (better,) = kinds(effects, PublishPlan)
    assert better.revision == repaired.revision + 1
    (again,) = [e for e in kinds(effects, Solve) if e.kind == SolveKind.IMPROVE]
    assert again.published is published and again.token != search.token
    assert again.time_limit == search.time_limit == SETTINGS.replan_time_limit
    # Searches that find nothing better double in length, up to 16 re-plan limits.
    limits = []
    while True:
        effects = fleet.take(fleet.controller.solved(again.token,
                                                     Improvement(published, False), fleet.wall))
        assert not kinds(effects, PublishPlan)
        searches = [e for e in kinds(effects, Solve) if e.kind == SolveKind.IMPROVE]
        if not searches:
            break
        (again,) = searches
        limits.append(again.time_limit)
    assert limits == [4.0, 8.0, 16.0, 32.0]


def test_a_better_plan_that_changes_what_the_robots_started_meanwhile_is_dropped(problem):
    """Robots may start jobs ahead of the plan, beyond what the search kept as it is. A
    plan that gives one of those to other robots cannot be followed: it is dropped with a
    warning, and a search twice as long starts from the published plan. The search's
    outcome is made up so that it does change such a job."""
    fleet, repaired, effects = repaired_after_a_failure(problem)
    (search,) = [e for e in kinds(effects, Solve) if e.kind == SolveKind.IMPROVE]
    published = search.published
    fleet.wall += 10
    fleet.execute(until=12)
    moved = next(name for name, a in sorted(published.schedule.jobs.items(),
                                            key=lambda kv: kv[1].start)
                 if name not in published.residual.problem.fixed
                 and fleet.controller.mission.tracker.jobs[name].started)
    job = published.schedule.jobs[moved]
    other = next(r for r in ROBOTS if r not in job.robots and r != 'MARC1')
    robots = dict(job.robots)
    robots[other] = robots.pop(next(iter(robots)))
    changed = replace(published.schedule, jobs={**published.schedule.jobs,
                                                moved: replace(job, robots=robots)})
    better = Replan(published.residual, replace(published.result, schedule=changed), [])
    effects = fleet.take(fleet.controller.solved(search.token, Improvement(better, True),
                                                 fleet.wall))
    assert not kinds(effects, PublishPlan)
    (warning,) = notes(effects, MissionEventKind.WARNING)
    assert 'dropped' in warning.reasons[0] and f"job '{moved}'" in warning.reasons[0]
    (again,) = [e for e in kinds(effects, Solve) if e.kind == SolveKind.IMPROVE]
    assert again.published is published
    assert again.time_limit == 2 * search.time_limit
    assert moved in again.started


def test_a_search_for_a_better_plan_is_dropped_when_the_fleet_changes(problem):
    fleet = executing(problem)
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    (repair_request,) = kinds(fleet.tick(), Solve)
    searches = [e for e in kinds(fleet.run_solves([repair_request]), Solve)
                if e.kind == SolveKind.IMPROVE]
    fleet.failures['MARC2'] += 1
    fleet.report('MARC2', RobotMode.FAILED)
    assert kinds(fleet.tick(), Solve)  # a new repair for the second failure
    for search in searches:
        assert not fleet.run_solves([search], improve_too=True)


# --- moves of the mission state the tests above do not make (states.TRANSITIONS) ---------

def test_a_mission_waiting_for_robots_can_be_cancelled(problem):
    fleet = Fleet(problem)
    fleet.start()
    effects = fleet.take(fleet.controller.cancel('m1', 'operator stop', fleet.wall))
    assert fleet.state() == MissionState.CANCELLED
    assert notes(effects, MissionEventKind.MISSION_CANCELLED)
    assert not kinds(effects, PublishPlan)  # no plan was ever published: nothing to revoke


def test_a_mission_cancelled_while_its_first_plan_is_solved_publishes_no_plan(problem):
    fleet = Fleet(problem)
    fleet.start()
    request = fleet.tick_until_solve()
    fleet.take(fleet.controller.cancel('m1', 'operator stop', fleet.wall))
    assert not fleet.run_solves([request])
    assert fleet.state() == MissionState.CANCELLED


def test_a_mission_cancelled_while_it_is_replanned_publishes_only_the_cancelling_plan(problem):
    fleet = executing(problem)
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    assert fleet.state() == MissionState.REPLANNING
    (cancelling,) = kinds(fleet.take(fleet.controller.cancel('m1', 'operator stop',
                                                             fleet.wall)), PublishPlan)
    assert cancelling.cancelled and cancelling.revision == 2
    assert not fleet.run_solves([request])
    assert fleet.state() == MissionState.CANCELLED


def test_a_blocked_mission_can_be_cancelled(problem):
    fleet = executing(problem)
    for robot in ('MARC1', 'MARC2'):
        fleet.failures[robot] += 1
        fleet.report(robot, RobotMode.FAILED)
    fleet.tick()
    fleet.run_solves()
    assert fleet.state() == MissionState.BLOCKED
    fleet.take(fleet.controller.cancel('m1', 'operator stop', fleet.wall))
    assert fleet.state() == MissionState.CANCELLED
    assert fleet.status().blocked == ('operator stop',)


def test_a_first_plan_the_solver_cannot_make_fails_the_mission(problem):
    fleet = Fleet(problem)
    fleet.start()
    request = fleet.tick_until_solve()
    effects = fleet.take(fleet.controller.solved(request.token, ValueError('out of memory'),
                                                 fleet.wall))
    assert notes(effects, MissionEventKind.MISSION_FAILED)
    assert fleet.state() == MissionState.FAILED
    assert fleet.status().blocked == ('solver: out of memory',)


def test_jobs_added_while_the_first_plan_is_solved_are_in_the_first_plan(problem):
    from fjsp_planner.model.extension import extend

    fleet = Fleet(problem)
    fleet.start()
    before = fleet.tick_until_solve()
    extended, added = extend(problem, 'jobs: [{name: Inspect, location: Ad, plans: '
                             '[[locomote]]}]\nprecedence: [[Ad, Inspect]]\n')
    (request,) = kinds(fleet.take(fleet.controller.add_jobs(extended, added, fleet.wall)),
                       Solve)
    assert request.kind == SolveKind.PLAN and 'Inspect' in {j.name for j in request.problem.jobs}
    assert fleet.state() == MissionState.PLANNING
    assert not fleet.run_solves([before])  # it left the new job out
    (published,) = kinds(fleet.run_solves([request]), PublishPlan)
    assert published.revision == 1 and 'Inspect' in published.result.schedule.jobs


def test_a_mission_blocked_before_its_first_plan_is_planned_once_robots_come_back(problem):
    fleet = Fleet(problem)
    fleet.start()
    for robot in ('MARC1', 'MARC2'):
        fleet.failures[robot] += 1
        fleet.modes[robot] = RobotMode.FAILED
    fleet.tick()
    assert fleet.state() == MissionState.BLOCKED
    blocked = fleet.status().blocked
    assert "robot 'MARC1' failed" in blocked and "robot 'MARC2' failed" in blocked
    # The Assembler fails too: still blocked, for more reasons.
    fleet.failures['Assembler'] += 1
    fleet.report('Assembler', RobotMode.FAILED)
    fleet.tick()
    assert fleet.state() == MissionState.BLOCKED
    assert "robot 'Assembler' failed" in fleet.status().blocked
    for robot in ('Assembler', 'MARC1'):
        fleet.report(robot, RobotMode.IDLE)
    (request,) = kinds(fleet.tick(), Solve)
    assert request.kind == SolveKind.PLAN
    assert fleet.state() == MissionState.PLANNING
    (published,) = kinds(fleet.run_solves([request]), PublishPlan)
    assert published.revision == 1 and 'MARC2' not in published.result.schedule.sequences


def all_but_one_operation_done(fleet):
    """Report the plan executed to plan but for one operation of its last job; (the robot
    that still works on it, the job, its operation's end)."""
    plan, problem = fleet.controller.mission.schedule, fleet.problem
    order = sorted(plan.jobs, key=lambda name: (plan.jobs[name].start, name))
    last, working = order[-1], next(iter(plan.jobs[order[-1]].robots))
    for name in order:
        a = plan.jobs[name]
        for robot in a.robots:
            fleet.event(EventKind.STARTED, robot, name, float(a.start))
        for robot, q in a.robots.items():
            if (name, robot) != (last, working):
                fleet.event(EventKind.OPERATION_DONE, robot, name,
                            float(a.start + problem.duration(robot, q)))
    a = plan.jobs[last]
    return working, last, float(a.start + problem.duration(working, a.robots[working]))


def test_a_mission_whose_last_job_ends_while_it_is_replanned_completes(problem):
    fleet = executing(problem)
    working, last, end = all_but_one_operation_done(fleet)
    assert fleet.controller.mission.tracker.done == {j.name for j in problem.jobs} - {last}
    idle = next(r for r in ROBOTS if r not in fleet.controller.mission.schedule.jobs[last].robots)
    fleet.failures[idle] += 1
    fleet.report(idle, RobotMode.FAILED)
    (request,) = kinds(fleet.tick(), Solve)
    assert fleet.state() == MissionState.REPLANNING
    fleet.event(EventKind.OPERATION_DONE, working, last, end)
    assert fleet.state() == MissionState.COMPLETE
    assert not fleet.run_solves([request])


def test_an_invalid_executed_timeline_fails_the_mission_while_it_is_replanned(problem):
    fleet = executing(problem)
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    fleet.tick()
    assert fleet.state() == MissionState.REPLANNING
    for name, a in fleet.controller.mission.schedule.jobs.items():
        for robot in a.robots:
            fleet.event(EventKind.STARTED, robot, name, 0.0)
            fleet.event(EventKind.OPERATION_DONE, robot, name, 1.0)
    assert fleet.state() == MissionState.FAILED
    assert any('executed timeline' in r for r in fleet.status().blocked)


def resumed_with_the_histories_on_their_way(problem, last_events):
    """Revision 1 of the paper's mission published, then the planner restarted: a new
    controller resumed from the journal, whose robots report following revision 1 and having
    published `last_events` (robot -> event id), not received yet; (the fleet, the plan)."""
    from fjsp_planner.execution.journal import PlanRecord

    fleet = executing(problem)
    first = kinds(fleet.effects, PublishPlan)[0]
    records = [PlanRecord(1, first.mission_start, first.result.schedule, frozenset(), ())]
    restarted = Fleet(problem)
    restarted.wall = fleet.wall + 1
    restarted.take(restarted.controller.resume('m1', problem, SETTINGS, fleet.wall, records,
                                               restarted.wall))
    restarted.following = {'mission_id': 'm1', 'revision': 1}
    for robot in ROBOTS:
        restarted.report(robot, last_event=last_events.get(robot, ''))
    restarted.take(restarted.controller.tick(restarted.wall))
    assert restarted.state() == MissionState.WAITING_FOR_ROBOTS
    return restarted, first.result.schedule


def history_of(restarted, plan, time=None):
    """The robots' event histories of `plan` arrive: every job done to plan, or all at once
    from `time` to `time + 1`; the id of each robot's last event."""
    problem, last = restarted.problem, {}
    for name, a in sorted(plan.jobs.items(), key=lambda kv: kv[1].start):
        for robot, q in a.robots.items():
            start = float(a.start) if time is None else time
            end = float(a.start + problem.duration(robot, q)) if time is None else time + 1
            for kind, at in ((EventKind.STARTED, start), (EventKind.OPERATION_DONE, end)):
                restarted.events += 1
                last[robot] = f'{robot}/{restarted.events}'
                restarted.take(restarted.controller.task_event(EventReport(
                    last[robot], 'm1', kind, robot, name, 1, at), restarted.wall)[0])
    return last


def test_a_mission_its_robots_finished_while_no_planner_ran_completes_on_their_reports(problem):
    """A planner killed for the whole mission, then started again: the robots finished the
    plan they had, and their histories complete the mission before any re-plan."""
    restarted, plan = resumed_with_the_histories_on_their_way(problem, dict.fromkeys(
        ROBOTS, 'on/its/way'))
    history_of(restarted, plan)
    assert restarted.state() == MissionState.COMPLETE
    assert notes(restarted.effects, MissionEventKind.MISSION_COMPLETE)


def test_a_resumed_mission_whose_histories_break_the_timeline_fails(problem):
    restarted, plan = resumed_with_the_histories_on_their_way(problem, dict.fromkeys(
        ROBOTS, 'on/its/way'))
    history_of(restarted, plan, time=0.0)
    assert restarted.state() == MissionState.FAILED
    assert any('executed timeline' in r for r in restarted.status().blocked)


def test_an_execution_state_the_tracker_cannot_tell_blocks_the_mission(problem):
    fleet = executing(problem)
    tracker = fleet.controller.mission.tracker

    def contradiction(now):
        raise ValueError("job 'Ja' ends before it starts")

    tracker.execution_state = contradiction
    fleet.failures['MARC1'] += 1
    fleet.report('MARC1', RobotMode.FAILED)
    assert not kinds(fleet.tick(), Solve)
    assert fleet.state() == MissionState.BLOCKED
    assert fleet.status().blocked == (
        "cannot tell the execution state: job 'Ja' ends before it starts",)


# --- missions submitted while one runs: the queue -----------------------------------------

def test_missions_submitted_while_one_runs_wait_their_turn_in_order(problem):
    fleet = executing(problem)
    assert fleet.controller.submit(problem, 'm2', fleet.wall) == (1, [])
    assert fleet.controller.submit(problem, 'm3', fleet.wall) == (2, [])
    assert fleet.status().queue == ('m2', 'm3')
    assert fleet.controller.waiting('m3').state == MissionState.QUEUED
    effects = fleet.take(fleet.controller.cancel('m2', 'not needed', fleet.wall))
    assert effects == [LeftQueue('m2', MissionState.CANCELLED, ('not needed',))]
    assert fleet.status().queue == ('m3',) and fleet.controller.position('m3') == 1
    fleet.execute()
    assert fleet.state() == MissionState.COMPLETE and fleet.controller.mission.id == 'm1'
    fleet.following = {'location': 'Ad'}
    effects = fleet.tick()
    assert notes(effects, MissionEventKind.MISSION_STARTED)
    assert fleet.controller.mission.id == 'm3' and fleet.status().queue == ()
    (request,) = kinds(effects, Solve)
    # The next mission starts where the last left the robots.
    assert {r.start_location for r in request.problem.robots} == {'Ad'}
    (published,) = kinds(fleet.run_solves([request]), PublishPlan)
    assert published.revision == 1 and fleet.state() == MissionState.EXECUTING


def test_a_mission_cancelled_with_a_queue_behind_it_hands_the_fleet_to_the_next(problem):
    fleet = executing(problem)
    fleet.controller.submit(problem, 'm2', fleet.wall)
    fleet.take(fleet.controller.cancel('m1', 'operator stop', fleet.wall))
    assert fleet.state() == MissionState.CANCELLED
    fleet.tick()
    assert fleet.controller.mission.id == 'm2'
    assert fleet.state() in (MissionState.WAITING_FOR_ROBOTS, MissionState.PLANNING)


def test_the_queue_is_bounded_and_optional(problem):
    fleet = executing(problem, replace(SETTINGS, queue_limit=1))
    with pytest.raises(ValueError, match="mission 'm1' is executing: one mission per fleet at "
                                         r'a time \(the goal asked not to be queued\)'):
        fleet.controller.submit(problem, 'm2', fleet.wall, queue=False)
    fleet.controller.submit(problem, 'm2', fleet.wall)
    with pytest.raises(ValueError, match=r'the queue is full: 1 missions wait their turn '
                                         r'\(queue_limit 1\)'):
        fleet.controller.submit(problem, 'm3', fleet.wall)
    with pytest.raises(ValueError, match='one mission per fleet'):
        fleet.controller.start(problem, 'm3', fleet.wall)
    assert fleet.status().queue == ('m2',)


def test_a_planner_without_a_queue_refuses_missions_while_one_runs(problem):
    fleet = executing(problem, replace(SETTINGS, queue_limit=0))
    with pytest.raises(ValueError, match="mission 'm1' is executing: one mission per fleet"):
        fleet.controller.submit(problem, 'm2', fleet.wall)


@pytest.mark.parametrize(('mission_id', 'why'), [
    ('', "name the mission: the request has no mission id \\(running: 'm1'\\)"),
    ('m0', "no mission 'm0' is running or waits in the queue \\(running: 'm1'\\)"),
    ('m2', "mission 'm2' waits in the queue \\(position 1\\): it is not running yet"),
])
def test_a_request_must_name_the_mission_it_is_for(problem, mission_id, why):
    fleet = executing(problem)
    fleet.controller.submit(problem, 'm2', fleet.wall)
    with pytest.raises(ValueError, match=why):
        fleet.controller.running(mission_id)
    if mission_id != 'm2':
        with pytest.raises(ValueError, match=why):
            fleet.controller.cancel(mission_id, 'stop', fleet.wall)
    assert fleet.state() == MissionState.EXECUTING


def test_a_planner_that_stands_down_fails_its_missions_and_publishes_no_plan(problem):
    fleet = executing(problem)
    fleet.controller.submit(problem, 'm2', fleet.wall)
    effects = fleet.take(fleet.controller.stand_down('another planner is in charge'))
    assert not kinds(effects, PublishPlan)
    assert notes(effects, MissionEventKind.MISSION_FAILED)
    assert kinds(effects, LeftQueue) == [LeftQueue('m2', MissionState.FAILED,
                                                   ('another planner is in charge',))]
    assert fleet.state() == MissionState.FAILED and not fleet.controller.busy
    assert fleet.status().blocked == ('another planner is in charge',)


def test_a_robot_whose_states_do_not_verify_is_named_so_not_merely_silent(problem):
    """An agent started without the fleet key: its states are dropped, so it is never heard,
    and the mission says why rather than only that it has not reported or went offline."""
    fleet = Fleet(problem)
    fleet.start()
    fleet.controller.unverified_state('MARC2', 'not signed', fleet.wall)
    fleet.controller.unverified_state('nobody', 'not signed', fleet.wall)
    assert fleet.status().blocked[-1] == ("waiting for robot 'MARC2' to report: its states do "
                                          'not verify: not signed')
    assert 'nobody' not in fleet.controller.liveness.unverified
    fleet = executing(problem)
    for _ in range(15):
        fleet.controller.unverified_state('MARC2', 'not signed', fleet.wall)
        fleet.tick(robots=ROBOTS[:3])
    (offline,) = notes(fleet.effects, MissionEventKind.ROBOT_OFFLINE)
    assert offline.robot == 'MARC2'
    assert offline.reasons[0].startswith('no state that verifies for 1.')
    assert offline.reasons[0].endswith('s: not signed')
    assert "robot 'MARC2' sends states that do not verify: not signed" in \
        kinds(fleet.effects, Solve)[-1].reasons


def test_the_missions_here_make_exactly_the_moves_the_state_table_allows(request):
    """Last in this file: the table allows no move that no mission here makes (an illegal one
    raises as it is made). Checked when every other test of the file ran before it, in this
    process."""
    others = {item.nodeid for item in request.node.parent.collect()} - {request.node.nodeid}
    if not others <= RAN:
        pytest.skip('needs every test of this file run before it in this process')
    moves = {(current, new) for current, new in MOVES if current != new}
    assert moves == {(current, new) for current, allowed in TRANSITIONS.items()
                     for new in allowed}
