"""What every bound reads of the jobs: their staffings, the order precedence imposes, heads
and tails along precedence chains, and the critical path."""

import itertools
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property

from fjsp_planner.model.problem import Problem


@dataclass(frozen=True, eq=False)
class StaffingChoice:
    """A way to staff a job in a relaxation: its least duration, the robot sets it stands
    for, whether it needs more than half of the robots that reach every panel ("heavy"),
    and the limited robots all its sets have."""

    duration: Fraction | int
    sets: tuple
    heavy: bool
    limited: frozenset

    @cached_property
    def always(self) -> frozenset:
        """The robots every set of the choice has."""
        return frozenset.intersection(*map(frozenset, self.sets))

    @cached_property
    def anyone(self) -> frozenset:
        """The robots some set of the choice has."""
        return frozenset.union(*map(frozenset, self.sets))


def staffings(problem: Problem, plan, robots):
    """Every assignment of the plan's operations to distinct robots among `robots` able to do
    them, as ((robot, operation type), ...)."""
    for chosen in itertools.permutations(robots, len(plan)):
        staffing = tuple(zip(chosen, plan, strict=True))
        if all(problem.duration(r, q) is not None for r, q in staffing):
            yield staffing


def fastest_sets(problem: Problem, plans, robots) -> list[tuple[Fraction, tuple[str, ...]]]:
    """[(least duration, robot set)] of a job with `plans`, staffed from `robots`, shortest
    first: a set is kept only if no smaller set is as fast (it would load more robots for
    nothing)."""
    fastest = {}
    for plan in plans:
        for staffing in staffings(problem, plan, robots):
            key = frozenset(r for r, _ in staffing)
            length = max(problem.duration(r, q) for r, q in staffing)
            fastest[key] = min(length, fastest.get(key, length))
    return sorted((d, tuple(sorted(s))) for s, d in fastest.items()
                  if not any(o < s and fastest[o] <= d for o in fastest))


def topological(problem: Problem) -> list[str]:
    """The jobs, each after every job that must complete before it."""
    before = problem.ancestors()
    return sorted(before, key=lambda name: len(before[name]))


def fastest_duration(problem: Problem, job) -> Fraction:
    """The least time the job can take: its plan whose slowest operation, each at the fastest
    robot able to do it, is least."""
    return min(max(min((t for r in problem.robots
                        if (t := problem.duration(r.name, q)) is not None),
                       default=Fraction(0)) for q in plan) for plan in job.plans)


def heads_and_tails(problem: Problem):
    """job -> least time before it can start / after it ends, along precedence chains at the
    fastest durations (panel copies have the same heads and tails as panel 0)."""
    fastest = {job.name: fastest_duration(problem, job) for job in problem.jobs}
    order = topological(problem)
    heads = {}
    for name in order:
        heads[name] = max((heads[a] + fastest[a] for a in problem.predecessors(name)),
                          default=Fraction(0))
    successors = {name: [] for name in order}
    for a, b in problem.precedence:
        successors[a].append(b)
    tails = {}
    for name in reversed(order):
        tails[name] = max((fastest[b] + tails[b] for b in successors[name]),
                          default=Fraction(0))
    return heads, tails


def critical_path_bound(problem: Problem) -> Fraction:
    """Longest precedence chain, each job at its fastest possible duration."""
    fastest = {}
    for job in problem.jobs:
        fixed = problem.fixed.get(job.name)
        fastest[job.name] = (fixed.end - fixed.start if fixed is not None
                             else fastest_duration(problem, job))
    starts = {job.name: Fraction(0) for job in problem.jobs}
    for name, fixed in problem.fixed.items():
        starts[name] = fixed.start
    ends = {}
    for name in topological(problem):
        ready = max((ends[a] for a in problem.predecessors(name)), default=starts[name])
        ends[name] = max(ready, starts[name]) + fastest[name]
    return max(ends.values(), default=Fraction(0))
