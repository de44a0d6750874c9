"""What CP-SAT optimises: the makespan, then, optionally, closeness to a previous plan."""

from fjsp_planner.model.schedule import Schedule
from fjsp_planner.solving.cpsat.variables import JobVariables


def makespan(m, jobs: JobVariables, horizon: int):
    """The makespan variable: no job ends after it."""
    variable = m.new_int_var(0, horizon, 'makespan')
    for end in jobs.end.values():
        m.add(variable >= end)
    return variable


def kept_assignments(jobs: JobVariables, keep: Schedule) -> list:
    """Literals of `keep`'s (job, robot) pairs that the model can still choose."""
    return [jobs.on_job[j, r] for j, a in keep.jobs.items() for r in a.robots
            if (j, r) in jobs.on_job]
