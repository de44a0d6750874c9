"""A lower bound for identical panels from a relaxation CP-SAT solves to optimality: the
"panel machine" (docs/solver.md, "Bounds").

Let G be the robots that can reach every panel within a known schedule's makespan U (the
others, "limited", reach only `bounds.panel_limits` many), and call a staffing of a job
*heavy* when it needs more than half of G. Two heavy staffings together need more of G than
there is, so heavy jobs run one after another, as on one machine; and a limited robot does
one job at a time. The relaxation keeps every job of every panel, with:

- its staffing choices (the robots, the least duration), whether a choice is heavy and
  which limited robots it takes;
- its panel's precedence chains: the least time from a job's end to a later job's start
  (heads, tails and lags at least durations plus the travel a chain forces: a robot that
  every staffing of a job needs leaves from that job's place);
- for two jobs whose choices share a robot, that the one ends before the other starts,
  apart by the shared robot's least travel from the one's place to the other's, in one
  panel or from one panel to another, whatever the robot does in between
  (`geometry.least_travel`; the slowest of the shared robots, for the cheapest pair of robot
  sets);
- for a jig job whose robots all hold into another job, that those robots start nothing
  else between the jig job's start and the held job's end;

and forgets the rest: which robot of a set does what, and routes (two jobs of a robot are
kept apart by the least travel between them, not by the sum along the robot's route). At
least N - (sum of the limits) panels are done without limited robots; the others may have
them all. Every schedule shorter than U is a schedule of this relaxation, so its least
makespan, or the bound CP-SAT proves on it within the time given, bounds every schedule
shorter than U, and min(bound, U) bounds all. Times are floored onto an integer grid, which
only lowers it.
"""

import itertools
import math
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.geometry import least_travel
from fjsp_planner.solving.bounds.jobs import StaffingChoice, staffings, topological
from fjsp_planner.solving.bounds.panel import panel_limits
from fjsp_planner.solving.cpsat.grid import objective_ticks

MAX_CHOICES = 8
"""Staffing choices kept apart per job and kind of choice; beyond, they merge into one at the
least duration that stands for all their robot sets (weaker, still a lower bound)."""
MAX_GRID = 1000
MAX_JOBS = 150
"""Problems of more jobs get no panel machine bound: building the relaxation alone takes
longer than its share of a usual limit, and on many panels the panel load bound proves more
in the time."""
EVERY_JOB_LIMIT = 30
"""Problems of at most this many jobs keep every job in the relaxation, which CP-SAT's
default search proves on 2 panels of the paper within seconds. On larger ones it proves
less in the time than the relaxation of the heavy jobs and those of limited robots alone,
which they keep."""
SMALL = 20
"""Relaxations of the heavy and limited jobs alone of at most this many jobs are left to
CP-SAT's default search, which proves them within seconds; on larger ones its bound stays
near the linear relaxation's, and BOUND_SUBSOLVERS do better. Relaxations of every job are
left to the default search."""
BOUND_SUBSOLVERS = ('objective_lb_search', 'default_lp')
"""A worker that asks for relaxed schedules shorter than the proven bound and raises the
bound when there are none, beside the default one: on 3 and 5 panels it proves much more
in the same time than the default search alone."""


def panel_machine_bound(problem: Problem, incumbent: Fraction, time_limit: float,
                        workers: int = 1) -> Fraction | None:
    """The bound of the module docstring, or None when it does not apply (fewer than two
    panels, running jobs, more than MAX_JOBS jobs, no robot of G, or, above EVERY_JOB_LIMIT
    jobs, nothing heavy) or CP-SAT proves nothing in `time_limit` seconds."""
    if len(problem.panels) < 2 or problem.fixed or len(problem.jobs) > MAX_JOBS:
        return None
    limits = panel_limits(problem, incumbent)
    group = frozenset(r.name for r in problem.robots if r.name not in limits)
    if not group:
        return None
    helped = min(len(problem.panels), sum(limits.values()))
    every_job = len(problem.jobs) <= EVERY_JOB_LIMIT
    kinds = [(len(problem.panels) - helped, sorted(group)),
             (helped, sorted(r.name for r in problem.robots))]
    jobs, lags, holds, kind_of = [], {}, set(), []
    for kind, (count, allowed) in enumerate(kinds):
        if count == 0:
            continue
        shape = panel_shape(problem, allowed, group, set(limits))
        if shape is None:
            return None
        panel_jobs, panel_lags, panel_holds = within_incumbent(shape, incumbent, every_job)
        for _ in range(count):
            kind_of.append(kind)
            jobs += [(len(kind_of) - 1, *job) for job in panel_jobs]
        lags.update({(kind, a, b): lag for (a, b), lag in panel_lags.items()})
        holds |= {(kind, a, b) for a, b in panel_holds}
    if not every_job and not any(c.heavy for *_, choices in jobs for c in choices):
        return None
    subsolvers = () if every_job or len(jobs) <= SMALL or workers < 2 else BOUND_SUBSOLVERS
    names = problem.panels[0]
    travel = {(r.name, a, b, across): least_travel(problem, r.name, a, b, across)
              for r in problem.robots for a in names for b in names for across in (False, True)}
    return _solve(jobs, lags, holds, kind_of, travel, time_limit, workers, subsolvers)


def within_incumbent(shape, incumbent, every_job):
    """The shape without the choices that make a job end at or after `incumbent` whatever
    else happens (no schedule shorter than it uses them), a job keeping at least its
    fastest; unless `every_job`, jobs left with no heavy choice and no limited robot are
    dropped."""
    jobs, lags, holds = shape
    kept = []
    for name, head, tail, choices in jobs:
        fit = [c for c in choices if head + c.duration + tail < incumbent]
        fit = fit or [min(choices, key=lambda c: c.duration)]
        if every_job or any(c.heavy or c.limited for c in fit):
            kept.append((name, head, tail, fit))
    names = {job[0] for job in kept}
    return (kept, {(a, b): lag for (a, b), lag in lags.items() if a in names and b in names},
            {(a, b) for a, b in holds if a in names and b in names})


def panel_shape(problem: Problem, allowed, group, limited):
    """For one panel staffed from `allowed`: its jobs as (name, head, tail, choices), the lags
    between them and the holding pairs, or None if some job cannot be staffed."""
    durations, choices, staffed = {}, {}, {}
    for name in problem.panels[0]:
        fastest = {}
        for plan in problem.job(name).plans:
            for staffing in staffings(problem, plan, allowed):
                robots = frozenset(r for r, _ in staffing)
                length = max(problem.duration(r, q) for r, q in staffing)
                fastest[robots] = min(length, fastest.get(robots, length))
        if not fastest:
            return None
        durations[name] = min(fastest.values())
        staffed[name] = list(fastest)
        choices[name] = _choices(fastest, group, limited)
    names = set(problem.panels[0])
    inside = [(a, b) for a, b in problem.precedence if a in names and b in names]
    inside += [(a, b) for a, b, _ in problem.holding if a in names and b in names]
    order = [n for n in topological(problem) if n in names]
    successors = {n: [b for a, b in inside if a == n] for n in names}
    predecessors = {n: [a for a, b in inside if b == n] for n in names}
    release = min(r.release_time for r in problem.robots if r.name in set(allowed))
    always = {name: frozenset.intersection(*sets) for name, sets in staffed.items()}

    def moved(a, b):
        return min(max((least_travel(problem, r, a, b) for r in robots & always[a]),
                       default=Fraction(0)) for robots in staffed[b])

    arcs = {(a, b): moved(a, b) for a, b in inside}
    heads, tails = {}, {}
    for name in order:
        heads[name] = max((heads[a] + durations[a] + arcs[a, name]
                           for a in predecessors[name]), default=release)
    for name in reversed(order):
        tails[name] = max((arcs[name, b] + durations[b] + tails[b] for b in successors[name]),
                          default=Fraction(0))
    lags = {}
    for source in choices:
        # Longest path from the end of `source` to the start of each job after it.
        reach = {source: Fraction(0)}
        for name in order[order.index(source):]:
            if name not in reach:
                continue
            for b in successors[name]:
                gap = reach[name] + (durations[name] if name != source else 0) + arcs[name, b]
                reach[b] = max(gap, reach.get(b, gap))
        lags.update({(source, b): reach[b] for b in choices if b != source and b in reach})
    # Holding arcs whose jig job's every operation is of the held type: all its robots hold
    # on into the held job, so they are busy from the jig job's start to the held job's end.
    # Only pairs (a held job that is no jig job, a jig job holding into one job only).
    sources = [a for a, _, _ in problem.holding]
    targets = {b for _, b, _ in problem.holding}
    holds = {(a, b) for a, b, q in problem.holding
             if a in names and b in names and sources.count(a) == 1 and b not in sources
             and a not in targets and all(set(plan) == {q} for plan in problem.job(a).plans)}
    jobs = [(name, heads[name], tails[name], found) for name, found in choices.items()]
    return jobs, lags, holds


def _choices(fastest, group, limited) -> list[StaffingChoice]:
    """Choices from robot set -> least duration: a set that contains another as fast with
    the same heaviness and limited robots is dropped (its crossings are no cheaper); past
    MAX_CHOICES of a kind, they merge."""
    kinds = {}
    for robots, length in fastest.items():
        key = (len(robots & group) * 2 > len(group), robots & limited)
        kinds.setdefault(key, {})[robots] = length
    out = []
    for (heavy, mine), sets in sorted(kinds.items(), key=lambda item: sorted(item[1].values())):
        kept = [(length, robots) for robots, length in sets.items()
                if not any(other < robots and sets[other] <= length for other in sets)]
        if len(kept) > MAX_CHOICES:
            kept = [(min(length for length, _ in kept), tuple(r for _, r in kept))]
        else:
            kept = [(length, (robots,)) for length, robots in kept]
        out += [StaffingChoice(length, sets_, heavy, mine) for length, sets_ in kept]
    return out


def _solve(jobs, lags, holds, kind_of, travel, time_limit, workers, subsolvers
           ) -> Fraction | None:
    """CP-SAT on the relaxation: `jobs` (panel, name, head, tail, choices), `lags` (kind,
    name, later name) -> least time between them inside a panel, `holds` (kind, jig job,
    held job) whose robots are busy from the one's start to the other's end, `travel`
    (robot, name, name, in different panels) -> its least travel from the one job to the
    other; `subsolvers` join CP-SAT's default ones."""
    keys = [(panel, name) for panel, name, *_ in jobs]
    index = {key: k for k, key in enumerate(keys)}
    held = {index[panel, a]: index[panel, b] for panel, kind in enumerate(kind_of)
            for held_kind, a, b in holds if held_kind == kind}

    def gap(a, b, robots):
        """Least time from job a's end to job b's start for all of `robots` to get there."""
        across = keys[a][0] != keys[b][0]
        return max(travel[r, keys[a][1], keys[b][1], across] for r in robots)

    def least_gap(a, first, b, second):
        """The least gap for the robots a choice of a's shares with one of b's, or None
        when some pair of their robot sets shares none (the two may overlap)."""
        shared = [x & y for x in first.sets for y in second.sets]
        return min(gap(a, b, s) for s in shared) if all(shared) else None

    lag = {}
    for a, b in itertools.permutations(range(len(jobs)), 2):
        if keys[a][0] == keys[b][0]:
            found = lags.get((kind_of[keys[a][0]], keys[a][1], keys[b][1]))
            if found is not None:
                lag[a, b] = found
    moves = {}
    """(a, i, b, j) -> least time between a's end and b's start when a comes first with
    choice i and b with choice j and the two cannot overlap; absent when they can."""
    for a, b in itertools.permutations(range(len(jobs)), 2):
        for i, first in enumerate(jobs[a][4]):
            for j, second in enumerate(jobs[b][4]):
                found = least_gap(a, first, b, second)
                if found is not None:
                    moves[a, i, b, j] = found
    after_hold = {}
    """(a, i, b, j) -> least time between the end of the job a holds into and b's start,
    when b comes after a with choice j and shares a robot with a's choice i: a's robots
    hold on into that job before they can go."""
    for a, b in itertools.product(held, range(len(jobs))):
        if b in (a, held[a]):
            continue
        for i, first in enumerate(jobs[a][4]):
            for j, second in enumerate(jobs[b][4]):
                found = least_gap(held[a], first, b, second)
                if found is not None:
                    after_hold[a, i, b, j] = found
    values = [v for job in jobs for v in (job[2], job[3], *(c.duration for c in job[4]))]
    values += list(lag.values()) + list(moves.values()) + list(after_hold.values())
    scale = min(MAX_GRID, math.lcm(*(v.denominator for v in values)))

    def ticks(value):
        return value.numerator * scale // value.denominator

    horizon = sum(max(ticks(c.duration) for c in job[4]) + ticks(job[2]) + ticks(job[3])
                  for job in jobs) + sum(ticks(v) for v in lag.values()) + sum(
                      ticks(v) for v in moves.values())
    m = cp_model.CpModel()
    start, end, length, picks, uses = [], [], [], [], []
    """uses[k]: resource ('machine' or a limited robot) -> literal: job k takes it."""
    for panel, name, head, _, choices in jobs:
        start.append(m.new_int_var(ticks(head), horizon, f'start_{name}_{panel}'))
        end.append(m.new_int_var(0, horizon, f'end_{name}_{panel}'))
        picks.append([m.new_bool_var(f'pick_{name}_{panel}_{i}') for i in range(len(choices))])
        m.add_exactly_one(picks[-1])
        sizes = [ticks(c.duration) for c in choices]
        length.append(m.new_int_var(min(sizes), max(sizes), f'duration_{name}_{panel}'))
        m.add(length[-1] == sum(p * size for p, size in zip(picks[-1], sizes, strict=True)))
        m.add(end[-1] == start[-1] + length[-1])
        taken = {}
        for resource in ('machine', *set().union(*(c.limited for c in choices))):
            literal = taken[resource] = m.new_bool_var(f'{resource}_{name}_{panel}')
            m.add(literal == sum(p for p, c in zip(picks[-1], choices, strict=True)
                                 if (c.heavy if resource == 'machine' else resource in c.limited)))
        uses.append(taken)
    _resources(m, keys, holds, kind_of, start, end, length, uses, horizon)
    makespan = m.new_int_var(0, horizon, 'makespan')
    for k, job in enumerate(jobs):
        m.add(makespan >= end[k] + ticks(job[3]))
    for (a, b), found in lag.items():
        m.add(start[b] >= end[a] + ticks(found))

    def after(a, i, b, j, *when):
        """b, with choice j, after a with choice i; `when` literals enforce it."""
        both = (picks[a][i], picks[b][j])
        found = moves.get((a, i, b, j))
        if found is not None:
            m.add(start[b] >= end[a] + ticks(found)).only_enforce_if(*when, *both)
        found = after_hold.get((a, i, b, j))
        if found is not None:
            m.add(start[b] >= end[held[a]] + ticks(found)).only_enforce_if(*when, *both)

    for a, b in itertools.permutations(range(len(jobs)), 2):
        if (a, b) in lag:
            for i, j in itertools.product(range(len(jobs[a][4])), range(len(jobs[b][4]))):
                after(a, i, b, j)
    for a, b in itertools.combinations(range(len(jobs)), 2):
        if (a, b) in lag or (b, a) in lag:
            continue
        pairs = [(i, j) for i in range(len(jobs[a][4])) for j in range(len(jobs[b][4]))
                 if (a, i, b, j) in moves]
        if not pairs:
            continue
        before = m.new_bool_var('')
        for i, j in pairs:
            after(a, i, b, j, before)
            after(b, j, a, i, ~before)
    _path_cut(m, jobs, keys, lag, moves, start, end, makespan, ticks)
    firsts = {}
    for k, (panel, *_) in enumerate(jobs):
        firsts.setdefault(panel, start[k])
    for panel in sorted(firsts)[1:]:
        if kind_of[panel] == kind_of[panel - 1]:
            m.add(firsts[panel - 1] <= firsts[panel])
    m.minimize(makespan)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(0.01, time_limit)
    solver.parameters.num_workers = workers
    solver.parameters.catch_sigint_signal = False
    solver.parameters.subsolvers.extend(subsolvers)
    status = solver.solve(m).name
    if status in ('INFEASIBLE', 'MODEL_INVALID') or not math.isfinite(
            solver.best_objective_bound):
        return None
    # Proven whether or not a schedule of the relaxation was found in time.
    return Fraction(objective_ticks(solver.best_objective_bound), scale)


def _resources(m, keys, holds, kind_of, start, end, length, uses, horizon):
    """One no-overlap per resource. A jig job that holds into another takes a resource from
    its own start to the held job's end when its choice takes it; the held job then takes
    it on its own only if the jig job's choice does not."""
    index = {key: k for k, key in enumerate(keys)}
    held_by = {}
    for k, (panel, name) in enumerate(keys):
        for kind, a, b in holds:
            if kind == kind_of[panel] and a == name:
                held_by[index[panel, b]] = k
    spans = {k: b for b, k in held_by.items()}
    intervals = {}
    for k, taken in enumerate(uses):
        for resource, literal in taken.items():
            if k in spans:
                b = spans[k]
                span = m.new_int_var(0, horizon, '')
                m.add(end[b] == start[k] + span)
                interval = m.new_optional_interval_var(start[k], span, end[b], literal, '')
            else:
                present = literal
                jig = held_by.get(k)
                if jig is not None and resource in uses[jig]:
                    present = m.new_bool_var('')
                    m.add_bool_and([literal, ~uses[jig][resource]]).only_enforce_if(present)
                    m.add_bool_or([~literal, uses[jig][resource], present])
                interval = m.new_optional_interval_var(start[k], length[k], end[k], present,
                                                       '')
            intervals.setdefault(resource, []).append(interval)
    for group in intervals.values():
        m.add_no_overlap(group)


def _path_cut(m, jobs, keys, lag, moves, start, end, makespan, ticks):
    """The jobs every choice makes heavy lie on the machine in some order: the makespan is
    at least the first one's head, their durations, the least gap between consecutive ones
    and the last one's tail. Implied, but as one linear sum it reaches the LP relaxation."""
    always = [k for k, job in enumerate(jobs) if all(c.heavy for c in job[4])]
    if len(always) < 2:
        return
    arcs, gaps = [], []
    for k in always:
        first, last = m.new_bool_var(''), m.new_bool_var('')
        arcs += [(0, k + 1, first), (k + 1, 0, last)]
        gaps += [first * ticks(jobs[k][2]), last * ticks(jobs[k][3])]
    for a, b in itertools.permutations(always, 2):
        if (b, a) in lag:
            continue
        if keys[a][0] == keys[b][0]:
            least = ticks(lag.get((a, b), Fraction(0)))
        else:
            least = min(ticks(moves[a, i, b, j]) for i in range(len(jobs[a][4]))
                        for j in range(len(jobs[b][4])))
        arc = m.new_bool_var('')
        arcs.append((a + 1, b + 1, arc))
        gaps.append(arc * least)
        m.add(start[b] >= end[a] + least).only_enforce_if(arc)
    m.add_circuit(arcs)
    m.add(makespan >= sum(gaps) + sum(end[k] - start[k] for k in always))
