"""A lower bound for any scenario from the jobs that need one operation type, each set
solved as a scenario of its own (`restricted`): the "operation set" bound (docs/solver.md,
"Chains and operation sets").

Every plan of such a job has an operation of that type, so one of the few robots able to do
it must come to the job, whichever plan is chosen. When those robots are few, slow or far
apart, the set's jobs, their windows (heads and tails) and the ways between their places
decide the makespan: a robot must go back to a place that precedence, through the heads and
tails, keeps it from finishing at once, or leave jobs to a slower partner. The fleet load
bound sees each place once in any order; here the order, the ways and who takes which job
are chosen together.
"""

from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.restricted import restricted_bound

MOST_JOBS = 16
"""Largest set tried: on generated scenarios CP-SAT proves sets of 4-15 jobs in 0.04 to 2.7 s
(`restricted`), and none of 18-22 jobs within 4 s."""


def operation_bound(problem: Problem, time_limit: float, incumbent: Fraction | None = None
                    ) -> Fraction | None:
    """The bound of the module docstring over the sets of `operation_sets` that CP-SAT
    solves within `time_limit` seconds, the most loaded first, or None when it does not
    apply (running jobs, no such set) or proves nothing. With `incumbent`, a makespan known
    to be reachable, it never exceeds that."""
    sets = operation_sets(problem)
    if not sets:
        return None

    def most_loaded_first(heads, tails, fastest):
        # The likeliest to lift the bound first, as the time may not allow every set: by
        # the least head, the work at the fastest shared among the robots able to do the
        # set's type, and the least tail.
        def load(kept):
            return (min(heads[j] for j in kept) + min(tails[j] for j in kept)
                    + sum(fastest[j] for j in kept) / _able(problem, sets[kept]))
        return sorted(sets, key=lambda kept: (-load(kept), kept))

    return restricted_bound(problem, most_loaded_first, time_limit, incumbent)


def operation_sets(problem: Problem) -> dict[tuple[str, ...], int]:
    """For each operation type, the jobs every plan of which has it: the distinct sets of 2
    to MOST_JOBS jobs, each with the type that makes it (the scarcest, when several do)."""
    found = {}
    for q in sorted({q for job in problem.jobs for plan in job.plans for q in plan}):
        needing = tuple(job.name for job in problem.jobs
                        if all(q in plan for plan in job.plans))
        if 2 <= len(needing) <= MOST_JOBS and (
                needing not in found or _able(problem, q) < _able(problem, found[needing])):
            found[needing] = q
    return found


def _able(problem: Problem, q) -> int:
    return sum(1 for r in problem.robots if problem.duration(r.name, q) is not None)
