"""A schedule for identical panels stitched from one-panel optima: the first panel with every
robot, then each further panel by the robots that can move between panels, one after another.

On the paper's panels the Assembler needs 200 units to cross, so a good schedule does the
first panel with all four robots (32) and the rest with LSMS and the MARCs alone (55 1/6
each), moving on between panels. CP-SAT on the whole 5-panel model reaches such schedules only
slowly; the one-panel problems solve quickly. The copies' optimal schedules, shifted
one after another, only say in which order and by whom jobs are done: `guided_schedule` turns
that into exact times, travel included, so the result is a valid schedule of the whole
problem, used as the search's starting point when it beats the greedy one.
"""

import time
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.bounds import panel as bounds
from fjsp_planner.solving.bounds.geometry import crossing_cost
from fjsp_planner.solving.greedy import GreedyOutOfTimeError, GreedyStuckError, guided_schedule


def stitched_schedule(problem: Problem, incumbent: Fraction, time_limit: float, workers: int
                      ) -> tuple[Schedule | None, Fraction | None]:
    """(the stitched schedule of the module docstring, the proven lower bound of one panel
    without the robots `bounds.panel_limits` keeps from some panel); either is None when it
    does not apply (no such robot), takes too long, or (the schedule) is invalid. The bound
    holds for every schedule shorter than `incumbent`, like the others of `bounds`."""
    from fjsp_planner.solving.cpsat import solve_cpsat

    began = time.monotonic()
    unhelped = bounds.unhelped_panel(problem, incumbent)
    first = bounds.one_panel(problem)
    if unhelped is None or first is None:
        return None, None
    alone = solve_cpsat(unhelped, time_limit / 2, workers)
    full = solve_cpsat(first, began + time_limit - time.monotonic(), workers)
    if full.schedule is None or alone.schedule is None:
        return None, alone.lower_bound
    guide, offset = {}, Fraction(0)
    cross = max(crossing_cost(problem, r.name) for r in unhelped.robots)
    for k, names in enumerate(problem.panels):
        copy = full.schedule if k == 0 else alone.schedule
        base = problem.panels[0]
        for i, name in enumerate(names):
            a = copy.jobs[base[i]]
            guide[name] = JobAssignment(name, a.plan, a.start + offset, a.end + offset,
                                        dict(a.robots))
        offset += copy.makespan + cross
    try:
        schedule = guided_schedule(problem, Schedule(guide, {}), began + time_limit)
    except (GreedyStuckError, GreedyOutOfTimeError):
        return None, alone.lower_bound
    return (None if validate(problem, schedule) else schedule), alone.lower_bound
