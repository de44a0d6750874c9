"""A lower bound for any scenario from its longest precedence chains, each solved as a
scenario of its own: the "chain" bound (docs/solver.md, "Bounds").

Any schedule, restricted to the jobs of a precedence chain, is a schedule of the smaller
scenario those jobs make: each job still starts no earlier than its head (its robots'
arrival and its predecessors at their fastest, `fleet`) and is still followed by its tail,
and a robot's way from one of its chain jobs to the next, whatever it did in between, is no
shorter than the least distance along the table (`geometry`). So the least makespan of that
scenario with heads and tails bounds the makespan. Unlike the other bounds it sees that a
chain's jobs are slow unless fast robots travel between them: the staffing, the waits for
the robots and their ways are chosen together, by CP-SAT on the full model of the chain.
"""

import dataclasses
import itertools
import math
import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem, ProblemError
from fjsp_planner.solving.bounds.fleet import heads_tails_and_fastest
from fjsp_planner.solving.bounds.geometry import location_distance
from fjsp_planner.solving.cpsat.model import CpsatModel
from fjsp_planner.solving.cpsat.variables import OutOfTimeError

MOST_CHAINS = 24
"""Chains tried at most, longest first (at their fastest, with heads and tails)."""
PAIRED_CHAINS = 5
"""After the chains alone, every two of this many longest are tried together: their robots
and ways are coupled."""
CHAIN_SHARE = 0.34
"""Most of the time limit one chain may take: a chain CP-SAT cannot prove quickly gives
what it proved and the time goes to the next."""


def chain_bound(problem: Problem, time_limit: float, incumbent: Fraction | None = None
                ) -> Fraction | None:
    """The bound of the module docstring over the longest chains CP-SAT solves within
    `time_limit` seconds, or None when it does not apply (running jobs, no precedence) or
    proves nothing. With `incumbent`, a makespan known to be reachable, it never exceeds
    that."""
    if problem.fixed or not problem.precedence:
        return None
    deadline = time.monotonic() + time_limit
    heads, tails, fastest = heads_tails_and_fastest(problem)
    places = problem.locations()
    least = {(a, b): location_distance(problem, a, b) for a in places for b in places
             if a != b}
    best = None
    chains = longest_chains(problem, heads, tails, fastest)
    paired = [tuple(dict.fromkeys(a + b)) for a, b in itertools.combinations(
        chains[:PAIRED_CHAINS], 2)]
    for chain in chains[:MOST_CHAINS] + paired:
        left = deadline - time.monotonic()
        if left <= 0:
            break
        try:
            scenario = _chain_scenario(problem, chain, least)
            # Every job may be held back to its head: the horizon leaves room for the latest.
            model = CpsatModel(scenario, None, deadline, max(heads[j] for j in chain))
        except (ProblemError, OutOfTimeError):
            continue
        if not model.grid.exact:
            # Durations rounded up on a coarse grid could lift the chain above the optimum.
            continue
        found = _solve(model, chain, heads, tails, min(left, CHAIN_SHARE * time_limit))
        if found is not None and (best is None or found > best):
            best = found
    if best is None:
        return None
    return best if incumbent is None else min(best, incumbent)


def longest_chains(problem: Problem, heads, tails, fastest) -> list[tuple[str, ...]]:
    """For every job, the precedence chain through it that grows backwards by the
    predecessor ending latest and forwards by the successor with the longest way to the end
    (at the fastest durations); distinct chains, the longest (head + durations + tail)
    first."""
    before = {job.name: [] for job in problem.jobs}
    after = {job.name: [] for job in problem.jobs}
    for a, b in problem.precedence:
        before[b].append(a)
        after[a].append(b)
    found = set()
    for job in problem.jobs:
        chain = [job.name]
        while before[chain[0]]:
            chain.insert(0, max(before[chain[0]], key=lambda a: (heads[a] + fastest[a], a)))
        while after[chain[-1]]:
            chain.append(max(after[chain[-1]], key=lambda b: (fastest[b] + tails[b], b)))
        found.add(tuple(chain))
    return sorted(found, key=lambda chain: (-(heads[chain[0]] + tails[chain[-1]] + sum(
        fastest[j] for j in chain)), chain))


def _chain_scenario(problem: Problem, chain, least) -> Problem:
    """The chain's jobs alone, their precedence and holding arcs among them, and every
    distance the least along the table."""
    kept = set(chain)
    return dataclasses.replace(
        problem, jobs=tuple(job for job in problem.jobs if job.name in kept),
        precedence=tuple((a, b) for a, b in problem.precedence if a in kept and b in kept),
        holding=tuple(arc for arc in problem.holding if arc[0] in kept and arc[1] in kept),
        distances=least, panels=())


def _solve(model, chain, heads, tails, time_limit) -> Fraction | None:
    """The least makespan of the chain's model with heads and tails that CP-SAT proves."""
    m, grid, jobs = model.model, model.grid, model.jobs
    horizon = model.horizon + grid.floor(max(tails[j] for j in chain))
    makespan = m.new_int_var(0, horizon, 'makespan_with_tails')
    m.add(makespan >= model.makespan)
    for name in chain:
        m.add(jobs.start[name] >= grid.floor(heads[name]))
        m.add(makespan >= jobs.end[name] + grid.floor(tails[name]))
    m.minimize(makespan)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(0.01, time_limit)
    solver.parameters.num_workers = 1
    solver.parameters.catch_sigint_signal = False
    solver.parameters.cp_model_probing_level = 0
    status = solver.solve(m).name
    if status not in ('OPTIMAL', 'FEASIBLE', 'UNKNOWN') or not math.isfinite(
            solver.best_objective_bound):
        return None
    return Fraction(math.ceil(solver.best_objective_bound), grid.scale)
