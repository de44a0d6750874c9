"""Problems too large for the CP-SAT routing model: the greedy schedule, then the local
search from it for the rest of the limit (two runs, a core each, given two cores), or
randomised greedy passes when no greedy schedule came in time (docs/solver.md, "Large
problems").

The CP-SAT model has one routing arc per robot and ordered pair of jobs it could do: past
`CPSAT_ROUTING_ARCS` building it alone takes longer than a usual limit and its memory grows
with the square of the jobs. The greedy's memory and time grow with the jobs and the ready
ones among them, so it schedules up to the scenario size limit (docs/scenario-format.md,
"Limits"); the local search's tables grow with the jobs and the places, and a step with the
critical path.
"""

import time

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Status
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.greedy import sampled_schedule
from fjsp_planner.solving.local_process import local_searches
from fjsp_planner.solving.start import Start

CPSAT_ROUTING_ARCS = 400_000
"""Routing arcs (sum over robots of the square of the jobs each could do) up to which the
CP-SAT model is built; beyond, `solve_large` schedules."""


def routing_arcs(problem: Problem) -> int:
    """The routing arcs the CP-SAT model would build (0 when neither travel nor holding
    orders a robot's jobs)."""
    if problem.locomote is None and not problem.holding:
        return 0
    total = 0
    for robot in problem.robots:
        able = sum(any(problem.duration(robot.name, q) is not None
                       for plan in job.plans for q in plan) for job in problem.jobs)
        total += able * able
    return total


def fits_cpsat(problem: Problem) -> bool:
    return routing_arcs(problem) <= CPSAT_ROUTING_ARCS


def solve_large(problem: Problem, start: Start, began: float, time_limit: float,
                workers: int, seed: int = 0) -> Result:
    """The local search from the start until the limit, two runs of it with two or more
    `workers` (without a start, the best of randomised greedy passes), with the static bound
    (`bounds.fleet.static_bound`)."""
    deadline = began + time_limit
    best, solver, notes = start.best, 'greedy', ()
    if best is not None:
        first_at = best_at = time.monotonic() - began
        how = 'the local search from the greedy schedule'
        found, found_at, notes = local_searches(problem, best, deadline, min(2, workers))
        if found is not best:
            best, best_at, solver = found, found_at - began, 'local search'
    else:
        how = 'randomised greedy passes'
        best = sampled_schedule(problem, deadline, seed)
        first_at = best_at = time.monotonic() - began
    elapsed = time.monotonic() - began
    if best is None:
        return Result(Status.UNKNOWN, None, None, elapsed, None, 'greedy',
                      notes=start.notes + ('no greedy pass finished in time',))
    bound = min(static_bound(problem), best.makespan)
    return Result(Status.OPTIMAL if bound >= best.makespan else Status.FEASIBLE,
                  best.makespan, bound, elapsed, best, solver,
                  first_solution_seconds=first_at, best_solution_seconds=best_at,
                  notes=start.notes + notes + (
                      f'{routing_arcs(problem)} routing arcs are more than the CP-SAT model '
                      f'takes ({CPSAT_ROUTING_ARCS}); {how}',))
