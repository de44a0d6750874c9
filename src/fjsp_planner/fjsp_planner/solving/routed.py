"""Multi-robot jobs with travel, beyond the sizes CP-SAT proves at once: CP-SAT or the local
search, from the start (docs/solver.md, "Local search").

Up to MAX_PAIRWISE_JOBS jobs CP-SAT runs with every core, in a thread of its own, from the
start's schedule, without its linear relaxation and with the travel between every two jobs
of a robot, which prove such scenarios sooner: its schedules win there. Beyond, the local
search (`local`) finds the schedules: two runs of it from the start, the second in a process
of its own (`local_process`), get a core each, and CP-SAT whatever cores are left, if any.
Meanwhile the fleet load, operation set and chain bounds (`bounds.assignment`,
`bounds.operations`, `bounds.chains`) run one after the other in a thread of their own, each
briefly (the first for a fixed amount of CP-SAT's work, the others for a share of the
limit). The shortest schedule wins; the bound is the best of CP-SAT's, the static bound and
those three.
"""

import time
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Status
from fjsp_planner.solving.beside import Beside, CpsatBeside
from fjsp_planner.solving.bounds.assignment import fleet_load_bound
from fjsp_planner.solving.bounds.chains import chain_bound
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.bounds.operations import operation_bound
from fjsp_planner.solving.local_process import local_searches
from fjsp_planner.solving.start import Start

MIN_JOBS = 25
"""Up to this many jobs CP-SAT usually proves the optimum in seconds with both cores."""
MAX_PAIRWISE_JOBS = 40
"""Up to this many jobs CP-SAT goes without its linear relaxation and with the travel between
every two jobs of a robot, which is quadratic in the jobs, and no local search runs beside
it."""
LOAD_BOUND_SHARE = 0.05
"""Share of the time limit for the fleet load bound when it runs before CP-SAT (small
scenarios, `solve`)."""
LOAD_BOUND_WORK = 0.3
"""Deterministic time (CP-SAT's measure of work, about seconds of one core) for the fleet
load bound beside the search: it comes within a few % of its optimum in that on 30-120
jobs, and beside a search on a busy machine a share of wall time may give it little of a
core."""
LOAD_BOUND_MOST_SHARE = 0.15
"""Share of the time limit the fleet load bound may take beside the search at most."""
CHAIN_BOUND_SHARE = 0.1
"""Share of the time limit for the chain bound, after the fleet load bound, beside the
search."""
OPERATION_BOUND_SHARE = 0.15
"""Share of the time limit for the operation set bound, after the chain bound, beside the
search."""


def applies(problem: Problem, start: Start, keep) -> bool:
    """Routed problems (travel or holding) of more than MIN_JOBS jobs with a start, and no
    assignments to keep (the local search does not weigh them)."""
    routed = problem.locomote is not None or bool(problem.holding)
    return (routed and keep is None and start.best is not None
            and len(problem.jobs) > MIN_JOBS)


def search_free_bound(problem: Problem, time_limit: float,
                      incumbent: Fraction | None = None) -> Fraction | None:
    """The best of the fleet load, chain and operation set bounds, one after the other on
    one core: the first until it has done `LOAD_BOUND_WORK`, then with chained ways for the
    rest of its most share of `time_limit`, the others in their shares; None when none
    applies."""
    found = [bound for bound in (
        fleet_load_bound(problem, LOAD_BOUND_MOST_SHARE * time_limit, incumbent=incumbent,
                         work=LOAD_BOUND_WORK, chains=True),
        operation_bound(problem, OPERATION_BOUND_SHARE * time_limit, incumbent=incumbent),
        chain_bound(problem, CHAIN_BOUND_SHARE * time_limit, incumbent=incumbent))
        if bound is not None]
    return max(found, default=None)


def solve_routed(problem: Problem, start: Start, began: float, time_limit: float,
                 workers: int, log: bool) -> Result:
    deadline = began + time_limit
    first = start.best
    setup = time.monotonic() - began
    small = len(problem.jobs) <= MAX_PAIRWISE_JOBS
    # Above MAX_PAIRWISE_JOBS the local search finds the schedules: two runs of it get a core
    # each, CP-SAT whatever cores are left.
    searches = 1 if small else min(2, workers)
    search = (CpsatBeside(problem, deadline, workers if small else workers - searches, first,
                          start.hint or first, log, relaxation=not small,
                          pairwise_travel=small)
              if small or workers > searches else None)
    load = Beside('fleet load and chain bounds', lambda: search_free_bound(
        problem, time_limit, first.makespan))
    if small:
        best, best_at, notes = first, time.monotonic(), ()
    else:
        best, best_at, notes = local_searches(problem, first, deadline, searches,
                                              stop=None if search is None else search.done)
    solver = 'local search' if best is not first else 'greedy'
    notes = start.notes + notes
    bound = max(static_bound(problem), load.result() or 0)
    if search is not None:
        result = search.result()
        notes += result.notes
        # The first schedule is valid: CP-SAT claiming infeasibility was given a bound too
        # high.
        if result.status == Status.INFEASIBLE:
            notes += ('CP-SAT claimed the problem infeasible, which the first schedule '
                      'disproves',)
        if result.schedule is not None and result.makespan < best.makespan:
            best, solver = result.schedule, 'cpsat'
            best_at = search.started + (result.best_solution_seconds or result.solve_seconds)
        bound = max(bound, result.lower_bound or 0)
    bound = min(bound, best.makespan)
    return Result(Status.OPTIMAL if bound >= best.makespan else Status.FEASIBLE,
                  best.makespan, bound, time.monotonic() - began, best, solver,
                  first_solution_seconds=setup, best_solution_seconds=max(best_at - began,
                                                                          setup),
                  notes=notes)
