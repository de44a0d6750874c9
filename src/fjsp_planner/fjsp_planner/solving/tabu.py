"""Tabu search for single-robot jobs without travel: the classic flexible job shop.

CP-SAT proves small classic instances at once but, on 2 cores, ends above the best known on
the larger ones within seconds (Brandimarte mk10, Dauzere-Peres, Hurink la21): its search
spends most of the time in the LP and in repairing its own neighbourhoods. The
critical-path neighbourhood of Mastrolilli and Gambardella ("Effective neighbourhood
functions for the flexible job shop problem", 2000) improves such schedules thousands of
times a second, and CP-SAT, hinted with the result, then closes what is left or proves it.

A schedule is a machine per job and an order of each machine's jobs; every job starts as
soon as its predecessors and the job before it on its machine are done. A move takes a job
of a longest path off its machine and puts it on any machine able to do it, at any place
where it cannot close a cycle; moves are ranked by the longest path through the moved job,
estimated from the heads and tails before the move (exact for that path, the rest is
recomputed once the move is made). A moved job may not move again for a few iterations
unless the move beats the best schedule; after a long run without improvement the search
restarts from the best schedule, shaken by a few random moves.

Works on integer times: a problem whose times are not integers is scaled by the least
common multiple of their denominators, and not searched when that exceeds MAX_SCALE.
"""

import bisect
import heapq
import math
import random
import time
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule

MAX_SCALE = 1000
TENURE = (2, 12)
"""A moved job stays put for a random number of iterations in this range plus one per
twenty jobs: long enough to leave a local optimum, short enough not to block the path."""
PATIENCE = 400
"""Iterations without a better schedule before restarting from the best one."""
KICKS = 4
EXACT = 1
"""Moves with the best estimates that are made and timed exactly before one is chosen."""
"""Random moves that shake the best schedule at a restart."""


def applies(problem: Problem) -> bool:
    """True for problems this search handles: every plan one operation, no holding arcs,
    no travel, no running jobs, no panels."""
    if problem.holding or problem.fixed or problem.panels:
        return False
    if any(len(plan) != 1 for job in problem.jobs for plan in job.plans):
        return False
    if problem.locomote is not None and any(d > 0 for d in problem.distances.values()):
        return False
    return _scale(problem) is not None


def _scale(problem: Problem) -> int | None:
    values = [r.release_time for r in problem.robots]
    values += [t for r in problem.robots for job in problem.jobs for plan in job.plans
               if (t := problem.duration(r.name, plan[0])) is not None]
    scale = math.lcm(*(Fraction(v).denominator for v in values)) if values else 1
    return scale if scale <= MAX_SCALE else None


class _Instance:
    """The problem in integer arrays: job i, its options (machine, duration, plan, type),
    its predecessors and successors by precedence, machine release times."""

    def __init__(self, problem: Problem):
        self.problem = problem
        self.scale = _scale(problem)
        self.names = [j.name for j in problem.jobs]
        index = {name: i for i, name in enumerate(self.names)}
        self.machines = [r.name for r in problem.robots]
        self.release = [int(r.release_time * self.scale) for r in problem.robots]
        self.options = []
        for job in problem.jobs:
            best = {}
            for p, plan in enumerate(job.plans):
                for m, robot in enumerate(self.machines):
                    t = problem.duration(robot, plan[0])
                    if t is not None:
                        ticks = int(t * self.scale)
                        if m not in best or ticks < best[m][0]:
                            best[m] = (ticks, p, plan[0])
            self.options.append([(m, t, p, q) for m, (t, p, q) in sorted(best.items())])
        self.preds = [[] for _ in self.names]
        self.succs = [[] for _ in self.names]
        for a, b in problem.precedence:
            self.preds[index[b]].append(index[a])
            self.succs[index[a]].append(index[b])
        self.index = index


class _Solution:
    """Machine of each job, each machine's order, and what a move's estimate reads: heads
    (earliest starts), tails (least time from a job's end to the makespan), and per machine
    the ends and ends-to-finish of its jobs in order."""

    def __init__(self, inst: _Instance, machine, sequences):
        self.inst = inst
        self.machine = list(machine)
        self.duration = [0] * len(machine)
        for i, m in enumerate(machine):
            self.duration[i] = next(t for k, t, _, _ in inst.options[i] if k == m)
        self.sequences = [list(s) for s in sequences]
        self.makespan = 0

    def copy(self):
        other = _Solution(self.inst, self.machine, self.sequences)
        other.evaluate()
        return other

    def evaluate(self) -> bool:
        """Recompute heads, tails and makespan; False if the orders close a cycle."""
        inst, n, d = self.inst, len(self.machine), self.duration
        preds, succs = inst.preds, inst.succs
        before = self.before = [-1] * n
        after = self.after = [-1] * n
        position = self.position = [0] * n
        for seq in self.sequences:
            for k, b in enumerate(seq):
                position[b] = k
            for a, b in zip(seq, seq[1:], strict=False):
                before[b], after[a] = a, b
        waiting = [len(preds[i]) + (before[i] >= 0) for i in range(n)]
        order = [i for i in range(n) if waiting[i] == 0]
        release = inst.release
        head = self.head = [release[self.machine[i]] if before[i] < 0 else 0
                            for i in range(n)]
        for i in order:  # grows while it is walked: Kahn's topological order
            end = head[i] + d[i]
            for j in succs[i]:
                if end > head[j]:
                    head[j] = end
                waiting[j] -= 1
                if waiting[j] == 0:
                    order.append(j)
            j = after[i]
            if j >= 0:
                if end > head[j]:
                    head[j] = end
                waiting[j] -= 1
                if waiting[j] == 0:
                    order.append(j)
        if len(order) < n:
            return False
        tail = self.tail = [0] * n
        # The tail along precedence arcs only, and (below) the end of the job's last
        # predecessor: what a job keeps of its times when it moves to another machine.
        rest = self.rest = [0] * n
        for i in reversed(order):
            longest = 0
            for j in succs[i]:
                if d[j] + tail[j] > longest:
                    longest = d[j] + tail[j]
            rest[i] = longest
            j = after[i]
            if j >= 0 and d[j] + tail[j] > longest:
                longest = d[j] + tail[j]
            tail[i] = longest
        self.ready = [max([head[p] + d[p] for p in preds[i]], default=0) for i in range(n)]
        self.ends = [[head[x] + d[x] for x in seq] for seq in self.sequences]
        self.rests = [[d[x] + tail[x] for x in seq] for seq in self.sequences]
        self.makespan = max([head[i] + d[i] for i in range(n)], default=0)
        return True

    def critical(self, rng) -> list[int]:
        """The jobs of one longest path, traced back from a job ending last (ties at
        random, so that successive iterations see different paths)."""
        inst, h, d, c = self.inst, self.head, self.duration, self.makespan
        v = rng.choice([i for i in range(len(h)) if h[i] + d[i] == c])
        path = [v]
        while h[v] > 0:
            before = [p for p in inst.preds[v] if h[p] + d[p] == h[v]]
            u = self.before[v]
            if u >= 0 and h[u] + d[u] == h[v]:
                before.append(u)
            if not before:
                break
            v = rng.choice(before)
            path.append(v)
        return path

    def moves(self, v):
        """(estimated makespan, machine, duration, place) of every move of job v."""
        inst, h, t = self.inst, self.head, self.tail
        ready, rest = self.ready[v], self.rest[v]
        latest_pred = max([h[p] for p in inst.preds[v]], default=-1)
        latest_succ = max([t[s] for s in inst.succs[v]], default=-1)
        own = self.machine[v]
        out = []
        for m, p_m, _, _ in inst.options[v]:
            seq, ends, rests = self.sequences[m], self.ends[m], self.rests[m]
            at = -1
            if m == own:
                at = self.position[v]
                seq = seq[:at] + seq[at + 1:]
                ends, rests = self._without(v, seq, at)
            # A job after v on m must not lead to v's predecessors (it ends after their
            # heads), one before v must not follow v's successors: windows by bisection, as
            # ends grow and ends-to-finish shrink along a machine's order. Taken from the
            # times with v in place: a path without v is a path with it.
            place_ends = ends if at < 0 else self.ends[m][:at] + self.ends[m][at + 1:]
            place_rests = rests if at < 0 else self.rests[m][:at] + self.rests[m][at + 1:]
            low = bisect.bisect_right(place_ends, latest_pred)
            high = _count_above(place_rests, latest_succ)
            # A predecessor or successor on m itself bounds the window whatever the times
            # (the comparisons above need positive durations to exclude them).
            for p in inst.preds[v]:
                if self.machine[p] == m:
                    low = max(low, self.position[p] + (1 if at < 0 or self.position[p] < at
                                                        else 0))
            for s in inst.succs[v]:
                if self.machine[s] == m:
                    high = min(high, self.position[s] - (0 if at < 0 or self.position[s] < at
                                                         else 1))
            release = inst.release[m]
            last = len(seq)
            for place in range(low, min(high, last) + 1):
                if place == at:
                    continue
                start = ends[place - 1] if place > 0 else release
                finish = rests[place] if place < last else 0
                out.append(((start if start > ready else ready) + p_m
                            + (finish if finish > rest else rest), m, p_m, place))
        return out

    def _without(self, v, seq, at):
        """Ends and ends-to-finish of v's machine-mates in order with v taken off the
        machine: the jobs after v no longer wait for it, the jobs before it no longer lead
        through it (followed along the machine only, as an estimate)."""
        d, ready, rest = self.duration, self.ready, self.rest
        m = self.machine[v]
        ends = self.ends[m][:at]
        previous = ends[-1] if at > 0 else self.inst.release[m]
        for x in seq[at:]:
            previous = (ready[x] if ready[x] > previous else previous) + d[x]
            ends.append(previous)
        rests = self.rests[m][at + 1:]
        following = rests[0] if rests else 0
        before = []
        for x in reversed(seq[:at]):
            following = d[x] + (rest[x] if rest[x] > following else following)
            before.append(following)
        before.reverse()
        return ends, before + rests

    def move(self, v, m, p_m, place):
        self.sequences[self.machine[v]].remove(v)
        self.sequences[m].insert(place, v)
        self.machine[v], self.duration[v] = m, p_m


def _count_above(descending, value) -> int:
    """How many leading items of a non-increasing list are greater than `value`."""
    low, high = 0, len(descending)
    while low < high:
        middle = (low + high) // 2
        if descending[middle] > value:
            low = middle + 1
        else:
            high = middle
    return low


def tabu_search(problem: Problem, start: Schedule, deadline: float, seed: int = 0,
                stop=None) -> tuple[Schedule, float]:
    """(the best schedule found from `start`, a valid schedule of `problem`, which
    `applies`, until `deadline` or until `stop()` returns true; when it was found, in
    time.monotonic()). `start` itself, with the time of the call, if nothing is better."""
    found_at = time.monotonic()
    inst = _Instance(problem)
    current = _from_schedule(inst, start)
    if not current.evaluate():
        return start, found_at
    best = current.copy()
    rng = random.Random(seed)
    tabu = [0] * len(inst.names)
    base_tenure = len(inst.names) // 20
    iteration = since_best = 0
    while time.monotonic() < deadline and best.makespan > 0 and not (stop and stop()):
        iteration += 1
        candidates = []
        for v in current.critical(rng):
            free = tabu[v] <= iteration
            for value, m, p_m, place in current.moves(v):
                if free or value < best.makespan:
                    candidates.append((value, rng.random(), v, m, p_m, place))
        chosen, chosen_key = None, None
        for value, _, v, m, p_m, place in heapq.nsmallest(EXACT, candidates):
            undo = (current.machine[v], current.duration[v],
                    current.sequences[current.machine[v]].index(v))
            current.move(v, m, p_m, place)
            if current.evaluate() and (chosen_key is None or (
                    current.makespan, value) < chosen_key):
                chosen, chosen_key = (v, m, p_m, place), (current.makespan, value)
            current.move(v, *undo)
        if chosen is None:
            since_best = PATIENCE
        else:
            current.move(*chosen)
            current.evaluate()
            tabu[chosen[0]] = iteration + base_tenure + rng.randint(*TENURE)
            if current.makespan < best.makespan:
                best, since_best, found_at = current.copy(), 0, time.monotonic()
            else:
                since_best += 1
        if since_best >= PATIENCE:
            current = _shaken(best, rng)
            since_best = 0
    if best.makespan >= start.makespan * inst.scale:
        return start, found_at
    return _to_schedule(inst, best), found_at


def _shaken(best: _Solution, rng) -> _Solution:
    current = best.copy()
    for _ in range(KICKS):
        v = rng.randrange(len(current.machine))
        options = current.moves(v)
        if not options:
            continue
        _, m, p_m, place = rng.choice(options)
        undo = (current.machine[v], current.duration[v],
                current.sequences[current.machine[v]].index(v))
        current.move(v, m, p_m, place)
        if not current.evaluate():
            current.move(v, *undo)
            current.evaluate()
    return current


def _from_schedule(inst: _Instance, schedule: Schedule) -> _Solution:
    machine = [0] * len(inst.names)
    robot_index = {name: m for m, name in enumerate(inst.machines)}
    for name, a in schedule.jobs.items():
        (robot,) = a.robots
        machine[inst.index[name]] = robot_index[robot]
    sequences = [[] for _ in inst.machines]
    for m, robot in enumerate(inst.machines):
        order = sorted(schedule.sequences.get(robot, ()),
                       key=lambda j: (schedule.jobs[j].start, schedule.jobs[j].end))
        sequences[m] = [inst.index[j] for j in order]
    return _Solution(inst, machine, sequences)


def _to_schedule(inst: _Instance, solution: _Solution) -> Schedule:
    jobs = {}
    for i, name in enumerate(inst.names):
        m = solution.machine[i]
        _, ticks, plan, q = next(o for o in inst.options[i] if o[0] == m)
        start = Fraction(solution.head[i], inst.scale)
        jobs[name] = JobAssignment(name, plan, start, start + Fraction(ticks, inst.scale),
                                   {inst.machines[m]: q})
    sequences = {robot: tuple(inst.names[i] for i in solution.sequences[m])
                 for m, robot in enumerate(inst.machines)}
    return Schedule(jobs, sequences)
