"""A lower bound for any scenario from what each robot must do and travel: the "fleet load"
bound (docs/solver.md, "Bounds").

Every robot is busy for the whole of each job it works on, and it enters each place it
works at, other than its start location, by a leg no shorter than the least into that place
from any other (a robot that may start anywhere enters its first place for free). So its
release time, the durations of its jobs and those legs fit in the makespan, whatever the
order; so do its release time, its jobs and its shortest way through those places, each
once, along the least ways of the distance table. CP-SAT chooses every job's staffing (a
set of robots, at the least duration that set achieves) to minimise the largest such sum;
`bounds.fleet` counts the same per robot only for the jobs nobody else can do, and the work
of a group without its travel. Times are floored onto a grid, which only lowers the bound.

Precedence orders a robot's jobs too: of two of its jobs, one preceding the other through
any chain of jobs, it does the first first, then makes its way to the second's place, by at
least the least way there, whatever it does in between. Along a chain of its jobs those ways
are separate parts of its travel, so its release time, its jobs and the longest such chain of
ways (from its start location) fit in the makespan too: a robot whose jobs alternate between
places layer after layer goes back and forth, where its route would visit each place once.
That model is slower to prove, so it is solved second, from what the first proves.
"""

import math
import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.geometry import least_leg_into, least_location_travel
from fjsp_planner.solving.bounds.jobs import fastest_sets
from fjsp_planner.solving.cpsat.grid import objective_ticks

MAX_GRID = 1000
MAX_CHOICES = 20_000
"""Staffing literals beyond which building the model alone would take seconds; large fleets
go without this bound."""
MIN_CHAIN_SOLVE = 0.2
"""Seconds below which the model with chained ways is not tried: it proves nothing more so
soon."""
DEFAULT_SEARCH_SHARE = 0.3
"""Share of its time the model with chained ways gets CP-SAT's default search before the
lower-bound tree search (tuning scenarios of 30-120 jobs, 4 s on one core: the tree search
alone raises 14 of 16 bounds more, by up to 3 %, but proves none of those the default search
proves within a second)."""


def fleet_load_bound(problem: Problem, time_limit: float, workers: int = 1,
                     incumbent: Fraction | None = None, routes: bool = True,
                     work: float | None = None, chains: bool = False) -> Fraction | None:
    """The bound of the module docstring, or None when it does not apply (running jobs, too
    many staffings) or CP-SAT proves nothing in `time_limit` seconds. With `incumbent`, a
    makespan known to be reachable, it never exceeds that. Without `routes`, each robot's
    way through its places is left out: one least leg into each place only, a model proven
    in tenths of a second where the routes take seconds. With `work`, CP-SAT also stops
    after that much deterministic time (its own measure of work done, about seconds of one
    core whatever the load), so that the bound is as strong on a busy machine as on an idle
    one, within `time_limit`. With `chains`, the model with each robot's ways along the
    precedence chains of its jobs is then solved for the rest of `time_limit`."""
    if problem.fixed or not problem.jobs:
        return None
    started = time.monotonic()
    robots = sorted(r.name for r in problem.robots)
    choices = {}
    count = 0
    for job in problem.jobs:
        choices[job.name] = fastest_sets(problem, job.plans, robots)
        count += len(choices[job.name])
        if count > MAX_CHOICES:
            return None
    found, _ = _LoadModel(problem, choices, routes).solve(time_limit, workers, work)
    before = problem.ancestors() if chains and problem.locomote is not None else None
    if (before is not None and found is not None and (incumbent is None or found < incumbent)
            and _places_chained(problem, before)):
        found = _chained_bound(problem, choices, routes, before, found,
                               started + time_limit - time.monotonic(), workers)
    return found if incumbent is None or found is None else min(found, incumbent)


def _chained_bound(problem: Problem, choices, routes: bool, before, floor: Fraction,
                   time_limit: float, workers: int) -> Fraction:
    """The model with chained ways from `floor`, in `time_limit`: CP-SAT's default search
    first (it proves the easy ones in tenths of a second), then, from what it proved, its
    lower-bound tree search, which raises the bound of the others faster."""
    if time_limit < MIN_CHAIN_SOLVE:
        return floor
    started = time.monotonic()
    model = _LoadModel(problem, choices, routes, before)
    model.raise_floor(floor)
    found, proven = model.solve(DEFAULT_SEARCH_SHARE * time_limit, workers)
    floor = max(floor, found or floor)
    left = started + time_limit - time.monotonic()
    if proven or left < MIN_CHAIN_SOLVE:
        return floor
    model.raise_floor(floor)
    found, _ = model.solve(left, workers, tree=True)
    return max(floor, found or floor)


class _LoadModel:
    """The CP-SAT model of the module docstring: every job's staffing picked, each robot's
    release time, load and least travel below the makespan (with `before`, job -> its
    ancestors, its ways along the precedence chains of its jobs too)."""

    def __init__(self, problem: Problem, choices, routes: bool, before=None):
        robots = sorted(r.name for r in problem.robots)
        places = {job.location for job in problem.jobs}
        legs = {(r, place): least_leg_into(problem, r, place) for r in robots
                for place in places}
        entries = {(r.name, place): problem.travel(r.name, r.start_location, place)
                   for r in problem.robots if r.start_location is not None
                   for place in places}
        values = [d for found in choices.values() for d, _ in found]
        values += [r.release_time for r in problem.robots] + list(legs.values())
        values += list(entries.values())
        self.scale = min(MAX_GRID, math.lcm(*(v.denominator for v in values)))
        ticks = self.ticks
        # Room for the longest route (a longest least way into each place) or chain of ways
        # (one into each job).
        longest_way = max((ticks(least_location_travel(problem, r.name, a, b))
                           for r in problem.robots
                           for a in places | {r.start_location} - {None} for b in places),
                          default=0)
        horizon = sum(max(ticks(d) for d, _ in found) for found in choices.values())
        horizon += max(ticks(r.release_time) for r in problem.robots) + max(
            map(ticks, entries.values()), default=0) + sum(map(ticks, legs.values()))
        horizon += (len(places) if before is None else len(problem.jobs)) * longest_way
        self.model = m = cp_model.CpModel()
        self.makespan = makespan = m.new_int_var(0, horizon, 'makespan')
        load = {r: [] for r in robots}
        works = {}
        """(robot, place) -> the literals of the choices that have the robot work there."""
        picked = {}
        """(robot, job) -> the literals of the job's choices that give it the robot."""
        for job in problem.jobs:
            found = choices[job.name]
            picks = [m.new_bool_var(f'pick_{job.name}_{i}') for i in range(len(found))]
            m.add_exactly_one(picks)
            for pick, (duration, members) in zip(picks, found, strict=True):
                for r in members:
                    load[r].append(pick * ticks(duration))
                    works.setdefault((r, job.location), []).append(pick)
                    picked.setdefault((r, job.name), []).append(pick)
        for robot in problem.robots:
            r = robot.name
            visits, firsts, travel = [], [], []
            places_of = []
            """The places the robot may work at, in the order of its `visits` literals."""
            for (who, place), picks in sorted(works.items()):
                if who != r:
                    continue
                places_of.append(place)
                visit = m.new_bool_var(f'visits_{place}_{r}')
                for pick in picks:
                    m.add_implication(pick, visit)
                first = m.new_bool_var(f'first_{place}_{r}')
                m.add_implication(first, visit)
                visits.append(visit)
                firsts.append(first)
                # The first place is entered from the start location (from nowhere without
                # one), every other place by at least its least leg.
                entry = entries.get((r, place), Fraction(0))
                travel.append(visit * ticks(legs[r, place])
                              + first * (ticks(entry) - ticks(legs[r, place])))
            if not visits:
                continue
            m.add_at_most_one(firsts)
            for visit in visits:
                m.add(sum(firsts) >= visit)
            busy = sum(load[r]) + ticks(robot.release_time)
            m.add(makespan >= busy + sum(travel))
            if routes:
                m.add(makespan >= busy + _route_through(m, problem, robot, ticks, places_of,
                                                        visits))
            if before is not None:
                m.add(makespan >= busy + _chained_ways(m, problem, robot, ticks, picked,
                                                       before, horizon))
        m.minimize(makespan)

    def raise_floor(self, floor: Fraction):
        """The makespan no less than `floor` (a bound proven already) from now on."""
        self.model.add(self.makespan >= -(-floor.numerator * self.scale // floor.denominator))

    def ticks(self, value: Fraction) -> int:
        return value.numerator * self.scale // value.denominator

    def solve(self, time_limit: float, workers: int, work: float | None = None,
              tree: bool = False) -> tuple[Fraction | None, bool]:
        """The least makespan CP-SAT proves within `time_limit` (and `work`), or None, and
        whether that is the model's optimum; with `tree`, by its lower-bound tree search."""
        solver = cp_model.CpSolver()
        solver.parameters.max_time_in_seconds = max(0.01, time_limit)
        solver.parameters.num_workers = workers
        solver.parameters.catch_sigint_signal = False
        # Only the bound is wanted: with the circuits' and every constraint's cuts in its LP,
        # CP-SAT proves far more of it in the same time (docs/solver.md, "Fleet load").
        solver.parameters.linearization_level = 2
        solver.parameters.optimize_with_lb_tree_search = tree
        if work is not None:
            solver.parameters.max_deterministic_time = work
        status = solver.solve(self.model).name
        if status in ('MODEL_INVALID', 'INFEASIBLE') or not math.isfinite(
                solver.best_objective_bound):
            return None, False
        return (Fraction(objective_ticks(solver.best_objective_bound), self.scale),
                status == 'OPTIMAL')


def _places_chained(problem: Problem, before) -> bool:
    """Whether some job precedes another at another place (`before`: job -> its
    ancestors): else no chain adds a way."""
    return any(problem.job(a).location != job.location
               for job in problem.jobs for a in before[job.name])


def _chained_ways(m, problem: Problem, robot, ticks, picked, before, horizon):
    """The robot's longest chain of ways (module docstring) as a variable of the model: per
    job it may do, the least time its ways up to that job take along some chain of its jobs,
    given that it does that job (`picked`: (robot, job) -> the literals giving it the robot;
    `before`: job -> its ancestors)."""
    r, start = robot.name, robot.start_location
    mine = [job for job in problem.jobs if (r, job.name) in picked]
    longest = m.new_int_var(0, horizon, f'chained_ways_{r}')
    does, up_to = {}, {}
    for job in mine:
        name = job.name
        does[name] = m.new_bool_var(f'does_{name}_{r}')
        m.add(does[name] == sum(picked[r, name]))
        up_to[name] = m.new_int_var(0, horizon, f'ways_to_{name}_{r}')
        if start is not None:
            entry = ticks(least_location_travel(problem, r, start, job.location))
            m.add(up_to[name] >= entry).only_enforce_if(does[name])
        m.add(longest >= up_to[name])
    for job in mine:
        for earlier in sorted(before[job.name] & does.keys()):
            # Ways between jobs at one place are 0; a chain through such a pair is also a
            # pair of jobs at two places, as ancestors are transitive.
            place = problem.job(earlier).location
            if place != job.location:
                way = ticks(least_location_travel(problem, r, place, job.location))
                m.add(up_to[job.name] >= up_to[earlier] + way).only_enforce_if(
                    [does[earlier], does[job.name]])
    return longest


def _route_through(m, problem: Problem, robot, ticks, places, visits):
    """The robot's least travel through the places it visits (`visits`, one literal per
    place), from its start location (from nowhere without one): a circuit over the places
    and a depot, each leg the least way between two places, the way back to the depot free.

    A robot's route visits its places in some order, maybe more than once; each leg is no
    shorter than the least way along the distance table, and with least ways a route that
    skips a place's later visits is no longer, so the shortest path through each visited
    place once bounds it."""
    r, start = robot.name, robot.start_location
    used = m.new_bool_var(f'used_{r}')
    m.add_max_equality(used, visits)
    arcs, cost = [(0, 0, ~used)], []
    for i, (place, visit) in enumerate(zip(places, visits, strict=True), start=1):
        first = m.new_bool_var(f'route_first_{place}_{r}')
        entry = (Fraction(0) if start is None
                 else least_location_travel(problem, r, start, place))
        last = m.new_bool_var(f'route_last_{place}_{r}')
        arcs += [(i, i, ~visit), (0, i, first), (i, 0, last)]
        cost.append(first * ticks(entry))
        for j, other in enumerate(places, start=1):
            if j != i:
                leg = m.new_bool_var(f'route_{place}_{other}_{r}')
                arcs.append((i, j, leg))
                cost.append(leg * ticks(least_location_travel(problem, r, place, other)))
    m.add_circuit(arcs)
    return sum(cost)
