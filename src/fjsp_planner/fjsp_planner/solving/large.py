"""Problems too large for the CP-SAT routing model: the greedy schedule, then randomised
greedy passes for the rest of the limit (docs/solver.md, "Large problems").

The CP-SAT model has one routing arc per robot and ordered pair of jobs it could do: past
`CPSAT_ROUTING_ARCS` building it alone takes longer than a usual limit and its memory grows
with the square of the jobs. The greedy's memory and time grow with the jobs and the ready
ones among them, so it schedules up to the scenario size limit (docs/scenario-format.md,
"Limits").
"""

import time

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Status
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.greedy import sampled_schedule
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
                seed: int = 0) -> Result:
    """The best of the start and randomised greedy passes until the limit, with the static
    bound (`bounds.fleet.static_bound`)."""
    best = start.best
    first_at = time.monotonic() - began if best is not None else None
    best_at = first_at
    found = sampled_schedule(problem, began + time_limit, seed)
    if found is not None and (best is None or found.makespan < best.makespan):
        best, best_at = found, time.monotonic() - began
        first_at = first_at if first_at is not None else best_at
    elapsed = time.monotonic() - began
    if best is None:
        return Result(Status.UNKNOWN, None, None, elapsed, None, 'greedy',
                      notes=start.notes + ('no greedy pass finished in time',))
    bound = min(static_bound(problem), best.makespan)
    return Result(Status.OPTIMAL if bound >= best.makespan else Status.FEASIBLE,
                  best.makespan, bound, elapsed, best, 'greedy',
                  first_solution_seconds=first_at, best_solution_seconds=best_at,
                  notes=start.notes + (f'{routing_arcs(problem)} routing arcs are more than '
                                       f'the CP-SAT model takes ({CPSAT_ROUTING_ARCS}); '
                                       'randomised greedy passes',))
