"""Running CP-SAT on the model: parameters, time accounting, and the keep-assignments phase."""

import threading
import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.solving.cpsat import objective
from fjsp_planner.solving.cpsat.grid import objective_ticks
from fjsp_planner.solving.cpsat.model import CpsatModel
from fjsp_planner.solving.cpsat.variables import OutOfTimeError

KEEP_SHARE = 0.3
"""At most this share of the time limit goes, once the makespan is proven, to keeping
previous assignments; an unproven makespan gets the whole limit."""
MIN_SOLVE_SECONDS = 0.01
SEARCH_WITHOUT_RELAXATION = 'no_lp'
"""CP-SAT's full search without its linear relaxation (`solve_cpsat(relaxation=False)`)."""


class SearchHandle:
    """Follows a `solve_cpsat` running in another thread and stops it on request."""

    def __init__(self):
        self._lock = threading.Lock()
        self._solver = None
        self._stopped = False
        self.best = None
        """The makespan of the best schedule found so far, in schedule units."""
        self.schedule = None
        """The best schedule found so far (read back from every new solution)."""

    def stop(self):
        with self._lock:
            self._stopped = True
            if self._solver is not None:
                self._solver.stop_search()

    def attach(self, solver) -> bool:
        """Called once the solver is about to search; False if it was stopped already."""
        with self._lock:
            self._solver = solver
            return not self._stopped


def solve_cpsat(problem: Problem, time_limit=10.0, workers=2, hint: Schedule | None = None,
                keep: Schedule | None = None, upper_bound: Schedule | None = None,
                log=False, handle: SearchHandle | None = None,
                lower_bound: Fraction | None = None, relaxation: bool = True,
                pairwise_travel: bool = False) -> Result:
    """Minimise the makespan; with `keep`, then prefer `keep`'s (job, robot) assignments.

    `upper_bound` is a valid schedule (e.g. greedy) that sets the horizon and, on models with
    routes, is hinted unless `hint` is given. `lower_bound`, a bound proven elsewhere, lets
    the search stop as soon as it reaches it. The whole call, model building
    included, ends within `time_limit` seconds (plus CP-SAT's reaction time to its limit).
    `handle` lets another thread see the best makespan so far and stop the search early.
    Without `relaxation`, CP-SAT's full search (with at most two workers, its only one)
    leaves out the linear relaxation; `pairwise_travel` adds the travel between every two
    jobs of a robot to the model (`CpsatModel`).
    """
    began = time.monotonic()
    deadline = began + time_limit
    try:
        model = CpsatModel(problem, upper_bound, deadline, pairwise_travel=pairwise_travel)
        # Without routes (classic FJSP) CP-SAT finds better schedules from scratch than from
        # the greedy one, which then only sets the horizon.
        start = hint if hint is not None or not model.routes.routed else upper_bound
        if start is not None:
            model.add_hint(start, deadline)
    except OutOfTimeError:
        return Result(Status.UNKNOWN, None, None, time.monotonic() - began, None, 'cpsat',
                      notes=(f'building the CP-SAT model took the whole {time_limit:g} s',))
    if lower_bound is not None:
        model.model.add(model.makespan >= model.grid.floor(lower_bound))
    model.minimize_makespan()
    setup = time.monotonic() - began
    solver, recorder, status = run(model.model, deadline - time.monotonic(), workers, log,
                                   handle=handle, scale=model.grid.scale, reader=model.read,
                                   relaxation=relaxation)
    if status == 'INFEASIBLE':
        return Result(Status.INFEASIBLE, None, None, time.monotonic() - began, None, 'cpsat',
                      notes=model.notes)
    if status not in ('OPTIMAL', 'FEASIBLE'):
        if status == 'MODEL_INVALID':
            raise RuntimeError(f'CP-SAT rejected the model: {model.model.validate()}')
        return Result(Status.UNKNOWN, None, None, time.monotonic() - began, None, 'cpsat',
                      notes=model.notes)
    best = solver.value(model.makespan)
    bound = Fraction(objective_ticks(solver.best_objective_bound), model.grid.scale)
    schedule = model.read(solver)
    if keep is not None and status == 'OPTIMAL':
        keep_time = min(time_limit * KEEP_SHARE, deadline - time.monotonic())
        if keep_time > MIN_SOLVE_SECONDS:
            schedule = _keep_assignments(model, solver, best, keep, keep_time, workers,
                                         log) or schedule
    makespan = schedule.makespan
    lower_bound = min(bound, makespan) if model.grid.exact else bound
    proven = status == 'OPTIMAL' or lower_bound >= makespan
    return Result(
        Status.OPTIMAL if proven and model.grid.exact else Status.FEASIBLE,
        makespan, lower_bound, time.monotonic() - began, schedule, 'cpsat',
        first_solution_seconds=_since_call(recorder.first, setup),
        best_solution_seconds=_since_call(recorder.best, setup), notes=model.notes)


def _since_call(solver_seconds, setup):
    return None if solver_seconds is None else setup + solver_seconds


def run(model, time_limit, workers, log, handle=None, scale=1, reader=None, relaxation=True):
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(MIN_SOLVE_SECONDS, time_limit)
    solver.parameters.num_workers = workers
    solver.parameters.log_search_progress = log
    # CP-SAT otherwise replaces the process's SIGINT handler, so a node that solved once
    # dies of Ctrl-C instead of shutting down cleanly.
    solver.parameters.catch_sigint_signal = False
    # Presolve probing took the whole budget on many panels before any search, and slowed
    # the one-panel proof, without tightening the bound.
    solver.parameters.cp_model_probing_level = 0
    if not relaxation and workers <= 2:
        # With two workers CP-SAT runs one full search (the other interleaves neighbourhood
        # searches), which by default solves the linear relaxation at every node. On small
        # routed scenarios that relaxation stays near the critical path whatever it cuts, so
        # the proof comes from the search alone, and it comes sooner without the LP.
        solver.parameters.subsolvers.append(SEARCH_WITHOUT_RELAXATION)
    recorder = _SolutionTimes(handle, scale, reader)
    if handle is not None and not handle.attach(solver):
        solver.parameters.max_time_in_seconds = MIN_SOLVE_SECONDS
    # status_name() without an argument is broken in ortools 9.15; name the returned status.
    status = solver.solve(model, recorder).name
    return solver, recorder, status


class _SolutionTimes(cp_model.CpSolverSolutionCallback):
    """When the first and the last (best) solutions arrived, in solver wall time; the best
    makespan and schedule (read by `reader`) also go to a `SearchHandle`, if any."""

    def __init__(self, handle=None, scale=1, reader=None):
        super().__init__()
        self.first = self.best = None
        self.handle, self.scale, self.reader = handle, scale, reader

    def on_solution_callback(self):
        if self.first is None:
            self.first = self.wall_time
        self.best = self.wall_time
        if self.handle is not None:
            self.handle.best = Fraction(objective_ticks(self.objective_value), self.scale)
            if self.reader is not None:
                self.handle.schedule = self.reader(self)


def _keep_assignments(model: CpsatModel, solver, best, keep, time_limit, workers, log):
    """Among schedules no longer than `best`, the one keeping most of `keep`'s robots."""
    kept = objective.kept_assignments(model.jobs, keep)
    if not kept:
        return None
    model.model.clear_hints()
    model.add_hint(model.read(solver))
    model.model.add(model.makespan <= best)
    model.model.maximize(sum(kept))
    second, _, status = run(model.model, time_limit, workers, log)
    if status not in ('OPTIMAL', 'FEASIBLE'):
        return None
    return model.read(second)
