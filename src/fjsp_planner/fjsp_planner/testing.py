"""Test a fleet as it runs: real node processes on a private ROS domain, started by the fleet
launcher, watched from the test through the public topics (see docs/testing.md).

Enable the pytest fixture in a `conftest.py` with

    pytest_plugins = ['fjsp_planner.testing']

and a test that a robot failure is re-planned to completion reads

    def test_losing_r1_mid_mission(fjsp_fleet):
        fleet = fjsp_fleet('truss.yaml', time_scale=0.1).start()
        fleet.wait_for(lambda o: o.schedule_time() >= 8, 60, 'schedule time 8')
        fleet.inject_fault('R1', 'fail')
        fleet.check_mission_complete(timeout=120)

Each fleet gets a ROS_DOMAIN_ID of its own (`DomainClaim`: the one `ROS_DOMAIN_ID` names,
or one of the range FJSP_TEST_DOMAINS names, else one of 1..100) and keeps discovery on this
host (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST), so tests never hear each other; its processes
are stopped (SIGINT, then SIGKILL) whatever the test does. Every wait is bounded and fails
the test naming what it waited for; `check_mission_complete` fails at once when the mission
ends failed or cancelled.

A fleet can also run across real network links instead (`fjsp_network`, `FleetHarness(...,
network=...)`): the planner and the monitor on one host, each agent on a host of its own,
as network namespaces on one bridge whose links a test can cut and restore.
"""

import dataclasses
import fcntl
import math
import os
import random
import subprocess
import tempfile
import time
from collections import Counter, defaultdict
from fractions import Fraction

import pytest

from fjsp_common.auth import Verifier, read_key
from fjsp_common.clock import ScheduleClock, seconds
from fjsp_common.contract import (
    JOB_STATES,
    MISSION_EVENTS,
    MISSION_STATUS,
    PLAN,
    ROBOT_STATES,
    TASK_EVENTS,
)
from fjsp_common.fleet import PLANNER_NODE, agent_node_name
from fjsp_common.revisions import Restarts, plan_attempts
from fjsp_msgs.msg import JobStates, MissionEvent, MissionStatus, Plan, RobotState, TaskEvent
from fjsp_planner.execution.tracking import met_before, relaxed_distances, without_durations
from fjsp_planner.faults import inject_fault
from fjsp_planner.launcher.hosts import HostsUnavailableError, Network
from fjsp_planner.launcher.listener import Listener, environment
from fjsp_planner.launcher.respawn import how_it_ended
from fjsp_planner.launcher.supervision import Fleet, find_executable
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate

TEST_TIME_SCALE = 0.03
"""Wall seconds per schedule unit: the paper's 32-unit mission takes about a second."""
TEST_PLANNER = {'time_limit': 5.0, 'start_delay': 0.3, 'rival_timeout': 1.0}
"""Planner parameters for tests: a first plan within 5 s, a mission start soon after it, and
1 s of listening for another planner (there is none: the domain is the test's own)."""
DISCOVERY_RANGE = 'LOCALHOST'
ACROSS_HOSTS = {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET', 'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4'}
"""DDS settings of a fleet whose nodes run on separate hosts: discovery by multicast on the
LAN, and UDP only: Fast DDS's shared-memory transport would carry messages between
namespaces of one machine past a link that is cut."""
DDS_VARIABLES = ('ROS_AUTOMATIC_DISCOVERY_RANGE', 'ROS_STATIC_PEERS',
                 'FASTDDS_BUILTIN_TRANSPORTS', 'FASTRTPS_DEFAULT_PROFILES_FILE')
"""The environment that decides whom a DDS participant discovers and how it talks: the
observer takes them from the fleet's environment, so it sees what the nodes see."""
UNDONE = {MissionStatus.STATE_FAILED: 'FAILED', MissionStatus.STATE_CANCELLED: 'CANCELLED'}
"""The ends of a mission that did not complete, by state."""
CONTROL_HOST = 'control'
"""The host of the planner and the monitor in a fleet across hosts; each agent's host is
named after its robot."""

DOMAINS = range(1, 101)
"""ROS domain ids the fleets of tests take by default (Fast DDS gives each its own ports)."""
DOMAINS_VARIABLE = 'FJSP_TEST_DOMAINS'
"""`first-last` (e.g. `150-230`): the ids the fleets of tests take instead, one each."""
HIGHEST_DOMAIN = 232
"""The highest ROS domain id Fast DDS can use on Linux."""


class DomainClaim:
    """A ROS domain id no other test on this machine uses while the claim is held: each id is
    claimed with an exclusive lock on a file, released by `release` or when the process
    dies. Without it, two test runs at once (two checkouts, CI and a developer) can share a
    domain and hear each other's robots.

    The id comes from the range FJSP_TEST_DOMAINS names (`150-230`), else from
    `ROS_DOMAIN_ID` (the one domain a CI job or a shell gave the tests; a second fleet at
    once cannot have it too), else from DOMAINS. An unusable setting, or no free id, is a
    RuntimeError saying which and what to do."""

    def __init__(self):
        domains, source = _test_domains()
        start = random.randrange(len(domains))
        for index in range(len(domains)):
            domain = domains[(start + index) % len(domains)]
            lock = open(f'{tempfile.gettempdir()}/fjsp-ros-domain-{domain}.lock', 'w')  # noqa: SIM115
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                lock.close()
                continue
            self.domain, self._lock = domain, lock
            return
        if source == 'ROS_DOMAIN_ID':
            raise RuntimeError(f'ROS_DOMAIN_ID={domains[0]} is in use by another fleet of '
                               f'tests on this machine; for several fleets at once set '
                               f'{DOMAINS_VARIABLE} to a range of ids (e.g. 150-230)')
        raise RuntimeError(f'every ROS domain id {domains[0]}..{domains[-1]} ({source}) is in '
                           'use by other tests on this machine')

    def release(self) -> None:
        self._lock.close()


def _test_domains() -> tuple[range, str]:
    """The domain ids a claim may take, and where they come from."""
    text = os.environ.get(DOMAINS_VARIABLE, '').strip()
    if text:
        first, dash, last = text.partition('-')
        try:
            domains = range(int(first), int(last if dash else first) + 1)
        except ValueError:
            domains = range(0)
        if not domains or domains[0] < 0 or domains[-1] > HIGHEST_DOMAIN:
            raise RuntimeError(f'{DOMAINS_VARIABLE}={text!r}: expected first-last, ids within '
                               f'0..{HIGHEST_DOMAIN}')
        return domains, DOMAINS_VARIABLE
    text = os.environ.get('ROS_DOMAIN_ID', '').strip()
    if text:
        if not text.isdigit() or int(text) > HIGHEST_DOMAIN:
            raise RuntimeError(f'ROS_DOMAIN_ID={text!r}: expected an id within '
                               f'0..{HIGHEST_DOMAIN}')
        return range(int(text), int(text) + 1), 'ROS_DOMAIN_ID'
    return DOMAINS, 'the default range'


class Observer(Listener):
    """Records every public topic of one domain, from the test process."""

    def __init__(self, domain: int, dds: dict | None = None, key_file=None):
        """`dds`: the DDS_VARIABLES the fleet's nodes have (default: discovery on this
        host only). With the fleet's `key_file`, it screens what it hears as the nodes do
        (`Verifier.screen`): a flood of unsigned messages is dropped from its bytes, past the
        first few a second, instead of each being decoded in the test's process. It records
        signed messages whether they verify or not."""
        self._verifier = Verifier(read_key(key_file)) if key_file is not None else None
        dds = {'ROS_AUTOMATIC_DISCOVERY_RANGE': DISCOVERY_RANGE, **(dds or {})}
        # Fast DDS reads its transports when the node's participant is made, after init.
        with environment(**dds):
            super().__init__(domain, name='test_observer',
                             discovery_range=dds['ROS_AUTOMATIC_DISCOVERY_RANGE'])
        self.plans: list[Plan] = []
        self.events: list[TaskEvent] = []
        self.mission_events: list[MissionEvent] = []
        self.status: MissionStatus | None = None
        self.job_states: JobStates | None = None
        self.robots: dict[str, RobotState] = {}
        """Latest state of each robot."""
        self.robot_history: list[RobotState] = []
        for topic, callback in ((PLAN, self.plans.append), (TASK_EVENTS, self.events.append),
                                (MISSION_EVENTS, self.mission_events.append),
                                (MISSION_STATUS, lambda msg: setattr(self, 'status', msg)),
                                (JOB_STATES, lambda msg: setattr(self, 'job_states', msg)),
                                (ROBOT_STATES, self._robot)):
            self.subscribe(topic.type, topic.name, topic.qos, callback)

    def subscribe(self, msg_type, topic: str, qos, callback, verifier=None):
        return super().subscribe(msg_type, topic, qos, callback, verifier or self._verifier)

    def _robot(self, msg: RobotState) -> None:
        self.robots[msg.robot] = msg
        self.robot_history.append(msg)

    def wait_for(self, predicate, timeout: float, what: str = 'a condition') -> None:
        """Wait until `predicate(observer)` holds; fail the test naming `what` after
        `timeout` seconds.

        A predicate that fails on something not heard yet (an attribute of the status while
        it is still None, the last of no plans, a robot not seen) counts as not holding: a
        plan can reach the agents before the first mission status reaches the test. Should
        the wait time out, the last such error is named."""
        failed = []

        def holds():
            try:
                return predicate(self)
            except (AttributeError, LookupError) as error:
                failed[:] = [error]
                return False

        if not super().wait_for(holds, timeout):
            raised = f'; the condition last raised {failed[0]!r}' if failed else ''
            pytest.fail(f'timed out after {timeout:g} s waiting for {what}{raised}; last '
                        f'mission status: {self.status}', pytrace=False)

    def complete(self) -> bool:
        return self.status is not None and self.status.state == MissionStatus.STATE_COMPLETE

    def ended_undone(self) -> bool:
        """The mission ended FAILED or CANCELLED: it will not complete any more."""
        return self.status is not None and self.status.state in UNDONE

    def latest_revision(self) -> int:
        return max((p.revision for p in self.plans), default=0)

    def schedule_time(self) -> float:
        """Schedule time now, from the first plan's mission start (-inf before any plan)."""
        if not self.plans:
            return -math.inf
        first = self.plans[0]
        return ScheduleClock(seconds(first.mission_start), first.time_scale).units(time.time())

    def jobs_done(self) -> set[str]:
        """Jobs declared done in their last attempt."""
        return {e.job for e in valid_events(self.plans, self.events)
                if e.kind == TaskEvent.KIND_JOB_DONE}


class FleetHarness(Fleet):
    """A `Fleet` on a private domain with an `observer` that records its topics from before
    the first node starts. Defaults suit tests: TEST_TIME_SCALE, TEST_PLANNER, no monitor.

    With a `network` (`fjsp_planner.launcher.hosts.Network`), each node runs on a host of that LAN:
    the planner and the monitor on CONTROL_HOST, each agent on a host named after its robot
    (made when the node first starts), discovering each other by multicast (ACROSS_HOSTS).
    The observer stays on this machine, which is on the LAN too."""

    def __init__(self, scenario=None, *, out, domain: int | None = None,
                 time_scale: float | None = TEST_TIME_SCALE, planner: dict | None = None,
                 env: dict | None = None, network: Network | None = None, **options):
        self.claim = DomainClaim() if domain is None else None
        domain = self.claim.domain if domain is None else domain
        self.network = network
        dds = ACROSS_HOSTS if network is not None else {
            'ROS_AUTOMATIC_DISCOVERY_RANGE': DISCOVERY_RANGE}
        try:
            super().__init__(scenario, out=out, domain=domain, time_scale=time_scale,
                             planner={**TEST_PLANNER, **(planner or {})},
                             env={**dds, **(env or {})}, **options)
            self.observer = Observer(domain, {k: self.env[k] for k in DDS_VARIABLES
                                              if k in self.env}, self.key_file)
        except BaseException:
            if self.claim is not None:
                self.claim.release()
            raise

    def start(self, *, monitor: bool = False, stream_monitor: bool = False,
              recorder: bool = False) -> 'FleetHarness':
        """`Fleet.start`, but the planner only once the observer hears every agent: DDS
        discovery between fresh processes can take seconds, and an observer that met an
        agent late would never see the states the agent went through before (on its first
        job, say), which a test may be waiting for."""
        if recorder:
            self.start_recorder()
        if monitor:
            self.start_monitor(stream=stream_monitor)
        robots = [r.name for r in self.problem.robots]
        for robot in robots:
            self.start_agent(robot)
        self.wait_for(lambda o: all(r in o.robots for r in robots), 60, 'every agent to report')
        self.start_planner()
        return self

    def start_node(self, name: str, *args, **kwargs):
        if self.network is not None and name not in self.prefixes:
            self.prefixes[name] = self.network.host(self.host_of(name)).prefix
        return super().start_node(name, *args, **kwargs)

    @staticmethod
    def host_of(node: str) -> str:
        """The host a node runs on in a fleet across hosts."""
        if node.startswith(agent_node_name('')):
            return node[len(agent_node_name('')):]
        return CONTROL_HOST

    def cut(self, node: str = PLANNER_NODE) -> None:
        """Cut the link of the host `node` runs on (a fleet across hosts only)."""
        self.network.cut(self.host_of(node))

    def restore(self, node: str = PLANNER_NODE) -> None:
        self.network.restore(self.host_of(node))

    def wait_for(self, predicate, timeout: float, what: str = 'a condition') -> None:
        """`Observer.wait_for`: `predicate` gets the observer. Should the wait time out,
        the failure also names the nodes that are no longer running and how they ended: a
        node that crashed, or never came back after a restart, is often why."""
        try:
            self.observer.wait_for(predicate, timeout, what)
        except pytest.fail.Exception as failure:
            ended = self.exited()
            if not ended:
                raise
            pytest.fail(f'{failure}; not running: ' + ', '.join(
                f'{name} ({how_it_ended(code)})' for name, code in sorted(ended.items())),
                pytrace=False)

    def inject_fault(self, robot: str, fault: str, factor: float | None = None,
                     timeout: float = 10.0) -> str:
        """`fjsp_planner.faults.inject_fault` from the observer's context, which has
        discovered the fleet: the fault lands within milliseconds."""
        return inject_fault(robot, fault, factor, node=self.observer.node, timeout=timeout)

    def run(self, package: str, executable: str, *args,
            timeout: float = 30.0) -> subprocess.CompletedProcess:
        """Run a tool of the workspace (e.g. the `inject_fault` command) in this fleet's
        domain, as a user's script would; its exit code and output."""
        return subprocess.run([str(find_executable(package, executable)), *args],
                              env=self.env, capture_output=True, text=True, timeout=timeout)

    def check_mission_complete(self, timeout: float = 60.0, durations: bool = True
                               ) -> Schedule:
        """Wait for the mission to complete, then check what a user relies on: every job of
        the scenario done exactly once, the timeline the robots ran (rebuilt from their
        events) valid, and the status agreeing. The executed timeline. A mission that ends
        failed or cancelled fails the test at once, naming the state and its reasons.

        With `durations` false, operations may take any time their robots took (robots
        behind the action driver that run short of the plan, e.g. noisy simulated ones)."""
        problem = self.problem
        jobs = {j.name for j in problem.jobs}
        self.wait_for(lambda o: o.complete() or o.ended_undone(), timeout,
                      'the mission to complete')
        status = self.observer.status
        if status.state != MissionStatus.STATE_COMPLETE:
            reasons = '; '.join(status.blocked_reasons) or 'no reason given'
            pytest.fail(f"mission '{status.mission_id}' ended {UNDONE[status.state]} instead "
                        f'of completing ({status.jobs_done}/{status.jobs_total} jobs done): '
                        f'{reasons}', pytrace=False)
        # The last job-done events and the status saying complete may come in either order;
        # each agent's event history comes when its writer is discovered.
        missing = []

        def reported(o) -> bool:
            missing[:] = [f"job-done of '{j}'" for j in sorted(jobs - o.jobs_done())]
            missing.extend(f"{robot}'s operation_done of '{job}'"
                           for robot, job in unreported_operations(o.plans, o.events))
            return not missing

        if not Listener.wait_for(self.observer, lambda: reported(self.observer), 10):
            pytest.fail(f'the mission completed, but 10 s later the observer still lacks '
                        f'{", ".join(missing)}', pytrace=False)
        with self.observer.lock:
            plans, events = list(self.observer.plans), list(self.observer.events)
            story = list(self.observer.mission_events)
            status = self.observer.status
        check_jobs_done_once(problem, plans, events)
        check_nothing_redone(events, story)
        executed = check_executed_timeline(problem, plans, events, durations)
        assert (status.jobs_done, status.jobs_total, status.jobs_running) == \
            (len(jobs), len(jobs), 0), status
        return executed

    def close(self) -> dict[str, int]:
        try:
            return self.stop()
        finally:
            self.observer.close()
            if self.claim is not None:
                self.claim.release()

    def __exit__(self, *exc) -> None:
        self.close()


def operations_reported(plans, events) -> bool:
    """Every operation the last of `plans` (one mission's) gives a robot reported done in
    the job's last attempt, among `events`. A robot's reports come on its own writer: an
    agent restarted late in a mission may be heard after the planner declared its last job
    done."""
    return bool(plans) and not unreported_operations(plans, events)


def unreported_operations(plans, events) -> list[tuple[str, str]]:
    """(robot, job) of the operations the last of `plans` gives a robot that `events` do not
    report done in the job's last attempt (none without a plan)."""
    if not plans:
        return []
    planned = {(r.robot, t.job) for r in plans[-1].robots for t in r.tasks}
    reported = {(e.robot, e.job) for e in valid_events(plans, events)
                if e.kind == TaskEvent.KIND_OPERATION_DONE}
    return sorted(planned - reported)


@pytest.fixture
def ros_domain():
    """A ROS domain id of this test's own (`DomainClaim`), for processes it starts itself."""
    claim = DomainClaim()
    try:
        yield claim.domain
    finally:
        claim.release()


def pytest_collection_modifyitems(items) -> None:
    """Tests across network links run first. Fast DDS lists the machine's network
    interfaces once per process, when its first participant is made: the observer of a test
    LAN whose bridge came after any other test's participant in this process announces only
    addresses the LAN's hosts cannot reach, and hears nothing."""
    items.sort(key=lambda item: 'fjsp_network' not in getattr(item, 'fixturenames', ()))


@pytest.fixture
def fjsp_network():
    """A LAN of simulated hosts for this test (`fjsp_planner.launcher.hosts.Network`), removed
    after it; pass it to `fjsp_fleet(..., network=...)`. Skips the test, saying why, where network
    namespaces cannot be created (not root, no `ip`, no CAP_NET_ADMIN)."""
    try:
        network = Network()
    except HostsUnavailableError as error:
        pytest.skip(f'cannot test across network links here: {error}')
    try:
        yield network
    finally:
        network.close()


@pytest.fixture
def fjsp_fleet(tmp_path):
    """A factory of fleets under test: `fjsp_fleet(scenario, **options)` returns a
    `FleetHarness` (not yet started) with its own domain and output directory; every fleet
    it made is stopped after the test."""
    made: list[FleetHarness] = []

    def make(scenario=None, **options) -> FleetHarness:
        fleet = FleetHarness(scenario, out=tmp_path / f'fleet{len(made) + 1}', **options)
        made.append(fleet)
        return fleet

    try:
        yield make
    finally:
        for fleet in made:
            fleet.close()


# --- what the robots did, from their events ----------------------------------------------

def restarts_in(plans) -> Restarts:
    """Per job, the last plan revision of `plans` that (re)started it: its reports under
    older ones are void (`PlanTask.continued`, `PlanTask.restarted_in`)."""
    restarts = Restarts()
    for plan in plans:
        tasks = (task for robot in plan.robots for task in robot.tasks)
        for job, since in plan_attempts(plan.revision, tasks).items():
            restarts.restart(job, since)
    return restarts


def valid_events(plans, events) -> list[TaskEvent]:
    """The events of each job's last attempt, the one that counts."""
    restarts = restarts_in(plans)
    return [e for e in events if not restarts.void(e.job, e.plan_revision)]


def executed_timeline(problem: Problem, plans, events) -> Schedule:
    """The schedule the robots actually ran, rebuilt from their task events alone (the last
    attempt of each job), with each robot's operation as the plans that ran it gave it.
    Jobs not (yet) finished by all their robots are left out. AssertionError if a robot
    started a job no plan of `plans` gives it: it followed a plan they miss."""
    started, operation_done = defaultdict(dict), defaultdict(dict)
    tasks = {(r.robot, t.job): t for plan in plans for r in plan.robots for t in r.tasks}
    for e in valid_events(plans, events):
        if e.kind == TaskEvent.KIND_STARTED:
            if (e.robot, e.job) not in tasks:
                raise AssertionError(
                    f"robot '{e.robot}' started job '{e.job}' under plan revision "
                    f'{e.plan_revision}, but no plan received (revisions '
                    f'{sorted({p.revision for p in plans})}) gives it that job')
            started[e.job][e.robot] = e.time
        elif e.kind == TaskEvent.KIND_OPERATION_DONE:
            operation_done[e.job][e.robot] = e.time
    jobs = {}
    for job, robots in started.items():
        if set(operation_done[job]) != set(robots):
            continue
        ops = {robot: tasks[robot, job].operation_type for robot in robots}
        plan = tasks[next(iter(robots)), job].process_plan
        end = max(operation_done[job].values())
        jobs[job] = JobAssignment(job, plan, Fraction(min(robots.values())), Fraction(end), ops)
    sequences = {r.name: tuple(sorted((j for j, a in jobs.items() if r.name in a.robots),
                                      key=lambda j: jobs[j].start))
                 for r in problem.robots}
    return Schedule(jobs, sequences)


def check_jobs_done_once(problem: Problem, plans, events) -> None:
    """Every job of `problem` declared done exactly once in its last attempt, and nothing
    else; AssertionError naming the jobs otherwise."""
    done = Counter(e.job for e in valid_events(plans, {e.event_id: e for e in events}.values())
                   if e.kind == TaskEvent.KIND_JOB_DONE)
    jobs = {j.name for j in problem.jobs}
    problems = [f"job '{j}' never done" for j in sorted(jobs - set(done))]
    problems += [f"job '{j}' done {n} times" for j, n in sorted(done.items()) if n > 1]
    problems += [f"job '{j}' done but not in the scenario" for j in sorted(set(done) - jobs)]
    if problems:
        raise AssertionError('; '.join(problems))


def check_nothing_redone(events, mission_events) -> None:
    """No job completed twice, but one the planner voided (a jig job whose hold was lost) and
    redid; AssertionError naming the jobs otherwise. A completion declared again with the same
    time (by a planner restarted before it had journaled it) is the same completion."""
    completions = defaultdict(set)
    for e in events:
        if e.kind == TaskEvent.KIND_JOB_DONE:
            completions[e.mission_id, e.job].add(round(e.time, 6))
    voided = Counter((e.mission_id, e.job) for e in mission_events
                     if e.kind == MissionEvent.KIND_JOB_VOIDED)
    redone = [f"job '{job}' completed {len(times)} times (at t={sorted(times)}), voided "
              f'{voided[mission, job]} times' for (mission, job), times in sorted(
                  completions.items()) if len(times) > 1 + voided[mission, job]]
    if redone:
        raise AssertionError('work done again: ' + '; '.join(redone))


def check_executed_timeline(problem: Problem, plans, events, durations: bool = True
                            ) -> Schedule:
    """The executed timeline, which must cover every job and pass the validator (with
    `durations` false: operations free of duration); AssertionError listing what is wrong
    otherwise."""
    executed = executed_timeline(problem, plans, events)
    missing = sorted({j.name for j in problem.jobs} - set(executed.jobs))
    if missing:
        raise AssertionError(f'no complete execution reported for {", ".join(missing)}')
    problems = validate_executed(problem if durations else without_durations(problem),
                                 executed, voided_ends(plans, events))
    if problems:
        raise AssertionError('the executed timeline is invalid:\n' + '\n'.join(problems))
    return executed


def validate_executed(problem: Problem, executed: Schedule, voided=None) -> list[str]:
    """What the executed timeline breaks, judged as the planner judges it: a robot may go
    between two of its jobs by the shortest route, through the location of a job it was
    withdrawn from or that a new revision left out; a job that followed the completion of a
    jig job voided since (`voided`: job -> when that completion ended, `voided_ends`) met
    that precedence."""
    relaxed = dataclasses.replace(problem, distances=relaxed_distances(problem, executed))
    return validate(met_before(relaxed, executed, voided or {}), executed)


def voided_ends(plans, events) -> dict[str, float]:
    """Job -> when its first completion ended, for the jobs of the missions of `plans` the
    planner declared done more than once (it voids a jig job whose hold was lost, and
    declares it done again when redone)."""
    missions = {p.mission_id for p in plans}
    completions = defaultdict(dict)
    for e in events:
        if e.kind == TaskEvent.KIND_JOB_DONE and e.mission_id in missions:
            # Declared again by a restarted planner, it is the same completion.
            same = completions[e.job].setdefault(round(e.time, 6), e.time)
            completions[e.job][round(e.time, 6)] = min(same, e.time)
    return {job: min(times.values()) for job, times in completions.items() if len(times) > 1}

