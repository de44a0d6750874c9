"""What every backend starts from and falls back on: the greedy schedule, the caller's hint
once checked, and the run of an exact search from them (`run_from`)."""

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

from fjsp_common.decimals import decimal
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.greedy import (
    GreedyOutOfTimeError,
    GreedyStuckError,
    greedy_schedule,
    quick_schedule,
)

GREEDY_PASSES_SHARE = 0.02
"""Share of the time limit for randomised greedy passes after the first: a better start for
CP-SAT on classic FJSP files, where the first pass is often far above the best known."""


@dataclass(frozen=True)
class Start:
    """The schedules a search starts from, each valid or None."""

    greedy: Schedule | None
    hint: Schedule | None
    notes: tuple[str, ...] = ()

    @property
    def best(self) -> Schedule | None:
        """The shorter of the two: the search's upper bound and its fallback."""
        return self.hint or self.greedy


def find_start(problem: Problem, hint: Schedule | None, began: float, greedy_time: float,
               time_limit: float) -> Start:
    """The greedy schedule (within `greedy_time` seconds of `began`) and the hint, each kept
    only if valid; the hint gives way to a shorter greedy schedule. Without a valid hint, a
    quick greedy pass is waited for when no pass finished in time."""
    notes = ()
    if hint is not None and validate(problem, hint):
        # Repairing a broken hint can cost CP-SAT more than starting from the greedy one.
        hint, notes = None, ('the hint is not a valid schedule of this problem; ignored',)
    try:
        greedy = greedy_schedule(problem, deadline=began + greedy_time,
                                 time_budget=max(0.15, GREEDY_PASSES_SHARE * time_limit))
    except GreedyStuckError:
        greedy = None
    except GreedyOutOfTimeError:
        greedy = None if hint is not None else _quick(problem)
        notes += (f'no greedy schedule within {greedy_time:g} s' + (
            '' if greedy is None else '; a quick pass waited for'),)
    if greedy is not None and validate(problem, greedy):
        # Its makespan would cap the horizon; an invalid one could make CP-SAT miss schedules.
        greedy, notes = None, notes + ('the greedy schedule was invalid; not used',)
    if hint is not None and greedy is not None and greedy.makespan < hint.makespan:
        # The horizon comes from the shorter one, and would cut the longer hint off.
        hint = greedy
    return Start(greedy, hint, notes)


def _quick(problem: Problem) -> Schedule | None:
    """One quick greedy pass, without a deadline: a caller without a valid schedule gets one
    whenever a quick pass finds it, even past a tiny time limit (as `replan.repair` does)."""
    try:
        return quick_schedule(problem)
    except GreedyStuckError:
        return None


def greedy_result(problem: Problem, start: Start, began: float) -> Result:
    """The greedy schedule as a result, bounded by the static bound."""
    elapsed = time.monotonic() - began
    if start.greedy is None:
        return Result(Status.UNKNOWN, None, None, elapsed, None, 'greedy',
                      notes=start.notes or ('greedy scheduling got stuck; try an exact solver',))
    return Result(Status.FEASIBLE, start.greedy.makespan, static_bound(problem), elapsed,
                  start.greedy, 'greedy', first_solution_seconds=elapsed)


def run_from(problem: Problem, start: Start, began: float, time_limit: float,
             search: Callable[[float], Result]) -> Result:
    """`search(seconds left)`, its times counted from `began`; the start's best schedule when
    the search found none. The start's schedule is valid, so a search claiming the problem
    infeasible is wrong (a bound it was given is too high): the schedule is returned, and
    the note says so."""
    setup = time.monotonic() - began
    result = search(max(0.05, time_limit - setup))
    best = start.best
    if result.schedule is None and best is not None:
        elapsed = time.monotonic() - began
        which = 'greedy schedule' if best is start.greedy else 'starting schedule'
        found = ('claimed the problem infeasible, which the starting schedule disproves'
                 if result.status == Status.INFEASIBLE else 'found no schedule')
        return Result(Status.FEASIBLE, best.makespan, static_bound(problem), elapsed,
                      best, 'greedy' if best is start.greedy else 'hint',
                      first_solution_seconds=setup, best_solution_seconds=setup,
                      notes=start.notes + result.notes + (
                          f'{result.solver} {found} in {time_limit:g} s; {which} returned',))
    return _count_from(problem, dataclasses.replace(result, notes=start.notes + result.notes),
                       setup)


def _count_from(problem: Problem, result: Result, setup: float) -> Result:
    """The backend's times counted from the call, and its bound no weaker than the
    static bound (`bounds.fleet.static_bound`), which an early-stopped search may not have
    reached."""
    def shifted(seconds):
        return None if seconds is None else seconds + setup

    bound, status = result.lower_bound, result.status
    if bound is not None:
        path = static_bound(problem)
        bound = min(max(bound, path), result.makespan)
        if path >= result.makespan:
            status = Status.OPTIMAL
    return dataclasses.replace(
        result, status=status, lower_bound=bound, solve_seconds=result.solve_seconds + setup,
        first_solution_seconds=shifted(result.first_solution_seconds),
        best_solution_seconds=shifted(result.best_solution_seconds))


def raised_bound(result: Result, bound: Fraction, why: str) -> Result:
    """The result with its bound raised to `bound` (capped by the makespan), optimal when it
    meets the makespan; unchanged when `bound` proves no more than it already had."""
    raised = min(max(result.lower_bound or 0, bound), result.makespan)
    if raised <= (result.lower_bound or 0):
        return result
    return dataclasses.replace(
        result, lower_bound=raised,
        status=Status.OPTIMAL if raised >= result.makespan else result.status,
        notes=result.notes + (why.format(decimal(raised)),))
