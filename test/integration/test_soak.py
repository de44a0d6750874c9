"""Soak: many missions, one after the other on long-running fleets, under random faults at
random times — robots failing and recovering (also both at once), operations delayed, agents
and the planner killed with SIGKILL and restarted (the planner resuming from its journal).

Every mission must end COMPLETE, or FAILED / blocked too long with its reasons; its executed
timeline (rebuilt from the robots' events alone) must pass the validator; no job may be done
twice; and no node may crash (a `Traceback` in any node's log fails the test).

The randomness is seeded and the seed printed: `FJSP_SOAK_SEED=<seed>` replays the same
missions and fault sequence (the moments they land in each mission depend on timing, and
so vary a little). `FJSP_SOAK_MISSIONS=<n>` runs more missions than the CI's few minutes
allow; `-s` shows the log of every fault and outcome.
"""

import dataclasses
import os
import random
import secrets
import time
from collections import Counter
from pathlib import Path

import pytest

from fjsp_common.fleet import agent_node_name
from fjsp_msgs.msg import MissionStatus, RobotState, TaskEvent
from fjsp_planner.faults import FaultError
from fjsp_planner.missions import MissionClient, MissionError
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.testing import (
    FleetHarness,
    executed_timeline,
    operations_reported,
    valid_events,
    validate_executed,
)

from repo_paths import SCENARIOS

GROUPS = (('solar_panel.yaml', (1, 2)), ('truss.yaml', (1,)), ('antenna.yaml', (1,)))
"""One fleet per scenario (a fleet runs one scenario's robots); its missions' panel counts
are drawn from the tuple."""
MISSIONS = int(os.environ.get('FJSP_SOAK_MISSIONS', '9'))
TIME_SCALE = 0.08
"""Wall seconds per schedule unit: the paper's panel takes about 2.6 s."""
PLAN_TIME_LIMIT = 2.0
BLOCKED_TIMEOUT = 20.0
"""Seconds a mission may stay blocked before it fails: every fault is undone within a few
seconds, so this only ends missions that would otherwise hang."""
FAULT_WEIGHTS = {'fail': 3, 'fail+recover': 1, 'delay': 2, 'kill agent': 2, 'kill planner': 1}
UNDO_AFTER = (0.3, 3.0)
"""Seconds after which a failed robot recovers, a killed node is started again."""
ENDED = (MissionStatus.STATE_COMPLETE, MissionStatus.STATE_FAILED,
         MissionStatus.STATE_CANCELLED)


@dataclasses.dataclass
class Mission:
    scenario: str
    panels: int
    mission_id: str = ''
    outcome: str = 'not started'
    reasons: tuple = ()
    jobs: str = ''
    revisions: int = 0
    faults: list = dataclasses.field(default_factory=list)
    problems: list = dataclasses.field(default_factory=list)

    def line(self) -> str:
        faults = ', '.join(self.faults) or 'none'
        why = f" ({'; '.join(self.reasons)[:300]})" if self.reasons else ''
        return (f'{self.scenario} x{self.panels} {self.mission_id}: {self.outcome}{why}, '
                f'{self.jobs} jobs, {self.revisions} revision(s); faults: {faults}')


class Soak:
    """One fleet of a scenario, its missions submitted one by one, faults injected."""

    def __init__(self, scenario: str, out: Path, rng: random.Random, log):
        self.path = SCENARIOS / scenario
        self.rng = rng
        self.log = log
        self.fleet = FleetHarness(self.path, out=out, time_scale=TIME_SCALE,
                                  planner={'journal_dir': out / 'journal'},
                                  agents={'reports_dir': out / 'reports'})
        self.robots = [r.name for r in self.fleet.problem.robots]
        self.down: set[str] = set()
        """Nodes killed and not started again yet."""
        self.failed: set[str] = set()
        self.client = None

    def start(self) -> None:
        self.fleet.start_planner(scenario='')
        for robot in self.robots:
            self.fleet.start_agent(robot)
        self.fleet.wait_for(lambda o: all(r in o.robots for r in self.robots), 60,
                            'every agent to report')
        self.client = MissionClient(domain_id=self.fleet.domain)

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        self.fleet.close()

    # --- faults and their undoing --------------------------------------------------------

    def inject(self, fault: str, robot: str, factor=None) -> str:
        try:
            self.fleet.inject_fault(robot, fault, factor, timeout=3.0)
            return 'ok'
        except FaultError as error:
            return f'refused: {str(error)[:120]}'

    def fault(self, kind: str, undo: list, now: float) -> str:
        """Inject one fault of `kind` on a random target; what it was (for the log)."""
        alive = [r for r in self.robots if agent_node_name(r) not in self.down]
        if kind == 'kill planner':
            if 'planner' in self.down:
                return ''
            self.fleet.kill('planner')
            self.down.add('planner')
            undo.append((now + self.rng.uniform(*UNDO_AFTER), 'restart planner', ''))
            return 'kill planner'
        if not alive:
            return ''
        robot = self.rng.choice(alive)
        if kind == 'kill agent':
            self.fleet.kill(agent_node_name(robot))
            self.down.add(agent_node_name(robot))
            self.failed.discard(robot)  # a new agent starts healthy
            undo.append((now + self.rng.uniform(*UNDO_AFTER), 'restart agent', robot))
            return f'kill {robot}'
        if kind == 'delay':
            factor = round(self.rng.uniform(1.5, 4.0), 2)
            return f'delay {robot} x{factor} ({self.inject("delay", robot, factor)})'
        if kind == 'fail+recover':
            first = self.inject('fail', robot)
            return f'fail+recover {robot} ({first}, {self.inject("recover", robot)})'
        answer = self.inject('fail', robot)
        if answer == 'ok':
            self.failed.add(robot)
            undo.append((now + self.rng.uniform(*UNDO_AFTER), 'recover', robot))
        return f'fail {robot} ({answer})'

    def undo(self, action: str, robot: str) -> str:
        if action == 'restart planner':
            self.fleet.start_planner(scenario='')
            self.down.discard('planner')
            return 'restart planner'
        if action == 'restart agent':
            self.fleet.start_agent(robot)
            self.down.discard(agent_node_name(robot))
            return f'restart {robot}'
        if robot in self.failed and agent_node_name(robot) not in self.down:
            self.failed.discard(robot)
            return f'recover {robot} ({self.inject("recover", robot)})'
        return ''

    # --- missions --------------------------------------------------------------------------

    def run(self, mission: Mission) -> None:
        observer = self.fleet.observer
        problem = self.problem_from_here(mission.panels)
        try:
            handle = self.client.submit(self.path, panels=mission.panels,
                                        time_limit=PLAN_TIME_LIMIT,
                                        blocked_timeout=BLOCKED_TIMEOUT, timeout=30)
        except MissionError as error:
            mission.outcome, mission.problems = 'not submitted', [f'submit: {error}']
            return
        mission.mission_id = handle.mission_id
        self.log(f'-- mission {mission.mission_id} ({mission.scenario} x{mission.panels})')
        observer.wait_for(lambda o: any(p.mission_id == mission.mission_id for p in o.plans)
                          or self.ended(mission), 60, f'the first plan of {mission.mission_id}')
        first = next((p for p in observer.plans if p.mission_id == mission.mission_id), None)
        length = first.makespan * TIME_SCALE if first is not None else 0.0
        began = time.monotonic()
        plan = sorted((self.rng.uniform(0, length), self.rng.choices(
            list(FAULT_WEIGHTS), list(FAULT_WEIGHTS.values()))[0])
            for _ in range(self.rng.randint(1, 4)))
        undo: list = []
        deadline = began + 60 + 20 * length
        restarted_planner = False
        while not self.ended(mission) and time.monotonic() < deadline:
            now = time.monotonic() - began
            if plan and plan[0][0] <= now:
                _, kind = plan.pop(0)
                done = self.fault(kind, undo, now)
                restarted_planner |= kind == 'kill planner' and bool(done)
                self.note(mission, now, done)
            due = [u for u in undo if u[0] <= now]
            for item in due:
                undo.remove(item)
                self.note(mission, now, self.undo(item[1], item[2]))
            time.sleep(0.02)
        for item in sorted(undo):  # the fleet made whole for the next mission
            self.note(mission, time.monotonic() - began, self.undo(item[1], item[2]))
        if not self.ended(mission):
            mission.outcome = 'hung'
            mission.problems.append(f'did not end within {deadline - began:.0f} s; last '
                                    f'status {observer.status}')
            mission.problems.append("the planner's log, its end:\n"
                                    + self.fleet.log('planner')[-3000:])
            try:
                self.client.cancel(mission.mission_id, reason='soak: hung')
            except MissionError as error:
                mission.problems.append(f'cancel: {error}')
            observer.wait_for(lambda o: self.ended(mission), 30, 'the hung mission cancelled')
        self.judge(mission, problem, None if restarted_planner else handle)
        self.wait_idle()

    def ended(self, mission: Mission) -> bool:
        status = self.fleet.observer.status
        return status is not None and status.mission_id == mission.mission_id \
            and status.state in ENDED

    def note(self, mission: Mission, at: float, what: str) -> None:
        if what:
            mission.faults.append(f'{what} @{at:.1f}s')
            self.log(f'   {at:6.2f} s  {what}')

    def problem_from_here(self, panels: int):
        """The mission's problem as the planner poses it: robots start where the previous
        mission left them, where the scenario knows that place."""
        problem = load_scenario(self.path, panels=panels)
        places = set(problem.locations())
        robots = []
        for robot in problem.robots:
            state = self.fleet.observer.robots.get(robot.name)
            here = (state.destination or state.location) if state is not None else ''
            robots.append(dataclasses.replace(robot, start_location=here)
                          if here in places else robot)
        return dataclasses.replace(problem, robots=tuple(robots))

    def wait_idle(self) -> None:
        """Every agent up, healthy and heard from just now; the planner up."""
        def healthy(o):
            now = time.time()
            return all(r in o.robots and o.robots[r].mode != RobotState.MODE_FAILED
                       and now - o.robots[r].stamp.sec - o.robots[r].stamp.nanosec * 1e-9 < 1
                       for r in self.robots)
        self.fleet.wait_for(healthy, 60, 'a healthy fleet after the mission')
        self.client.status(timeout=30)

    def judge(self, mission: Mission, problem, handle) -> None:
        """The outcome, and every way the mission went wrong."""
        observer = self.fleet.observer
        with observer.lock:
            status = observer.status
            plans = [p for p in observer.plans if p.mission_id == mission.mission_id]
            events = [e for e in observer.events if e.mission_id == mission.mission_id]
        if mission.outcome != 'hung':
            mission.outcome = {MissionStatus.STATE_COMPLETE: 'complete',
                               MissionStatus.STATE_FAILED: 'failed',
                               MissionStatus.STATE_CANCELLED: 'cancelled'}[status.state]
        mission.reasons = tuple(status.blocked_reasons)
        mission.jobs = f'{status.jobs_done}/{status.jobs_total}'
        mission.revisions = max((p.revision for p in plans), default=0)
        if mission.outcome == 'cancelled':
            mission.problems.append('cancelled, though nobody cancelled it')
        if mission.outcome == 'failed' and not mission.reasons:
            mission.problems.append('failed without a reason')
        if handle is not None:
            try:
                result = handle.result(timeout=10)
            except MissionError as error:
                mission.problems.append(f'RunMission result: {error}')
            else:
                expected = {'complete': 'complete', 'failed': ('failed', 'blocked too long')}
                if result.state not in expected.get(mission.outcome, ()):
                    mission.problems.append(f'RunMission result {result.state!r} but '
                                            f'mission_status says {mission.outcome}')
        if mission.outcome == 'complete':
            # Each job's last JOB_DONE and every robot's reports come on their own writers.
            observer.wait_for(lambda o: _done(problem, o, mission.mission_id), 15,
                              f'the job-done events of {mission.mission_id}')
            observer.wait_for(lambda o: _reported(o, mission.mission_id), 15,
                              f"the robots' reports of {mission.mission_id}")
            with observer.lock:
                events = [e for e in observer.events if e.mission_id == mission.mission_id]
        mission.problems += check_execution(problem, plans, events,
                                            complete=mission.outcome == 'complete')
        if mission.problems:
            self.keep(mission, plans, events)

    def keep(self, mission: Mission, plans, events) -> None:
        """What the observer saw of a mission that went wrong, next to the node logs."""
        lines = [f'{mission.line()}\n']
        for p in plans:
            lines.append(f'plan revision {p.revision} ({"; ".join(p.reasons)})\n')
            for r in p.robots:
                lines.append(f'  {r.robot}: ' + ' -> '.join(
                    f'{t.job}{"(continued)" if t.continued else ""}@{t.start:g}'
                    for t in r.tasks) + '\n')
        for e in events:
            lines.append(f'{e.event_id} r{e.plan_revision} {e.robot or "planner"} kind {e.kind} '
                         f'{e.job} t={e.time:.3f}\n')
        with self.fleet.observer.lock:
            states = list(self.fleet.observer.robots.values())
        lines += [f'state {s.robot}: mode {s.mode} job {s.current_job!r} revision '
                  f'{s.plan_revision} of {s.mission_id} at {s.location!r} -> {s.destination!r}\n'
                  for s in states]
        path = self.fleet.out / f'{mission.mission_id}.txt'
        path.write_text(''.join(lines))
        # The CI shows only what the test prints: the end of the record goes with it.
        mission.problems.append(f'what the observer saw ({path}), its end:\n'
                                + ''.join(lines)[-4000:])


def _done(problem, observer, mission_id) -> bool:
    plans = [p for p in observer.plans if p.mission_id == mission_id]
    events = [e for e in observer.events if e.mission_id == mission_id]
    done = {e.job for e in valid_events(plans, events) if e.kind == TaskEvent.KIND_JOB_DONE}
    return done >= {j.name for j in problem.jobs}


def _reported(observer, mission_id) -> bool:
    return operations_reported([p for p in observer.plans if p.mission_id == mission_id],
                               [e for e in observer.events if e.mission_id == mission_id])


def check_execution(problem, plans, events, complete: bool) -> list[str]:
    """No job done twice in its last attempt; the executed timeline of the jobs done valid
    (all of them, if the mission completed)."""
    problems = []
    last = valid_events(plans, {e.event_id: e for e in events}.values())
    done = Counter(e.job for e in last if e.kind == TaskEvent.KIND_JOB_DONE)
    problems += [f"job '{j}' done {n} times" for j, n in sorted(done.items()) if n > 1]
    jobs = {j.name for j in problem.jobs}
    if complete:
        problems += [f"job '{j}' never done" for j in sorted(jobs - set(done))]
    try:
        executed = executed_timeline(problem, plans, events)
    except AssertionError as error:
        return problems + [str(error)]
    unreported = sorted(set(done) - set(executed.jobs))
    problems += [f"job '{j}' declared done without its robots' reports" for j in unreported]
    kept = set(executed.jobs) & set(done)
    executed = dataclasses.replace(
        executed, jobs={j: a for j, a in executed.jobs.items() if j in kept},
        sequences={r: tuple(j for j in s if j in kept) for r, s in executed.sequences.items()})
    for before, after in problem.precedence:
        if after in kept and before not in kept:
            problems.append(f"job '{after}' done but its predecessor '{before}' is not")
    part = dataclasses.replace(
        problem, jobs=tuple(j for j in problem.jobs if j.name in kept),
        precedence=tuple((a, b) for a, b in problem.precedence if a in kept and b in kept),
        holding=tuple((a, b, q) for a, b, q in problem.holding if a in kept and b in kept),
        panels=())
    problems += [f'executed timeline: {p}' for p in validate_executed(part, executed)]
    # The robots of a job start it at one instant, computed alike from the same reports.
    starts = {}
    for e in last:
        if e.kind == TaskEvent.KIND_STARTED and e.job in kept:
            starts.setdefault(e.job, {})[e.robot] = e.time
    problems += [f"job '{j}' started apart: {t}" for j, t in sorted(starts.items())
                 if max(t.values()) - min(t.values()) > 1e-3]
    return problems


@pytest.fixture
def seed():
    value = int(os.environ.get('FJSP_SOAK_SEED') or secrets.randbelow(2 ** 32))
    print(f'\nsoak seed {value} (replay: FJSP_SOAK_SEED={value})', flush=True)
    return value


def test_soak(tmp_path, seed):
    rng = random.Random(seed)
    missions = []
    per_group = [MISSIONS // len(GROUPS) + (i < MISSIONS % len(GROUPS))
                 for i in range(len(GROUPS))]
    for (scenario, panel_choices), count in zip(GROUPS, per_group, strict=True):
        missions += [Mission(scenario, rng.choice(panel_choices)) for _ in range(count)]
    crashed = []
    for index, (scenario, _) in enumerate(GROUPS):
        mine = [m for m in missions if m.scenario == scenario]
        if not mine:
            continue
        soak = Soak(scenario, tmp_path / f'fleet{index}', rng,
                    lambda line: print(line, flush=True))
        try:
            soak.start()
            for mission in mine:
                soak.run(mission)
                print(mission.line() + ''.join(f'\n   PROBLEM: {p}' for p in mission.problems),
                      flush=True)
        finally:
            soak.close()
            for name in soak.fleet.processes:
                log = soak.fleet.log(name)
                if 'Traceback' in log:
                    at = log.index('Traceback')
                    crashed.append(f'{scenario} {name}:\n{log[max(0, at - 500):at + 3000]}')
    faults = Counter(f.split(' ')[0] for m in missions for f in m.faults)
    outcomes = Counter(m.outcome for m in missions)
    print(f'\nsoak seed {seed}: {len(missions)} missions, {sum(faults.values())} faults and '
          f'undos ({dict(faults)}), outcomes {dict(outcomes)}', flush=True)
    wrong = [m for m in missions if m.problems]
    assert not crashed and not wrong, (
        f'soak seed {seed} (replay: FJSP_SOAK_SEED={seed}):\n'
        + '\n'.join(m.line() + ''.join(f'\n   {p}' for p in m.problems) for m in wrong)
        + ''.join(f'\nnode crashed: {c}' for c in crashed))
    assert all(m.outcome in ('complete', 'failed') for m in missions)
