"""Plans that no robot of the fleet can staff, left out before solving.

A plan with an operation type no robot of the problem can do is never chosen. A scenario may
list one (an alternative for robots it does not have), and a re-plan poses one whenever the
only robots able to do an operation have failed. The solvers and bounds reason about each
plan's fastest robots; they get the problem without such plans, and the schedule they return
names each job's plan by its index in the problem as posed.
"""

import dataclasses

from fjsp_planner.model.problem import Problem, ProblemError
from fjsp_planner.model.schedule import Schedule


@dataclasses.dataclass(frozen=True)
class Staffable:
    problem: Problem
    """The problem without the plans no robot can staff."""
    kept: dict[str, tuple[int, ...]]
    """job -> the indices, in the problem as posed, of the plans it keeps (only jobs that lost
    one)."""

    def posed(self, schedule: Schedule | None) -> Schedule | None:
        """`schedule` of the staffable problem, its plans indexed as in the problem posed."""
        if schedule is None:
            return None
        return _with_plan_indices(schedule, {job: dict(enumerate(kept))
                                          for job, kept in self.kept.items()})

    def staffable(self, schedule: Schedule | None) -> Schedule | None:
        """`schedule` of the problem posed, indexed as in the staffable problem; None if it
        uses a plan left out."""
        if schedule is None:
            return None
        if any(a.plan not in self.kept[a.job] for a in schedule.jobs.values()
               if a.job in self.kept):
            return None
        return _with_plan_indices(schedule, {job: {k: i for i, k in enumerate(kept)}
                                          for job, kept in self.kept.items()})


def staffable(problem: Problem) -> Staffable | None:
    """The problem without the plans no robot can staff, or None if every plan can be (or a
    job could keep none: the problem cannot be solved, and the solvers say so)."""
    able = {q for r in problem.robots for q in problem.operation_types
            if problem.duration(r.name, q) is not None}
    kept, jobs = {}, []
    for job in problem.jobs:
        fixed = problem.fixed.get(job.name)
        indices = tuple(k for k, plan in enumerate(job.plans)
                        if all(q in able for q in plan) or (fixed is not None and fixed.plan == k))
        if len(indices) in (0, len(job.plans)):
            if not indices:
                return None
            jobs.append(job)
            continue
        kept[job.name] = indices
        jobs.append(dataclasses.replace(job, plans=tuple(job.plans[k] for k in indices)))
    if not kept:
        return None
    fixed = {name: dataclasses.replace(f, plan=kept[name].index(f.plan)) if name in kept else f
             for name, f in problem.fixed.items()}
    try:
        return Staffable(dataclasses.replace(problem, jobs=tuple(jobs), fixed=fixed), kept)
    except ProblemError:
        return None  # e.g. a holding arc only a plan left out could serve: solved as posed


def _with_plan_indices(schedule: Schedule, index: dict[str, dict[int, int]]) -> Schedule:
    jobs = {name: dataclasses.replace(a, plan=index[name][a.plan]) if name in index else a
            for name, a in schedule.jobs.items()}
    return Schedule(jobs, schedule.sequences)
