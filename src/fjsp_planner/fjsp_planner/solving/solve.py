"""One entry point for every backend, returning the solver-neutral `Result`: `solve` checks
its arguments, finds the start every backend shares (`start`) and picks the backend."""

import dataclasses
import time

from fjsp_planner.model.limits import MAX_WORKERS
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.solving import large, portfolio, routed, tabu
from fjsp_planner.solving.bounds.assignment import fleet_load_bound
from fjsp_planner.solving.bounds.chains import chain_bound
from fjsp_planner.solving.bounds.operations import operation_bound
from fjsp_planner.solving.classic import solve_classic
from fjsp_planner.solving.compact import left_shifted
from fjsp_planner.solving.cpsat import solve_cpsat
from fjsp_planner.solving.staffable import staffable
from fjsp_planner.solving.start import find_start, greedy_result, raised_bound, run_from

SOLVERS = ('cpsat', 'greedy', 'mip')
GREEDY_SHARE = 0.4
"""Share of the time limit the greedy schedule may take before the exact solver starts."""


def solve(problem: Problem, solver: str = 'cpsat', time_limit: float = 10.0, workers: int = 2,
          hint: Schedule | None = None, keep: Schedule | None = None,
          mip_backend: str = 'SCIP', log: bool = False) -> Result:
    """Minimise the makespan of `problem`.

    `hint` warm-starts the search if it is a valid schedule of `problem`; `keep` (CP-SAT
    only) then prefers, among schedules of the proven best makespan, those that change the
    fewest of its (job, robot) assignments. The greedy schedule bounds the horizon and is
    returned when an exact solver finds nothing in time.

    Every schedule returned is left-shifted (`compact`). The backends: `greedy` alone;
    `mip`, the paper's program; `cpsat`, the CP-SAT model, beside the tabu search on the
    classic flexible job shop (`classic`), with the panel bounds on several identical
    panels (`portfolio`), or the local search on other routed problems (`routed`), and the
    local search where the CP-SAT routing model would be too large (`large`).

    Plans no robot of the problem can staff are left out first (`staffable`); the schedule
    names plans as `problem` does. The whole call (greedy, model building, solving, keeping
    assignments) takes at most
    `time_limit` seconds, plus the solver's reaction time to its own limit (milliseconds),
    for problems up to the size limit of the scenario checks (1000 jobs); but without a
    valid hint, a limit too short for any greedy pass is exceeded by one quick pass, so that
    a schedule is returned whenever a quick pass finds one. `workers` must lie in
    1..MAX_WORKERS.
    """
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver '{solver}'; choose one of {', '.join(SOLVERS)}")
    if isinstance(workers, bool) or not isinstance(workers, int) or not (
            1 <= workers <= MAX_WORKERS):
        raise ValueError(f'workers must be an integer from 1 to {MAX_WORKERS}, got {workers!r}')
    if not time_limit > 0:
        raise ValueError(f'time_limit must be a positive number of seconds, got {time_limit!r}')
    lean = staffable(problem)
    if lean is not None:
        result = solve(lean.problem, solver, time_limit, workers, lean.staffable(hint),
                       lean.staffable(keep), mip_backend, log)
        return dataclasses.replace(result, schedule=lean.posed(result.schedule))
    began = time.monotonic()
    greedy_time = time_limit if solver == 'greedy' else GREEDY_SHARE * time_limit
    start = find_start(problem, hint, began, greedy_time, time_limit)
    return _left_shifted(problem, _backend(problem, solver, start, began, time_limit, workers,
                                           keep, mip_backend, log))


def _backend(problem, solver, start, began, time_limit, workers, keep, mip_backend, log
             ) -> Result:
    if solver == 'greedy':
        return greedy_result(problem, start, began)
    if solver == 'mip':
        from fjsp_planner.solving.mip import solve_mip

        result = run_from(problem, start, began, time_limit, lambda left: solve_mip(
            problem, left, backend=mip_backend, workers=workers, hint=start.best, log=log))
        return portfolio.with_panel_bounds(problem, result, None) if portfolio.applies(
            problem) else result
    if not large.fits_cpsat(problem):
        result = large.solve_large(problem, start, began, time_limit, workers)
        return portfolio.with_panel_bounds(problem, result, None) if portfolio.applies(
            problem) else result
    if start.hint is None and keep is None and start.greedy is not None and tabu.applies(
            problem):
        return solve_classic(problem, start.greedy, began, time_limit, workers, start.notes,
                             log)
    if portfolio.applies(problem):
        return portfolio.solve_panels(problem, start, began, time_limit, workers, keep, log)
    if routed.applies(problem, start, keep):
        return routed.solve_routed(problem, start, began, time_limit, workers, log)
    if keep is not None:
        # A re-plan's bound would cost time that counts against its latency.
        return run_from(problem, start, began, time_limit, lambda left: solve_cpsat(
            problem, left, workers, hint=start.hint, keep=keep, upper_bound=start.best,
            log=log))
    # A proven bound lets CP-SAT stop as soon as a schedule meets it. The operation set and
    # chain bounds get the end of the limit, and only when CP-SAT has not proven its
    # schedule optimal by then: small scenarios are often proven in less. The robots' routes
    # would delay CP-SAT's start by about a second, for a floor still below the optimum. The
    # search goes without CP-SAT's linear relaxation, and with the travel between every two
    # jobs of a robot: both prove these scenarios sooner. That travel is quadratic in the
    # jobs: a large scenario comes here only when no start was found, and then needs its
    # time to search.
    bound = fleet_load_bound(problem, routed.LOAD_BOUND_SHARE * time_limit, routes=False)
    result = run_from(
        problem, start, began, (1 - routed.CHAIN_BOUND_SHARE) * time_limit,
        lambda left: solve_cpsat(problem, left, workers, hint=start.hint, upper_bound=start.best,
                                 log=log, lower_bound=bound, relaxation=False,
                                 pairwise_travel=len(problem.jobs) <= routed.MIN_JOBS))
    if result.status == Status.OPTIMAL or result.schedule is None:
        return result
    operations = operation_bound(problem, (began + time_limit - time.monotonic()) / 2,
                                 result.makespan)
    chains = chain_bound(problem, began + time_limit - time.monotonic(), result.makespan)
    found = [bound for bound in (operations, chains) if bound is not None]
    if not found:
        return result
    return dataclasses.replace(
        raised_bound(result, max(found), 'bound raised to {} by the operation set and chain '
                                         'bounds'),
        solve_seconds=time.monotonic() - began)


def _left_shifted(problem: Problem, result: Result) -> Result:
    """The result with its schedule left-shifted (`compact.left_shifted`); greedy schedules
    are by construction."""
    if result.schedule is None or result.solver == 'greedy':
        return result
    shifted = left_shifted(problem, result.schedule)
    if shifted is result.schedule:
        return result
    bound = None if result.lower_bound is None else min(result.lower_bound, shifted.makespan)
    return dataclasses.replace(result, schedule=shifted, makespan=shifted.makespan,
                               lower_bound=bound)
