"""The planner node: ROS plumbing around the mission controller (`execution/mission/`).

It turns robot states and task events into controller inputs, runs the solves the controller
asks for in a worker thread (a guard condition wakes the executor the moment one finishes),
and publishes what the controller decides: plans (latched), job completions, the mission's
story on `mission_events`, its summary on `mission_status` and per-job states on `job_states`
(see docs/ros-interfaces.md).
"""

import hashlib
import itertools
import math
import os
import secrets
import sys
import threading
import time
from collections import deque
from concurrent.futures import Future, ThreadPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node
from rclpy.serialization import deserialize_message, serialize_message
from rclpy.task import Future as RosFuture
from rclpy.time import Time

from fjsp_common.auth import NodeAuth
from fjsp_common.clock import seconds
from fjsp_common.contract import (
    ADD_JOBS_SERVICE,
    CANCEL_MISSION_SERVICE,
    DIAGNOSTICS,
    EVENT_FROM_MSG,
    EVENT_HISTORY,
    JOB_STATES,
    JOB_STATES_TOPIC,
    MAX_FLEET,
    MISSION_EVENT_TO_MSG,
    MISSION_EVENTS,
    MISSION_EVENTS_TOPIC,
    MISSION_STATUS,
    MISSION_STATUS_TOPIC,
    MODE_FROM_MSG,
    PLAN,
    PLAN_TOPIC,
    ROBOT_STATES,
    ROBOT_STATES_TOPIC,
    RUN_MISSION_ACTION,
    STATE_FROM_MSG,
    STATE_TO_MSG,
    TASK_EVENTS,
    TASK_EVENTS_TOPIC,
    catch_up,
    publisher,
    subscription,
)
from fjsp_common.decimals import decimal, decimals
from fjsp_common.diagnostics import diagnostic_array, planner_diagnostic
from fjsp_common.fleet import DIAGNOSTICS_PERIOD, PLANNER_NODE
from fjsp_common.running import ParameterError, declare, run_node, shorten
from fjsp_common.vocabulary import MissionEventKind, MissionState
from fjsp_msgs.action import RunMission
from fjsp_msgs.msg import JobStates, MissionEvent, MissionStatus, Plan, RobotState, TaskEvent
from fjsp_msgs.srv import AddJobs, CancelMission
from fjsp_planner.execution.journal import (
    DoneRecord,
    EndRecord,
    JobsAddedRecord,
    Journal,
    JournalError,
    MissionRecord,
    PlanRecord,
    StartRecord,
    journal_directory,
    journal_path,
    journals,
    waits_in_queue,
)
from fjsp_planner.execution.mission.charge import Change, Charge, Role
from fjsp_planner.execution.mission.controller import MissionController
from fjsp_planner.execution.mission.effects import (
    JobDone,
    LeftQueue,
    Note,
    PublishPlan,
    ResendPlan,
    Solve,
    SolveKind,
)
from fjsp_planner.execution.mission.reports import EventReport, RobotReport
from fjsp_planner.execution.mission.settings import PARAMETERS, SETTINGS_PARAMETERS, Settings
from fjsp_planner.execution.replan import improve, repair
from fjsp_planner.execution.tracking import Ignored
from fjsp_planner.model.extension import extend
from fjsp_planner.model.problem import Problem, ProblemError
from fjsp_planner.model.scenario import load_scenario, scenario_from_text, scenario_warnings
from fjsp_planner.nodes.conversions import cancel_msg, job_states, plan_msg
from fjsp_planner.solving.solve import solve

ANSWERS_KEPT = 256
"""Answers kept per service for requests that are resent."""

WITHDRAW_GRACE = 1.0
"""Seconds a planner that stood down keeps serving, so the goals it failed get their
results."""

SOLVER_NICENESS = 10

JOURNAL_RETRY = 5.0
"""Seconds between attempts to resume a mission whose journal could not be written."""


def yield_to_the_fleet() -> None:
    """Lower the priority of a solver thread, and so of the CP-SAT workers it starts: a
    solve that takes every core must not delay the heartbeats and reports of the robots (a
    robot whose agent is starved looks offline) or this node's own callbacks."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), SOLVER_NICENESS)
    except OSError:
        pass  # not allowed here: the solve runs at the node's priority


def new_mission_id(scenario: str) -> str:
    """Unique, readable and sorting by start time: `<scenario>-<UTC time>-<random>`."""
    stamp = datetime.now(UTC).strftime('%Y%m%dT%H%M%S')
    name = ''.join(c if c.isalnum() or c in '_-' else '_' for c in scenario)[:40]
    return f'{name}-{stamp}-{secrets.token_hex(2)}'


ENDINGS = {
    MissionEventKind.MISSION_COMPLETE: MissionState.COMPLETE,
    MissionEventKind.MISSION_CANCELLED: MissionState.CANCELLED,
    MissionEventKind.MISSION_FAILED: MissionState.FAILED,
}
RESULT_OF = {
    MissionState.COMPLETE: RunMission.Result.STATE_COMPLETE,
    MissionState.CANCELLED: RunMission.Result.STATE_CANCELLED,
    MissionState.FAILED: RunMission.Result.STATE_FAILED,
}


def origin_of(text: str, panels: int, shift: float) -> str:
    """What identifies a mission given by the `scenario` parameter across restarts."""
    digest = hashlib.sha256(f'{panels}/{shift}/{text}'.encode()).hexdigest()[:16]
    return f'parameter:{digest}'


class Goal:
    """A RunMission goal whose mission runs or waits its turn: answered with its result when
    the mission ends, or None when a resent goal takes the mission over."""

    def __init__(self, handle, mission_id: str):
        self.handle = handle
        self.mission_id = mission_id
        self.request_id = handle.request.request_id
        self.ended = RosFuture()


SUBJECTS = {
    MissionEventKind.ROBOT_FAILED: ('robot', 'failed'),
    MissionEventKind.ROBOT_OFFLINE: ('robot', 'offline'),
    MissionEventKind.ROBOT_BACK: ('robot', 'back'),
    MissionEventKind.JOB_ABORTED: ('job', 'aborted'),
    MissionEventKind.JOB_VOIDED: ('job', 'voided'),
}


def describe(note: Note) -> str:
    """One log line: "robot 'MARC1' offline: no state for 1.2 s", "plan published: ..."."""
    subject = SUBJECTS.get(note.kind)
    if subject is None:
        text = str(note.kind) + (f': {note.job}' if note.job else '')
    else:
        text = f"{subject[0]} '{note.robot if subject[0] == 'robot' else note.job}' {subject[1]}"
    return text + (': ' + '; '.join(note.reasons) if note.reasons else '')


class PlannerNode(Node):
    def __init__(self, context=None):
        super().__init__(PLANNER_NODE, context=context)
        value = {name: declare(self, spec) for name, spec in PARAMETERS.items()}
        scenario, panels, shift = value['scenario'], value['panels'], value['shift']
        self.solver = value['solver']
        self.time_scale, self.start_delay = value['time_scale'], value['start_delay']
        status_period, journal_dir = value['status_period'], value['journal_dir']
        self.journal_dir = None
        if journal_dir:
            try:
                self.journal_dir = journal_directory(journal_dir)
            except JournalError as error:
                raise ParameterError(f"parameter 'journal_dir': {error}") from None
        self.startup = None
        """The `scenario` parameter's mission, started once this planner takes charge:
        (problem, text, file, panels, shift, origin)."""
        if scenario:
            try:
                problem = load_scenario(scenario, panels=panels or None,
                                        shift=shift if shift >= 0 else None)
                text = Path(scenario).read_text()
            except (ProblemError, OSError, UnicodeDecodeError) as error:
                problems = getattr(error, 'problems', [str(error)])
                raise ParameterError(f"parameter 'scenario': cannot use '{scenario}':\n"
                                     + '\n'.join(problems)) from None
            self.startup = (problem, text, scenario, panels, shift,
                            origin_of(text, panels, shift))

        self.auth = NodeAuth(self, PLANNER_NODE)
        self.controller = MissionController(self.settings())
        self.journal: Journal | None = None
        self.goals: dict[str, Goal] = {}
        """The RunMission goals of missions running or queued, by mission id."""
        self.journal_blocked: tuple[str, str, float] | None = None
        """(mission, why, when) of a mission set aside because its journal could not be
        written: resumed from the journal once it can be."""
        self.job_done_ids: set[str] = set()
        self.solver_answer: tuple[str, float | None] = ('', None)
        """Status and gap of the latest plan's solve."""
        self.replan_began: float | None = None
        self.replan_latency: float | None = None
        """Seconds from the decision to re-plan to the new revision's publication."""
        self.last_published = None
        """(mission, revision, stamp) of this node's latest plan, which it hears back."""
        self.last_plan: Plan | None = None
        """The latest plan message published, unsigned: published again for a robot that
        has not taken it."""
        self.event_count = 0
        self.incarnation = self.auth.signer.incarnation
        self.solves: dict[int, Future] = {}
        # Solves run off the executor so it keeps serving callbacks; two, so that a repair
        # need not wait for the search for a better plan it makes obsolete.
        self.pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix='solver',
                                       initializer=yield_to_the_fleet)
        self.solved_guard = self.create_guard_condition(self.collect_solves)
        self.waking = threading.Lock()
        self.closing = False
        """Set under `waking` once the node is being destroyed: a solve ending then has no
        guard condition left to trigger."""

        self.charge = Charge(self.incarnation, self.wall(), value['rival_timeout'])
        self.started_up = False
        self.servers: list | None = None
        """The action server and services of mission requests, while this planner serves."""
        self.withdraw_at: float | None = None
        """Wall seconds when a planner that stood down withdraws its servers, once its
        goals have had their answers."""
        self.unheard: dict[str, deque] = {}
        """Robot -> the task events heard while this planner was not in charge (as many as
        its agent keeps for late joiners), with their order of arrival: a journal's mission
        resumed once it takes charge must know what the robots did meanwhile."""
        self.arrivals = itertools.count()
        self.make_publishers()
        self.robot_states = subscription(self, ROBOT_STATES, self.on_robot_state, self.auth)
        self.task_events = subscription(self, TASK_EVENTS, self.on_event, self.auth)
        subscription(self, PLAN, self.on_plan, self.auth)
        subscription(self, MISSION_STATUS, self.on_status, self.auth)
        self.create_timer(0.1, self.tick)
        self.create_timer(status_period, self.publish_periodic)
        self.create_timer(DIAGNOSTICS_PERIOD, self.publish_diagnostics)
        self.get_logger().info(f"listening for another planner on this ROS domain for "
                               f"{value['rival_timeout']:g} s before taking charge")

    def make_publishers(self) -> None:
        """Fresh writers of every topic the planner publishes: a planner that stood down
        leaves nothing latched for late joiners."""
        for name in ('plan_pub', 'status_pub', 'jobs_pub', 'event_pub', 'story_pub',
                     'diagnostics_pub'):
            if hasattr(self, name):
                self.destroy_publisher(getattr(self, name))
        self.plan_pub = publisher(self, PLAN)
        self.status_pub = publisher(self, MISSION_STATUS)
        self.jobs_pub = publisher(self, JOB_STATES)
        self.event_pub = publisher(self, TASK_EVENTS)
        self.story_pub = publisher(self, MISSION_EVENTS)
        self.diagnostics_pub = publisher(self, DIAGNOSTICS)

    def start_up(self) -> None:
        """What a planner does once it first takes charge: resume what its journal left
        unfinished, start the `scenario` parameter's mission."""
        resumed = self.resume_unfinished()
        log = self.get_logger()
        if self.startup is None:
            if not resumed:
                log.info('no scenario given: waiting for RunMission goals')
            return
        problem, text, scenario, panels, shift, origin = self.startup
        if resumed == origin or self.ran_before(origin):
            log.info(f"not starting '{scenario}' again: its mission is in the journal "
                     '(resumed or ended)')
        elif resumed:
            log.warning(f"not starting '{scenario}': the resumed mission runs on this fleet")
        else:
            log.info(f"scenario '{problem.name}' from {scenario}: {len(problem.jobs)} jobs, "
                     'robots ' + ', '.join(r.name for r in problem.robots))
            try:
                self.submit_mission(problem, text, problem.name, panels, shift, origin,
                                    self.settings())
            except (JournalError, ValueError) as error:
                log.error(f"cannot start '{scenario}': {error}")

    # --- who is in charge ------------------------------------------------------------------

    @property
    def speaking(self) -> bool:
        """In charge: it publishes what it decides. Listening or standing by, it is silent."""
        return self.charge.role == Role.IN_CHARGE

    def on_status(self, msg: MissionStatus) -> None:
        if msg.auth.sender == PLANNER_NODE and msg.auth.incarnation == self.incarnation:
            return  # its own
        if not self.auth.accept(msg, MISSION_STATUS_TOPIC, {PLANNER_NODE}):
            return
        state = STATE_FROM_MSG.get(msg.state)
        busy = bool(msg.queue) or (state is not None and state != MissionState.IDLE
                                   and not state.ended)
        self.charge.hear(msg.auth.incarnation, busy, msg.mission_id, seconds(msg.stamp),
                         self.wall())

    def take_role(self, change: Change) -> None:
        log = self.get_logger()
        if change.role == Role.IN_CHARGE:
            log.warning(f'in charge of the fleet: {change.why}')
            self.serve()
            if not self.started_up:
                self.started_up = True
                self.start_up()
            self.use_unheard()
            self.publish_status()
            return
        leader = self.charge.leader()
        log.warning(f'standing by: {change.why}. This planner serves no mission request and '
                    'publishes nothing until it has heard no other planner for '
                    f'{self.charge.timeout:g} s')
        spoke = self.servers is not None
        self.carry_out(self.controller.stand_down(f'another planner is in charge: {leader}'))
        if spoke:
            self.withdraw_at = self.wall() + WITHDRAW_GRACE
            self.make_publishers()

    def serve(self) -> None:
        self.withdraw_at = None
        if self.servers is not None:
            return
        self.servers = [
            ActionServer(self, RunMission, RUN_MISSION_ACTION, self.execute_goal,
                         goal_callback=lambda _: GoalResponse.ACCEPT,
                         cancel_callback=self.cancel_goal),
            self.create_service(AddJobs, ADD_JOBS_SERVICE, self.answer_once(self.on_add_jobs)),
            self.create_service(CancelMission, CANCEL_MISSION_SERVICE,
                                self.answer_once(self.on_cancel))]

    def withdraw(self) -> None:
        """Serve mission requests no more: clients reach only the planner in charge."""
        action, *services = self.servers
        action.destroy()
        for service in services:
            self.destroy_service(service)
        self.servers = self.withdraw_at = None

    # --- parameters and time -------------------------------------------------------------

    def settings(self) -> Settings:
        return Settings.from_parameters({name: self.get_parameter(name).value
                                         for name in SETTINGS_PARAMETERS})

    def wall(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    # --- missions --------------------------------------------------------------------------

    def submit_mission(self, problem, text, name, panels, shift, origin, settings,
                       queue: bool = True) -> tuple[str, int]:
        """Start a mission, or queue it behind the running one unless `queue` is False; its
        id and place in the queue (0: started). ValueError saying why if it cannot be taken,
        JournalError if its journal cannot be written: it is refused before it is taken."""
        if self.journal_blocked is not None:
            raise ValueError(f"mission '{self.journal_blocked[0]}' is set aside until its "
                             'journal can be written: no mission is taken meanwhile')
        mission_id = new_mission_id(problem.name)
        journal = None
        if self.journal_dir is not None:
            journal = Journal(journal_path(self.journal_dir, mission_id))
            try:
                journal.write(MissionRecord(mission_id, text, name, panels, shift, origin,
                                            settings.__dict__, self.wall(),
                                            queued=self.controller.busy))
            except JournalError:
                journal.discard()
                raise
        try:
            position, effects = self.controller.submit(problem, mission_id, self.wall(),
                                                       settings, queue)
        except ValueError:
            if journal is not None:
                journal.discard()
            raise
        if journal is not None:
            if position:
                journal.close()
            else:
                self.journal = journal
        self.get_logger().info(f"mission '{mission_id}' accepted"
                               + (f', queued at position {position}' if position else ''))
        for warning in scenario_warnings(problem):
            self.get_logger().warning(f'scenario {problem.name!r}: {warning}')
        self.carry_out(effects)
        return mission_id, position

    def begin(self) -> None:
        """The controller's mission has just started: a queued one's journal says so."""
        mission = self.controller.mission
        if self.journal_dir is None:
            return
        path = journal_path(self.journal_dir, mission.id)
        if self.journal is not None and self.journal.path == path:
            return
        self.journal = Journal(path)
        self.journal.write(StartRecord(self.wall()))
        self.get_logger().info(f"mission '{mission.id}' starts: its turn in the queue came")

    def resume_unfinished(self) -> str:
        """Resume the newest mission a previous planner left running, and queue again the
        missions it left waiting; the resumed one's origin ('' if none). Older unfinished
        ones are closed as abandoned."""
        if self.journal_dir is None:
            return ''
        unfinished = [(path, records) for path, records in journals(self.journal_dir)
                      if not isinstance(records[-1], EndRecord)]
        started = [(path, records) for path, records in unfinished
                   if not waits_in_queue(records)]
        origin = self.resume(started) if started else ''
        # A mission set aside and tried again finds its queue still in memory.
        self.requeue([(path, records) for path, records in unfinished
                      if waits_in_queue(records)
                      and not self.controller.position(records[0].mission_id)])
        return origin

    def resume(self, started) -> str:
        log = self.get_logger()
        for path, _ in started[:-1]:
            why = close_journal(path, EndRecord('failed', ('abandoned: a newer mission was '
                                                           'resumed',)))
            if why:
                log.warning(f'cannot close an abandoned mission: {why}')
        path, records = started[-1]
        head: MissionRecord = records[0]
        try:
            problem, settings = self.journaled(records)
        except ProblemError as error:
            log.error(f'cannot resume the mission of {path}: ' + '; '.join(error.problems))
            return ''
        try:
            self.journal = Journal(path)
        except JournalError as error:
            self.journal_blocked = (head.mission_id, f'cannot resume: {error}', self.wall())
            log.error(f"mission '{head.mission_id}' {self.journal_blocked[1]}")
            return head.origin
        log.warning(f"resuming mission '{head.mission_id}' from {path}")
        self.carry_out(self.controller.resume(head.mission_id, problem, settings,
                                              head.accepted, records[1:], self.wall()))
        if self.journal is None:
            return head.origin  # set aside again
        self.publish_journaled_plan(head.mission_id)
        # The previous process's event history died with it, and a completion it published
        # just before it was killed may never have reached anyone: declared again, with its
        # own id, so those who heard it recognise it.
        for record in records:
            if isinstance(record, DoneRecord) and record.event_id:
                self.publish_done_event(record.event_id, head.mission_id, record.assignment.job,
                                        record.revision, float(record.assignment.end))
        return head.origin

    def requeue(self, waiting) -> None:
        """Queue again, in their order, the missions a previous planner left waiting."""
        for path, records in waiting:
            head: MissionRecord = records[0]
            try:
                problem, settings = self.journaled(records)
            except ProblemError as error:
                why = close_journal(path, EndRecord('failed', tuple(error.problems)))
                self.get_logger().error(f'cannot queue the mission of {path} again: '
                                        + '; '.join(error.problems)
                                        + (f' (and cannot close it: {why})' if why else ''))
                continue
            position = self.controller.requeue(problem, head.mission_id, head.accepted,
                                               settings)
            self.get_logger().warning(f"mission '{head.mission_id}' waits in the queue again "
                                      f'(position {position}), from {path}')

    def journaled(self, records) -> tuple[Problem, Settings]:
        """The problem (with the jobs added to it) and settings of the mission journaled in
        `records`; ProblemError if its scenario does not load any more."""
        head: MissionRecord = records[0]
        problem = scenario_from_text(head.scenario_yaml, head.scenario_name,
                                     head.panels or None, head.shift if head.shift >= 0 else None)
        for record in records:
            if isinstance(record, JobsAddedRecord):
                problem, _ = extend(problem, record.fragment_yaml)
        return problem, Settings(**{**self.settings().__dict__, **head.settings})

    def publish_journaled_plan(self, mission_id: str) -> None:
        """Publish again the plan the previous process published last: killed while
        publishing it, it may have reached some subscribers and not others, and an agent
        following it reports work no one else could place."""
        path = plan_file(self.journal.path)
        revision = self.controller.mission.tracker.revision
        try:
            msg = deserialize_message(path.read_bytes(), Plan)
        except FileNotFoundError:
            return
        except Exception as error:  # noqa: BLE001 - any damage to the file means the same
            self.get_logger().warning(f'cannot publish the last plan again from {path}: '
                                      f'{error}')
            return
        if msg.mission_id != mission_id or msg.revision != revision:
            return
        self.last_published = (msg.mission_id, msg.revision, msg.stamp)
        self.last_plan = msg
        self.plan_pub.publish(self.auth.sign(msg, PLAN_TOPIC))
        self.get_logger().info(f'published plan revision {msg.revision} again, as journaled')

    def ran_before(self, origin: str) -> bool:
        return self.journal_dir is not None and any(
            records[0].origin == origin for _, records in journals(self.journal_dir))

    # --- missions as a service -----------------------------------------------------------

    async def execute_goal(self, handle):
        goal = handle.request
        why = self.auth.refusal(goal, RUN_MISSION_ACTION)
        if why:
            return self.reject(handle, [f'refused: {why}'])
        resent = next((g for g in self.goals.values()
                       if goal.request_id and g.request_id == goal.request_id), None)
        if resent is not None:
            return await self.take_over(handle, resent)
        try:
            problem, text, name = self.problem_of(goal)
        except ProblemError as error:
            return self.reject(handle, error.problems)
        defaults = self.settings()
        settings = Settings(**{**defaults.__dict__, **{
            key: value for key, value in (
                ('time_limit', goal.time_limit), ('replan_time_limit', goal.replan_time_limit),
                ('time_scale', goal.time_scale), ('blocked_timeout', goal.blocked_timeout))
            if value > 0}})
        try:
            mission_id, _ = self.submit_mission(
                problem, text, name, goal.panels, goal.shift,
                f'goal:{bytes(handle.goal_id.uuid).hex()}', settings, queue=not goal.no_queue)
        except ValueError as error:
            return self.reject(handle, [str(error)])
        self.goals[mission_id] = Goal(handle, mission_id)
        self.publish_feedback()
        return await self.follow(self.goals[mission_id])

    async def take_over(self, handle, superseded: 'Goal'):
        """A goal resent by a client that did not hear the first one accepted: it follows
        the mission the first one started, which answers no more."""
        self.goals[superseded.mission_id] = Goal(handle, superseded.mission_id)
        superseded.ended.set_result(None)
        self.publish_feedback()
        return await self.follow(self.goals[superseded.mission_id])

    async def follow(self, goal: 'Goal') -> RunMission.Result:
        """The goal's result once its mission ends (or it is superseded)."""
        ended = await goal.ended
        if ended is None:
            goal.handle.abort()
            return RunMission.Result(state=RunMission.Result.STATE_REJECTED, makespan=math.nan,
                                     planned_makespan=math.nan,
                                     reasons=['superseded: the same request was sent again'])
        if ended.state == RunMission.Result.STATE_COMPLETE:
            goal.handle.succeed()
        elif ended.state == RunMission.Result.STATE_CANCELLED \
                and goal.handle.is_cancel_requested:
            goal.handle.canceled()
        else:
            goal.handle.abort()
        return ended

    def answer_goal(self, mission_id: str, result: RunMission.Result) -> None:
        goal = self.goals.pop(mission_id, None)
        if goal is not None and not goal.ended.done():
            goal.ended.set_result(result)

    def problem_of(self, goal):
        """The goal's scenario: (problem, YAML text, name); ProblemError if it has problems."""
        if bool(goal.scenario_path) == bool(goal.scenario_yaml):
            raise ProblemError(['give exactly one of scenario_path and scenario_yaml'])
        problems = []
        if not math.isfinite(goal.shift):
            problems.append(f'shift must be a finite number, got {goal.shift}')
        for key in ('time_limit', 'replan_time_limit', 'time_scale', 'blocked_timeout'):
            value = getattr(goal, key)
            if not (math.isfinite(value) and value >= 0):
                problems.append(f"{key} must be a finite number >= 0 (0: the planner's "
                                f'default), got {value}')
        if goal.panels > 50:
            problems.append(f'panels must be at most 50, got {goal.panels}')
        if problems:
            raise ProblemError(problems)
        panels = goal.panels or None
        shift = goal.shift if goal.shift >= 0 else None
        if goal.scenario_path:
            path = Path(goal.scenario_path)
            problem = load_scenario(path, panels=panels, shift=shift)
            return problem, path.read_text(), path.stem
        name = goal.scenario_name or 'mission'
        problem = scenario_from_text(goal.scenario_yaml, name, panels, shift)
        return problem, goal.scenario_yaml, name

    def reject(self, handle, reasons) -> RunMission.Result:
        self.get_logger().warning('RunMission goal rejected: '
                                  + shorten('; '.join(reasons), 2000))
        handle.abort()
        return RunMission.Result(state=RunMission.Result.STATE_REJECTED,
                                 makespan=math.nan, planned_makespan=math.nan,
                                 reasons=list(reasons))

    def result_of(self, state: MissionState) -> RunMission.Result:
        """The result of the running mission, which ended in `state`."""
        view = self.controller.status(self.wall())
        complete = state == MissionState.COMPLETE
        if complete:
            code = RunMission.Result.STATE_COMPLETE
        elif state == MissionState.CANCELLED:
            code = RunMission.Result.STATE_CANCELLED
        else:
            code = (RunMission.Result.STATE_BLOCKED_TIMEOUT if view.blocked_too_long
                    else RunMission.Result.STATE_FAILED)
        return RunMission.Result(
            mission_id=view.mission_id, state=code,
            makespan=view.projected_makespan if complete else math.nan,
            planned_makespan=view.planned_makespan, revisions=view.revision,
            jobs_done=view.jobs_done, jobs_total=view.jobs_total,
            reasons=list(view.blocked) if not complete else
            ['executed makespan {}, planned {}'.format(
                *decimals(view.projected_makespan, view.planned_makespan))])

    def cancel_goal(self, handle) -> CancelResponse:
        goal = next((g for g in self.goals.values() if g.handle.goal_id == handle.goal_id),
                    None)
        if goal is None:
            return CancelResponse.REJECT
        if self.auth.enabled:
            # An action's cancel request carries nothing to sign: in an authenticated fleet,
            # missions are cancelled through the signed cancel_mission service.
            self.get_logger().warning('refusing an unsigned cancel of the RunMission goal: '
                                      f'use the {CANCEL_MISSION_SERVICE} service')
            return CancelResponse.REJECT
        self.carry_out(self.controller.cancel(goal.mission_id,
                                              'cancelled by the RunMission client',
                                              self.wall()))
        return CancelResponse.ACCEPT

    def answer_once(self, handle):
        """`handle` for a service whose callers resend a request until they get its answer
        (a fresh client's first answer can be lost): a request id seen before gets the answer
        it got then, and nothing is done twice."""
        answers: dict[str, object] = {}

        def answer(request, response):
            if request.request_id in answers:
                return answers[request.request_id]
            response = handle(request, response)
            if request.request_id:
                answers[request.request_id[:100]] = response
                while len(answers) > ANSWERS_KEPT:
                    answers.pop(next(iter(answers)))
            return response

        return answer

    def refused(self, service: str, request, response, why: str):
        """`response` refusing `request`, with why; logged."""
        response.success, response.message = False, why
        self.get_logger().warning(f"{service} request of '{shorten(request.auth.sender, 80)}' "
                                  f'refused: {shorten(why, 500)}')
        return response

    def on_cancel(self, request, response):
        why = self.auth.refusal(request, CANCEL_MISSION_SERVICE, service=True)
        if why:
            return self.refused(CANCEL_MISSION_SERVICE, request, response, f'refused: {why}')
        queued = self.controller.position(request.mission_id) > 0
        try:
            effects = self.controller.cancel(request.mission_id,
                                             shorten(request.reason, 500) or 'cancelled',
                                             self.wall())
        except ValueError as error:
            return self.refused(CANCEL_MISSION_SERVICE, request, response, str(error))
        self.carry_out(effects)
        response.success = True
        response.message = f"mission '{request.mission_id}' " + (
            'taken out of the queue' if queued else 'cancelled')
        return response

    def on_add_jobs(self, request, response):
        why = self.auth.refusal(request, ADD_JOBS_SERVICE, service=True)
        if why:
            return self.refused(ADD_JOBS_SERVICE, request, response, f'refused: {why}')
        try:
            mission = self.controller.running(request.mission_id)
        except ValueError as error:
            return self.refused(ADD_JOBS_SERVICE, request, response, str(error))
        tracker = mission.tracker
        try:
            problem, jobs = extend(mission.problem, request.fragment_yaml,
                                   tracker.done | tracker.running)
        except ProblemError as error:
            response.success = False
            response.message = f'{len(error.problems)} problem(s); the mission is unchanged'
            response.problems = [shorten(p, 500) for p in error.problems]
            return response
        if self.journal is not None:
            try:
                self.journal.write(JobsAddedRecord(request.fragment_yaml, jobs))
            except JournalError as error:
                response.message = f'{error}; the mission is unchanged'
                return response
        self.carry_out(self.controller.add_jobs(problem, jobs, self.wall()))
        response.success, response.jobs = True, list(jobs)
        response.message = f"{len(jobs)} job(s) added to mission '{mission.id}'"
        return response

    # --- inputs ------------------------------------------------------------------------------

    def tick(self) -> None:
        self.controller.settings = self.settings()
        wall = self.wall()
        change = self.charge.update(self.controller.busy, wall)
        if change is not None:
            self.take_role(change)
        if self.withdraw_at is not None and wall >= self.withdraw_at:
            self.withdraw()
        if self.journal_blocked is not None:
            if wall - self.journal_blocked[2] < JOURNAL_RETRY:
                return
            # The queue waits meanwhile: its missions must not start before the one set aside.
            self.journal_blocked = None
            self.resume_unfinished()
            if self.journal_blocked is not None:
                return
        # Robots are judged silent by what has arrived, not by what the executor served.
        catch_up(self.task_events)
        catch_up(self.robot_states)
        self.carry_out(self.controller.tick(self.wall(), self.plan_pub.get_subscription_count(),
                                            self.auth.rejected))

    def on_robot_state(self, msg: RobotState) -> None:
        why = self.auth.refusal(msg, ROBOT_STATES_TOPIC, {msg.robot})
        if why:
            self.controller.unverified_state(msg.robot, why, self.wall())
            return
        mode = MODE_FROM_MSG.get(msg.mode)
        if mode is None:
            self.ignore(Ignored.UNKNOWN, f"state of robot '{shorten(msg.robot, 80)}' has "
                                         f'unknown mode {msg.mode}')
            return
        report = RobotReport(
            robot=msg.robot, mode=mode, incarnation=msg.incarnation, mission_id=msg.mission_id,
            revision=msg.plan_revision, refusal=msg.refusal, failures=msg.failures,
            robot_type=msg.robot_type, location=msg.location, destination=msg.destination,
            busy_until=msg.busy_until, progress=msg.progress, current_job=msg.current_job,
            last_event=msg.last_event_id, refused=msg.refused)
        self.carry_out(self.controller.robot_state(report, self.wall()))

    def on_event(self, msg: TaskEvent) -> None:
        if msg.kind == TaskEvent.KIND_JOB_DONE and msg.event_id in self.job_done_ids:
            return  # its own
        senders = {PLANNER_NODE} if msg.kind == TaskEvent.KIND_JOB_DONE else {msg.robot}
        if not self.auth.accept(msg, TASK_EVENTS_TOPIC, senders):
            return
        if self.speaking:
            self.use_event(msg)
            return
        history = self.unheard.get(msg.robot)
        if history is None and len(self.unheard) < MAX_FLEET:
            history = self.unheard[msg.robot] = deque(maxlen=EVENT_HISTORY)
        if history is not None:
            history.append((next(self.arrivals), msg))

    def use_unheard(self) -> None:
        """Give the controller the task events heard while this planner was not in charge,
        in their order."""
        unheard = sorted((item for history in self.unheard.values() for item in history),
                         key=lambda item: item[0])
        self.unheard = {}
        for _, msg in unheard:
            self.use_event(msg)

    def use_event(self, msg: TaskEvent) -> None:
        kind = EVENT_FROM_MSG.get(msg.kind)
        if kind is None:
            self.ignore(Ignored.UNKNOWN, f"event '{shorten(msg.event_id)}': kind {msg.kind} "
                                         'is not a TaskEvent kind')
            return
        event = EventReport(msg.event_id, msg.mission_id, kind, msg.robot, msg.job,
                            msg.plan_revision, msg.time)
        effects, ignored = self.controller.task_event(event, self.wall())
        if ignored:
            self.get_logger().warning(f'ignoring {shorten(ignored, 300)}')
            self.publish_status()
        self.carry_out(effects)

    def on_plan(self, msg: Plan) -> None:
        if (msg.mission_id, msg.revision, msg.stamp) == self.last_published \
                or not self.speaking:
            return  # its own, or the plan of the planner in charge
        if not self.auth.accept(msg, PLAN_TOPIC, {PLANNER_NODE}):
            return
        current = self.controller.mission
        revision = current.tracker.revision if current is not None else 0
        stale = current is not None and msg.mission_id == current.id \
            and msg.revision <= revision
        self.ignore(Ignored.STALE if stale else Ignored.UNKNOWN,
                    f"{'stale' if stale else 'unknown'} plan revision {msg.revision} of "
                    f"mission '{shorten(msg.mission_id, 80)}' from another publisher: this "
                    f'planner owns the plan (revision {revision})')

    def ignore(self, kind: Ignored, why: str) -> None:
        mission = self.controller.mission
        if mission is not None:
            mission.tracker.ignored[kind] += 1
        self.get_logger().warning(f'ignoring {why}')
        self.publish_status()

    # --- solving ------------------------------------------------------------------------------

    def solve(self, request: Solve) -> None:
        workers = self.get_parameter('workers').value
        if request.kind == SolveKind.PLAN:
            self.get_logger().info(f'solving with {self.solver}, time limit '
                                   f'{request.time_limit:g} s, {workers} workers')
            future = self.pool.submit(solve, request.problem, solver=self.solver,
                                      time_limit=request.time_limit, workers=workers)
        elif request.kind == SolveKind.REPAIR:
            self.replan_began = time.monotonic()
            now_units = self.controller.now_units(self.wall())
            self.get_logger().warning(f're-planning at t={decimal(now_units)}: '
                                      + shorten('; '.join(request.reasons), 2000))
            future = self.pool.submit(repair, request.problem, request.previous,
                                      request.state, time_limit=request.time_limit)
        else:
            future = self.pool.submit(improve, request.published,
                                      time_limit=request.time_limit, workers=workers,
                                      frozen_until=request.frozen_until,
                                      started=request.started)
        self.solves[request.token] = future
        future.add_done_callback(self.wake)

    def wake(self, _future) -> None:
        """Have the executor collect a finished solve (called in the solver's thread)."""
        with self.waking:
            if not self.closing:
                self.solved_guard.trigger()

    def collect_solves(self) -> None:
        for token, future in list(self.solves.items()):
            if not future.done():
                continue
            del self.solves[token]
            try:
                outcome = future.result()
            except Exception as error:  # noqa: BLE001  a solver's fault must not stop the fleet
                self.get_logger().error(f'solve failed: {type(error).__name__}: '
                                        f'{shorten(str(error), 500)}')
                outcome = error
            self.carry_out(self.controller.solved(token, outcome, self.wall()))

    # --- outputs ------------------------------------------------------------------------------

    def carry_out(self, effects) -> None:
        if not effects:
            return
        try:
            for effect in effects:
                if isinstance(effect, Solve):
                    self.solve(effect)
                elif isinstance(effect, PublishPlan):
                    self.publish_plan(effect)
                elif isinstance(effect, ResendPlan):
                    self.resend_plan(effect)
                elif isinstance(effect, JobDone):
                    self.publish_job_done(effect)
                elif isinstance(effect, Note):
                    if effect.kind == MissionEventKind.MISSION_STARTED:
                        self.begin()
                    self.tell(effect)
                    if effect.kind in ENDINGS:
                        self.end(ENDINGS[effect.kind], effect.reasons)
                elif isinstance(effect, LeftQueue):
                    self.left_queue(effect)
        except JournalError as error:
            self.set_aside(error)
        self.publish_jobs()
        self.publish_status()

    def set_aside(self, error: JournalError) -> None:
        """The journal cannot take what the mission must record before the fleet hears it:
        nothing more is published. The mission is dropped as a planner that died would drop
        it, and resumed from its journal and the robots' histories (as after a restart) once
        the journal can be written again; meanwhile the robots finish what they were given
        and wait, and the status says why."""
        mission = self.controller.forget()
        if self.journal is not None:
            self.journal.close()
        self.journal = None
        self.solves.clear()
        self.journal_blocked = (mission.id, f'{error}; nothing more is planned or declared '
                                f'done until it can be written (tried again every '
                                f'{JOURNAL_RETRY:g} s)', self.wall())
        self.get_logger().error(f"mission '{mission.id}' set aside: "
                                f'{self.journal_blocked[1]}')

    def end(self, state: MissionState, reasons) -> None:
        """The running mission ended: its journal is closed and its goal answered."""
        if self.journal is not None:
            try:
                self.journal.write(EndRecord(str(state), tuple(reasons)))
            except JournalError as error:
                self.get_logger().error(f'the end of the mission is not journaled: {error}')
            self.journal.close()
            plan_file(self.journal.path).unlink(missing_ok=True)
            self.journal = None
        self.answer_goal(self.controller.mission.id, self.result_of(state))

    def left_queue(self, effect: LeftQueue) -> None:
        why = '' if self.journal_dir is None else close_journal(
            journal_path(self.journal_dir, effect.mission_id),
            EndRecord(str(effect.state), effect.reasons))
        if why:
            self.get_logger().error(f"the end of mission '{effect.mission_id}' is not "
                                    f'journaled: {why}')
        self.get_logger().warning(f"mission '{effect.mission_id}' left the queue, "
                                  f'{effect.state}: ' + shorten('; '.join(effect.reasons), 500))
        self.answer_goal(effect.mission_id, RunMission.Result(
            mission_id=effect.mission_id, state=RESULT_OF[effect.state], makespan=math.nan,
            planned_makespan=math.nan, reasons=list(effect.reasons)))

    def publish_plan(self, effect: PublishPlan) -> None:
        mission = self.controller.mission
        stamp = self.get_clock().now().to_msg()
        start = Time(nanoseconds=int(effect.mission_start * 1e9)).to_msg()
        if effect.cancelled:
            msg = cancel_msg(mission.problem, mission.id, effect.revision, start,
                             mission.settings.time_scale, stamp, effect.reasons)
        else:
            msg = plan_msg(mission.problem, effect.posed, effect.result.schedule, effect.result,
                           mission.id, effect.revision, start, mission.settings.time_scale,
                           stamp, effect.restarted_in, effect.reasons, effect.incarnations)
        if self.journal is not None:
            # On disk before any robot can follow it; the message first: a restarted planner
            # publishes it again only if the journal's latest revision is its own.
            write_plan_file(plan_file(self.journal.path), msg)
            self.journal.write(PlanRecord(
                effect.revision, effect.mission_start,
                None if effect.cancelled else effect.result.schedule, effect.continued,
                effect.reasons, dict(effect.starts), dict(effect.incarnations)))
        self.last_published = (msg.mission_id, msg.revision, msg.stamp)
        self.last_plan = msg
        self.plan_pub.publish(self.auth.sign(msg, PLAN_TOPIC))
        log = self.get_logger()
        if effect.cancelled:
            log.warning(f'published plan revision {effect.revision}: mission cancelled')
            return
        result = effect.result
        self.solver_answer = (str(result.status), result.gap)
        if effect.revision > 1 and self.replan_began is not None:
            self.replan_latency, self.replan_began = time.monotonic() - self.replan_began, None
        gap = f', gap {result.gap:.1%}' if result.gap is not None else ''
        now_units = self.controller.now_units(self.wall())
        log.info(f'published plan revision {effect.revision}: makespan '
                 f'{decimal(result.makespan)} ({result.status}{gap}, '
                 f'{result.solve_seconds:.2f} s)'
                 + (f'; mission starts in {self.start_delay:g} s at {self.time_scale:g} s '
                    'per unit' if effect.revision == 1 else f' at t={decimal(now_units)}'))
        for robot_plan in msg.robots:
            log.info(f'  {robot_plan.robot}: '
                     + (' -> '.join(t.job for t in robot_plan.tasks) or 'no task'))

    def resend_plan(self, effect: ResendPlan) -> None:
        msg = self.last_plan
        if msg is None or msg.revision != effect.revision:
            return
        # A subscription that has not matched the writer in seconds may never match it; a new
        # writer is announced to every subscription afresh.
        self.destroy_publisher(self.plan_pub)
        self.plan_pub = publisher(self, PLAN)
        self.plan_pub.publish(self.auth.sign(msg, PLAN_TOPIC))
        self.get_logger().warning(f'published plan revision {msg.revision} again, on a new '
                                  'writer')

    def publish_job_done(self, effect: JobDone) -> None:
        mission = self.controller.mission
        self.event_count += 1
        event_id = f'planner/{self.incarnation}/{self.event_count}'
        if self.journal is not None:
            # On disk before the fleet hears of it: a planner killed after publishing would
            # otherwise rebuild the job from the agents' event histories once restarted, and
            # declare it done a second time.
            self.journal.write(DoneRecord(effect.assignment, effect.revision, event_id))
        self.publish_done_event(event_id, mission.id, effect.job, effect.revision, effect.time)
        tracker = mission.tracker
        self.get_logger().info(f'job {effect.job} done at t={decimal(effect.time)} '
                               f'({len(tracker.done)}/{len(tracker.jobs)})')

    def publish_done_event(self, event_id: str, mission_id: str, job: str, revision: int,
                           time: float) -> None:
        self.job_done_ids.add(event_id)
        self.event_pub.publish(self.auth.sign(TaskEvent(
            stamp=self.get_clock().now().to_msg(), event_id=event_id, mission_id=mission_id,
            kind=TaskEvent.KIND_JOB_DONE, job=job, plan_revision=revision, time=time),
            TASK_EVENTS_TOPIC))

    def tell(self, note: Note) -> None:
        mission = self.controller.mission
        wall = self.wall()
        self.get_logger().info(shorten(describe(note), 2000))
        if not self.speaking:
            return
        self.event_count += 1
        self.story_pub.publish(self.auth.sign(MissionEvent(
            stamp=self.get_clock().now().to_msg(),
            event_id=f'planner/{self.incarnation}/{self.event_count}', mission_id=mission.id,
            kind=MISSION_EVENT_TO_MSG[note.kind],
            plan_revision=mission.tracker.revision if note.revision is None else note.revision,
            time=max(self.controller.now_units(wall), 0.0), robot=note.robot, job=note.job,
            reasons=list(note.reasons)), MISSION_EVENTS_TOPIC))

    def publish_diagnostics(self) -> None:
        if not self.speaking:
            return
        view = self.controller.status(self.wall())
        if view is None:
            self.diagnostics_pub.publish(diagnostic_array(
                self.get_clock().now().to_msg(),
                [planner_diagnostic(f'{self.get_name()}: mission', MissionState.IDLE)]))
            return
        status, gap = self.solver_answer
        self.diagnostics_pub.publish(diagnostic_array(
            self.get_clock().now().to_msg(),
            [planner_diagnostic(f'{self.get_name()}: mission', view.state,
                                mission_id=view.mission_id, revision=view.revision,
                                jobs_done=view.jobs_done, jobs_total=view.jobs_total,
                                solver_status=status, gap=gap,
                                replan_latency=self.replan_latency,
                                blocked_reasons=view.blocked, warnings=view.warnings)]))

    def publish_periodic(self) -> None:
        self.publish_status()
        self.publish_jobs()

    def publish_jobs(self) -> None:
        mission = self.controller.mission
        if not self.speaking or mission is None or mission.tracker.plan is None:
            return
        self.jobs_pub.publish(self.auth.sign(JobStates(
            stamp=self.get_clock().now().to_msg(), mission_id=mission.id,
            plan_revision=mission.tracker.revision, jobs=job_states(mission.tracker)),
            JOB_STATES_TOPIC))

    def publish_feedback(self, view=None) -> None:
        """Feedback to each goal: its running mission's state, or its place in the queue."""
        view = view or self.controller.status(self.wall())
        for mission_id, goal in self.goals.items():
            waiting = self.controller.waiting(mission_id)
            if waiting is not None:
                feedback = RunMission.Feedback(
                    mission_id=mission_id, state=STATE_TO_MSG[MissionState.QUEUED],
                    queue_position=self.controller.position(mission_id),
                    jobs_total=len(waiting.problem.jobs), planned_makespan=math.nan,
                    projected_makespan=math.nan)
            elif view is not None and view.mission_id == mission_id:
                feedback = RunMission.Feedback(
                    mission_id=view.mission_id, state=STATE_TO_MSG[view.state],
                    plan_revision=view.revision, jobs_done=view.jobs_done,
                    jobs_running=view.jobs_running, jobs_total=view.jobs_total,
                    planned_makespan=view.planned_makespan,
                    projected_makespan=view.projected_makespan, elapsed=view.elapsed,
                    reasons=list(view.blocked or view.replan_reasons))
            else:
                continue
            goal.handle.publish_feedback(feedback)

    def publish_status(self) -> None:
        if not self.speaking:
            return
        view = self.controller.status(self.wall())
        if view is None and self.journal_blocked is not None:
            mission_id, why, _ = self.journal_blocked
            self.status_pub.publish(self.auth.sign(MissionStatus(
                stamp=self.get_clock().now().to_msg(), mission_id=mission_id,
                state=STATE_TO_MSG[MissionState.BLOCKED], blocked_reasons=[why],
                planned_makespan=math.nan, projected_makespan=math.nan,
                ignored_unauthenticated=self.auth.rejected), MISSION_STATUS_TOPIC))
            return
        if view is None:
            # Heard by `mission status`, monitors and recorders before any mission: they
            # know the planner is there, waiting for one.
            self.status_pub.publish(self.auth.sign(MissionStatus(
                stamp=self.get_clock().now().to_msg(),
                state=STATE_TO_MSG[MissionState.IDLE],
                ignored_unauthenticated=self.auth.rejected), MISSION_STATUS_TOPIC))
            return
        self.publish_feedback(view)
        ignored = view.ignored
        self.status_pub.publish(self.auth.sign(MissionStatus(
            stamp=self.get_clock().now().to_msg(), mission_id=view.mission_id,
            state=STATE_TO_MSG[view.state], plan_revision=view.revision,
            scenario_id=view.scenario, jobs_done=view.jobs_done,
            jobs_running=view.jobs_running, jobs_total=view.jobs_total,
            planned_makespan=view.planned_makespan,
            projected_makespan=view.projected_makespan, elapsed=view.elapsed,
            blocked_reasons=list(view.blocked), replan_reasons=list(view.replan_reasons),
            warnings=list(view.warnings), queue=list(view.queue),
            ignored_stale=ignored[Ignored.STALE], ignored_duplicate=ignored[Ignored.DUPLICATE],
            ignored_unknown=ignored[Ignored.UNKNOWN],
            ignored_unauthenticated=self.auth.rejected), MISSION_STATUS_TOPIC))

    def destroy_node(self):
        with self.waking:
            self.closing = True
        self.pool.shutdown(wait=False, cancel_futures=True)
        if self.journal is not None:
            self.journal.close()
        return super().destroy_node()


def close_journal(path: Path, end: EndRecord) -> str:
    """End the journal of a mission that is not the running one; why it cannot be ('' once
    it is)."""
    try:
        journal = Journal(path)
        try:
            journal.write(end)
        finally:
            journal.close()
    except JournalError as error:
        return str(error)
    return ''


def plan_file(journal: Path) -> Path:
    """Where the latest plan message of the mission journaled in `journal` is kept."""
    return journal.with_name(journal.name + '.plan')


def write_plan_file(path: Path, msg: Plan) -> None:
    """`msg` in `path`, whole or not at all: a process killed while writing leaves the
    previous one."""
    partial = path.with_name(path.name + '.partial')
    try:
        partial.write_bytes(serialize_message(msg))
        partial.replace(path)
    except OSError as error:
        partial.unlink(missing_ok=True)
        raise JournalError(f'{path}: cannot write the plan: {error.strerror or error}'
                           ) from None


def main(args=None):
    sys.exit(run_node(PlannerNode, PLANNER_NODE, args))
