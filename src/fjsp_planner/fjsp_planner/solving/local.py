"""A local search for multi-robot jobs with travel (docs/solver.md, "Local search").

A schedule is kept as its decisions: each job's plan and robots, each robot's order of jobs;
its times are the earliest those decisions allow (`compact.earliest_schedule`), computed
here in floating point for speed and exactly for the schedule returned. Each step looks at
the jobs of a critical path (the chain of jobs, each started by the end of the one before
it on a robot or by precedence, that ends at the makespan) and tries, for each:

- giving one of its operations to another able robot, put into that robot's order where the
  job's current start falls (or one place earlier or later);
- swapping it with the job before or after it on one of its robots, or moving it on that
  robot's route next to a job at the same place (the legs around it vanish);

and makes the best move that shortens the makespan, or that keeps it and shortens the sum
of job ends (which frees robots earlier), or else the least bad one; a job moved is left
where it is for some steps (tabu) unless moving it beats the best schedule, so the search
walks on past a local optimum instead of undoing its last move. After some steps without a
better schedule it shakes the best one by a few random moves. Jobs of holding arcs keep
their holders and their order (the holders go directly from one to the other); running
(fixed) jobs are never moved. A move whose orders and precedence close a cycle is refused.
"""

import random
import time

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Schedule
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.compact import earliest_schedule

STALL_STEPS = 30
"""Steps without a better schedule before the search shakes the best one."""
SHAKE_MOVES = 3
TABU_STEPS = (8, 20)
"""A job moved is tabu for a random number of steps in this range: long enough that the
search does not cycle through a few schedules, short enough that a stall of STALL_STEPS still
ends in a shake."""


class _Instance:
    """The problem in floating point, by index."""

    def __init__(self, problem: Problem):
        self.problem = p = problem
        self.names = [j.name for j in p.jobs]
        self.index = {name: k for k, name in enumerate(self.names)}
        self.robots = [r.name for r in p.robots]
        self.location = [p.job(name).location for name in self.names]
        self.predecessors = [[] for _ in self.names]
        for a, b in p.precedence:
            self.predecessors[self.index[b]].append(self.index[a])
        self.fixed = {self.index[name]: (float(f.start), float(f.end))
                      for name, f in p.fixed.items()}
        self.held_types = {}
        """job -> operation types a holding arc ties to its robots."""
        for a, b, q in p.holding:
            for name in (a, b):
                self.held_types.setdefault(self.index[name], set()).add(q)
        self.holding = [(self.index[a], self.index[b], q) for a, b, q in p.holding]
        self.release = {r.name: float(r.release_time) for r in p.robots}
        self.successors = [[] for _ in self.names]
        for j, before in enumerate(self.predecessors):
            for a in before:
                self.successors[a].append(j)
        # Tabled once: timing a candidate looks them up for every job and robot.
        places = sorted(set(self.location))
        self.arrival = {r.name: [self.release[r.name] + self._leg(r.name, r.start_location, here)
                                 for here in self.location] for r in p.robots}
        self.between = {r: {a: {b: self._leg(r, a, b) for b in places} for a in places}
                        for r in self.robots}
        self.times = {r: {q: float(found) for q in p.operation_types
                          if (found := p.duration(r, q)) is not None} for r in self.robots}

    def _leg(self, robot, a, b) -> float:
        return 0.0 if a is None else float(self.problem.travel(robot, a, b))


class _Solution:
    """Plans, robots (job -> {robot: operation type}) and orders (robot -> [job])."""

    def __init__(self, plan, robots, orders):
        self.plan, self.robots, self.orders = plan, robots, orders
        self.start = self.end = None
        self.makespan = self.total = None
        self.cause = None
        """job -> the job whose end set its start (None: its robots' release or arrival)."""

    def copy(self):
        return _Solution(list(self.plan), [dict(r) for r in self.robots],
                         {r: list(o) for r, o in self.orders.items()})

    def evaluate(self, inst: _Instance) -> bool:
        """Earliest times; False if the orders and precedence close a cycle."""
        n = len(inst.names)
        previous = [None] * n
        waiting = [len(before) for before in inst.predecessors]
        unblocks = [list(after) for after in inst.successors]
        for r, order in self.orders.items():
            for a, b in zip(order, order[1:], strict=False):
                if previous[b] is None:
                    previous[b] = {r: a}
                else:
                    previous[b][r] = a
                waiting[b] += 1
                unblocks[a].append(b)
        ready = [j for j in range(n) if not waiting[j]]
        start, end, cause = [0.0] * n, [0.0] * n, [None] * n
        location, predecessors, fixed = inst.location, inst.predecessors, inst.fixed
        arrival, between, times, release = inst.arrival, inst.between, inst.times, inst.release
        done = 0
        while ready:
            j = ready.pop()
            done += 1
            if j in fixed:
                start[j], end[j] = fixed[j]
            else:
                here = location[j]
                at, by = 0.0, None
                for a in predecessors[j]:
                    if end[a] > at:
                        at, by = end[a], a
                longest = 0.0
                before_on = previous[j]
                for r, q in self.robots[j].items():
                    before = None if before_on is None else before_on.get(r)
                    if before is None:
                        there = arrival[r][j]
                        if there > at:
                            at, by = there, None
                    else:
                        there = end[before] + between[r][location[before]][here]
                        if there < release[r]:
                            there = release[r]
                        if there > at:
                            at, by = there, before
                    took = times[r][q]
                    if took > longest:
                        longest = took
                start[j], end[j], cause[j] = at, at + longest, by
            for b in unblocks[j]:
                waiting[b] -= 1
                if not waiting[b]:
                    ready.append(b)
        if done < n:
            return False
        self.start, self.end, self.cause = start, end, cause
        self.makespan, self.total = max(end, default=0.0), sum(end)
        return True

    def critical(self) -> list[int]:
        """The jobs of a critical path, last first."""
        j = max(range(len(self.end)), key=self.end.__getitem__)
        path = []
        while j is not None and j not in path:
            path.append(j)
            j = self.cause[j]
        return path

    def better(self, other) -> bool:
        return (self.makespan, self.total) < (other.makespan - 1e-9, other.total - 1e-9)


def local_search(problem: Problem, start: Schedule, deadline: float, seed: int = 0,
                 stop=None) -> tuple[Schedule, float]:
    """The best schedule the search finds from `start` (valid) by `deadline` or until
    `stop()`, and when it was found (time.monotonic())."""
    inst = _Instance(problem)
    current = _from_schedule(inst, start)
    found_at = time.monotonic()
    if not current.evaluate(inst):
        return start, found_at
    best = current
    rng = random.Random(seed)
    stalled = 0
    tabu, step = {}, 0
    while time.monotonic() < deadline and not (stop is not None and stop()):
        step += 1
        moved, job = _best_move(inst, current, rng, tabu, step, best)
        if job is not None:
            tabu[job] = step + rng.randint(*TABU_STEPS)
        if moved is None or not moved.better(current):
            stalled += 1
            if stalled >= STALL_STEPS:
                current, stalled = _shaken(inst, best, rng), 0
            elif moved is None:
                current, stalled = _shaken(inst, best, rng), 0
            else:
                current = moved
            continue
        current = moved
        if current.better(best):
            best, found_at, stalled = current, time.monotonic(), 0
    schedule = _to_schedule(inst, best)
    if schedule.makespan >= start.makespan or validate(problem, schedule):
        return start, found_at
    return schedule, found_at


def _from_schedule(inst: _Instance, schedule: Schedule) -> _Solution:
    plan = [schedule.jobs[name].plan for name in inst.names]
    robots = [dict(schedule.jobs[name].robots) for name in inst.names]
    orders = {r: [inst.index[j] for j in schedule.sequences.get(r, ())] for r in inst.robots}
    return _Solution(plan, robots, orders)


def _to_schedule(inst: _Instance, solution: _Solution) -> Schedule:
    names = inst.names
    return earliest_schedule(
        inst.problem, {names[j]: solution.plan[j] for j in range(len(names))},
        {names[j]: solution.robots[j] for j in range(len(names))},
        {r: [names[j] for j in order] for r, order in solution.orders.items()})


def _movable_operations(inst: _Instance, solution: _Solution, j):
    """(robot, operation type) of job j that a move may give to another robot."""
    if j in inst.fixed:
        return []
    held = inst.held_types.get(j, ())
    return [(r, q) for r, q in solution.robots[j].items() if q not in held]


def _tied(inst: _Instance, j) -> bool:
    return j in inst.fixed or j in inst.held_types


def _best_move(inst: _Instance, current: _Solution, rng, tabu, step, record):
    """The best solution one move from `current` around a job of its critical path, and that
    job; a job tabu until a later step is moved only to beat `record`."""
    best, job = None, None
    for j in current.critical():
        banned = tabu.get(j, 0) > step
        for moved in _moves(inst, current, j, rng):
            if moved.evaluate(inst) and (best is None or moved.better(best)) and \
                    (not banned or moved.better(record)):
                best, job = moved, j
    return best, job


def _moves(inst: _Instance, current: _Solution, j, rng):
    """Solutions one move from `current` around job j (not yet evaluated)."""
    for r, q in _movable_operations(inst, current, j):
        others = [o for o in inst.robots
                  if o not in current.robots[j] and q in inst.times[o]]
        rng.shuffle(others)
        for other in others[:4]:
            for shift in (0, -1, 1):
                moved = current.copy()
                del moved.robots[j][r]
                moved.robots[j][other] = q
                moved.orders[r].remove(j)
                order = moved.orders[other]
                place = sum(1 for k in order if current.start[k] < current.start[j]) + shift
                if 0 <= place <= len(order):
                    order.insert(place, j)
                    if _holds_kept(inst, moved, other):
                        yield moved
    if _tied(inst, j):
        return
    for r in current.robots[j]:
        order = current.orders[r]
        k = order.index(j)
        for other in (k - 1, k + 1):
            if 0 <= other < len(order) and not _tied(inst, order[other]):
                moved = current.copy()
                swapped = moved.orders[r]
                swapped[k], swapped[other] = swapped[other], swapped[k]
                yield moved
        # Next to a job at the same place on the robot's route, the legs around it vanish.
        here = inst.location[j]
        rest = order[:k] + order[k + 1:]
        places = [m for m in range(len(rest) + 1)
                  if m != k and ((m > 0 and inst.location[rest[m - 1]] == here)
                                 or (m < len(rest) and inst.location[rest[m]] == here))]
        rng.shuffle(places)
        for m in places[:4]:
            moved = current.copy()
            moved.orders[r] = rest[:m] + [j] + rest[m:]
            if _holds_kept(inst, moved, r):
                yield moved


def _holds_kept(inst: _Instance, solution: _Solution, robot) -> bool:
    """Whether every job the robot holds out of is still directly followed by the job it
    holds into, in the robot's order."""
    order = solution.orders[robot]
    for a, b, q in inst.holding:
        if solution.robots[a].get(robot) == q:
            k = order.index(a)
            if k + 1 >= len(order) or order[k + 1] != b:
                return False
    return True


def _shaken(inst: _Instance, best: _Solution, rng) -> _Solution:
    """`best` after a few random moves that keep it evaluable."""
    current = best
    for _ in range(SHAKE_MOVES):
        jobs = list(range(len(inst.names)))
        rng.shuffle(jobs)
        for j in jobs[:10]:
            options = list(_moves(inst, current, j, rng))
            rng.shuffle(options)
            moved = next((o for o in options if o.evaluate(inst)), None)
            if moved is not None:
                current = moved
                break
    return current

