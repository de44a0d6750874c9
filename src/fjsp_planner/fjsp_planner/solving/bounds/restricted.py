"""Lower bounds from sets of jobs, each solved as a scenario of its own (docs/solver.md,
"Chains and operation sets").

Any schedule, restricted to a set of its jobs, is a schedule of the smaller scenario those
jobs make, in which each job starts no earlier than its head (its robots' arrival and its
predecessors at their fastest, `fleet`) and is followed by its tail, and in which a robot's
way from one of the set's jobs to the next, whatever it did in between, is no shorter than
the least distance along the table (`geometry`). Precedence and holding arcs to jobs outside
the set only constrain the schedule further. So the least makespan of that scenario with
heads and tails, which CP-SAT proves on the full model, bounds the makespan. `chains` and
`operations` choose the sets.
"""

import dataclasses
import math
import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem, ProblemError
from fjsp_planner.solving.bounds.fleet import heads_tails_and_fastest
from fjsp_planner.solving.bounds.geometry import location_distance
from fjsp_planner.solving.cpsat.model import CpsatModel
from fjsp_planner.solving.cpsat.variables import OutOfTimeError

SET_SHARE = 0.34
"""Most of the time limit one set may take: a set CP-SAT cannot prove quickly gives what it
proved and the time goes to the next."""


def restricted_bound(problem: Problem, job_sets, time_limit: float,
                     incumbent: Fraction | None = None) -> Fraction | None:
    """The best bound of the module docstring over the sets `job_sets(heads, tails,
    fastest)` yields (each a tuple of job names), in that order, within `time_limit`
    seconds; None when none is proven (or the problem has running jobs). With `incumbent`,
    a makespan known to be reachable, it never exceeds that."""
    if problem.fixed:
        return None
    deadline = time.monotonic() + time_limit
    heads, tails, fastest = heads_tails_and_fastest(problem)
    places = problem.locations()
    least = {(a, b): location_distance(problem, a, b) for a in places for b in places
             if a != b}
    best = None
    for kept in job_sets(heads, tails, fastest):
        left = deadline - time.monotonic()
        if left <= 0:
            break
        try:
            scenario = _restricted_scenario(problem, kept, least)
            # Every job may be held back to its head: the horizon leaves room for the latest.
            model = CpsatModel(scenario, None, deadline, max(heads[j] for j in kept),
                               pairwise_travel=True)
        except (ProblemError, OutOfTimeError):
            continue
        if not model.grid.exact:
            # Durations rounded up on a coarse grid could lift the set above the optimum.
            continue
        found = _solve(model, kept, heads, tails, min(left, SET_SHARE * time_limit))
        if found is not None and (best is None or found > best):
            best = found
    if best is None:
        return None
    return best if incumbent is None else min(best, incumbent)


def _restricted_scenario(problem: Problem, kept, least) -> Problem:
    """The set's jobs alone, their precedence and holding arcs among them, and every
    distance the least along the table."""
    kept = set(kept)
    return dataclasses.replace(
        problem, jobs=tuple(job for job in problem.jobs if job.name in kept),
        precedence=tuple((a, b) for a, b in problem.precedence if a in kept and b in kept),
        holding=tuple(arc for arc in problem.holding if arc[0] in kept and arc[1] in kept),
        distances=least, panels=())


def _solve(model, kept, heads, tails, time_limit) -> Fraction | None:
    """The least makespan of the set's model with heads and tails that CP-SAT proves."""
    m, grid, jobs = model.model, model.grid, model.jobs
    horizon = model.horizon + grid.floor(max(tails[j] for j in kept))
    makespan = m.new_int_var(0, horizon, 'makespan_with_tails')
    m.add(makespan >= model.makespan)
    for name in kept:
        m.add(jobs.start[name] >= grid.floor(heads[name]))
        m.add(makespan >= jobs.end[name] + grid.floor(tails[name]))
    m.minimize(makespan)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(0.01, time_limit)
    solver.parameters.num_workers = 1
    solver.parameters.catch_sigint_signal = False
    solver.parameters.cp_model_probing_level = 0
    # As on small scenarios (`cpsat.search`), the linear relaxation stays near the critical
    # path whatever it cuts: without it, and with the travel between every two jobs of a
    # robot, sets of 8-15 generated jobs are proven 5-40 times sooner.
    solver.parameters.linearization_level = 0
    status = solver.solve(m).name
    if status not in ('OPTIMAL', 'FEASIBLE', 'UNKNOWN') or not math.isfinite(
            solver.best_objective_bound):
        return None
    return Fraction(math.ceil(solver.best_objective_bound), grid.scale)
