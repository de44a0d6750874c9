"""Submit, follow, extend and cancel missions on a running fleet, from a shell or a script.

    ros2 run fjsp_planner mission submit SCENARIO [--panels N] [--time-scale S] [--wait]
                                                  [--no-queue]
    ros2 run fjsp_planner mission cancel [--mission ID] [--reason TEXT]
    ros2 run fjsp_planner mission add FRAGMENT.yaml [--mission ID]
    ros2 run fjsp_planner mission status

From Python (a test script, a mission monitor):

    from fjsp_planner.missions import MissionClient

    with MissionClient() as client:
        mission = client.submit('config/scenarios/truss.yaml', feedback=print)
        client.add_jobs('more_jobs.yaml')
        result = mission.result(timeout=120)       # MissionResult: state, makespan, ...

The client owns a private ROS context, node and executor thread, so it works whether or not
the caller uses rclpy, and never spins (or waits on) the caller's nodes. It discovers the
planner once and stays ready: keep one client for a whole script. A scenario file is sent as
its YAML text, so the planner may run on another machine. A mission submitted while another
runs waits its turn in the planner's queue. Requests that change a mission name it: `cancel`
and `add_jobs` without a mission id are for the running mission, as the planner's status
names it.
"""

import argparse
import math
import sys
import threading
import time
import uuid
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from fjsp_common.decimals import decimal, decimals
from fjsp_common.fleet import PLANNER_NODE

RESEND = 1.0
"""Seconds without an answer after which a request is sent again."""
SEND_TIMEOUT = 10.0
"""Seconds a request may wait for the client's executor thread to send it."""
SILENCE = 10.0
"""Seconds without feedback on a submitted mission after which the planner is taken for gone:
it gives feedback with every status it publishes (every `status_period`, 0.5 s by default)."""
RESULT_STATES = ('complete', 'cancelled', 'failed', 'blocked too long', 'rejected')
"""RunMission.Result.STATE_* in order."""


class MissionError(RuntimeError):
    """A request the fleet did not take: nobody answering, or refused (with its reasons)."""

    def __init__(self, message: str, problems=()):
        self.problems = list(problems)
        super().__init__('\n'.join([message, *self.problems]))


@dataclass(frozen=True)
class MissionResult:
    mission_id: str
    state: str
    """One of RESULT_STATES."""
    makespan: float
    planned_makespan: float
    revisions: int
    jobs_done: int
    jobs_total: int
    reasons: tuple[str, ...]

    @property
    def complete(self) -> bool:
        return self.state == 'complete'


class _Feedback:
    """What the planner said of one goal so far: called with each feedback message."""

    def __init__(self, user=None):
        self.user = user
        self.first = threading.Event()
        self.mission_id = ''
        self.queue_position = 0
        self.heard = time.monotonic()

    def __call__(self, msg):
        feedback = msg.feedback
        self.heard = time.monotonic()
        self.mission_id = self.mission_id or feedback.mission_id
        self.queue_position = feedback.queue_position
        self.first.set()
        if self.user is not None:
            self.user(feedback)


class MissionHandle:
    """A submitted mission: its id, its place in the queue, its feedback as it comes, its
    result when it ends."""

    def __init__(self, client: 'MissionClient', goal_handle, feedback: _Feedback):
        self._client = client
        self._goal = goal_handle
        self._feedback = feedback
        self.mission_id = ''
        self._result = client._sent(goal_handle.get_result_async)
        self._ended = threading.Event()
        self._result.add_done_callback(lambda _: self._ended.set())

    @property
    def queue_position(self) -> int:
        """Where the mission waits in the planner's queue (1: next), as last heard; 0 once
        it runs."""
        return self._feedback.queue_position

    def result(self, timeout: float | None = None, silence: float | None = SILENCE
               ) -> MissionResult:
        """Wait for the mission to end; MissionError after `timeout` seconds, or once the
        planner has said nothing of the mission for `silence` seconds (it stopped, or the
        link to it is down: its result would never come)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while not self._ended.wait(0.2):
            now = time.monotonic()
            if deadline is not None and now >= deadline:
                raise MissionError(f"mission '{self.mission_id}' did not end within "
                                   f'{timeout:g} s')
            if silence is not None and now - self._feedback.heard > silence:
                gone = '' if self._client._action.server_is_ready() else \
                    f"; no planner serves '{self._client._action_name}' any more"
                raise MissionError(
                    f"the planner has said nothing of mission '{self.mission_id}' for "
                    f'{silence:g} s{gone}: it stopped, or the link to it is down, and the '
                    "mission's result will not come ('mission status' says what runs now)")
        return _result(self._result.result().result)

    def cancel(self, timeout: float = 10.0) -> None:
        if self._client._signer.key is not None:
            # An action's cancel cannot be signed; the signed service does the same.
            self._client.cancel(self.mission_id, timeout=timeout)
            return
        future = self._client._sent(self._goal.cancel_goal_async)
        if not self._client._wait(future, timeout):
            raise MissionError('the planner did not answer the cancel request within '
                               f'{timeout:g} s')
        if not future.result().goals_canceling:
            raise MissionError(f"mission '{self.mission_id}' could not be cancelled: it has "
                               'ended already')


class MissionClient:
    """Talks to the planner of the fleet on this ROS domain (ROS_DOMAIN_ID and the other
    ROS variables apply, `domain_id` overrides the first); `args` are ROS arguments, e.g.
    ['--ros-args', '-r', '__ns:=/cell1']. Requests are signed with the fleet key in
    `key_file` (default: the file named by $FJSP_FLEET_KEY_FILE; none: unsigned)."""

    def __init__(self, args=None, domain_id: int | None = None, key_file=None):
        import rclpy
        from rclpy.action import ActionClient
        from rclpy.executors import SingleThreadedExecutor

        from fjsp_common.auth import FleetKeyError, Verifier, client_signer
        from fjsp_common.contract import (
            ADD_JOBS_SERVICE,
            CANCEL_MISSION_SERVICE,
            MISSION_STATUS,
            MISSION_STATUS_TOPIC,
            RUN_MISSION_ACTION,
            screened_subscription,
        )
        from fjsp_msgs.action import RunMission
        from fjsp_msgs.msg import MissionStatus
        from fjsp_msgs.srv import AddJobs, CancelMission

        try:
            self._signer = client_signer(key_file, 'mission_client')
        except FleetKeyError as error:
            raise MissionError(str(error)) from None
        self._context = rclpy.Context()
        try:
            rclpy.init(args=args, context=self._context, domain_id=domain_id)
        except RuntimeError as error:  # rclpy's RCLError, e.g. a bad ROS_DOMAIN_ID
            raise MissionError(f'could not start ROS: {error}') from None
        self._node = rclpy.create_node(f'mission_client_{time.time_ns()}',
                                       context=self._context)
        self._action_name = RUN_MISSION_ACTION
        self._action = ActionClient(self._node, RunMission, RUN_MISSION_ACTION)
        self._add = self._node.create_client(AddJobs, ADD_JOBS_SERVICE)
        self._cancel = self._node.create_client(CancelMission, CANCEL_MISSION_SERVICE)
        self._status = None
        self._status_seen = threading.Event()
        self._verifier = Verifier(self._signer.key)
        self._status_topic = self._node.resolve_topic_name(MISSION_STATUS_TOPIC)
        self.statuses_dropped: Counter[str] = Counter()
        """Mission statuses that do not verify with the fleet key, by reason: never shown."""
        screened_subscription(self._node, MissionStatus, MISSION_STATUS_TOPIC,
                              MISSION_STATUS.qos, self._on_status, self._verifier)
        self._executor = SingleThreadedExecutor(context=self._context)
        self._executor.add_node(self._node)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self):
        while self._context.ok():
            try:
                self._executor.spin_once(timeout_sec=0.1)
            except Exception:  # noqa: BLE001  the context went down between checks
                if self._context.ok():
                    raise

    def _on_status(self, msg):
        why = self._verifier.check(msg, self._status_topic, {PLANNER_NODE})
        if why:
            self.statuses_dropped[why] += 1
            return
        self._status = msg
        self._status_seen.set()

    def _sent(self, send):
        """What `send()` returns, called on the executor thread. rclpy's action client files
        a request only after sending it (ros2/rclpy#1123): an answer the executor thread took
        in between would be dropped and its request never answered. Sent from that thread, the
        answer is taken once the request is filed."""
        task = self._executor.create_task(send)
        if not self._wait(task, SEND_TIMEOUT):
            raise MissionError(f'the client could not send a request within {SEND_TIMEOUT:g} '
                               's: is it closed, or called from one of its own callbacks?')
        return task.result()

    def _wait(self, future, timeout) -> bool:
        done = threading.Event()
        future.add_done_callback(lambda _: done.set())
        return done.wait(timeout)

    def close(self) -> None:
        import rclpy

        self._executor.shutdown(timeout_sec=1.0)
        self._node.destroy_node()
        rclpy.try_shutdown(context=self._context)
        self._thread.join(timeout=2.0)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # --- requests --------------------------------------------------------------------------

    def submit(self, scenario=None, *, scenario_yaml: str = '', name: str = '',
               panels: int = 0, shift: float = -1.0, time_scale: float = 0.0,
               time_limit: float = 0.0, replan_time_limit: float = 0.0,
               blocked_timeout: float = 0.0, queue: bool = True, feedback=None,
               timeout: float = 10.0) -> MissionHandle:
        """Start a mission, or queue it behind the running one (with `queue` False, it is
        rejected instead): `scenario` is a file (sent as its text), or give the text as
        `scenario_yaml`. `feedback(RunMission.Feedback)` is called as the mission goes.
        MissionError if the planner does not answer within `timeout` or rejects it (with
        every problem of the scenario)."""
        from fjsp_msgs.action import RunMission

        if (scenario is None) == (not scenario_yaml):
            raise MissionError('give a scenario file or scenario_yaml (one of them)')
        if scenario is not None:
            path = Path(scenario)
            try:
                scenario_yaml = path.read_text()
            except (OSError, UnicodeDecodeError) as error:
                raise MissionError(f'{path}: cannot read the scenario: {error}') from None
            name = name or path.stem
        goal = RunMission.Goal(scenario_yaml=scenario_yaml, scenario_name=name, panels=panels,
                               shift=shift, time_limit=time_limit,
                               replan_time_limit=replan_time_limit, time_scale=time_scale,
                               blocked_timeout=blocked_timeout, no_queue=not queue)
        if not self._action.wait_for_server(timeout_sec=timeout):
            raise MissionError(f"no planner serves '{self._action_name}' (waited "
                               f'{timeout:g} s): is the planner running, with the same '
                               'ROS_DOMAIN_ID?')
        heard = _Feedback(feedback)
        # A fresh client's first answer can be lost: the goal is resent, with the same
        # request id, until one is answered; the planner hands the mission to the latest.
        goal.request_id = f'{self._node.get_name()}/{uuid.uuid4().hex}'
        deadline = time.monotonic() + timeout
        while True:
            self._signer.sign(goal, self._node.resolve_topic_name(self._action_name))
            accepted = self._sent(lambda: self._action.send_goal_async(
                goal, feedback_callback=heard))
            if self._wait(accepted, min(RESEND, max(deadline - time.monotonic(), 0.0))):
                break
            if time.monotonic() >= deadline:
                raise MissionError(f'the planner did not answer the goal within {timeout:g} s')
        goal_handle = accepted.result()
        if not goal_handle.accepted:
            raise MissionError('the planner refused the goal')
        heard.heard = time.monotonic()
        handle = MissionHandle(self, goal_handle, heard)
        # A mission started or queued names itself in its first feedback; a rejected one
        # ends at once.
        deadline = time.monotonic() + timeout
        while not heard.first.is_set() and not handle._ended.is_set() \
                and time.monotonic() < deadline:
            heard.first.wait(0.02)
        if handle._ended.is_set():
            result = _result(handle._result.result().result)
            if result.state == 'rejected':
                raise MissionError('mission rejected', result.reasons)
            handle.mission_id = result.mission_id
        elif heard.first.is_set():
            handle.mission_id = heard.mission_id
        else:
            raise MissionError(f'the planner accepted the goal but said nothing of it within '
                               f'{timeout:g} s')
        # The planner published the status naming a mission it started before its feedback,
        # on another topic: once it is here, `cancel()` and `add_jobs()` find the mission.
        while handle.queue_position == 0 and not handle._ended.is_set() \
                and getattr(self._status, 'mission_id', '') != handle.mission_id \
                and time.monotonic() < deadline:
            time.sleep(0.02)
        return handle

    def run(self, scenario=None, *, timeout: float | None = None, **goal) -> MissionResult:
        """`submit`, then wait up to `timeout` seconds for the result."""
        return self.submit(scenario, **goal).result(timeout)

    def cancel(self, mission_id: str = '', reason: str = '', timeout: float = 10.0) -> str:
        """Cancel mission `mission_id`, running or queued (default: the running one, as the
        planner's status names it); the planner's answer."""
        from fjsp_msgs.srv import CancelMission

        mission_id = mission_id or self.running_mission(timeout)
        response = self._call(self._cancel, CancelMission.Request(mission_id=mission_id,
                                                                  reason=reason), timeout)
        if not response.success:
            raise MissionError(response.message)
        return response.message

    def add_jobs(self, fragment=None, *, fragment_yaml: str = '', mission_id: str = '',
                 timeout: float = 10.0) -> list[str]:
        """Add the jobs of a scenario fragment (a file, or its text) to mission `mission_id`
        (default: the running one, as the planner's status names it); the names added.
        MissionError lists every problem of a refused fragment."""
        from fjsp_msgs.srv import AddJobs

        if (fragment is None) == (not fragment_yaml):
            raise MissionError('give a fragment file or fragment_yaml (one of them)')
        if fragment is not None:
            try:
                fragment_yaml = Path(fragment).read_text()
            except (OSError, UnicodeDecodeError) as error:
                raise MissionError(f'{fragment}: cannot read the fragment: {error}') from None
        mission_id = mission_id or self.running_mission(timeout)
        response = self._call(self._add, AddJobs.Request(mission_id=mission_id,
                                                         fragment_yaml=fragment_yaml), timeout)
        if not response.success:
            raise MissionError(response.message, response.problems)
        return list(response.jobs)

    def running_mission(self, timeout: float = 10.0) -> str:
        """The id of the mission running now, as the planner's status names it; MissionError
        if none runs."""
        from fjsp_common.contract import STATE_FROM_MSG
        from fjsp_common.vocabulary import MissionState

        status = self.status(timeout)
        state = STATE_FROM_MSG.get(status.state, f'state {status.state}')
        if state == MissionState.IDLE or not status.mission_id:
            raise MissionError('no mission runs: the planner waits for one')
        if state in (MissionState.COMPLETE, MissionState.CANCELLED, MissionState.FAILED):
            raise MissionError(f"no mission runs: the last one, '{status.mission_id}', has "
                               f'ended ({state})')
        return status.mission_id

    def status(self, timeout: float = 10.0):
        """The latest MissionStatus that verifies with the fleet key, if the client has one
        (latched: it comes as soon as the planner is found). Those that do not verify are
        counted in `statuses_dropped`, never returned."""
        if not self._status_seen.wait(timeout):
            dropped = self.dropped_statuses()
            raise MissionError(f'no mission status within {timeout:g} s'
                               + (f' ({dropped})' if dropped else '')
                               + ': is the planner running, with the same ROS_DOMAIN_ID and '
                               'fleet key?')
        return self._status

    def dropped_statuses(self) -> str:
        """How many mission statuses were dropped as not verifying, and why ('' if none)."""
        if not self.statuses_dropped:
            return ''
        return (f'ignored {self.statuses_dropped.total()} mission status message(s) that do '
                'not verify with the fleet key: ' + '; '.join(
                    f'{n} {why}' for why, n in self.statuses_dropped.most_common(3)))

    def _call(self, client, request, timeout):
        """The planner's answer. The request is resent every RESEND seconds until answered
        (a fresh client's first answer can be lost); its id makes the planner answer a resent
        request without doing it twice."""
        name = self._node.resolve_service_name(client.srv_name)
        if not client.wait_for_service(timeout_sec=timeout):
            raise MissionError(f"no planner serves '{name}' (waited {timeout:g} s): is the "
                               'planner running, with the same ROS_DOMAIN_ID?')
        request.request_id = f'{self._node.get_name()}/{uuid.uuid4().hex}'
        deadline = time.monotonic() + timeout
        while True:
            self._signer.sign(request, name)
            future = client.call_async(request)
            if self._wait(future, min(RESEND, max(deadline - time.monotonic(), 0.0))):
                return future.result()
            client.remove_pending_request(future)
            if time.monotonic() >= deadline:
                raise MissionError(f"'{name}' did not answer within {timeout:g} s")


def _result(msg) -> MissionResult:
    state = RESULT_STATES[msg.state] if msg.state < len(RESULT_STATES) else f'state {msg.state}'
    return MissionResult(msg.mission_id, state, msg.makespan, msg.planned_makespan,
                         msg.revisions, msg.jobs_done, msg.jobs_total, tuple(msg.reasons))


# --- command line ------------------------------------------------------------------------

def describe_feedback(feedback) -> str:
    from fjsp_common.contract import STATE_FROM_MSG
    from fjsp_common.vocabulary import MissionState

    state = STATE_FROM_MSG.get(feedback.state, f'state {feedback.state}')
    if state == MissionState.QUEUED:
        return (f'{feedback.mission_id}: queued, position {feedback.queue_position}, '
                f'{feedback.jobs_total} jobs')
    line = (f'{feedback.mission_id}: {state}, revision {feedback.plan_revision}, '
            f'{feedback.jobs_done}/{feedback.jobs_total} jobs done, {feedback.jobs_running} '
            'running, makespan planned {} projected {}, t={}'.format(
                *decimals(feedback.planned_makespan, feedback.projected_makespan,
                          feedback.elapsed)))
    return line + (': ' + '; '.join(feedback.reasons) if feedback.reasons else '')


def describe_result(result: MissionResult) -> str:
    makespan = f', executed makespan {decimal(result.makespan)}' \
        if math.isfinite(result.makespan) else ''
    return (f'{result.mission_id}: {result.state}, {result.jobs_done}/{result.jobs_total} jobs '
            f'done, {result.revisions} revision(s){makespan}'
            + (': ' + '; '.join(result.reasons) if result.reasons else ''))


def _parser():
    parser = argparse.ArgumentParser(prog='mission', description='Missions on a running '
                                     'fleet: submit, cancel, extend, status.')
    verbs = parser.add_subparsers(dest='verb', required=True)
    submit = verbs.add_parser('submit', help='run a mission (a scenario file)')
    submit.add_argument('scenario', type=Path)
    submit.add_argument('--panels', type=int, default=0, help="0: the scenario's own")
    submit.add_argument('--time-scale', type=float, default=0.0,
                        help="wall seconds per schedule unit; 0: the planner's")
    submit.add_argument('--blocked-timeout', type=float, default=0.0,
                        help='fail the mission after being blocked this long (s); 0: never')
    submit.add_argument('--wait', action='store_true',
                        help='follow the mission to its end, printing its progress; exit 0 '
                             'only if it completes, 1 as soon as the planner says nothing '
                             'of it for --timeout seconds')
    submit.add_argument('--no-queue', action='store_true',
                        help='refused if a mission runs, rather than waiting its turn')
    cancel = verbs.add_parser('cancel', help='cancel the running mission, or a queued one')
    cancel.add_argument('--reason', default='', help='shown in the mission story')
    add = verbs.add_parser('add', help='add the jobs of a scenario fragment')
    add.add_argument('fragment', type=Path)
    for verb in (cancel, add):
        verb.add_argument('--mission', default='', metavar='ID',
                          help="the mission's id (default: the running mission, as the "
                               "planner's status names it)")
    verbs.add_parser('status', help='print the mission state, jobs done and the queue')
    for verb in (submit, cancel, add, verbs.choices['status']):
        verb.add_argument('--timeout', type=float, default=10.0,
                          help='seconds to wait for the planner (default 10)')
        verb.add_argument('--key-file', help='fleet key to sign requests with (default: '
                                             '$FJSP_FLEET_KEY_FILE; none: unsigned)')
    return parser


def main(argv=None) -> int:
    """Exit 0: done (submit --wait: the mission completed); 1: refused, failed, nobody
    answered; 2: bad arguments."""
    from rclpy.utilities import remove_ros_args

    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _parser()
    try:
        own = remove_ros_args(['mission', *argv])[1:]
    except RuntimeError as error:  # rclpy's RCLInvalidROSArgsError
        parser.error(f'bad ROS arguments: {error}')
    args = parser.parse_args(own)
    if not (math.isfinite(args.timeout) and args.timeout > 0):
        parser.error(f'--timeout must be a number of seconds > 0, got {args.timeout:g}')
    if args.verb == 'submit':
        for flag, value in (('--time-scale', args.time_scale),
                            ('--blocked-timeout', args.blocked_timeout)):
            if not (math.isfinite(value) and value >= 0):
                parser.error(f'{flag} must be a number >= 0, got {value:g}')
        if not 0 <= args.panels <= 50:
            parser.error(f'--panels must be within 0..50, got {args.panels}')
    try:
        with MissionClient(['mission', *argv], key_file=args.key_file) as client:
            return _run(client, args)
    except MissionError as error:
        print(f'mission: {error}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


def _run(client: MissionClient, args) -> int:
    if args.verb == 'submit':
        shown = []

        # Feedback comes on the client's thread: each line is printed whole, never into another.
        printing = threading.Lock()

        def say(text: str) -> None:
            with printing:
                print(text, flush=True)

        def show(feedback):
            line = describe_feedback(feedback)
            if args.wait and (not shown or line.split(', t=')[0] != shown[-1]):
                shown.append(line.split(', t=')[0])
                say(line)

        mission = client.submit(args.scenario, panels=args.panels, time_scale=args.time_scale,
                                blocked_timeout=args.blocked_timeout,
                                queue=not args.no_queue, feedback=show, timeout=args.timeout)
        position = mission.queue_position
        say(f'mission {mission.mission_id} '
            + (f'queued at position {position}' if position else 'started'))
        if not args.wait:
            return 0
        result = mission.result(silence=args.timeout)
        say(describe_result(result))
        return 0 if result.complete else 1
    if args.verb == 'cancel':
        print(client.cancel(args.mission, reason=args.reason, timeout=args.timeout))
        return 0
    if args.verb == 'add':
        jobs = client.add_jobs(args.fragment, mission_id=args.mission, timeout=args.timeout)
        print(f'{len(jobs)} job(s) added: {", ".join(jobs)}')
        return 0
    from fjsp_common.contract import STATE_FROM_MSG
    from fjsp_common.vocabulary import MissionState

    status = client.status(args.timeout)
    if client.statuses_dropped:
        print(f'mission: {client.dropped_statuses()}', file=sys.stderr)
    state = STATE_FROM_MSG.get(status.state, f'state {status.state}')
    if state == MissionState.IDLE:
        print('idle: no mission yet, the planner waits for one')
    else:
        print(f'{state} {status.jobs_done}/{status.jobs_total}  mission {status.mission_id} '
              f'revision {status.plan_revision}')
    for reason in status.blocked_reasons:
        print(f'  blocked: {reason}')
    for warning in status.warnings:
        print(f'  warning: {warning}')
    for position, mission_id in enumerate(status.queue, 1):
        print(f'  queued {position}: {mission_id}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
