"""A local search for multi-robot jobs with travel (docs/solver.md, "Local search").

A schedule is kept as its decisions: each job's plan and robots, each robot's order of jobs;
its times are the earliest those decisions allow (`compact.earliest_schedule`), computed
here in floating point for speed and exactly for the schedule returned. Each step looks at
the jobs of a critical path (the chain of jobs, each started by the end of the one before
it on a robot or by precedence, that ends at the makespan) and tries, for each:

- giving one of its operations to another able robot, put into that robot's order where the
  job's current start falls (or one place earlier or later);
- doing it by another of its plans: its robots able to do one of that plan's operations keep
  it, other able robots are drawn for the rest and put into their orders where it starts;
- swapping it with the job before or after it on one of its robots (on every robot the two
  share: swapped on one only, their order on another would close a cycle), or moving it on
  that robot's route next to a job at the same place (the legs around it vanish).

Each move is first estimated by the longest path through what it changes, from the current
times and each job's longest way to the end (as in Mastrolilli and Gambardella's tabu
search): a few lookups instead of timing every job. The few best estimated are timed; the
search makes the best that shortens the makespan, or that keeps it and shortens the sum
of job ends (which frees robots earlier), or else the least bad one; a job moved is left
where it is for some steps (tabu) unless moving it beats the best schedule, so the search
walks on past a local optimum instead of undoing its last move. After some steps without a
better schedule it ruins and recreates the best one: a job of its critical path and the jobs
nearest it in time that share its place or one of its robots leave the schedule, and each in
turn, earliest first, is put back where it ends the schedule soonest (by any of a few random
staffings of any of its plans, each robot's place in its order chosen by estimate, the best
few timed), which lets a stretch of several robots' routes change at once. Jobs of holding
arcs keep their holders and their order (the holders go directly from one to the other);
running (fixed) jobs are never moved. A move whose orders and precedence close a cycle, or that
puts a job before a running one without room for it, is refused.
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
EXACT_MOVES = 3
"""Moves timed per step, the best estimated: an estimate costs a few lookups, timing a move
every job."""
PLAN_STAFFINGS = 3
"""Random staffings tried per other plan of a job of the critical path, each step."""
RUIN_JOBS = 8
"""Jobs taken out of the best schedule and put back when the search stalls: 4 and 14 did as
well on average (60 and 120 jobs); far more than a shake's three moves."""
RECREATE_STAFFINGS = 8
"""Random staffings drawn per plan of a job put back (the one it had gets no preference:
with it the search did no better)."""


class _Instance:
    """The problem in floating point, by index."""

    def __init__(self, problem: Problem):
        self.problem = p = problem
        self.names = [j.name for j in p.jobs]
        self.index = {name: k for k, name in enumerate(self.names)}
        self.robots = [r.name for r in p.robots]
        self.location = [p.job(name).location for name in self.names]
        self.plans = [p.job(name).plans for name in self.names]
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
        self.holds_into = {}
        """job -> [(the job it holds into, operation type)]."""
        for a, b, q in self.holding:
            self.holds_into.setdefault(a, []).append((b, q))
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
        self.previous = self.timed = None
        """job -> {robot: the job before it in the robot's order} (None: first on all), and
        the jobs in the order they were timed (a topological order)."""

    def copy(self):
        return _Solution(list(self.plan), [dict(r) for r in self.robots],
                         {r: list(o) for r, o in self.orders.items()})

    def evaluate(self, inst: _Instance) -> bool:
        """Earliest times; False if the orders and precedence close a cycle, or a robot
        cannot reach a running (fixed) job from the job before it in its order by its
        start."""
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
        timed = []
        location, predecessors, fixed = inst.location, inst.predecessors, inst.fixed
        arrival, between, times, release = inst.arrival, inst.between, inst.times, inst.release
        while ready:
            j = ready.pop()
            timed.append(j)
            if j in fixed:
                start[j], end[j] = fixed[j]
                # A running job starts where it is: a job put before it must make way.
                for r, before in (previous[j] or {}).items():
                    if end[before] + between[r][location[before]][location[j]] > start[j] + 1e-9:
                        return False
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
        if len(timed) < n:
            return False
        self.start, self.end, self.cause = start, end, cause
        self.previous, self.timed = previous, timed
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
                current, stalled = _ruined_and_recreated(inst, best, rng), 0
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


class _Around:
    """What the estimates of moves from a solution need: each job's longest way to the
    end (from its start, its duration included) and its next job on each robot."""

    def __init__(self, inst: _Instance, solution: _Solution):
        self.solution = solution
        start, end = solution.start, solution.end
        n = len(start)
        following = [None] * n
        for r, order in solution.orders.items():
            for a, b in zip(order, order[1:], strict=False):
                if following[a] is None:
                    following[a] = {r: b}
                else:
                    following[a][r] = b
        self.following = following
        tail = [0.0] * n
        location, between, successors = inst.location, inst.between, inst.successors
        for j in reversed(solution.timed):
            longest = 0.0
            for b in successors[j]:
                if tail[b] > longest:
                    longest = tail[b]
            after = following[j]
            if after is not None:
                here = location[j]
                for r, b in after.items():
                    way = between[r][here][location[b]] + tail[b]
                    if way > longest:
                        longest = way
            tail[j] = end[j] - start[j] + longest
        self.tail = tail

    def inputs(self, inst, j, skip):
        """The earliest job j can start by its predecessors and its robots but `skip`."""
        end = self.solution.end
        at = 0.0
        for a in inst.predecessors[j]:
            if end[a] > at:
                at = end[a]
        before_on = self.solution.previous[j]
        for r in self.solution.robots[j]:
            if r in skip:
                continue
            before = None if before_on is None else before_on.get(r)
            there = self.reach(inst, r, before, j)
            if there > at:
                at = there
        return at

    def reach(self, inst, r, before, j):
        """When robot r can be at job j coming from job `before` (None: from its start)."""
        if before is None:
            return inst.arrival[r][j]
        leg = inst.between[r][inst.location[before]][inst.location[j]]
        return max(self.solution.end[before] + leg, inst.release[r])

    def outputs(self, inst, j, skip):
        """The longest way from j's end to the end, through its successors and the next
        jobs of its robots but `skip`."""
        tail, location = self.tail, inst.location
        longest = 0.0
        for b in inst.successors[j]:
            if tail[b] > longest:
                longest = tail[b]
        after = self.following[j]
        if after is not None:
            here = location[j]
            for r, b in after.items():
                if r not in skip:
                    way = inst.between[r][here][location[b]] + tail[b]
                    if way > longest:
                        longest = way
        return longest

    def onward(self, inst, r, j, after):
        """The longest way to the end through robot r's leg from j to `after` (0 if None)."""
        if after is None:
            return 0.0
        return inst.between[r][inst.location[j]][inst.location[after]] + self.tail[after]

    def closing(self, inst, r, j):
        """The longest path through the leg that closes robot r's order once j leaves it."""
        order = self.solution.orders[r]
        k = order.index(j)
        if k + 1 == len(order):
            return 0.0
        after = order[k + 1]
        return (self.reach(inst, r, order[k - 1] if k > 0 else None, after)
                + self.tail[after])

    def estimate(self, inst, move) -> float:
        """The longest path through what the move changes, in the current times."""
        solution = self.solution
        kind = move[0]
        if kind == 'swap':
            return self._swap(inst, *move[1:])
        if kind == 'give':
            _, j, r, q, other, place = move
            took = inst.times[other][q]
            for s, qs in solution.robots[j].items():
                if s != r and inst.times[s][qs] > took:
                    took = inst.times[s][qs]
            return self._moved(inst, j, took, (r,), ((other, solution.orders[other], place),))
        if kind == 'plan':
            _, j, _, staffing, places = move
            took = max(inst.times[s][q] for s, q in staffing.items())
            leaving = [s for s in solution.robots[j] if s not in staffing]
            return self._moved(inst, j, took, leaving,
                               [(s, solution.orders[s], place) for s, place in places.items()])
        _, r, j, m = move
        order = solution.orders[r]
        k = order.index(j)
        rest = order[:k] + order[k + 1:]
        return self._moved(inst, j, solution.end[j] - solution.start[j], (r,), ((r, rest, m),))

    def _moved(self, inst, j, took, leaving, entering):
        """Job j, `took` long, left by the robots `leaving` and put by each robot of
        `entering` (robot, its order without j, place) into that order."""
        at = self.inputs(inst, j, leaving)
        out = self.outputs(inst, j, leaving)
        for r, order, place in entering:
            at = max(at, self.reach(inst, r, order[place - 1] if place > 0 else None, j))
            out = max(out, self.onward(inst, r, j, order[place] if place < len(order) else None))
        longest = at + took + out
        for r in leaving:
            gone = self.closing(inst, r, j)
            if gone > longest:
                longest = gone
        return longest

    def _swap(self, inst, r, k):
        """x, the k-th job of robot r's order, and y, the next, swapped on every robot they
        share."""
        solution, location = self.solution, inst.location
        order = solution.orders[r]
        x, y = order[k], order[k + 1]
        shared = [s for s in solution.robots[x] if s in solution.robots[y]]
        end, between = solution.end, inst.between
        before_x = solution.previous[x] or {}
        after_x, after_y = self.following[x] or {}, self.following[y] or {}
        start_y = self.inputs(inst, y, shared)
        for s in shared:
            start_y = max(start_y, self.reach(inst, s, before_x.get(s), y))
        end_y = start_y + end[y] - solution.start[y]
        start_x = self.inputs(inst, x, shared)
        out_x = self.outputs(inst, x, shared)
        back = 0.0
        for s in shared:
            leg = between[s][location[y]][location[x]]
            start_x = max(start_x, end_y + leg)
            after = after_x[s]
            out_x = max(out_x, self.onward(inst, s, x, after_y.get(s) if after == y else after))
            back = max(back, leg)
        tail_x = end[x] - solution.start[x] + out_x
        tail_y = end[y] - solution.start[y] + max(self.outputs(inst, y, shared), back + tail_x)
        return max(start_y + tail_y, start_x + tail_x)


def _best_move(inst: _Instance, current: _Solution, rng, tabu, step, record):
    """The best solution one move from `current` around a job of its critical path, and that
    job; a job tabu until a later step is moved only to beat `record`. Moves are ranked by
    an estimate; the EXACT_MOVES best of them are timed, but a tabu job's only when their
    estimate beats `record` (else nearly all the timings go to tabu jobs' moves)."""
    around = _Around(inst, current)
    ranked = []
    for j in current.critical():
        for move in _moves(inst, current, j, rng):
            ranked.append((around.estimate(inst, move), rng.random(), j, move))
    ranked.sort(key=lambda e: (e[0], e[1]))
    best, job, timed = None, None, 0
    for estimate, _, j, move in ranked:
        banned = tabu.get(j, 0) > step
        if banned and estimate >= record.makespan - 1e-9:
            continue
        moved = _apply(current, move)
        if not moved.evaluate(inst):
            continue
        if banned and not moved.better(record):
            continue
        timed += 1
        if best is None or moved.better(best):
            best, job = moved, j
        if timed >= EXACT_MOVES:
            break
    return best, job


def _moves(inst: _Instance, current: _Solution, j, rng):
    """Moves from `current` around job j: ('give', j, robot, type, other robot, place in its
    order), ('plan', j, plan, staffing, places: see `_plan_move`), ('swap', robot, k: the k-th
    and next job of its order), ('reinsert', robot, j, place in its order without j)."""
    for r, q in _movable_operations(inst, current, j):
        others = [o for o in inst.robots
                  if o not in current.robots[j] and q in inst.times[o]]
        rng.shuffle(others)
        for other in others[:4]:
            order = current.orders[other]
            near = sum(1 for k in order if current.start[k] < current.start[j])
            for place in (near, near - 1, near + 1):
                if 0 <= place <= len(order) and not _splits_hold(inst, current, other,
                                                                  order, place):
                    yield ('give', j, r, q, other, place)
    if _tied(inst, j):
        return
    for plan in range(len(inst.plans[j])):
        if plan != current.plan[j]:
            for _ in range(PLAN_STAFFINGS):
                move = _plan_move(inst, current, j, plan, rng)
                if move is not None:
                    yield move
    for r in current.robots[j]:
        order = current.orders[r]
        k = order.index(j)
        for first in (k - 1, k):
            if 0 <= first and first + 1 < len(order) and \
                    not _tied(inst, order[first if first != k else k + 1]):
                yield ('swap', r, first)
        # Next to a job at the same place on the robot's route, the legs around it vanish.
        here = inst.location[j]
        rest = order[:k] + order[k + 1:]
        places = [m for m in range(len(rest) + 1)
                  if m != k and ((m > 0 and inst.location[rest[m - 1]] == here)
                                 or (m < len(rest) and inst.location[rest[m]] == here))]
        rng.shuffle(places)
        for m in places[:4]:
            if not _splits_hold(inst, current, r, rest, m):
                yield ('reinsert', r, j, m)


def _plan_move(inst: _Instance, current: _Solution, j, plan, rng):
    """('plan', j, plan, {robot: type}, {robot new to j: place in its order}): j done by
    another of its plans, keeping those of its robots able to do one of its operations and
    drawing the others among the able robots, each put into its order where j now starts;
    None if no draw staffs it."""
    staffing, places = {}, {}
    left = list(inst.plans[j][plan])
    for r, q in current.robots[j].items():
        for q2 in (q, *left):
            if q2 in left and q2 in inst.times[r]:
                staffing[r] = q2
                left.remove(q2)
                break
    rng.shuffle(left)
    for q in left:
        able = [o for o in inst.robots if o not in staffing and q in inst.times[o]]
        if not able:
            return None
        other = rng.choice(able)
        if other in current.robots[j]:
            staffing[other] = q
            continue
        order = current.orders[other]
        place = sum(1 for k in order if current.start[k] < current.start[j])
        if _splits_hold(inst, current, other, order, place):
            return None
        staffing[other], places[other] = q, place
    return ('plan', j, plan, staffing, places)


def _apply(current: _Solution, move) -> _Solution:
    """The solution `move` makes of `current` (not yet evaluated)."""
    moved = current.copy()
    if move[0] == 'plan':
        _, j, plan, staffing, places = move
        for r in current.robots[j]:
            if r not in staffing:
                moved.orders[r].remove(j)
        for r, place in places.items():
            moved.orders[r].insert(place, j)
        moved.plan[j], moved.robots[j] = plan, dict(staffing)
    elif move[0] == 'give':
        _, j, r, q, other, place = move
        del moved.robots[j][r]
        moved.robots[j][other] = q
        moved.orders[r].remove(j)
        moved.orders[other].insert(place, j)
    elif move[0] == 'swap':
        _, r, k = move
        x, y = current.orders[r][k], current.orders[r][k + 1]
        for s in current.robots[x]:
            if s in current.robots[y]:
                order = moved.orders[s]
                order.remove(y)
                order.insert(order.index(x), y)
    else:
        _, r, j, m = move
        order = moved.orders[r]
        order.remove(j)
        order.insert(m, j)
    return moved


def _splits_hold(inst: _Instance, solution: _Solution, robot, order, place) -> bool:
    """Whether putting a job at `place` of the robot's `order` comes between a job the robot
    holds out of and the job it holds into."""
    if not 0 < place < len(order):
        return False
    a, b = order[place - 1], order[place]
    return any(into == b and solution.robots[a].get(robot) == q
               for into, q in inst.holds_into.get(a, ()))


def _shaken(inst: _Instance, best: _Solution, rng) -> _Solution:
    """`best` after a few random moves that keep it evaluable."""
    current = best
    for _ in range(SHAKE_MOVES):
        jobs = list(range(len(inst.names)))
        rng.shuffle(jobs)
        for j in jobs[:10]:
            options = list(_moves(inst, current, j, rng))
            rng.shuffle(options)
            moved = next((m for o in options if (m := _apply(current, o)).evaluate(inst)),
                         None)
            if moved is not None:
                current = moved
                break
    return current


def _ruined_and_recreated(inst: _Instance, best: _Solution, rng) -> _Solution:
    """`best` with RUIN_JOBS jobs taken out and put back one by one where each ends the
    schedule soonest (`_put_back`): a job of its critical path and those nearest it in time
    that share its place or one of its robots, never a tied one. A job taken out keeps its
    precedence, taking no time. `best` shaken instead if nothing can be taken out or put
    back."""
    path = [j for j in best.critical() if not _tied(inst, j)]
    if not path:
        return _shaken(inst, best, rng)
    seed = rng.choice(path)
    place, robots = inst.location[seed], set(best.robots[seed])
    related = [j for j in range(len(inst.names)) if j != seed and not _tied(inst, j)
               and (inst.location[j] == place or robots.intersection(best.robots[j]))]
    # Nearest in time, loosely: the same stretch is not taken out at every stall.
    related.sort(key=lambda j: abs(best.start[j] - best.start[seed]) * (1 + rng.random()))
    out = sorted([seed] + related[:RUIN_JOBS - 1], key=best.start.__getitem__)
    current = best.copy()
    for j in out:
        for r in current.robots[j]:
            current.orders[r].remove(j)
        current.robots[j] = {}
    if not current.evaluate(inst):
        return _shaken(inst, best, rng)
    for j in out:
        current = _put_back(inst, current, j, rng)
        if current is None:
            return _shaken(inst, best, rng)
    return current


def _put_back(inst: _Instance, current: _Solution, j, rng):
    """`current` (evaluated) with job j, taken out, put back by the best timed of the
    EXACT_MOVES best estimated of its random staffings (`_random_staffings`), each robot's
    place in its order the one whose estimate is least; None if none can be timed."""
    around = _Around(inst, current)
    ahead, behind = around.inputs(inst, j, ()), around.outputs(inst, j, ())
    ranked = []
    for plan, staffing in _random_staffings(inst, j, rng):
        places = {}
        for r in staffing:
            order = current.orders[r]
            fits = [(max(ahead, around.reach(inst, r, order[k - 1] if k else None, j))
                     + max(behind, around.onward(inst, r, j, order[k] if k < len(order)
                                                 else None)), k)
                    for k in range(len(order) + 1)
                    if not _splits_hold(inst, current, r, order, k)]
            if not fits:
                break
            places[r] = min(fits)[1]
        else:
            move = ('plan', j, plan, staffing, places)
            ranked.append((around.estimate(inst, move), rng.random(), move))
    ranked.sort(key=lambda e: (e[0], e[1]))
    chosen = None
    for _, _, move in ranked[:EXACT_MOVES]:
        moved = _apply(current, move)
        if moved.evaluate(inst) and (chosen is None or moved.better(chosen)):
            chosen = moved
    return chosen


def _random_staffings(inst: _Instance, j, rng):
    """Up to RECREATE_STAFFINGS distinct (plan, {robot: type}) per plan of job j, each
    operation by a distinct able robot drawn at random."""
    found = {}
    for plan, operations in enumerate(inst.plans[j]):
        for _ in range(RECREATE_STAFFINGS):
            staffing = {}
            for q in operations:
                able = [r for r in inst.robots if r not in staffing and q in inst.times[r]]
                if not able:
                    break
                staffing[rng.choice(able)] = q
            else:
                found[plan, frozenset(staffing.items())] = staffing
    return [(plan, staffing) for (plan, _), staffing in found.items()]
