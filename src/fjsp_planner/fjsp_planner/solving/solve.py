"""One entry point for every backend, returning the solver-neutral `Result`."""

import dataclasses
import threading
import time
from fractions import Fraction

from fjsp_common.decimals import decimal
from fjsp_planner.model.limits import MAX_WORKERS
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving import tabu
from fjsp_planner.solving.bounds import panel as bounds
from fjsp_planner.solving.bounds.load import panel_load_bound
from fjsp_planner.solving.bounds.machine import EVERY_JOB_LIMIT, panel_machine_bound
from fjsp_planner.solving.bounds.panel import critical_path_bound
from fjsp_planner.solving.bounds.sequence import MAX_PANELS as SEQUENCE_PANELS
from fjsp_planner.solving.bounds.sequence import panel_sequence_bound
from fjsp_planner.solving.cpsat import SearchHandle, solve_cpsat
from fjsp_planner.solving.greedy import (
    GreedyOutOfTimeError,
    GreedyStuckError,
    greedy_schedule,
)
from fjsp_planner.solving.panels import stitched_schedule

SOLVERS = ('cpsat', 'greedy', 'mip')
GREEDY_SHARE = 0.4
"""Share of the time limit the greedy schedule may take before the exact solver starts."""
GREEDY_PASSES_SHARE = 0.02
"""Share of the time limit for randomised greedy passes after the first: a better start for
CP-SAT on classic FJSP files (where the first pass is often 20-30 % above the best known)."""
PANEL_SHARE = 0.1
"""Share of the time limit spent, on several identical panels, on one-panel problems: the
start stitched from their optima (`panels.stitched_schedule`) and the bound of one panel done
without the robots that cannot move between panels (`bounds.unhelped_panel`)."""
MACHINE_SHARE = 0.1
"""Share of the time limit for the panel machine bound (`machine_bound`) when it keeps every
job (up to `machine_bound.EVERY_JOB_LIMIT`: on 2 panels of the paper it is solved to its
optimum, 91 1/3, in about 3 s), half of it when it does not and the panel sequence bound
(`sequence_bound`, which runs beside it and the search) does not apply."""
LOAD_SHARE = 0.05
"""Share of the time limit for the panel load bound (`load_bound`): it proves the loads alone
on 2 to 10 panels of the paper in 0.1-2 s (2 workers), then counts waits for the rest."""
MIN_PANEL_SECONDS = 0.5
"""Below this the one-panel solves' own overhead outweighs their share."""
HANDOFF_SHARE = 0.5
"""Classic FJSP: when CP-SAT restarts from the tabu search's best schedule, if it is behind."""


def solve(problem: Problem, solver: str = 'cpsat', time_limit: float = 10.0, workers: int = 2,
          hint: Schedule | None = None, keep: Schedule | None = None,
          mip_backend: str = 'SCIP', log: bool = False) -> Result:
    """Minimise the makespan of `problem`.

    `hint` warm-starts the search if it is a valid schedule of `problem`; `keep` (CP-SAT
    only) then prefers, among schedules of the proven best makespan, those that change the
    fewest of its (job, robot) assignments. The greedy schedule bounds the horizon and is
    returned when an exact solver finds nothing in time.

    The whole call (greedy, model building, solving, keeping assignments) takes at most
    `time_limit` seconds, plus the solver's reaction time to its own limit (milliseconds),
    for problems up to the size limit of the scenario checks (about 1000 jobs). `workers`
    must lie in 1..MAX_WORKERS.
    """
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver '{solver}'; choose one of {', '.join(SOLVERS)}")
    if isinstance(workers, bool) or not isinstance(workers, int) or not (
            1 <= workers <= MAX_WORKERS):
        raise ValueError(f'workers must be an integer from 1 to {MAX_WORKERS}, got {workers!r}')
    if not time_limit > 0:
        raise ValueError(f'time_limit must be a positive number of seconds, got {time_limit!r}')
    began = time.monotonic()
    notes = ()
    if hint is not None and validate(problem, hint):
        # Repairing a broken hint can cost CP-SAT more than starting from the greedy one.
        hint, notes = None, ('the hint is not a valid schedule of this problem; ignored',)
    greedy_time = time_limit if solver == 'greedy' else GREEDY_SHARE * time_limit
    try:
        greedy = greedy_schedule(problem, deadline=began + greedy_time,
                                 time_budget=max(0.15, GREEDY_PASSES_SHARE * time_limit))
    except GreedyStuckError:
        greedy = None
    except GreedyOutOfTimeError:
        greedy, notes = None, notes + (f'no greedy schedule within {greedy_time:g} s',)
    if greedy is not None and validate(problem, greedy):
        # Its makespan would cap the horizon; an invalid one could make CP-SAT miss schedules.
        greedy, notes = None, notes + ('the greedy schedule was invalid; not used',)
    if hint is not None and greedy is not None and greedy.makespan < hint.makespan:
        # The horizon comes from the shorter one, and would cut the longer hint off.
        hint = greedy
    if solver == 'greedy':
        if greedy is None:
            return Result(Status.UNKNOWN, None, None, time.monotonic() - began, None, 'greedy',
                          notes=notes or ('greedy scheduling got stuck; try an exact solver',))
        elapsed = time.monotonic() - began
        return Result(Status.FEASIBLE, greedy.makespan, critical_path_bound(problem), elapsed,
                      greedy, 'greedy', first_solution_seconds=elapsed)
    panel_bound = sequence = handle = None
    if solver == 'cpsat' and greedy is not None and len(problem.panels) >= 2 and (
            not problem.fixed) and PANEL_SHARE * time_limit >= MIN_PANEL_SECONDS:
        stitched, panel_bound = stitched_schedule(problem, greedy.makespan,
                                                  PANEL_SHARE * time_limit, workers)
        if stitched is not None and stitched.makespan < (hint or greedy).makespan:
            hint, notes = stitched, notes + ('started from panels stitched from one-panel '
                                             'optima',)
        incumbent = (hint or greedy).makespan
        handle = SearchHandle()
        sequence = _SequenceBeside(problem, incumbent, began + time_limit, handle)
        share = MACHINE_SHARE * time_limit
        if len(problem.jobs) > EVERY_JOB_LIMIT:
            # The sequence bound, where it applies, proves more (3 panels: 146 1/3 to 126).
            share = share / 2 if len(problem.panels) > SEQUENCE_PANELS else 0
        machine = (panel_machine_bound(problem, incumbent, share, workers)
                   if share >= MIN_PANEL_SECONDS else None)
        load = panel_load_bound(problem, incumbent, LOAD_SHARE * time_limit, workers)
        panel_bound = max((b for b in (panel_bound, machine, load) if b is not None),
                          default=None)
    try:
        if solver == 'cpsat' and hint is None and keep is None and greedy is not None and (
                tabu.applies(problem)):
            return _classic(problem, greedy, began, time_limit, workers, notes, log)
        setup = time.monotonic() - began
        remaining = max(0.05, time_limit - setup)
        if solver == 'mip':
            from fjsp_planner.solving.mip import solve_mip

            result = solve_mip(problem, remaining, backend=mip_backend, workers=workers,
                               hint=hint or greedy, log=log)
        else:
            result = solve_cpsat(problem, remaining, workers, hint=hint, keep=keep,
                                 upper_bound=hint or greedy, log=log, handle=handle)
    finally:
        found = sequence.result() if sequence is not None else None
    if found is not None:
        panel_bound = max(found, panel_bound or found)
    start = hint or greedy
    if result.schedule is None and start is not None and result.status != Status.INFEASIBLE:
        # The start is the shorter of the (valid) hint and the greedy schedule.
        elapsed = time.monotonic() - began
        which = 'greedy schedule' if start is greedy else 'starting schedule'
        result = Result(Status.FEASIBLE, start.makespan, critical_path_bound(problem), elapsed,
                        start, 'greedy' if start is greedy else 'hint',
                        first_solution_seconds=setup, best_solution_seconds=setup,
                        notes=notes + result.notes + (f'{result.solver} found no schedule in '
                                                      f'{time_limit:g} s; {which} returned',))
    else:
        result = _count_from(problem, dataclasses.replace(result, notes=notes + result.notes),
                             setup)
    if result.schedule is not None and len(problem.panels) >= 2 and not problem.fixed:
        result = _with_panel_bounds(problem, result, panel_bound)
    return result


def _classic(problem: Problem, greedy: Schedule, began: float, time_limit: float, workers: int,
             notes: tuple, log: bool) -> Result:
    """Single-robot jobs without travel: CP-SAT and the tabu search side by side, from the
    greedy schedule. CP-SAT proves small instances at once (the search then stops); on larger
    ones the search usually finds the better schedules, so at HANDOFF_SHARE of the limit a
    CP-SAT behind it starts again from the search's best, for the bound and the last steps,
    while the search goes on. The shorter schedule wins; the bound is the best either CP-SAT
    run proved."""
    deadline = began + time_limit
    greedy_seconds = time.monotonic() - began
    runs = [_Background(problem, deadline, workers, greedy, None, log)]
    best, best_at = tabu.tabu_search(problem, greedy, began + HANDOFF_SHARE * time_limit,
                                     stop=runs[0].done)
    handle, resume = runs[0].handle, best
    if not runs[0].done() and best.makespan < (handle.best or greedy.makespan) and (
            not validate(problem, best)):
        handle.stop()
        runs.append(_Background(problem, deadline, workers, best, best, log))
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
    bound = min(max(bound, critical_path_bound(problem)), best.makespan)
    if any(r.status == Status.INFEASIBLE for r in results):
        raise RuntimeError('CP-SAT found a problem infeasible that has a valid schedule')
    return Result(Status.OPTIMAL if bound >= best.makespan else Status.FEASIBLE,
                  best.makespan, bound, time.monotonic() - began, best, solver,
                  first_solution_seconds=greedy_seconds, best_solution_seconds=best_at - began,
                  notes=notes + results[-1].notes)


class _Thread:
    """`work()` in a daemon thread of its own; `result()` waits for it and returns its value
    or re-raises its error in the caller's thread."""

    def __init__(self, name, work):
        self._outcome = {}

        def run():
            try:
                self._outcome['value'] = work()
            except BaseException as error:  # re-raised in the caller's thread
                self._outcome['error'] = error

        self._thread = threading.Thread(target=run, name=name, daemon=True)
        self._thread.start()

    def done(self) -> bool:
        return not self._thread.is_alive()

    def result(self):
        self._thread.join()
        if 'error' in self._outcome:
            raise self._outcome['error']
        return self._outcome['value']


class _SequenceBeside:
    """The panel sequence bound (`sequence_bound`) in a thread of its own, beside the
    search, from the start's makespan `incumbent` (then each shorter one `handle` reports)
    until `deadline` or until its result is asked for. Its search is pure Python: on 5
    panels it runs for most of the limit on about a third of 2 cores, where before the
    search it had a tenth of the limit to itself."""

    def __init__(self, problem, incumbent, deadline, handle):
        self._stop = threading.Event()
        self._thread = _Thread('sequence-bound', lambda: panel_sequence_bound(
            problem, incumbent, max(0.0, deadline - time.monotonic()), self._stop,
            lambda: handle.best))

    def result(self) -> Fraction | None:
        """Stop the search and return its bound (None where it does not apply)."""
        self._stop.set()
        return self._thread.result()


class _Background(_Thread):
    """`solve_cpsat` in a thread of its own until `deadline`, followed by a `SearchHandle`."""

    def __init__(self, problem, deadline, workers, upper_bound, hint, log):
        self.handle = SearchHandle()
        self.started = time.monotonic()
        super().__init__('cpsat', lambda: solve_cpsat(
            problem, max(0.05, deadline - time.monotonic()), workers, hint=hint,
            upper_bound=upper_bound, log=log, handle=self.handle))


def _with_panel_bounds(problem: Problem, result: Result, found_before: Fraction | None
                       ) -> Result:
    """The result with its bound raised by the panel decomposition bounds (bounds.py);
    `found_before` is the best of the one-panel, panel sequence, machine and load bounds found
    before the search, if any (they hold for schedules shorter than the search's start, hence
    for all with the minimum taken below)."""
    best = result.makespan
    found = [b for b in (bounds.panel_energy_bound(problem, best),
                         bounds.panel_clique_bound(problem, best), found_before)
             if b is not None]
    if not found:
        return result
    raised = min(max(result.lower_bound or 0, *found), best)
    if raised <= (result.lower_bound or 0):
        return result
    return dataclasses.replace(
        result, lower_bound=raised,
        status=Status.OPTIMAL if raised >= best else result.status,
        notes=result.notes + (f'bound raised to {decimal(raised)} by panel decomposition',))


def _count_from(problem: Problem, result: Result, setup: float) -> Result:
    """The backend's times counted from the call, and its bound no weaker than the
    critical path (an early-stopped search may not have reached even that)."""
    def shifted(seconds):
        return None if seconds is None else seconds + setup

    bound, status = result.lower_bound, result.status
    if bound is not None:
        path = critical_path_bound(problem)
        bound = min(max(bound, path), result.makespan)
        if path >= result.makespan:
            status = Status.OPTIMAL
    return dataclasses.replace(
        result, status=status, lower_bound=bound, solve_seconds=result.solve_seconds + setup,
        first_solution_seconds=shifted(result.first_solution_seconds),
        best_solution_seconds=shifted(result.best_solution_seconds))
