"""Re-planning after off-nominal events (docs/model.md, "Re-planning"): what remains, solved.

A failure turns the executing mission into a smaller problem posed at `now`:

- completed jobs leave, and precedence arcs out of them are dropped, as are arcs into jobs
  already running (they held when the job started);
- a running job whose robots are all healthy stays, as a `FixedJob` with its actual start,
  plan and robots and its expected end;
- a running job with a failed robot is aborted: it is redone from scratch, and its healthy
  robots are free at `now`, at the job's location;
- a completed jig job whose holder failed (or went offline) after it began and before the
  held job finished is voided (the hold it set up is lost, even if the holder is back) and
  redone, and the held job, if running, is aborted;
- a completed jig job whose held job has not finished (not started, or aborted) and whose
  holders never failed since it began stays as a `FixedJob` of just its holders: the holders
  are still holding, and only its holding arc forces them to go directly to the held job;
- every healthy robot starts where it is, released at max(now, free_at); a failed robot is
  left out, so it gets nothing. A robot on a leg, or stopped on one, starts at the point of
  the leg it has reached (a `Waypoint`), from which the plan may send it anywhere: it need not
  drive to the end of a leg no task needs any more. A robot carrying a held part to the job it
  holds into starts there, at its arrival.

A job the healthy robots cannot staff is reported in `Residual.blocked`, never raised: the
robot may come back, and a later state then gives a solvable residual. Holds that leave no
schedule at all (each holder waiting for the other's held job) are given up by `replan`.
"""

import dataclasses
import time
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from fractions import Fraction

from fjsp_common.decimals import decimal
from fjsp_planner.model.problem import (
    FixedJob,
    Job,
    Problem,
    Robot,
    how_many_can,
    max_staffed,
    robots_needed,
)
from fjsp_planner.model.schedule import JobAssignment, Result, Schedule, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.bounds.jobs import critical_path_bound
from fjsp_planner.solving.greedy import (
    GreedyOutOfTimeError,
    GreedyStuckError,
    guided_schedule,
    quick_schedule,
)
from fjsp_planner.solving.solve import solve


class StateError(ValueError):
    """An execution state that contradicts its problem; `problems` lists every reason."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__('\n'.join(self.problems))


WAYPOINT_SHARES = 100
"""A point on a leg is placed at the share of the leg behind it rounded down to a hundredth:
no further than the robot got, and a grid coarse enough to keep CP-SAT's time grid exact."""


@dataclass(frozen=True)
class Waypoint:
    """A point on the way between two places: `share` of the way from `origin` to
    `destination` (0 <= share < 1), where a robot on (or stopped on) that leg stands.

    Its distance to a place is the shorter of two ways the robot can surely drive: back to
    the origin, or on to the destination, and from there as the problem's distances say. It
    is exact where the leg is the shortest way between its ends, never shorter than a way the
    robot has, and so never lets a plan start a job before the robot can get there; the
    executed timeline holds whichever way the robot takes (docs/robot-drivers.md)."""

    origin: str
    destination: str
    share: Fraction

    @classmethod
    def reached(cls, origin: str, destination: str, progress: float) -> 'Waypoint':
        """The point of the leg a robot reporting `progress` (0..1) has reached, at least."""
        steps = min(max(int(progress * WAYPOINT_SHARES), 0), WAYPOINT_SHARES - 1)
        return cls(origin, destination, Fraction(steps, WAYPOINT_SHARES))

    @property
    def name(self) -> str:
        """As a location of a re-planned problem (and a plan's start location)."""
        return f'{self.origin}->{self.destination}@{float(self.share):.2f}'

    def distance(self, problem: Problem, place: str) -> Fraction:
        leg = problem.distance(self.origin, self.destination)
        return min(self.share * leg + problem.distance(self.origin, place),
                   (1 - self.share) * leg + problem.distance(self.destination, place))


@dataclass(frozen=True)
class RobotSituation:
    """Where a robot stands as re-planning starts: whether it can work, where and from when.
    (Not the `RobotState` message, from which the tracker derives it.)"""

    name: str
    healthy: bool
    location: str | None
    """Where it is, or where it is travelling to; None: never placed (may start anywhere)."""
    free_at: Fraction
    """When it can start something new: the end of its running job, or its arrival."""
    last_failure: Fraction | None = None
    """When it last became failed or offline, even if it is healthy again; None: never."""
    on_way: Waypoint | None = None
    """Where on a leg it is, travelling (then at least this far) or stopped; `location` is
    the leg's destination and `free_at` its arrival there."""


@dataclass(frozen=True)
class ExecutionState:
    now: Fraction
    done: frozenset[str]
    """Jobs completed."""
    running: Mapping[str, JobAssignment]
    """Jobs in progress: actual start, plan and robots; `end` is the expected end."""
    robots: Mapping[str, RobotSituation]
    """Every robot of the problem, by name."""
    done_as: Mapping[str, JobAssignment] = field(default_factory=dict)
    """How completed jobs were done, where known: their plan, robots and actual times. A
    done jig job's holders are the robots that did it, and its hold is lost if one of them
    failed after it began (without it: the previous schedule's robots and planned start)."""


@dataclass(frozen=True)
class Residual:
    problem: Problem | None
    """What remains to plan; None when nothing remains or something is blocked."""
    blocked: list[str]
    """Why what remains cannot be done by the healthy robots, one reason per job."""
    voided: list[str]
    """Completed jig jobs to redo because a holder failed (even if it is back now) after the
    jig job began and before the held job finished."""
    aborted: list[str]
    """Running jobs to redo from scratch: a robot on them failed, or their hold was lost."""
    kept: list[str] = field(default_factory=list)
    """Completed jig jobs kept as fixed jobs of their holders, which are still holding."""
    failed: list[str] = field(default_factory=list)
    """Robots left out of the residual problem."""
    released: list[str] = field(default_factory=list)
    """Jig jobs whose holds were given up on request (see `replan`): voided or aborted."""

    @property
    def complete(self) -> bool:
        """Every job is done: there is nothing left to plan."""
        return self.problem is None and not self.blocked


@dataclass(frozen=True)
class Replan:
    residual: Residual
    result: Result | None
    """None when there was nothing to solve: everything is done, or something is blocked."""
    problems: list[str]
    """What `validate` finds wrong with the result's schedule; empty when it is valid."""

    @property
    def schedule(self) -> Schedule | None:
        """The new plan of what remains, with its running and kept jobs fixed."""
        return self.result.schedule if self.result is not None else None


def replan(problem: Problem, previous: Schedule, state: ExecutionState, time_limit=1.0,
           workers=2) -> Replan:
    """Re-plan what remains of `problem` in `state`, `previous` being the schedule executed.

    The search starts from `previous` when it still works and, among the shortest schedules
    it finds, prefers the one moving the fewest robots off their previous jobs.

    Holds can deadlock: robots holding for two held jobs may each need the other's holders
    to finish. When the residual problem has no schedule and some of its fixed jobs hold,
    their holds are given up (done jig jobs voided, running ones aborted) and it is solved
    again, so such a state may take up to twice `time_limit`.
    """
    residual = residual_problem(problem, state, previous)
    if residual.problem is None:
        return Replan(residual, None, [])
    result = _solve(residual.problem, previous, time_limit, workers)
    holding = {a for a, _, _ in residual.problem.holding if a in residual.problem.fixed}
    if result.schedule is None and holding:
        residual = residual_problem(problem, state, previous, release=holding)
        if residual.problem is None:
            return Replan(residual, None, [])
        result = _solve(residual.problem, previous, time_limit, workers)
    problems = [] if result.schedule is None else validate(residual.problem, result.schedule)
    return Replan(residual, result, problems)


def _solve(residual: Problem, previous: Schedule, time_limit, workers) -> Result:
    """Solve, keeping close to `previous`, and starting from the best of what it suggests.

    A previous plan broken by the failure is a poor start: CP-SAT repairing its stale parts
    can take longer than finding a schedule afresh. So the search starts from `previous`
    restricted to what remains if that still works, else from a schedule that follows it
    where it can (`guided_schedule`), whichever is shorter; `solve` adds the greedy one.
    """
    began = time.monotonic()
    start = _starts(residual, previous, began + GUIDE_SHARE * time_limit)
    return solve(residual, time_limit=max(0.05, time_limit - (time.monotonic() - began)),
                 workers=workers, hint=start[0] if start else None, keep=previous)


GUIDE_SHARE = 0.5
"""Share of a re-plan's time limit the schedule following the previous plan may take: on 5
panels it is usually the re-plan (CP-SAT rarely improves on it in the rest of 0.7 s), and a
quarter of the limit was too little for it on a loaded machine."""


def _starts(residual: Problem, previous: Schedule, deadline) -> list[Schedule]:
    """Valid schedules of `residual` suggested by `previous`, shortest first."""
    found = []
    projected = _project(residual, previous)
    if projected is not None and not validate(residual, projected):
        found.append(projected)
    try:
        guided = guided_schedule(residual, previous, deadline)
    except (GreedyStuckError, GreedyOutOfTimeError):
        guided = None
    if guided is not None and not validate(residual, guided):
        found.append(guided)
    return sorted(found, key=lambda schedule: schedule.makespan)


def repair(problem: Problem, previous: Schedule, state: ExecutionState,
           time_limit: float = 0.5) -> Replan:
    """A valid plan of what remains, at once: the first stage of anytime re-planning.

    The shortest of the previous plan restricted to what remains (when that still works), a
    schedule following it where it can (`guided_schedule`) and the greedy schedule, without
    any search: publish it, then call `improve`. Holds that deadlock are given up as in
    `replan`. `time_limit` bounds the heuristics (a 5-panel residual takes ~0.2 s); should
    none finish in it, a quick greedy pass (~20 ms on 5 panels) is waited for.
    """
    began = time.monotonic()
    residual = residual_problem(problem, state, previous)
    if residual.problem is None:
        return Replan(residual, None, [])
    starts = _starts(residual.problem, previous, began + time_limit / 2)
    # With a start in hand, the greedy pass must not outlast the limit (`solve` waits for a
    # quick pass only when it has no valid schedule at all).
    result = solve(residual.problem, solver='greedy',
                   time_limit=max(0.05, began + time_limit - time.monotonic()),
                   hint=starts[0] if starts else None)
    holding = {a for a, _, _ in residual.problem.holding if a in residual.problem.fixed}
    if result.schedule is None and not starts and holding:
        residual = residual_problem(problem, state, previous, release=holding)
        if residual.problem is None:
            return Replan(residual, None, [])
        starts = _starts(residual.problem, previous, began + time_limit)
        result = solve(residual.problem, solver='greedy', time_limit=time_limit)
    if result.schedule is None and not starts:
        try:
            starts = [quick_schedule(residual.problem)]
        except GreedyStuckError:
            starts = []
    if starts and (result.schedule is None or starts[0].makespan < result.schedule.makespan):
        result = Result(Status.FEASIBLE, starts[0].makespan,
                        critical_path_bound(residual.problem), time.monotonic() - began,
                        starts[0], 'greedy', notes=('follows the previous plan where it can',))
    problems = [] if result.schedule is None else validate(residual.problem, result.schedule)
    return Replan(residual, result, problems)


@dataclass(frozen=True)
class Improvement:
    replan: Replan
    """The better plan (or the published one, unchanged), on the same residual problem."""
    improved: bool
    """The new plan is shorter than the published one by more than `margin`: worth a new
    revision. False keeps agents on the published plan rather than thrash for a few %."""


IMPROVE_MARGIN = 0.02


def improve(published: Replan, time_limit: float = 2.0, workers: int = 2,
            margin: float = IMPROVE_MARGIN, frozen_until=None,
            started=frozenset()) -> Improvement:
    """The second stage of anytime re-planning: search from the published plan.

    CP-SAT starts from `published` (a `repair` or earlier `improve` outcome) and, among the
    shortest schedules it finds, prefers those moving the fewest robots off it. `improved`
    says whether the result beats the published makespan by more than `margin` (a share).

    The robots follow `published` while the search runs. `frozen_until` (schedule time) is
    when the search's plan can reach them: what `published` has them do by then is kept as
    it is (`frozen`), and nothing else starts before it, so the better plan still fits what
    they did meanwhile; so are the `started` jobs (robots may be ahead of the plan). Without
    it the residual is the published one, posed at the failure's time: a plan that changes
    jobs the robots have started since cannot be followed.
    """
    residual = published.residual
    if residual.problem is None or published.schedule is None:
        return Improvement(published, False)
    if frozen_until is not None:
        residual = frozen(residual, published.schedule, Fraction(frozen_until), started)
    result = solve(residual.problem, time_limit=time_limit, workers=workers,
                   hint=published.schedule, keep=published.schedule)
    if result.schedule is None or validate(residual.problem, result.schedule):
        return Improvement(published, False)
    better = result.makespan < published.schedule.makespan * (1 - Fraction(margin))
    if not better:
        # Same plan, but the search may have proven it optimal: keep its bound.
        kept = dataclasses.replace(published.result, lower_bound=max(
            published.result.lower_bound or 0, result.lower_bound or 0))
        return Improvement(Replan(residual, kept, published.problems), False)
    return Improvement(Replan(residual, result, []), True)


def frozen(residual: Residual, schedule: Schedule, until: Fraction, started=frozenset()
           ) -> Residual:
    """`residual` with what `schedule` has the robots do before `until` fixed as it is.

    A job is kept when it starts before `until`, one of its robots sets off for it before
    then, or it is one of the `started` jobs, and so is every job a robot does before a kept
    one (a robot's fixed jobs come first in its sequence). The robots are released at
    `until` for anything else, so no other job starts before it. `schedule` stays valid for
    the result.
    """
    problem = residual.problem
    kept = set(problem.fixed) | (set(started) & set(schedule.jobs))
    for robot in problem.robots:
        for visit in schedule.visits(problem, robot.name):
            if visit.start < until or visit.travel_start < until:
                kept.add(visit.job)
    grew = True
    while grew:
        grew = False
        for sequence in schedule.sequences.values():
            last = max((i for i, job in enumerate(sequence) if job in kept), default=-1)
            before = set(sequence[:last + 1]) - kept
            if before:
                kept |= before
                grew = True
    fixed = dict(problem.fixed)
    for name in kept - set(fixed):
        a = schedule.jobs[name]
        fixed[name] = FixedJob(a.plan, a.start, a.end, dict(a.robots))
    robots = tuple(replace(r, release_time=max(r.release_time, until)) for r in problem.robots)
    return replace(residual, problem=replace(problem, fixed=fixed, robots=robots))


def _project(residual: Problem, previous: Schedule) -> Schedule | None:
    """`previous` restricted to the residual problem, or None if it misses one of its jobs."""
    jobs = {}
    for job in residual.jobs:
        fixed = residual.fixed.get(job.name)
        if fixed is not None:
            jobs[job.name] = JobAssignment(job.name, fixed.plan, fixed.start, fixed.end,
                                           dict(fixed.robots))
        elif job.name in previous.jobs:
            jobs[job.name] = previous.jobs[job.name]
        else:
            return None
    sequences = {r.name: tuple(j for j in previous.sequences.get(r.name, ())
                               if j in jobs and r.name in jobs[j].robots)
                 for r in residual.robots}
    return Schedule(jobs, sequences)


def residual_problem(problem: Problem, state: ExecutionState,
                     previous: Schedule | None = None, release=frozenset()) -> Residual:
    """The part of `problem` that remains in `state`, posed at `state.now`.

    `previous` is the schedule being executed. It tells which robots did the completed jobs,
    which matters only for a completed jig job whose held job has not started; without it
    such a state raises ValueError. `release` names jig jobs whose holds are given up: done
    ones are voided, running ones aborted. A state naming unknown jobs, robots or locations, or
    contradicting itself, raises `StateError` (a ValueError) listing every issue.
    """
    _raise_on_state_problems(problem, state)
    unknown = sorted(set(release) - {j.name for j in problem.jobs})
    if unknown:
        raise ValueError('release names unknown job(s) ' + ', '.join(f"'{j}'" for j in unknown))
    healthy = {name for name, robot in state.robots.items() if robot.healthy}
    aborted = {name for name, a in state.running.items()
               if not set(a.robots) <= healthy or name in release}
    holds = _open_holds(problem, state, previous)
    voided = {h.source for h in holds
              if not set(h.holders) <= healthy or h.source in release or _lost(h, state)}
    aborted.update(h.target for h in holds if h.source in voided and h.target in state.running)
    fixed = {name: a for name, a in state.running.items() if name not in aborted}
    kept, jigs, carried_to = {}, {}, {}
    for h in holds:
        if h.source not in voided and h.target not in fixed:
            kept.setdefault(h.source, {}).update(h.holders)
            jigs[h.source] = (h.began, h.plan)
            carried_to.update(dict.fromkeys(h.holders, h.target))
    _raise_on_hold_conflicts(holds, kept, state.running)

    order = [j.name for j in problem.jobs]
    residual = Residual(
        problem=None, blocked=[], voided=[j for j in order if j in voided],
        aborted=[j for j in order if j in aborted], kept=[j for j in order if j in kept],
        failed=[r.name for r in problem.robots if r.name not in healthy],
        released=[j for j in order if j in release and (j in voided or j in aborted)])
    todo = [j for j in problem.jobs
            if (j.name not in state.done or j.name in voided) and j.name not in fixed]
    if not todo and not fixed:
        return residual
    blocked = _staffing_problems(problem, todo, healthy, kept, residual.failed)
    if blocked:
        return replace(residual, blocked=blocked)
    posed = _pose(problem, state, healthy, todo, fixed, kept, jigs, carried_to, aborted)
    return replace(residual, problem=posed)


@dataclass(frozen=True)
class _Hold:
    """A holding arc whose source is done but whose target is not: its holders are still
    holding, unless they failed."""

    source: str
    target: str
    holders: dict[str, int]
    began: Fraction
    """When the source started, or at the latest could have."""
    plan: int | None
    """The source's plan, when known (the target's holders tell who, not which plan)."""


def _open_holds(problem, state, previous) -> list[_Hold]:
    """The holders are the source's type-q robots in `previous`; a source finished before
    `previous` was planned is missing from it only if its target was already running then,
    and the target's type-q robots are the holders.
    """
    holds = []
    for source, target, q in problem.holding:
        if source not in state.done or target in state.done:
            continue
        if source in state.done_as:
            done = state.done_as[source]
            robots, began, plan = done.robots, done.start, done.plan
        elif previous is not None and source in previous.jobs:
            done = previous.jobs[source]
            robots, began, plan = done.robots, done.start, done.plan
        elif target in state.running:
            robots, began, plan = state.running[target].robots, None, None
        else:
            raise ValueError(f"job '{source}' is done and holds for '{target}', which is "
                             f'not: pass the schedule being executed as `previous` to tell '
                             f'who holds it')
        unknown = sorted(set(robots) - {r.name for r in problem.robots})
        if unknown:
            raise ValueError(f"previous schedule: job '{source}' names unknown robot(s) "
                             + ', '.join(f"'{r}'" for r in unknown))
        holders = {r: t for r, t in robots.items() if t == q}
        if began is None:
            began = state.running[target].start - _longest(problem, holders)
        holds.append(_Hold(source, target, holders, began, plan))
    return holds


def _lost(hold: _Hold, state: ExecutionState) -> bool:
    """A holder failed, however briefly, after the jig job began: what it held was let go."""
    for robot in hold.holders:
        failed = state.robots[robot].last_failure
        if failed is not None and failed >= hold.began:
            return True
    return False


def _longest(problem, robots: Mapping[str, int]) -> Fraction:
    return max(problem.duration(r, q) for r, q in robots.items())


def _raise_on_hold_conflicts(holds, kept, running):
    """A holder at work on anything but the job it holds for contradicts its hold."""
    problems = []
    holding = {}
    for source, holders in kept.items():
        for robot in holders:
            if robot in holding:
                problems.append(f"robot '{robot}' cannot hold for both '{holding[robot]}' "
                                f"and '{source}'")
            holding[robot] = source
    targets = {(h.source, h.target) for h in holds}
    for name, a in running.items():
        for robot in a.robots:
            if robot in holding and (holding[robot], name) not in targets:
                problems.append(f"robot '{robot}' is running '{name}' while it should still "
                                f"hold since '{holding[robot]}'")
    if problems:
        raise StateError(problems)


def _staffing_problems(problem, todo, healthy, kept, failed) -> list[str]:
    """Jobs to do that no plan lets the healthy robots staff, each with the reason.

    A job held from a kept jig job must give its held operations to the holders, so the
    rest of its plan is matched against the other healthy robots.
    """
    forced = {}
    for source, target, q in problem.holding:
        if source in kept:
            forced.setdefault(target, {}).update(
                {r: t for r, t in kept[source].items() if t == q})
    names = [r.name for r in problem.robots if r.name in healthy]
    why_short = f' (failed: {", ".join(failed)})' if failed else ''
    problems = []
    for job in todo:
        holders = forced.get(job.name, {})
        others = [r for r in names if r not in holders]
        shortfalls = []
        for index, plan in enumerate(job.plans):
            rest = Counter(plan)
            rest.subtract(holders.values())
            if min(rest.values(), default=0) < 0:
                shortfalls.append(f'plan {index} {problem.plan_label(plan)} has no place for '
                                  f'the holders {_named(holders)}')
                continue
            rest_plan = list(rest.elements())
            staffed = max_staffed(problem, rest_plan, others)
            if staffed < len(rest_plan):
                held = f' besides the holders {_named(holders)}' if holders else ''
                needed = robots_needed(len(rest_plan), problem.plan_label(rest_plan))
                shortfalls.append(f'plan {index} {problem.plan_label(plan)} needs {needed}'
                                  f"{held}; {how_many_can(staffed, 'healthy')}")
        if len(shortfalls) == len(job.plans):
            problems.append(f"job '{job.name}' cannot be staffed: " + '; '.join(shortfalls)
                            + why_short)
    return problems


def _named(robots: Mapping[str, int]) -> str:
    return ', '.join(f"'{r}'" for r in sorted(robots))


def _pose(problem, state, healthy, todo, fixed, kept, jigs, carried_to, aborted) -> Problem:
    """The residual `Problem`: todo + fixed running + kept jig jobs, healthy robots only.
    `jigs`: kept jig job -> (when it began, its plan or None if unknown)."""
    now = state.now
    place = {}
    for name, a in fixed.items():
        place.update(dict.fromkeys(a.robots, problem.job(name).location))
    for name, holders in kept.items():
        place.update(dict.fromkeys(holders, problem.job(name).location))
    freed = {}
    for name in aborted:
        freed.update(dict.fromkeys(state.running[name].robots, problem.job(name).location))

    robots, waypoints = [], {}
    for robot in problem.robots:
        if robot.name not in healthy:
            continue
        s = state.robots[robot.name]
        location, release = s.location, max(now, s.free_at)
        if robot.name in freed:
            location, release = freed[robot.name], now
        elif s.on_way is not None and robot.name not in place:
            # It is free to turn where it is: as early as the rest of the leg allows.
            way = s.on_way
            rest = (1 - way.share) * problem.travel(robot.name, way.origin, way.destination)
            # Nor before its release: a robot standing at the start of its first leg may not
            # have been released yet.
            location, release = way.name, max(now, s.free_at - rest, robot.release_time)
            if way.share == 0:
                location = way.origin
            else:
                waypoints[way.name] = way
        # A robot's route begins at its fixed job, which is exempt from start-location travel.
        location = place.get(robot.name, location)
        robots.append(Robot(robot.name, robot.type, robot.speed, location, release))

    jobs = list(todo) + [problem.job(name) for name in fixed]
    # A job still running at `now` cannot end before it, whatever was expected.
    pinned = {name: FixedJob(a.plan, a.start, max(a.end, now), dict(a.robots))
              for name, a in fixed.items()}
    for name, holders in kept.items():
        # Only the holders are still bound to the jig job: its plan becomes just their
        # operations, which keeps the fixed job consistent and lets its other robots go on
        # freely. It keeps its index, which the published plan and the robots go by.
        job = problem.job(name)
        held_since, plan = jigs[name]
        ops = tuple(sorted(holders.values()))
        plans = (ops,) if plan is None else job.plans[:plan] + (ops,) + job.plans[plan + 1:]
        jobs.append(Job(job.name, job.location, plans))
        end = _hold_end(problem, state, name, holders, carried_to)
        start = min(held_since, end - _longest(problem, holders))
        pinned[name] = FixedJob(plan or 0, start, end, dict(holders))
    names = {j.name for j in jobs}
    scheduled = {j.name for j in todo}
    precedence = tuple((a, b) for a, b in problem.precedence if a in names and b in scheduled)
    holding = tuple((a, b, q) for a, b, q in problem.holding if a in names and b in scheduled)
    order = {j.name: i for i, j in enumerate(problem.jobs)}
    jobs.sort(key=lambda j: order[j.name])
    # No `panels`: once execution has begun, the panels are no longer identical copies.
    return Problem(
        operation_types=problem.operation_types,
        robot_types=problem.robot_types,
        robots=tuple(robots),
        jobs=tuple(jobs),
        distances=_with_waypoints(problem, waypoints),
        precedence=precedence,
        holding=holding,
        locomote=problem.locomote,
        time_overrides={k: v for k, v in problem.time_overrides.items() if k[0] in healthy},
        fixed=pinned,
        name=f'{problem.name}@{decimal(now)}',
    )


def _with_waypoints(problem: Problem, waypoints: Mapping[str, Waypoint]) -> Mapping:
    """The problem's distances, and those of the waypoints robots start at to every place
    and to each other (through an end of each leg)."""
    if not waypoints:
        return problem.distances
    distances = dict(problem.distances)
    places = problem.locations()
    for name, way in waypoints.items():
        for place in places:
            distances[name, place] = distances[place, name] = way.distance(problem, place)
    for a, first in waypoints.items():
        for b, second in waypoints.items():
            if a != b:
                distances[a, b] = min(
                    end_share + second.distance(problem, end)
                    for end, end_share in (
                        (first.origin, first.share * problem.distance(first.origin,
                                                                      first.destination)),
                        (first.destination, (1 - first.share) * problem.distance(
                            first.origin, first.destination))))
    return distances


def _hold_end(problem, state, source, holders, carried_to) -> Fraction:
    """When the kept jig job `source` ends for its holders, as its fixed job: the latest of
    their departures to the jobs they hold into, so that none of them gets there earlier
    than it can, nor in the past (the solvers apply release times only to a robot's first
    job, and this fixed job comes first). A holder still at the jig job's place sets off at
    `now`; one the state places at the held job's place, carrying the part there or holding
    it there already, arrives when its state says."""
    here = problem.job(source).location
    departures = []
    for robot in holders:
        there = problem.job(carried_to[robot]).location
        travel = problem.travel(robot, here, there)
        s = state.robots[robot]
        on_its_way = there != here and s.location == there
        departures.append((max(state.now, s.free_at) if on_its_way else state.now + travel)
                          - travel)
    return max(departures)


def _raise_on_state_problems(problem: Problem, state: ExecutionState) -> None:
    jobs = {j.name for j in problem.jobs}
    robots = {r.name for r in problem.robots}
    locations = set(problem.locations())
    problems = []
    if state.now < 0:
        problems.append(f'now is negative ({decimal(state.now)})')
    for name in sorted(set(state.done) - jobs):
        problems.append(f"done job '{name}' is not a job")
    for name in sorted(set(state.done) & set(state.running)):
        problems.append(f"job '{name}' is both done and running")
    busy = {}
    for name, a in state.running.items():
        if name not in jobs:
            problems.append(f"running job '{name}' is not a job")
            continue
        if a.job != name:
            problems.append(f"running job '{name}' carries the assignment of '{a.job}'")
        plans = problem.job(name).plans
        if not 0 <= a.plan < len(plans):
            problems.append(f"running job '{name}': no plan {a.plan}")
        elif sorted(a.robots.values()) != sorted(plans[a.plan]):
            problems.append(f"running job '{name}': robots do {sorted(a.robots.values())}, "
                            f'but plan {a.plan} is {sorted(plans[a.plan])}')
        if a.end < a.start:
            problems.append(f"running job '{name}' ends before it starts")
        for robot in a.robots:
            if robot not in robots:
                problems.append(f"running job '{name}' names unknown robot '{robot}'")
            elif robot in busy:
                problems.append(f"robot '{robot}' runs both '{busy[robot]}' and '{name}'")
            busy[robot] = name
    for name, r in state.robots.items():
        if name not in robots:
            problems.append(f"robot state for unknown robot '{name}'")
        if r.name != name:
            problems.append(f"robot state under '{name}' is named '{r.name}'")
        if r.location is not None and r.location not in locations:
            problems.append(f"robot '{name}' is at unknown location '{r.location}'")
        if r.on_way is not None:
            way = r.on_way
            for end in (way.origin, way.destination):
                if end not in locations:
                    problems.append(f"robot '{name}' is on its way from or to unknown "
                                    f"location '{end}'")
            if way.name in locations:
                problems.append(f"robot '{name}' is on its way at '{way.name}', which is "
                                'the name of a location too')
            if not 0 <= way.share < 1:
                problems.append(f"robot '{name}' is {way.share} of its way from "
                                f"'{way.origin}' to '{way.destination}': not within [0, 1)")
    for name in sorted(robots - set(state.robots)):
        problems.append(f"no state for robot '{name}'")
    if problems:
        raise StateError(problems)


def simulated_state(problem: Problem, schedule: Schedule, now: Fraction,
                    failed=frozenset(), done=frozenset()) -> ExecutionState:
    """The state reached at `now` by executing `schedule` exactly as planned, with the
    `failed` robots failing at `now`; `done` adds jobs finished before `schedule` was made.

    A robot leaves as soon as it is free and waits at its next job (`Schedule.visits`); one
    that has not started its first job yet and has no start location is still unplaced.
    """
    now = Fraction(now)
    finished = set(done) | {name for name, a in schedule.jobs.items() if a.end <= now}
    running = {name: a for name, a in schedule.jobs.items() if a.start <= now < a.end}
    robots = {}
    for robot in problem.robots:
        location, free_at = robot.start_location, robot.release_time
        for visit in schedule.visits(problem, robot.name):
            here = problem.job(visit.job).location
            if visit.end <= now:
                location, free_at = here, visit.end
                continue
            if visit.start <= now:
                location, free_at = here, visit.end
            elif location is not None and visit.travel_start <= now:
                location, free_at = here, visit.arrival
            break
        robots[robot.name] = RobotSituation(robot.name, robot.name not in failed, location,
                                        max(now, free_at),
                                        now if robot.name in failed else None)
    done_as = {name: a for name, a in schedule.jobs.items() if name in finished}
    return ExecutionState(now, frozenset(finished), running, robots, done_as)
