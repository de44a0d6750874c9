"""Several identical panels: CP-SAT beside the panel bounds and a start stitched from
one-panel optima (docs/solver.md, "Several panels").

Before the search: the start stitched from one-panel optima (`panels.stitched_schedule`),
the panel machine and panel load bounds; beside it, the panel sequence bound in a thread of
its own; after it, the panel energy and clique bounds at the makespan found. Every bound
holds for schedules shorter than the start, so the least of it and the makespan holds for
all."""

import threading
import time
from dataclasses import replace
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result
from fjsp_planner.solving.beside import Beside
from fjsp_planner.solving.bounds import panel as bounds
from fjsp_planner.solving.bounds.load import panel_load_bound
from fjsp_planner.solving.bounds.machine import EVERY_JOB_LIMIT, panel_machine_bound
from fjsp_planner.solving.bounds.sequence import MAX_PANELS as SEQUENCE_PANELS
from fjsp_planner.solving.bounds.sequence import panel_sequence_bound
from fjsp_planner.solving.cpsat import SearchHandle, solve_cpsat
from fjsp_planner.solving.panels import stitched_schedule
from fjsp_planner.solving.start import Start, raised_bound, run_from

PANEL_SHARE = 0.1
"""Share of the time limit spent on one-panel problems: the start stitched from their
optima and the bound of one panel done without the robots that cannot move between panels
(`bounds.unhelped_panel`)."""
MACHINE_SHARE = 0.1
"""Share of the time limit for the panel machine bound when it keeps every job (up to
`machine.EVERY_JOB_LIMIT`), half of it when it does not and the panel sequence bound (which
runs beside it and the search) does not apply."""
LOAD_SHARE = 0.05
"""Share of the time limit for the panel load bound, which proves the loads alone within
seconds, then counts waits for the rest."""
MIN_PANEL_SECONDS = 0.5
"""Below this the one-panel solves' own overhead outweighs their share."""


def applies(problem: Problem) -> bool:
    """Two panels or more and no running job: the premise of every panel bound."""
    return len(problem.panels) >= 2 and not problem.fixed


def solve_panels(problem: Problem, start: Start, began: float, time_limit: float,
                 workers: int, keep, log: bool) -> Result:
    """CP-SAT from the best start, with the panel bounds of the module docstring."""
    if start.greedy is None or PANEL_SHARE * time_limit < MIN_PANEL_SECONDS:
        result = run_from(problem, start, began, time_limit, lambda left: solve_cpsat(
            problem, left, workers, hint=start.hint, keep=keep, upper_bound=start.best,
            log=log))
        return with_panel_bounds(problem, result, None)
    stitched, panel_bound = stitched_schedule(problem, start.greedy.makespan,
                                              PANEL_SHARE * time_limit, workers)
    if stitched is not None and stitched.makespan < start.best.makespan:
        start = replace(start, hint=stitched, notes=start.notes + (
            'started from panels stitched from one-panel optima',))
    incumbent = start.best.makespan
    handle = SearchHandle()
    sequence = _SequenceBeside(problem, incumbent, began + time_limit, handle)
    share = MACHINE_SHARE * time_limit
    if len(problem.jobs) > EVERY_JOB_LIMIT:
        # The sequence bound, where it applies, proves more than the machine bound.
        share = share / 2 if len(problem.panels) > SEQUENCE_PANELS else 0
    machine = (panel_machine_bound(problem, incumbent, share, workers)
               if share >= MIN_PANEL_SECONDS else None)
    load = panel_load_bound(problem, incumbent, LOAD_SHARE * time_limit, workers)
    panel_bound = max((b for b in (panel_bound, machine, load) if b is not None), default=None)
    try:
        result = run_from(problem, start, began, time_limit, lambda left: solve_cpsat(
            problem, left, workers, hint=start.hint, keep=keep, upper_bound=start.best,
            log=log, handle=handle))
    finally:
        found = sequence.result()
    if found is not None:
        panel_bound = max(found, panel_bound or found)
    return with_panel_bounds(problem, result, panel_bound)


def with_panel_bounds(problem: Problem, result: Result, found_before: Fraction | None
                      ) -> Result:
    """The result with its bound raised by the panel energy and clique bounds at its
    makespan; `found_before` is the best of the one-panel, panel sequence, machine and load
    bounds found before the search, if any (they hold for schedules shorter than the
    search's start, hence for all with the minimum taken)."""
    if result.schedule is None:
        return result
    best = result.makespan
    found = [b for b in (bounds.panel_energy_bound(problem, best),
                         bounds.panel_clique_bound(problem, best), found_before)
             if b is not None]
    if not found:
        return result
    return raised_bound(result, max(found), 'bound raised to {} by panel decomposition')


class _SequenceBeside:
    """The panel sequence bound in a thread of its own, beside the search, from the start's
    makespan `incumbent` (then each shorter one `handle` reports) until `deadline` or until
    its result is asked for. Its search is pure Python and shares the cores with CP-SAT."""

    def __init__(self, problem, incumbent, deadline, handle):
        self._stop = threading.Event()
        self._thread = Beside('sequence-bound', lambda: panel_sequence_bound(
            problem, incumbent, max(0.0, deadline - time.monotonic()), self._stop,
            lambda: handle.best))

    def result(self) -> Fraction | None:
        """Stop the search and return its bound (None where it does not apply)."""
        self._stop.set()
        return self._thread.result()
