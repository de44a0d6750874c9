"""A lower bound for identical panels that knows where each panel lies: the "panel sequence"
bound (docs/solver.md, "Bounds").

Let G be the robots that can reach every panel within a known schedule's makespan U (the
others, "limited", reach only `bounds.panel_limits` many), and call a staffing *heavy* when
it needs more than half of G. Two heavy staffings together need more of G than there is, so
in any schedule the jobs staffed heavily, over all panels, run one after another, and a
limited robot does one job at a time. The relaxation keeps, per panel, the jobs that have
no staffing that is neither heavy nor has a limited robot (the others can always be done by
few robots of G and are forgotten), and orders them all by their start times. A job then
starts no earlier than:

- its head (the least time precedence chains need before it, `machine_bound.panel_shape`);
- when heavy, the end of the heavy job before it plus the least travel of the slowest robot
  both share, along the places of the panels *where they lie* (the paper's panels lie in a
  row: from the fifth back to the second is three crossings), or the lag a precedence chain
  puts between the two when they are of one panel;
- when heavy, for each robot of G that all its robot sets have, the end of that robot's
  last heavy job (the last one all of whose sets have it) plus its least travel from a kept
  job of that job's panel (on the paper, MARC2 coming back along the row while the heavy
  job before shared only LSMS with it, which crosses in 2);
- when it has a limited robot, the end of that robot's job before it plus its least travel
  from there;
- the end of either of those plus the lag of a chain from it, when it precedes the job.

A jig job staffed heavily whose robots all hold into another job is directly followed by it
among the heavy ones (its robots are busy until the held job ends, and any other heavy job
shares one of them). One staffed lightly, that no other job follows, is placed right before
the job it holds into, which keeps its robots: they are busy from its start to the held
job's end, so a job placed before it sharing one of them ended before it began, and its
limited robot does nothing in between.

A heavy job and a light one with a limited robot never overlap either when every robot set
of the one shares a robot with every one of the other's (the paper's Assembler with a MARC,
and a heavy job of both MARCs elsewhere): one ends, and the robots they share travel, before
the other begins. The order keeps the times of each limited robot's last few light jobs
(`TRACKED`, less those that end too early to hold up a heavy job to come) and of the last
heavy job. A heavy job placed comes after the first few of a robot's light jobs it clashes
with and before the others, which then begin after it (and the robot's later ones after
them); a light job placed comes before the last heavy job or after it. Whichever was placed
earlier may be taken later; what was placed after it then starts earlier than it could,
which only lowers the bound.

Every schedule has a set of panels where limited robots work on kept jobs, at most the sum
of their limits; in the other panels the kept jobs are staffed from G. The search takes each
such set on its own (its *layout*): a limited robot works in each of its panels, so an order
in which one has not yet is no shorter than the least way of a limited robot from its last
job to a job left there and that job's tail (for two such panels, of one robot through both
or two robots; panels a robot cannot reach in time rule the layout out; a job after a job
only heavy staffings can do, not yet done, starts no earlier than that one's least end after
the last heavy job, and a jig job keeps the robot until the job it holds into ends), and an
order that does every job of such a panel without one belongs to another layout. Its value
is the least makespan over such orders, each job at its least duration for the robots chosen
plus the least time after its end (its tail), over every layout: a best-first search over
(the layout, which jobs of each panel are done, the last heavy one, each limited robot's
last one, the panels they have worked in and their light jobs kept, the panel of each robot
of G's last heavy job), with an estimate of what is left that never overstates it (the least
durations of the jobs only heavy staffings can do, the lags or switches between them and one
switch into each panel left but the first one entered, a switch costing at least its travel
and how much longer the job after it takes than its least). An order's value is the largest
of its latest end plus tail, its last heavy end plus that estimate, and the limited robots'
least way to the panels of its layout they have yet to work in.

It forgets lags between jobs whose ends it does not keep, the ways of robots of G but from
their last heavy jobs, and which robot of a set does what. Every schedule shorter than U is
one of these orders, so the search's least value, or the least value still open (or let
go, `MAX_OPEN`) when its time runs out, bounds every schedule shorter than U, and min(bound,
U) bounds all. CP-SAT's model of a similar relaxation (`machine`), which knows no panel's
place, proves less.
"""

import heapq
import itertools
import math
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.geometry import least_job_travel
from fjsp_planner.solving.bounds.machine import panel_shape, within_incumbent
from fjsp_planner.solving.bounds.panel import panel_limits

MAX_PANELS = 6
"""Above this many panels the search is not run: its states grow as the product of the
panels' progress (12 per panel of the paper), and the panel load bound proves more in the
time."""
MAX_PANEL_JOBS = 12
"""Above this many kept jobs in a panel the search is not run: what is left of a panel is
estimated over every set of its jobs done (2^12 sets)."""
MAX_GRID = 1000
TRACKED = 3
"""How many of a limited robot's last light jobs the state keeps, for heavy jobs to keep
clear of: the paper's Assembler does three in a panel it helps without a heavy job
between (`Ac`, `Jd`, `Ad`)."""
MAX_OPEN = 320_000
"""When this many orders are open, the quarter of highest value is let go (about 430 MB in
all with what the search has closed): the bound then rises no further than the least of
them."""


def panel_sequence_bound(problem: Problem, incumbent: Fraction, time_limit: float,
                         stop: threading.Event | None = None,
                         improved: Callable[[], Fraction | None] | None = None
                         ) -> Fraction | None:
    """The bound of the module docstring, or None when it does not apply (fewer than two
    or more than MAX_PANELS panels, running jobs, no robot of G, no job kept or more than
    MAX_PANEL_JOBS of them in a panel). The search ends early, with the least value still
    open or let go, once `stop` is set; `improved` gives the makespan of a shorter schedule found
    meanwhile, if any (orders that cannot end before it are then dropped too, and the
    bound holds below it)."""
    deadline = time.monotonic() + time_limit
    prepared = _prepared_search(problem, incumbent)
    if prepared is None:
        return None
    search, helped_count = prepared
    layouts = [search.shapes(helped) for helped in search.layouts(helped_count)]
    found = min(search.run(layouts, deadline, stop, improved), incumbent)
    shorter = improved() if improved is not None else None
    return found if shorter is None else min(found, shorter)


def layouts(problem: Problem, incumbent: Fraction) -> list[tuple[int, ...]]:
    """The layouts `panel_sequence_bound` searches, each as the panels (numbered from 0)
    where limited robots work; empty when the bound does not apply."""
    prepared = _prepared_search(problem, incumbent)
    return [] if prepared is None else prepared[0].layouts(prepared[1])


def layout_value(problem: Problem, incumbent: Fraction, helped: tuple[int, ...],
                 time_limit: float, max_open: int | None = None) -> Fraction:
    """The relaxation's least makespan in the one layout where limited robots work in the
    panels `helped` (one of `layouts`), or the least value still open or let go (above
    `max_open` open orders, default `MAX_OPEN`) when `time_limit` ran out. Searched to their
    ends, the least over the layouts is what `panel_sequence_bound` reaches at its end: this
    tells which layout holds the bound down and how far each is from the incumbent
    (`bench/panel_layouts.py`). ValueError when the bound does not apply or `helped` is
    not one of the layouts."""
    prepared = _prepared_search(problem, incumbent)
    if prepared is None or tuple(helped) not in prepared[0].layouts(prepared[1]):
        raise ValueError(f'panels {tuple(helped)} are not a layout of the panel sequence bound '
                         'on this problem')
    search, _ = prepared
    return min(search.run([search.shapes(helped)], time.monotonic() + time_limit,
                          max_open=max_open), incumbent)


def _prepared_search(problem, incumbent):
    """(the search, how many panels limited robots may work in), or None when the bound does
    not apply (see `panel_sequence_bound`)."""
    panels = len(problem.panels)
    if not 2 <= panels <= MAX_PANELS or problem.fixed:
        return None
    limits = panel_limits(problem, incumbent)
    group = frozenset(r.name for r in problem.robots if r.name not in limits)
    if not group:
        return None
    bare = _kept_jobs(problem, sorted(group), group, set(limits), incumbent)
    helped_count = min(panels, sum(limits.values()))
    helped = (_kept_jobs(problem, sorted(r.name for r in problem.robots), group,
                         set(limits), incumbent) if helped_count else bare)
    if bare is None or helped is None or not (bare[0] or helped[0]) or max(
            len(bare[0]), len(helped[0])) > MAX_PANEL_JOBS:
        return None
    return _Search(problem, bare, helped, sorted(limits), incumbent), helped_count


def _kept_jobs(problem, allowed, group, limited, incumbent):
    """(jobs, lags, holds) of one panel staffed from `allowed`, keeping the jobs each choice
    of which is heavy or has a limited robot, or None if some job cannot be staffed."""
    shape = panel_shape(problem, allowed, group, limited)
    if shape is None:
        return None
    jobs, lags, holds = within_incumbent(shape, incumbent, every_job=True)
    kept = [job for job in jobs if all(c.heavy or c.limited for c in job[3])]
    names = {job[0] for job in kept}
    return (kept, {key: lag for key, lag in lags.items() if set(key) <= names},
            {(a, b) for a, b in holds if a in names and b in names})


class _Search:
    """The best-first search of the module docstring, on an integer time grid (every time
    floored onto it, which only lowers the bound)."""

    def __init__(self, problem, bare, helped, limited, incumbent):
        self.limited = limited
        self.panels = len(problem.panels)
        names = problem.panels[0]
        kept = sorted({job[0] for shape in (bare, helped) for job in shape[0]})
        copies = [(k, n, problem.panels[k][names.index(n)]) for k in range(self.panels)
                  for n in kept]
        travel = {(r.name, k, a, m, b): least_job_travel(problem, r.name, x, y)
                  for r in problem.robots for k, a, x in copies for m, b, y in copies}
        values = [v for shape in (bare, helped) for _, head, tail, choices in shape[0]
                  for v in (head, tail, *(c.duration for c in choices))]
        values += [v for shape in (bare, helped) for v in shape[1].values()]
        values += list(travel.values()) + [incumbent]
        scale = min(MAX_GRID, math.lcm(*(v.denominator for v in values)))
        self.scale = scale

        def ticks(value):
            return value.numerator * scale // value.denominator

        self.travel = {key: ticks(v) for key, v in travel.items()}
        self.bare, self.helped = _Shape(bare, ticks), _Shape(helped, ticks)
        self._ways_of_limited()
        arcs = list(problem.precedence) + [(a, b) for a, b, _ in problem.holding]
        for shape in (self.bare, self.helped):
            shape.jig_into = {i: h for i, h in shape.held.items() if {
                b for a, b in arcs if a == shape.names[i]} == {shape.names[h]}}
        self.incumbent = ticks(incumbent)
        self.ticks = ticks
        self.switch = self._least_switch()
        self.farthest = max((value for (r, *_), value in self.travel.items()
                             if r not in limited), default=0)
        self.group = sorted({r for r, *_ in self.travel} - set(limited))
        self.leave = {}
        for (r, q, _, k, b), value in self.travel.items():
            if r not in limited:
                key = (r, q, k, b)
                self.leave[key] = min(value, self.leave.get(key, value))
        self.farthest_from = {}
        for (r, q, _, _), value in self.leave.items():
            self.farthest_from[r, q] = max(value, self.farthest_from.get((r, q), 0))
        for shape in (self.bare, self.helped):
            shape.rest = _rest_costs(shape, self.switch)

    def _ways_of_limited(self):
        """What `_way` and `_first_step` read: per limited robot, from each job of a helped
        panel it could have done last (or from nowhere yet), to each job of a helped panel
        it can do (bit, travel, head, least duration with it, tail, the job, the job it
        holds into and its least duration with it, if any); per set of jobs of a helped
        panel done, `pending` of each job; per set of jobs of a helped panel done and
        whether the tail counts, the least of those durations (plus tails) left; and its
        least travel between two panels."""
        self.crossing = {}
        for (r, k, _, m, _), value in self.travel.items():
            if r in self.limited and k != m:
                self.crossing[r, k, m] = min(value, self.crossing.get((r, k, m), value))
        shape = self.helped
        self.pending = _pending(shape)
        durations = [{n: min(c.duration for c in choices if robot in c.limited)
                      for n, robot in enumerate(self.limited)
                      if any(robot in c.limited for c in choices)} for choices in shape.choices]
        starts = [None] + [(q, m) for q in range(self.panels) for m in range(len(shape.names))]
        self.reach, self.least_with = {}, {}
        for n, robot in enumerate(self.limited):
            able = [j for j, by_robot in enumerate(durations) if n in by_robot]
            for at, k in itertools.product(starts, range(self.panels)):
                self.reach[n, at, k] = [
                    (1 << j, 0 if at is None else self.travel[
                        robot, at[0], shape.names[at[1]], k, shape.names[j]],
                     shape.heads[j], durations[j][n], shape.tails[j], j,
                     shape.held.get(j), durations[shape.held[j]].get(n)
                     if j in shape.held else None) for j in able]
            for last in (False, True):
                self.least_with[n, last] = [
                    min((durations[j][n] + (shape.tails[j] if last else 0) for j in able
                         if not done >> j & 1), default=None) for done in range(shape.full + 1)]

    def layouts(self, helped_count):
        """Every set of at most `helped_count` panels (as sorted panel numbers), one of each
        pair of mirror images when the travel between panels reads the same from the other
        end."""
        last = self.panels - 1
        mirrored = all(value == self.travel[r, last - k, a, last - m, b]
                       for (r, k, a, m, b), value in self.travel.items())
        chosen = []
        for count in range(helped_count + 1):
            for helped in itertools.combinations(range(self.panels), count):
                mirror = tuple(sorted(last - k for k in helped))
                if not (mirrored and mirror in chosen):
                    chosen.append(helped)
        return chosen

    def shapes(self, helped):
        """The layout in which limited robots work in the panels `helped`: each panel's
        shape."""
        return tuple(self.helped if k in helped else self.bare for k in range(self.panels))

    def gap(self, k, first, a, m, second, b):
        """Least time from job a's end (panel k, `first` choice) to job b's start (panel m,
        `second`) for the robots both choices share to get there."""
        least = None
        for x in first.sets:
            for y in second.sets:
                shared = x & y
                if not shared:
                    return 0
                found = max(self.travel[r, k, a, m, b] for r in shared)
                least = found if least is None else min(least, found)
        return least

    def _least_switch(self):
        """Least cost of going on, among heavy jobs, with one of another panel: the gap (for
        each shared robot its least travel between copies of the two jobs in two panels)
        and how much longer the second takes than its least (a job is the second of one
        switch at most, so this counts no time twice)."""
        across = {}
        for (r, k, a, m, b), value in self.travel.items():
            if k != m:
                across[r, a, b] = min(value, across.get((r, a, b), value))
        least = None
        shapes = (self.bare, self.helped)
        for first, second in itertools.product(shapes, shapes):
            for i, j in itertools.product(range(len(first.names)), range(len(second.names))):
                if not (first.always_heavy[i] and second.always_heavy[j]):
                    continue
                a, b = first.names[i], second.names[j]
                for ci, cj in itertools.product(first.choices[i], second.choices[j]):
                    shared = [x & y for x in ci.sets for y in cj.sets]
                    gap = min(max((across[r, a, b] for r in robots), default=0)
                              for robots in shared)
                    found = gap + cj.duration - second.least[j]
                    least = found if least is None else min(least, found)
        return least or 0

    def _eager(self, shape, k, j, choice, last, where, recent) -> bool:
        """Whether job j of panel k, staffed lightly by `choice` (so with a limited robot),
        may come now: right after what must come before it (the job before it on a limited
        robot of the choice, or a job it follows by precedence), or after another light job
        (several placed after the same job go in any order). Every order of a schedule can
        be rearranged so, its light jobs each moved up to right after the last of those,
        which keeps each robot's order and every precedence, so the search keeps no other
        orders and loses nothing."""
        if recent is not None:
            return True
        if last is None:
            return not shape.before[j] and all(w is None for w in where)
        p, i, _ = last
        return (p == k and shape.before[j] >> i & 1) or any(
            where[n] == (p, i) for n, robot in enumerate(self.limited)
            if robot in choice.limited)

    def run(self, layouts, deadline, stop=None, improved=None, max_open=None) -> Fraction:
        """The least makespan of the relaxation over `layouts` (per panel, its shape), or the
        least value still open or let go when the deadline comes or the search reaches the
        orders let go (a lower bound either way); the incumbent when no order ends before
        it. Above `max_open` open orders (default `MAX_OPEN`) some are let go."""
        max_open = MAX_OPEN if max_open is None else max_open
        self.layout_shapes = layouts
        self.helped_masks = [sum(1 << k for k, shape in enumerate(shapes) if shape is self.helped)
                             for shapes in layouts]
        self.counter = itertools.count()
        self.frontier = []
        self.gaps = {}
        self.clashes = {}
        self.clashing = {}
        nobody = tuple(None for _ in self.limited)
        untracked = tuple(() for _ in self.limited)
        nowhere = tuple(None for _ in self.group)
        idle = tuple(0 for _ in self.group)
        for layout, shapes in enumerate(layouts):
            progress = tuple(0 for _ in shapes)
            state = (layout, progress, None, nobody, None, 0, untracked, nowhere)
            free = tuple(0 for _ in nobody)
            value = max(self._visits_left(layout, progress, nobody, free, 0, 0),
                        self._estimate_anew(shapes, progress, None, -1))
            if value < self.incumbent:
                self.frontier.append((value, next(self.counter), state, 0, 0, free, untracked,
                                      idle))
        heapq.heapify(self.frontier)
        closed = self.closed = {}
        expansions = 0
        let_go = self.incumbent
        while self.frontier:
            expansions += 1
            if expansions % 512 == 0:
                if time.monotonic() > deadline or (stop is not None and stop.is_set()):
                    return Fraction(min(self.frontier[0][0], let_go), self.scale)
                if len(self.frontier) > max_open:
                    # The orders of highest value are let go: none of what follows them ends
                    # before the least of them, which caps the bound, and the memory they
                    # held lets the search go on raising the bound up to it.
                    self.frontier.sort()
                    kept = max_open * 3 // 4
                    let_go = min(let_go, self.frontier[kept][0])
                    del self.frontier[kept:]
                shorter = improved() if improved is not None else None
                if shorter is not None and self.ticks(shorter) < self.incumbent:
                    self.incumbent = self.ticks(shorter)
                    # What can no longer end before it would hold memory the search needs.
                    self.frontier = [entry for entry in self.frontier
                                     if entry[0] < self.incumbent]
                    heapq.heapify(self.frontier)
            value, _, state, now, latest, ends, light_ends, free = heapq.heappop(self.frontier)
            if value >= let_go:
                return Fraction(let_go, self.scale)
            layout, progress, last, where, recent, *_ = state
            shapes = layouts[layout]
            if all(done == shape.full for done, shape in zip(progress, shapes, strict=True)):
                # `_visits_left` let no order do a helped panel without a limited robot.
                return Fraction(value, self.scale)
            labels = closed.setdefault(state, [])
            if _dominated(labels, now, latest, ends, light_ends, free):
                continue
            labels.append((now, latest, ends, light_ends, free))
            node = (state, now, latest, ends, light_ends, free)
            self.estimates = {}
            forced = None
            if last is not None:
                p, i, last_choice = last
                held = shapes[p].held.get(i)
                if held is not None and not progress[p] >> held & 1:
                    forced = (p, held)
            for k, shape in enumerate(shapes):
                done = progress[k]
                for j in range(len(shape.names)):
                    if done >> j & 1 or shape.before[j] & ~done:
                        continue
                    jig_into = shape.jig_into.get(j)
                    for choice in shape.choices[j]:
                        if jig_into is not None and not choice.heavy:
                            self._place_jig(node, k, j, choice, jig_into, forced)
                            continue
                        if choice.heavy and forced is not None and (
                                forced != (k, j) or not any(
                                    a <= b for a in last_choice.sets for b in choice.sets)):
                            continue
                        if not choice.heavy and not self._eager(shape, k, j, choice, last,
                                                                 where, recent):
                            continue
                        begin = self._after_last(node, k, j, choice, eager=True)
                        self._place(node, k, j, choice, begin)
        return Fraction(min(self.incumbent, let_go), self.scale)

    def _after_last(self, node, k, j, choice, eager):
        """Earliest start of job j of panel k staffed by `choice` after the last heavy job
        and each limited robot's last job: a heavy one starts the gap after the last heavy
        job; a light one placed right after the jobs it must follow (`eager`) no earlier
        than the end of a last heavy job of its panel (which it follows, or follows a job
        that does), one placed elsewhere only after a last heavy job it shares a robot with
        or follows."""
        (layout, _, last, where, *_, at), now, _, ends, _, free = node
        shapes = self.layout_shapes[layout]
        shape = shapes[k]
        begin = shape.heads[j]
        if choice.heavy:
            name = shape.names[j]
            for g, robot in enumerate(self.group):
                if at[g] is not None and robot in choice.always:
                    begin = max(begin, free[g] + self.leave[robot, at[g], k, name])
        if last is not None:
            p, i, last_choice = last
            if choice.heavy or not eager and self._clash(last_choice, choice):
                begin = max(begin, now + self._gap_between(shapes, last, (k, j, choice)))
            if p == k and (eager and not choice.heavy or (i, j) in shape.lags):
                begin = max(begin, now + shape.lags.get((i, j), 0))
        for n, robot in enumerate(self.limited):
            if where[n] is None:
                continue
            q, m = where[n]
            if robot in choice.limited:
                begin = max(begin, ends[n] + self.travel[robot, q, shapes[q].names[m], k,
                                                         shape.names[j]])
            if q == k and (m, j) in shape.lags:
                begin = max(begin, ends[n] + shape.lags[m, j])
        return begin

    def _place_jig(self, node, k, j, choice, held, forced):
        """Job j, a jig job staffed lightly whose robots all hold into job `held` and which
        nothing else follows, placed right before `held` (each staffing of it that keeps
        them): its robots are busy from its start to the held job's end, so a job placed
        before sharing a robot with it ended before it began, and its light staffing then
        needs no place of its own in the order."""
        (layout, progress, last, where, recent, visited, light, at), now, latest, ends, \
            light_ends, free = node
        shape = self.layout_shapes[layout][k]
        if shape.before[held] & ~(progress[k] | 1 << j):
            return
        end = self._after_last(node, k, j, choice, eager=False) + choice.duration
        moved, new_ends, visited, light, light_ends = self._limited_at(
            where, ends, visited, light, light_ends, choice, k, j, end)
        after = progress[:k] + (progress[k] | 1 << j,) + progress[k + 1:]
        inner = ((layout, after, last, moved, recent, visited, light, at), now,
                 max(latest, end + shape.tails[j]), new_ends, light_ends, free)
        for second in shape.choices[held]:
            if not any(a <= b for a in choice.sets for b in second.sets) or (
                    second.heavy and forced is not None and forced != (k, held)):
                continue
            begin = max(self._after_last(inner, k, held, second, eager=False),
                        end + shape.lags.get((j, held), 0))
            self._place(inner, k, held, second, begin)

    def _place(self, node, k, j, choice, begin):
        """Push the order `node` continued by job j of panel k staffed by `choice` from
        `begin`, in each way it keeps clear of the jobs it cannot overlap (`_apart`),
        unless it cannot end before the incumbent."""
        (layout, progress, last, where, recent, visited, light, at), *_, free = node
        shapes = self.layout_shapes[layout]
        shape = shapes[k]
        after = progress[:k] + (progress[k] | 1 << j,) + progress[k + 1:]
        for start, now, latest, ends, light_ends in self._apart(node, k, j, choice, begin):
            end = start + choice.duration
            moved, new_ends, new_visited, new_light, new_light_ends = self._limited_at(
                where, ends, visited, light, light_ends, choice, k, j, end)
            new_latest = max(latest, end + shape.tails[j])
            if choice.heavy:
                new_now, new_last, new_recent = end, (k, j, choice), None
                bound = max(new_latest, end + self._estimate(layout, after, k, j))
            else:
                new_now, new_last, new_recent = now, last, (k, j)
                bound = max(new_latest, now + self._estimate(
                    layout, after, last[0] if last else None, last[1] if last else -1))
            if bound >= self.incumbent:
                continue
            bound = max(bound, self._visits_left(layout, after, moved, new_ends, new_visited,
                                                 new_now))
            if bound >= self.incumbent:
                continue
            new_light, new_light_ends = self._still_near(new_light, new_light_ends, new_now)
            new_at, new_free = self._group_at(at, free, choice, k, end)
            new_state = (layout, after, new_last, moved, new_recent, new_visited, new_light,
                         new_at)
            # Checked here as well as when taken: an order no better than one already
            # continued would only hold memory until then.
            closed = self.closed.get(new_state)
            if closed and _dominated(closed, new_now, new_latest, new_ends, new_light_ends,
                                     new_free):
                continue
            heapq.heappush(self.frontier, (
                bound, next(self.counter),
                new_state, new_now, new_latest, new_ends, new_light_ends, new_free))

    def _group_at(self, at, free, choice, k, end):
        """(the panel of each robot of G's last heavy job, when known, and its end) once a
        job of panel k, staffed by `choice`, ends at `end`: a heavy job moves the robots all
        its sets have there, and leaves unknown where those only some have are. A robot
        that could reach any job from its panel by `end` holds up no heavy job to come (each
        starts after `end`), so its panel is forgotten too: orders that differ only there
        become one state."""
        if not choice.heavy:
            return at, free
        new_at, new_free = list(at), list(free)
        for g, robot in enumerate(self.group):
            if robot in choice.always:
                new_at[g], new_free[g] = k, end
            elif robot in choice.anyone:
                new_at[g] = None
            if new_at[g] is not None and new_free[g] + self.farthest_from[robot, new_at[g]] <= end:
                new_at[g] = None
            if new_at[g] is None:
                new_free[g] = 0
        return tuple(new_at), tuple(new_free)

    def _still_near(self, light, light_ends, now):
        """The light jobs kept per limited robot less those that end too early to keep a
        heavy job starting after `now` waiting (the longest travel of a robot of G)."""
        kept = [tuple(t for t, end in enumerate(ends) if end + self.farthest > now)
                for ends in light_ends]
        if all(len(mine) == len(ends) for mine, ends in zip(kept, light_ends, strict=True)):
            return light, light_ends
        return (tuple(tuple(jobs[t] for t in mine)
                      for jobs, mine in zip(light, kept, strict=True)),
                tuple(tuple(ends[t] for t in mine)
                      for ends, mine in zip(light_ends, kept, strict=True)))

    def _apart(self, node, k, j, choice, begin):
        """(begin, the last heavy job's end, latest end plus tail, the limited robots' ends,
        the ends of their light jobs kept) for each way job j of panel k, staffed by
        `choice`, keeps clear of the jobs whose every robot set shares a robot with every
        one of its own, among those the order keeps the times of: a heavy job of the light
        jobs of limited robots kept in the state, a light one of the last heavy job. Two
        such jobs never overlap, so one ends, and its shared robots travel, before the
        other begins: either the new job waits, or the one placed earlier is taken to begin
        after it (what was placed after that one then starts earlier than it could, which
        only lowers the bound)."""
        (layout, _, last, _, _, _, light, _), now, latest, ends, light_ends, _ = node
        shapes = self.layout_shapes[layout]
        ways = [(begin, now, latest, ends, light_ends)]
        if choice.heavy:
            for n, jobs in enumerate(light):
                if jobs:
                    ways = [way for old in ways for way in self._apart_from_light(
                        shapes, old, n, jobs, (k, j, choice))]
        elif last is not None and self._clash(last[2], choice):
            p, i, last_choice = last
            into = self._gap_between(shapes, last, (k, j, choice))
            if begin >= now + into:
                return ways
            follows = p == k and (i, j) in shapes[k].lags
            back = self._gap_between(shapes, (k, j, choice), last)
            start = now - last_choice.duration
            if not follows and begin + choice.duration + back <= start:
                return ways
            ways = [(now + into, now, latest, ends, light_ends)]
            if not follows:
                moved = begin + choice.duration + back + last_choice.duration
                ways.append((begin, moved, max(latest, moved + shapes[p].tails[i]), ends,
                             light_ends))
        return ways

    def _apart_from_light(self, shapes, way, n, jobs, heavy_job):
        """`_apart`'s ways, from `way`, for heavy job `heavy_job` (panel, job, choice) and
        limited robot n's light jobs kept, `jobs` (each (panel, job, choice), in the robot's
        order, the last one its last job): the heavy job comes after the first few of those
        it clashes with and before the others, which then begin after it, and each job of
        the robot after one taken later no earlier than its end and the robot's way on."""
        begin, now, latest, ends, light_ends = way
        k, j, heavy_choice = heavy_job
        mine = light_ends[n]
        clashing = self.clashing.get((jobs, heavy_job))
        if clashing is None:
            clashing = self.clashing[jobs, heavy_job] = [
                (t, self._gap_between(shapes, job, heavy_job),
                 self._gap_between(shapes, heavy_job, job), job[0] == k and (job[1], j) in
                 shapes[k].lags)
                for t, job in enumerate(jobs) if self._clash(job[2], heavy_choice)]
        if not clashing:
            return [way]
        # Only one place can keep every time as it is: after the jobs that ended in time.
        done = 0
        while done < len(clashing) and mine[clashing[done][0]] + clashing[done][1] <= begin:
            done += 1
        end = begin + heavy_choice.duration
        if all(not follows and mine[t] - jobs[t][2].duration >= end + back
               for t, _, back, follows in clashing[done:]):
            return [way]
        ways = []
        for split in range(len(clashing) + 1):
            if any(follows for *_, follows in clashing[split:]):
                continue
            start = max([begin] + [mine[t] + into for t, into, _, _ in clashing[:split]])
            end = start + heavy_choice.duration
            after = {t: back for t, _, back, _ in clashing[split:]}
            moved, new_latest = list(mine), latest
            for t, (q, m, light_choice) in enumerate(jobs):
                light_start = mine[t] - light_choice.duration
                if t in after:
                    light_start = max(light_start, end + after[t])
                if t and moved[t - 1] > mine[t - 1]:
                    light_start = max(light_start, moved[t - 1] + self._link(
                        shapes, n, jobs[t - 1], jobs[t]))
                moved[t] = max(mine[t], light_start + light_choice.duration)
                new_latest = max(new_latest, moved[t] + shapes[q].tails[m])
            new_ends = ends[:n] + (moved[-1],) + ends[n + 1:]
            ways.append((start, now, new_latest, new_ends,
                         light_ends[:n] + (tuple(moved),) + light_ends[n + 1:]))
        return ways

    def _link(self, shapes, n, first, second):
        """Least time from the end of limited robot n's job `first` to the start of its next
        one, `second` (each (panel, job, choice)): its travel, or a chain's lag between them."""
        q, m, _ = first
        k, j, _ = second
        travel = self.travel[self.limited[n], q, shapes[q].names[m], k, shapes[k].names[j]]
        return max(travel, shapes[k].lags.get((m, j), 0) if q == k else 0)

    def _clash(self, first, second):
        """Whether every robot set of one choice shares a robot with every one of the
        other's, so that the two jobs never overlap."""
        key = (first, second)
        found = self.clashes.get(key)
        if found is None:
            found = self.clashes[key] = all(x & y for x in first.sets for y in second.sets)
        return found

    def _gap_between(self, shapes, first, second):
        """`gap` from the end of `first` to the start of `second`, each (panel, job, choice)."""
        p, i, first_choice = first
        k, j, choice = second
        key = (p, i, first_choice, k, j, choice)
        found = self.gaps.get(key)
        if found is None:
            found = self.gaps[key] = self.gap(p, first_choice, shapes[p].names[i], k, choice,
                                              shapes[k].names[j])
        return found

    def _limited_at(self, where, ends, visited, light, light_ends, choice, k, j, end):
        """(each limited robot's last job, its end, the panels they have worked in, its
        light jobs kept and their ends) once job j of panel k, staffed by `choice`, ends at
        `end`. A heavy job ends what a robot's light jobs before it can hold up."""
        if not choice.limited:
            return where, ends, visited, light, light_ends
        moved, new_ends = list(where), list(ends)
        new_light, new_light_ends = list(light), list(light_ends)
        for n, robot in enumerate(self.limited):
            if robot in choice.limited:
                moved[n], new_ends[n] = (k, j), end
                if choice.heavy:
                    new_light[n], new_light_ends[n] = (), ()
                else:
                    new_light[n] = (light[n] + ((k, j, choice),))[-TRACKED:]
                    new_light_ends[n] = (light_ends[n] + (end,))[-TRACKED:]
        return (tuple(moved), tuple(new_ends), visited | (1 << k if choice.limited else 0),
                tuple(new_light), tuple(new_light_ends))

    def _visits_left(self, layout, progress, where, ends, visited, now):
        """The least makespan for the limited robots to work in each of the layout's helped
        panels where none has worked yet, after their last jobs: each such panel needs one
        of them there, and each two such panels one robot going on from one to the other
        or two robots (the largest of these over single panels and pairs; a robot's way is
        `_way`). A panel with no job left that a limited robot can do is never reached: the
        order belongs to a layout with fewer helped panels."""
        left = [k for k in range(self.panels) if (self.helped_masks[layout] & ~visited) >> k & 1]
        if not left:
            return 0
        shapes = self.layout_shapes[layout]
        robots = range(len(self.limited))

        def way(n, order):
            return self._way(shapes, progress, n, where[n], ends[n], order, now)

        alone = {k: [way(n, (k,)) for n in robots] for k in left}
        latest = max(min(ways) for ways in alone.values())
        for k, m in itertools.combinations(left, 2):
            both = min(min(way(n, (k, m)), way(n, (m, k))) for n in robots)
            for n, o in itertools.permutations(robots, 2):
                both = min(both, max(alone[k][n], alone[m][o]))
            latest = max(latest, both)
        return latest

    def _way(self, shapes, progress, n, at, free, order, now):
        """The least end of limited robot n's way from its last job `at`, free from `free`,
        through a job left in each panel of `order` in turn, with the last one's tail."""
        time = None
        for step, k in enumerate(order):
            done = progress[k]
            last = step == len(order) - 1
            if step == 0:
                least = self._first_step(n, at, free, k, done, last, now)
            else:
                least = self.least_with[n, last][done]
                if least is not None:
                    least += time + self.crossing[self.limited[n], order[step - 1], k]
            if least is None:
                return self.incumbent
            time = least
        return time

    def _first_step(self, n, at, free, k, done, last, now):
        """The least end (with its tail when `last`) of limited robot n's next job in panel
        k, from its last job `at`, free from `free`, once the order's last heavy job ends at
        `now`: a job after a heavy-only one not yet done starts no earlier than that one's
        least end after `now` and the lag between them, and a jig job keeps the robot until
        the job it holds into ends (panel k is a helped one)."""
        shape, pending = self.helped, self.pending[done]
        least = None
        for bit, travel, head, duration, tail, j, held, held_duration in self.reach[n, at, k]:
            if done & bit:
                continue
            start = max(free + travel, head)
            if pending[j] is not None:
                start = max(start, now + pending[j])
            end = start + duration + (tail if last else 0)
            if held_duration is not None:
                held_start = shape.heads[held]
                if pending[held] is not None:
                    held_start = max(held_start, now + pending[held])
                end = max(end, held_start + held_duration + (shape.tails[held] if last else 0))
            if least is None or end < least:
                least = end
        return least

    def _estimate(self, layout, progress, last_panel, last_job):
        """What is left after the last heavy job (job `last_job` of panel `last_panel`, or
        none): the module docstring's estimate, kept while one order is continued (its
        staffings of one job share it)."""
        key = (layout, progress, last_panel, last_job)
        found = self.estimates.get(key)
        if found is None:
            found = self.estimates[key] = self._estimate_anew(
                self.layout_shapes[layout], progress, last_panel, last_job)
        return found

    def _estimate_anew(self, shapes, progress, last_panel, last_job):
        left, tail, others = 0, None, 0
        for k, shape in enumerate(shapes):
            done = progress[k]
            if done & shape.heavy_mask == shape.heavy_mask:
                continue
            left += shape.left[done]
            tail = shape.least_tail[done] if tail is None else min(
                tail, shape.least_tail[done])
            if k == last_panel:
                left += shape.rest[done, last_job]
            else:
                left += shape.rest[done, -1]
                others += 1
        if last_panel is None:
            others -= 1  # the first heavy job is entered from no panel
        return left + max(others, 0) * self.switch + (tail or 0)


def _dominated(labels, now, latest, ends, light_ends, free):
    """Whether one of `labels` (times of orders in one state) is no later in any time than
    the ones given, so that whatever follows the given order follows it no later."""
    return any(t <= now and m <= latest and all(a <= b for a, b in zip(e, ends, strict=True))
               and all(a <= b for x, y in zip(le, light_ends, strict=True)
                       for a, b in zip(x, y, strict=True))
               and all(a <= b for a, b in zip(f, free, strict=True))
               for t, m, e, le, f in labels)


class _Shape:
    """The kept jobs of one panel on the grid: names, heads, tails, choices (durations in
    ticks), which jobs must come first (bit masks), lags, holds, the jobs only heavy
    staffings can do, and per set of jobs done the least durations of those left and the
    least tail among them."""

    def __init__(self, shape, ticks):
        jobs, lags, holds = shape
        self.names = [name for name, *_ in jobs]
        self.heads = [ticks(head) for _, head, _, _ in jobs]
        self.tails = [ticks(tail) for _, _, tail, _ in jobs]
        self.choices = [[replace(c, duration=ticks(c.duration))
                         for c in choices] for *_, choices in jobs]
        index = {name: k for k, name in enumerate(self.names)}
        self.before = [sum(1 << index[a] for (a, b) in lags if b == name)
                       for name in self.names]
        self.lags = {(index[a], index[b]): ticks(lag) for (a, b), lag in lags.items()}
        self.held = {index[a]: index[b] for a, b in holds}
        self.least = [min(c.duration for c in choices) for choices in self.choices]
        self.always_heavy = [all(c.heavy for c in choices) for choices in self.choices]
        count = len(self.names)
        self.full = (1 << count) - 1
        self.heavy_mask = sum(1 << j for j in range(count) if self.always_heavy[j])
        heavy_left = [[j for j in range(count) if self.always_heavy[j] and not done >> j & 1]
                      for done in range(self.full + 1)]
        self.left = [sum(self.least[j] for j in left) for left in heavy_left]
        self.least_tail = [min((self.tails[j] for j in left), default=0)
                           for left in heavy_left]
        self.rest = {}


def _pending(shape):
    """(jobs done) -> per job x, the least time from the end of the last heavy job to the
    start of x that the jobs only heavy staffings can do, not done, before x or x itself
    need (each starts after that end), or None when there is none."""
    heavy = [a for a in range(len(shape.names)) if shape.always_heavy[a]]
    table = []
    for done in range(shape.full + 1):
        row = []
        for x in range(len(shape.names)):
            gaps = [0 if a == x else shape.least[a] + shape.lags[a, x] for a in heavy
                    if not done >> a & 1 and (a == x or (a, x) in shape.lags)]
            row.append(max(gaps) if gaps else None)
        table.append(row)
    return table


def _rest_costs(shape, switch):
    """(jobs done, the last heavy one or -1) -> least sum, over the orders of the jobs left
    that only heavy staffings can do, of what separates consecutive ones: the lag between
    them when one comes right after the other among the heavy jobs, or a switch to another
    panel and back when not, whichever is less (the switch into the panel is counted by the
    caller, once per panel)."""
    rest = {}
    heavy = [j for j in range(len(shape.names)) if shape.always_heavy[j]]
    for done in range(shape.full, -1, -1):
        for last in range(-1, len(shape.names)):
            left = [j for j in heavy if not done >> j & 1]
            if not left:
                rest[done, last] = 0
                continue
            best = None
            for j in left:
                before = shape.before[j] & shape.heavy_mask
                if before & ~done:
                    continue
                step = 0 if last < 0 else min(shape.lags.get((last, j), 0), switch)
                found = step + rest[done | 1 << j, j]
                best = found if best is None else min(best, found)
            rest[done, last] = best or 0
    return rest
