"""Greedy list scheduling: a valid schedule in milliseconds, for horizons, hints and fallback.

Jobs are placed one at a time, each at the assignment (plan and robots) that completes it
earliest. A holding arc (j, j', q) is placed as one block: j, then j' straight away with j's
type-q robots, so no other job can come between them on the holders' routes. When no block
can be placed (two arcs whose held jobs each wait for the other's jig job), j is placed
alone and its holders are kept for j', which is placed once its other predecessors are; a
pass that gets stuck so comes back to its last such choice and tries another.

`guided_schedule` places jobs instead in the order and with the staffing of a schedule to
follow (a plan a failure broke, or copies of one-panel optima), wherever that is still
possible, so that what worked before is kept and only exact times are recomputed.
"""

import random
import time
from dataclasses import dataclass
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule

MAX_CANDIDATES_PER_PLAN = 2000
MAX_BACKTRACKS = 1000
"""Partial placements of holding chains undone in one pass before it gives up as stuck."""


@dataclass(frozen=True)
class Breadth:
    """How widely a pass looks at each step."""

    jobs: int | None
    """Placeable jobs weighed, those ready soonest first (None: all)."""
    staffings: int
    """Staffings of a jig job tried, best first, when placing it with the jobs it holds into."""
    robots: int
    """Robots weighed per operation of a plan, those that could end it soonest first."""


BREADTH = Breadth(jobs=None, staffings=4, robots=8)
"""Every placeable job weighed: weighing fewer made many-panel schedules much longer, while
more staffings than 4 changed no makespan and cost time."""
QUICK = Breadth(jobs=4, staffings=2, robots=3)
"""For when a full pass does not fit the time left: a fraction of its time on many jobs."""
FULL_PASS_SHARE = 0.5
"""Share of the time to a deadline a full first pass may take before a quick one replaces it."""


class GreedyStuckError(RuntimeError):
    """No job can be placed although some remain (e.g. held robots are needed elsewhere)."""


class GreedyOutOfTimeError(RuntimeError):
    """The first pass did not finish before the deadline."""


def greedy_schedule(problem: Problem, passes: int = 16, seed: int = 0,
                    time_budget: float = 0.15, deadline: float | None = None) -> Schedule:
    """Best of up to `passes` randomised passes, the first deterministic; passes after the
    first stop once `time_budget` seconds are spent, so large problems stay fast.

    With a `deadline` (time.monotonic()), a first pass that has not finished within
    FULL_PASS_SHARE of the time left is replaced by a QUICK one, and a pass still running at
    the deadline is abandoned: the best finished one is returned, or `GreedyOutOfTimeError` raised
    if none finished."""
    rng = random.Random(seed)
    best, stuck = None, None
    began = time.monotonic()
    for attempt in range(passes):
        if attempt and best is not None and time.monotonic() - began > time_budget:
            break
        try:
            schedule = _first_pass(problem, deadline) if not attempt else _one_pass(
                problem, rng, deadline)
        except GreedyOutOfTimeError:
            if best is None:
                raise
            break
        except GreedyStuckError as error:
            stuck = error
            continue
        if best is None or schedule.makespan < best.makespan:
            best = schedule
    if best is None:
        raise stuck
    return best


def sampled_schedule(problem: Problem, deadline: float, seed: int = 0,
                     breadth: Breadth = QUICK) -> Schedule | None:
    """The best of randomised passes of `breadth` run one after another until `deadline`
    (time.monotonic()), or None if none finished: more samples of a large problem than full
    passes would give."""
    rng = random.Random(seed)
    best = None
    while time.monotonic() < deadline:
        try:
            schedule = _one_pass(problem, rng, deadline, breadth)
        except GreedyOutOfTimeError:
            break
        except GreedyStuckError:
            continue
        if best is None or schedule.makespan < best.makespan:
            best = schedule
    return best


def serial_upper_bound(problem: Problem) -> Fraction:
    """Makespan of doing the jobs one after another, each with its slowest robots."""
    robots = [r.name for r in problem.robots]
    locations = problem.locations()
    longest_leg = max((problem.travel(r, a, b) for r in robots for a in locations
                       for b in locations), default=Fraction(0))
    total = max([r.release_time for r in problem.robots]
                + [f.end for f in problem.fixed.values()])
    for job in problem.jobs:
        if job.name in problem.fixed:
            continue
        slowest = max((problem.duration(r, q) for plan in job.plans for q in plan
                       for r in robots if problem.duration(r, q) is not None),
                      default=Fraction(0))
        total += slowest + longest_leg
    return total


class _State:
    def __init__(self, problem: Problem, breadth):
        self.problem = problem
        self.breadth = breadth
        self.free = {r.name: r.release_time for r in problem.robots}
        self.free_f = {r: float(t) for r, t in self.free.items()}
        self.legs_f = {}
        """(robot, from, to) -> travel time in floating point, for ranking staffings."""
        self.ready = {}
        """job -> when its predecessors are all done, once they are all placed."""
        self.ready_f = {}
        self.where = {r.name: r.start_location for r in problem.robots}
        self.reserved = {}
        self.jobs = {}
        self.sequences = {r.name: [] for r in problem.robots}
        self.holds_into = {a: (b, q) for a, b, q in problem.holding}
        self.held_from = {b: (a, q) for a, b, q in problem.holding}
        self.order = {j.name: i for i, j in enumerate(problem.jobs)}
        self.durations = {}
        self.guide = {}
        """job -> its assignment in a schedule to follow (`guided_schedule`)."""
        self.predecessors = {j.name: [] for j in problem.jobs}
        for a, b in problem.precedence:
            self.predecessors[b].append(a)

    def copy(self):
        other = _State.__new__(_State)
        other.__dict__.update(self.__dict__)
        for name in ('free', 'free_f', 'where', 'reserved', 'jobs', 'ready', 'ready_f'):
            setattr(other, name, dict(getattr(self, name)))
        other.sequences = {r: list(s) for r, s in self.sequences.items()}
        return other

    def arrival(self, robot, location):
        here = self.where[robot]
        leg = Fraction(0) if here is None else self.problem.travel(robot, here, location)
        return self.free[robot] + leg

    def arrival_f(self, robot, location) -> float:
        """`arrival` in floating point, without Fraction arithmetic."""
        here = self.where[robot]
        if here is None or here == location:
            return self.free_f[robot]
        key = (robot, here, location)
        leg = self.legs_f.get(key)
        if leg is None:
            leg = self.legs_f[key] = float(self.problem.travel(robot, here, location))
        return self.free_f[robot] + leg

    def place(self, name, plan, robots):
        """Start the job as soon as it is ready and its robots have arrived, exactly."""
        location = self.problem.job(name).location
        start = max([self.ready_at(name)] + [self.arrival(r, location) for r in robots])
        end = start + max(self.problem.duration(r, q) for r, q in robots.items())
        self.commit(JobAssignment(name, plan, start, end, dict(robots)))

    def commit(self, assignment):
        self.jobs[assignment.job] = assignment
        for r in assignment.robots:
            # max: a running (fixed) job may end before its robot's release time.
            self.free[r] = max(self.free[r], assignment.end)
            self.free_f[r] = float(self.free[r])
            self.where[r] = self.problem.job(assignment.job).location
            self.sequences[r].append(assignment.job)
            if self.reserved.get(r) == assignment.job:
                del self.reserved[r]
        target = self.holds_into.get(assignment.job)
        if target:
            for r, q in assignment.robots.items():
                if q == target[1]:
                    self.reserved[r] = target[0]

    def ready_at(self, name):
        """When every predecessor is done, or None while one is still unplaced."""
        found = self.ready.get(name)
        if found is None:
            ends = []
            for a in self.predecessors[name]:
                if a not in self.jobs:
                    return None
                ends.append(self.jobs[a].end)
            found = self.ready[name] = max(ends, default=Fraction(0))
            self.ready_f[name] = float(found)
        return found

    def candidates(self, name, ready, forced=None):
        """(end, start, plan, robots) for the `breadth.staffings` best ways to staff the job,
        best first, in floating point: ranking in exact Fractions made a pass on many jobs
        many times slower. `place` recomputes the chosen staffing's times exactly."""
        job = self.problem.job(name)
        forced = forced or {}
        free_robots = [r for r in self.free
                       if r not in forced and self.reserved.get(r, name) == name]
        arrive_f = {r: self.arrival_f(r, job.location) for r in (*free_robots, *forced)}
        ready_f = max([float(ready)] + [arrive_f[r] for r in forced])
        forced_longest = max((self.duration_f(r, q) for r, q in forced.items()), default=0.0)
        out = []
        for plan_index, plan in enumerate(job.plans):
            remaining = list(plan)
            for q in forced.values():
                if q not in remaining:
                    break
                remaining.remove(q)
            else:
                remaining.sort()
                able = {}
                for q in set(remaining):
                    found = [(r, arrive_f[r], d) for r in free_robots
                             if (d := self.duration_f(r, q)) is not None]
                    if len(found) > self.breadth.robots:
                        found.sort(key=lambda o: max(ready_f, o[1]) + o[2])
                        found = found[:self.breadth.robots + remaining.count(q) - 1]
                    able[q] = found
                found = []
                _staff(remaining, able, 0, 0, [], ready_f, forced_longest, found)
                for start, end, chosen in found:
                    robots = dict(forced)
                    robots.update(zip(chosen, remaining, strict=True))
                    out.append((end, start, plan_index, robots))
        out.sort(key=lambda c: (c[0], c[1]))
        return out[:self.breadth.staffings]

    def duration_f(self, robot, q):
        key = (robot, q)
        if key not in self.durations:
            time = self.problem.duration(robot, q)
            self.durations[key] = None if time is None else float(time)
        return self.durations[key]


def _staff(operations, able, k, first, chosen, start, longest, found):
    """Append to `found` (start, end, robots) for each way to give `operations[k:]` (sorted)
    distinct robots not in `chosen`, up to MAX_CANDIDATES_PER_PLAN: equal operations take
    robots in the order of `able` (robot, arrival, duration), so each set is found once."""
    if k == len(operations):
        found.append((start, start + longest, tuple(chosen)))
        return
    options = able[operations[k]]
    for index in range(first, len(options)):
        if len(found) >= MAX_CANDIDATES_PER_PLAN:
            return
        robot, arrival, duration = options[index]
        if robot in chosen:
            continue
        chosen.append(robot)
        following = index + 1 if k + 1 < len(operations) and operations[k + 1] == operations[
            k] else 0
        _staff(operations, able, k + 1, following, chosen, max(start, arrival),
               max(longest, duration), found)
        chosen.pop()


def _first_pass(problem: Problem, deadline) -> Schedule:
    if deadline is None:
        return _one_pass(problem, None)
    share = time.monotonic() + FULL_PASS_SHARE * (deadline - time.monotonic())
    try:
        return _one_pass(problem, None, share)
    except GreedyOutOfTimeError:
        return _one_pass(problem, None, deadline, QUICK)


def quick_schedule(problem: Problem) -> Schedule:
    """One QUICK pass: the fastest valid schedule this module makes (no deadline)."""
    return _one_pass(problem, None, None, QUICK)


def guided_schedule(problem: Problem, guide: Schedule, deadline: float | None = None
                    ) -> Schedule:
    """A schedule that follows `guide` (e.g. the plan a failure broke) as far as it still
    can: jobs are placed in the guide's start order, each with the guide's plan and robots
    when they can still do it, the rest (a failed robot's jobs, new jobs) where they end
    soonest. Raises GreedyStuckError or GreedyOutOfTimeError like `greedy_schedule`."""
    return _one_pass(problem, None, deadline, BREADTH, guide)


def _one_pass(problem: Problem, rng, deadline=None, breadth=None, guide=None) -> Schedule:
    state = _State(problem, breadth or BREADTH)
    state.guide = guide.jobs if guide is not None else {}
    for name, fixed in problem.fixed.items():
        state.commit(JobAssignment(name, fixed.plan, fixed.start, fixed.end,
                                   dict(fixed.robots)))
    pending = [j.name for j in problem.jobs if j.name not in problem.fixed]
    backtrack, tries = [], 0
    while pending:
        if deadline is not None and time.monotonic() > deadline:
            raise GreedyOutOfTimeError
        options = _options(state, pending)
        if options:
            options.sort(key=lambda o: (_guide_order(state, o[1][0][0]), o[0]))
            if rng is not None and len(options) > 1 and rng.random() < 0.3:
                choice = options[rng.randrange(min(3, len(options)))]
            else:
                choice = options[0]
        else:
            # Each partial placement keeps holders from other jobs: the first tried may
            # leave a job no robots, so the others are kept to come back to.
            options = sorted(_options(state, pending, partial=True),
                             key=lambda o: (_guide_order(state, o[1][0][0]), o[0]))
            if not options:
                if not backtrack or tries >= MAX_BACKTRACKS:
                    raise GreedyStuckError('greedy scheduling found no job it can place next '
                                           'among ' + ', '.join(sorted(pending)))
                state, pending, options = backtrack.pop()
                tries += 1
            choice = options[0]
            if len(options) > 1:
                backtrack.append((state.copy(), list(pending), options[1:]))
        for name, plan, robots in choice[1]:
            state.place(name, plan, robots)
            pending.remove(name)
    return Schedule(state.jobs, {r: tuple(s) for r, s in state.sequences.items()})


def _options(state: _State, pending, partial=False) -> list:
    """(score, [placements]) for the jobs that can be placed next, with the jobs they hold
    into; with `partial`, a holding chain whose held job still waits for another job is
    offered up to that job, its holders kept for it (two arcs whose held jobs each wait for
    the other's jig job can only be placed so)."""
    options = []
    for name in _by_readiness(state, pending):
        if name in state.held_from and state.held_from[name][0] not in state.jobs:
            continue
        block = _block_option(state, name, partial)
        if block is not None:
            options.append(block)
            if state.breadth.jobs is not None and len(options) == state.breadth.jobs:
                break
    return options


def _guide_order(state: _State, name) -> float:
    """Where the guide starts the job (unguided passes and new jobs: no preference)."""
    assignment = state.guide.get(name)
    return float(assignment.start) if assignment is not None else float('inf')


def _guide_first(state: _State, name, ready, forced, candidates):
    """`candidates` with the guide's staffing of the job first, when it is still possible."""
    assignment = state.guide.get(name)
    if assignment is None:
        return candidates
    robots = dict(assignment.robots)
    job = state.problem.job(name)
    if (assignment.plan >= len(job.plans)
            or sorted(robots.values()) != sorted(job.plans[assignment.plan])
            or any(r not in state.free or state.duration_f(r, q) is None
                   or state.reserved.get(r, name) != name for r, q in robots.items())
            or any(robots.get(r) != q for r, q in forced.items())):
        return candidates
    start = max(float(ready), *(float(state.arrival(r, job.location)) for r in robots))
    end = start + max(state.duration_f(r, q) for r, q in robots.items())
    return [(end, start, assignment.plan, robots)] + [
        c for c in candidates if (c[2], c[3]) != (assignment.plan, robots)]


def _by_readiness(state: _State, pending):
    """Pending jobs whose predecessors are all placed, those ready soonest first, ties in the
    problem's order (which keeps a panel's jobs together)."""
    ready = []
    for name in pending:
        if state.ready_at(name) is not None:
            ready.append((state.ready_f[name], state.order[name], name))
    ready.sort()
    return [name for _, _, name in ready]


def _block_option(state: _State, name, partial=False):
    """(score, [placements]) for the job and the jobs it holds into, or None if not ready;
    with `partial`, for the job and those it holds into up to the first that waits for a job
    outside the chain."""
    chain = [name]
    while chain[-1] in state.holds_into:
        chain.append(state.holds_into[chain[-1]][0])
    for index, member in enumerate(chain[1:], 1):
        others = [a for a in state.predecessors[member] if a not in chain]
        if any(a not in state.jobs for a in others):
            if not partial:
                return None
            chain = chain[:index]
            break
    ready = state.ready_at(name)
    if ready is None:
        return None
    forced = {}
    if name in state.held_from:
        _, q = state.held_from[name]
        forced = {r: q for r, target in state.reserved.items() if target == name}
    candidates = _guide_first(state, name, ready, forced,
                              state.candidates(name, ready, forced))
    if len(chain) == 1:
        if not candidates:
            return None
        end, _, plan, robots = candidates[0]
        return (end, [(name, plan, robots)])
    if name in state.guide and candidates:
        guided = _place_chain(state, chain, candidates[0][2], candidates[0][3])
        if guided is not None:
            return guided
    # The jig job's staffing decides who must also do the held job, so judge each staffing
    # by when the whole chain completes, not by when the jig job does.
    best = None
    for _, _, plan, robots in candidates:
        placed = _place_chain(state, chain, plan, robots)
        if placed is not None and (best is None or placed[0] < best[0]):
            best = placed
    return best


def _place_chain(state: _State, chain, plan, robots):
    """(end of the chain, placements) with the first job staffed so, the rest greedily."""
    trial = state.copy()
    trial.place(chain[0], plan, robots)
    placements = [(chain[0], plan, robots)]
    end = None
    for member in chain[1:]:
        _, q = trial.held_from[member]
        forced = {r: q for r, target in trial.reserved.items() if target == member}
        ready = trial.ready_at(member)
        options = _guide_first(trial, member, ready, forced,
                               trial.candidates(member, ready, forced))
        if not options:
            return None
        end, _, member_plan, member_robots = options[0]
        trial.place(member, member_plan, member_robots)
        placements.append((member, member_plan, member_robots))
    return end, placements
