"""A lower bound for panels from what each robot must do: the "panel load" bound
(docs/solver.md, "Bounds").

Every robot is busy for the whole of each job it works on, and it must travel between the
places of its jobs. So whatever the order, a robot's release time, the durations of its jobs
and the least travel its set of jobs forces fit in the makespan. The least travel is counted
from which panels and which *places* of a panel the robot visits, a place being the job
locations of a panel joined by distances 0 (the paper's panel has two: the 8 assembly jobs at one
spot, the 4 moves at another, 35 to 58 apart; a robot goes straight from one job to the next,
so moving between two places of a panel costs at least the least distance between two):

- a robot that visits p panels and c places in all enters panels E >= p times, so it makes at
  least E - 1 moves between panels, each at least the least distance between two panels (x,
  times its travel factor), and, within each panel k, at least c_k - e_k moves between two of
  its places (e_k its entries into k), each at least the least distance between two places
  of a panel (h). Over E in [p, c] that is at least (p - 1) x + (c - p) h when x >= h, and
  (c - 1) x otherwise;
- a robot whose moves between panels are slow visits at most `bounds.panel_limits` panels
  (a schedule that visits more is no shorter than the known one, U).

CP-SAT chooses every job's staffing (the robots, at the least duration of each set) to
minimise the largest such sum: no sequencing, so even many panels are proven or nearly in
seconds, where the panel machine bound, which sequences, falls behind. What it
misses is idle time: robots waiting for predecessors or for the other robots of a job. One
kind is counted in a second solve, from the first one's bound: a *cut job*, one that every
other job of its panel precedes or follows, runs alone in its panel, so a robot that works
there before and after it, but not on it, waits meanwhile or leaves the panel and comes back
(`_waiting`). Times are floored onto a grid, which only lowers it; every schedule shorter
than U is counted, so min(bound, U) bounds all.
"""

import math
import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.geometry import panel_distance, travel_factor
from fjsp_planner.solving.bounds.jobs import fastest_sets, heads_and_tails
from fjsp_planner.solving.bounds.machine import BOUND_SUBSOLVERS
from fjsp_planner.solving.bounds.panel import panel_limits
from fjsp_planner.solving.cpsat.grid import objective_ticks

MAX_GRID = 1000
MAX_CHOICES = 20_000
"""Staffing literals beyond which building the model alone would take seconds; large fleets
and many panels go without this bound."""
MIN_SECOND_SOLVE = 0.2
"""Seconds below which the model with waits is not tried: it proves nothing more so soon."""


def panel_load_bound(problem: Problem, incumbent: Fraction, time_limit: float,
                     workers: int = 1) -> Fraction | None:
    """The bound of the module docstring, or None when it does not apply (fewer than two
    panels, running jobs, jobs outside the panels) or CP-SAT proves nothing in `time_limit`
    seconds.

    The loads alone are proven quickly even on many panels; with the waits the model is
    proven on few panels only, so it is solved second, from what the loads alone prove, for
    the time left."""
    panels = problem.panels
    if len(panels) < 2 or problem.fixed or sum(map(len, panels)) != len(problem.jobs):
        return None
    choices = _choices(problem, incumbent)
    if sum(len(found) for found in choices.values()) > MAX_CHOICES:
        return None
    started = time.monotonic()
    loads = _solve(problem, incumbent, choices, time_limit, workers)
    left = time_limit - (time.monotonic() - started)
    before = problem.ancestors()
    cuts = [_cut_jobs(before, names) for names in panels]
    if loads is None or loads >= incumbent or left < MIN_SECOND_SOLVE or not any(cuts):
        return loads
    waits = _solve(problem, incumbent, choices, left, workers, cuts, floor=loads)
    return loads if waits is None else max(loads, waits)


def _solve(problem: Problem, incumbent: Fraction, choices, time_limit: float, workers: int,
           cuts=None, floor: Fraction | None = None) -> Fraction | None:
    """The least largest robot sum CP-SAT proves in `time_limit`; with `cuts` (per panel, see
    `_cut_jobs`) the waits around them count too, from `floor` (what is proven without)."""
    panels = problem.panels
    places, between_places = _places(problem)
    between_panels = panel_distance(problem)
    factors = {r.name: travel_factor(problem, r.name) for r in problem.robots}
    values = [d for found in choices.values() for d, _ in found]
    values += [r.release_time for r in problem.robots]
    values += [f * d for f in factors.values() for d in (between_places, between_panels)]
    scale = min(MAX_GRID, math.lcm(*(v.denominator for v in values)))

    def ticks(value):
        return value.numerator * scale // value.denominator

    # Schedules shorter than the incumbent only: a floored one ends at most a tick before it.
    limit = -(-incumbent.numerator * scale // incumbent.denominator) - 1
    if limit < 0:
        return None
    m = cp_model.CpModel()
    makespan = m.new_int_var(0, limit, 'makespan')
    load = {r.name: [] for r in problem.robots}
    works = {}
    """(robot, job) -> the literals of the job's choices that give it the robot."""
    picked = {}
    for name, found in choices.items():
        picks = [m.new_bool_var(f'pick_{name}_{i}') for i in range(len(found))]
        picked[name] = picks
        m.add_exactly_one(picks)
        for pick, (duration, robots) in zip(picks, found, strict=True):
            for r in robots:
                load[r].append(pick * ticks(duration))
                works.setdefault((r, name), []).append(pick)
    limits = panel_limits(problem, incumbent)
    visits = {}
    for robot in problem.robots:
        r = robot.name
        f = factors[r]
        panel_visits, place_visits, waits = [], [], []
        for k, names in enumerate(panels):
            visit = _any(m, [p for n in names for p in works.get((r, n), ())],
                         f'visits_panel_{k + 1}_{r}')
            panel_visits.append(visit)
            in_panel = [_any(
                m, [p for n in names if places[n] == place for p in works.get((r, n), ())],
                f'visits_{place}_{r}') for place in sorted(set(places[n] for n in names))]
            place_visits += in_panel
            if cuts:
                waits.append(_waiting(m, r, k, cuts[k], in_panel, picked, choices, works,
                                      ticks, f * between_places, f * between_panels))
        used = _any(m, panel_visits, f'used_{r}')
        visits[r] = panel_visits
        p, c = sum(panel_visits), sum(place_visits)
        x = ticks(f * between_panels)
        h = ticks(f * between_places)
        travel = (p - used) * x + (c - p) * h if x >= h else (c - used) * x
        m.add(makespan >= sum(load[r]) + travel + sum(waits) + ticks(robot.release_time))
        if r in limits:
            m.add(p <= limits[r])
    if limits and _interchangeable(problem, choices, places):
        # Any panel order gives the same loads: let the slowest limited robot's panels be
        # the first ones, which spares the search every reordering of them.
        slowest = max(limits, key=factors.get)
        for k in range(len(panels) - 1):
            m.add(visits[slowest][k] >= visits[slowest][k + 1])
    if floor is not None:
        m.add(makespan >= -(-floor.numerator * scale // floor.denominator))
    m.minimize(makespan)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(0.01, time_limit)
    solver.parameters.num_workers = workers
    solver.parameters.catch_sigint_signal = False
    if floor is not None and workers >= 2:
        solver.parameters.subsolvers.extend(BOUND_SUBSOLVERS)
    status = solver.solve(m).name
    if status == 'INFEASIBLE':
        # No robot loads fit below the incumbent: no schedule is shorter than it.
        return incumbent
    if status == 'MODEL_INVALID' or not math.isfinite(solver.best_objective_bound):
        return None
    return min(Fraction(objective_ticks(solver.best_objective_bound), scale), incumbent)


def _cut_jobs(before, names):
    """[(job, the jobs of the panel before it, those after it)] for each job of the panel that
    every other job of the panel precedes or follows, with jobs on both sides (`before`: job
    -> its ancestors)."""
    inside = set(names)
    cuts = []
    for j in names:
        ahead = before[j] & inside
        behind = {n for n in names if j in before[n]}
        if ahead and behind and len(ahead) + len(behind) == len(inside) - 1:
            cuts.append((j, sorted(ahead), sorted(behind)))
    return cuts


def _waiting(m, r, k, cuts, in_panel, picked, choices, works, ticks, move, crossing):
    """The least time robot `r` spends in panel `k` neither working nor in the travel the
    load counts, as an expression of the model (`move`, `crossing`: its least travel between
    two places of a panel and between two panels).

    While a cut job runs no other job of its panel does. A robot working in the panel before
    it and after it, but not on it, either waits meanwhile or leaves the panel and comes back.
    Waiting, the gap between its two jobs around the cut job lasts at least the cut job's
    duration, of which at most one counted move between places can be travel the load
    already counts: none when the robot works at one place of the panel. Leaving, it enters
    the panel once more than counted: one more crossing, less the move between places that
    entering might save when it works at two places or more. Cut jobs are ordered, so their
    runs do not overlap and their waits add up."""
    at_one_place, anywhere = [], []
    for j, ahead, behind in cuts:
        before = _any(m, [p for n in ahead for p in works.get((r, n), ())], f'before_{j}_{r}')
        after = _any(m, [p for n in behind for p in works.get((r, n), ())], f'after_{j}_{r}')
        for pick, (duration, robots) in zip(picked[j], choices[j], strict=True):
            if r in robots:
                continue
            waits = m.new_bool_var(f'waits_{j}_{r}_{len(anywhere)}')
            m.add(waits >= before + after + pick - 2)
            at_one_place.append(waits * ticks(duration))
            anywhere.append(waits * ticks(max(Fraction(0), duration - move)))
    if not anywhere:
        return 0
    one_place = m.new_bool_var(f'one_place_{k + 1}_{r}')
    m.add(sum(in_panel) <= 1).only_enforce_if(one_place)
    m.add(sum(in_panel) >= 2).only_enforce_if(~one_place)
    wait = m.new_int_var(0, ticks(crossing), f'wait_{k + 1}_{r}')
    for expression, leaving, enforced in (
            (sum(at_one_place), crossing, one_place),
            (sum(anywhere), max(Fraction(0), crossing - move), None)):
        least = m.new_int_var(0, ticks(crossing), f'least_wait_{k + 1}_{r}')
        staying = m.new_int_var(0, sum(ticks(d) for found in choices.values() for d, _ in found),
                                f'staying_{k + 1}_{r}')
        m.add(staying == expression)
        m.add_min_equality(least, [staying, ticks(leaving)])
        constraint = m.add(wait >= least)
        if enforced is not None:
            constraint.only_enforce_if(enforced)
    return wait


def _interchangeable(problem: Problem, choices, places) -> bool:
    """Panels whose k-th jobs have the same choices and whose places group the same
    positions: renumbering the panels maps loads to the same loads."""
    def shape(names):
        first = {}
        return [(choices[n], first.setdefault(places[n], i)) for i, n in enumerate(names)]

    pattern = shape(problem.panels[0])
    return all(shape(names) == pattern for names in problem.panels[1:])


def _any(m, literals, name):
    """A literal true exactly when one of `literals` is."""
    visit = m.new_bool_var(name)
    m.add_max_equality(visit, literals or [0])
    return visit


def _choices(problem: Problem, incumbent: Fraction):
    """job -> [(least duration, robot set)]: a set is kept only if no smaller set is as
    fast (it would load more robots for nothing), nor does it end the job at or after
    `incumbent` whatever else happens (the fastest is kept regardless)."""
    heads, tails = heads_and_tails(problem)
    robots = sorted(r.name for r in problem.robots)
    out, known = {}, {}
    for job in problem.jobs:
        # Copies of a job in other panels have the same plans, heads and tails.
        key = (job.plans, heads[job.name], tails[job.name])
        if key not in known:
            known[key] = _fitting(problem, job.plans, robots, heads[job.name] + tails[job.name],
                                  incumbent)
        out[job.name] = known[key]
    return out


def _fitting(problem, plans, robots, around, incumbent):
    found = fastest_sets(problem, plans, robots)
    return [(d, s) for d, s in found if around + d < incumbent] or found[:1]


def _places(problem: Problem):
    """(job -> its place: the panel and one of the job locations joined to its own by
    distances 0; the least distance between two places of a panel, 0 if no panel has two).
    A robot goes straight from one job to the next, so a move between places costs at least
    that least distance."""
    place, least = {}, None
    for k, names in enumerate(problem.panels):
        spots = sorted({problem.job(n).location for n in names})
        root = {a: a for a in spots}
        for i, a in enumerate(spots):
            for b in spots[i + 1:]:
                if problem.distance(a, b) == 0 or problem.distance(b, a) == 0:
                    root[_find(root, b)] = _find(root, a)
        for n in names:
            place[n] = f'{k + 1}_{_find(root, problem.job(n).location)}'
        apart = [problem.distance(a, b) for a in spots for b in spots
                 if _find(root, a) != _find(root, b)]
        if apart:
            least = min(apart) if least is None else min(least, *apart)
    return place, least or Fraction(0)


def _find(root, a):
    while root[a] != a:
        a = root[a]
    return a
