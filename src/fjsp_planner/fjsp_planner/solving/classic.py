"""The classic flexible job shop (single-robot jobs, no travel): CP-SAT and the tabu search
side by side, from the greedy schedule (docs/solver.md, "Classic FJSP")."""

import time
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving import tabu
from fjsp_planner.solving.beside import CpsatBeside
from fjsp_planner.solving.bounds.jobs import critical_path_bound

HANDOFF_SHARE = 0.5
"""Share of the time limit after which CP-SAT, if behind, restarts from the tabu search's
best schedule."""


def solve_classic(problem: Problem, greedy: Schedule, began: float, time_limit: float,
                  workers: int, notes: tuple, log: bool) -> Result:
    """For problems `tabu.applies` to. CP-SAT proves small instances at once (the search
    then stops); on larger ones the search usually finds the better schedules, so at
    HANDOFF_SHARE of the limit a CP-SAT behind it starts again from the search's best, for
    the bound and the last steps, while the search goes on. The shorter schedule wins; the
    bound is the best either CP-SAT run proved."""
    deadline = began + time_limit
    greedy_seconds = time.monotonic() - began
    runs = [CpsatBeside(problem, deadline, workers, greedy, None, log)]
    best, best_at = tabu.tabu_search(problem, greedy, began + HANDOFF_SHARE * time_limit,
                                     stop=runs[0].done)
    handle, resume = runs[0].handle, best
    if not runs[0].done() and best.makespan < (handle.best or greedy.makespan) and (
            not validate(problem, best)):
        handle.stop()
        runs.append(CpsatBeside(problem, deadline, workers, best, best, log))
    elif handle.schedule is not None and handle.schedule.makespan < best.makespan and (
            not validate(problem, handle.schedule)):
        resume = handle.schedule
    found, found_at = tabu.tabu_search(problem, resume, deadline, seed=1, stop=runs[-1].done)
    if found.makespan < best.makespan:
        best, best_at = found, found_at
    results = [run.result() for run in runs]
    if validate(problem, best):
        best, best_at = greedy, began + greedy_seconds
    solver = 'greedy' if best is greedy else 'tabu'
    for run, result in zip(runs, results, strict=True):
        if result.schedule is not None and result.makespan < best.makespan:
            best, solver = result.schedule, 'cpsat'
            best_at = run.started + (result.best_solution_seconds or result.solve_seconds)
    bound = max((r.lower_bound for r in results if r.lower_bound is not None),
                default=Fraction(0))
    # The fleet bounds see no more than CP-SAT here and would take their time from the search.
    bound = min(max(bound, critical_path_bound(problem)), best.makespan)
    if any(r.status == Status.INFEASIBLE for r in results):
        raise RuntimeError('CP-SAT found a problem infeasible that has a valid schedule')
    return Result(Status.OPTIMAL if bound >= best.makespan else Status.FEASIBLE,
                  best.makespan, bound, time.monotonic() - began, best, solver,
                  first_solution_seconds=greedy_seconds, best_solution_seconds=best_at - began,
                  notes=notes + results[-1].notes)
