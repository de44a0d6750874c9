"""What a solver answers: a schedule in exact time, and a solver-neutral result."""

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from fractions import Fraction

from fjsp_planner.model.problem import Problem


@dataclass(frozen=True)
class JobAssignment:
    job: str
    plan: int
    start: Fraction
    end: Fraction
    robots: Mapping[str, int]
    """robot name -> operation type it performs in this job."""


@dataclass(frozen=True)
class Visit:
    """One stop on a robot's route: travel (possibly empty), then the job."""

    job: str
    travel_start: Fraction
    arrival: Fraction
    start: Fraction
    end: Fraction


@dataclass(frozen=True)
class Schedule:
    jobs: Mapping[str, JobAssignment]
    sequences: Mapping[str, tuple[str, ...]]
    """robot name -> the jobs it does, in order (every robot appears, maybe with none)."""

    @property
    def makespan(self) -> Fraction:
        return max((a.end for a in self.jobs.values()), default=Fraction(0))

    def visits(self, problem: Problem, robot: str) -> list[Visit]:
        """The robot's route: it leaves as soon as it is free and waits on arrival."""
        r = problem.robot(robot)
        location, free_at = r.start_location, r.release_time
        visits = []
        for name in self.sequences[robot]:
            a = self.jobs[name]
            here = problem.job(name).location
            if location is None:
                leg, free_at = Fraction(0), a.start
            else:
                leg = problem.travel(robot, location, here)
                if name in problem.fixed:
                    # Kept as planned before: running (the robot is there, released at its
                    # end) or frozen (`replan.frozen`), the robot set off in time for it.
                    free_at = min(free_at, a.start - leg)
            visits.append(Visit(name, free_at, free_at + leg, a.start, a.end))
            location, free_at = here, a.end
        return visits


class Status(StrEnum):
    OPTIMAL = 'optimal'
    FEASIBLE = 'feasible'
    INFEASIBLE = 'infeasible'
    UNKNOWN = 'unknown'


@dataclass(frozen=True)
class Result:
    status: Status
    makespan: Fraction | None
    lower_bound: Fraction | None
    solve_seconds: float
    schedule: Schedule | None
    solver: str
    first_solution_seconds: float | None = None
    best_solution_seconds: float | None = None
    notes: tuple[str, ...] = field(default=())
    """How the solver treated the input, e.g. the time grid it scaled to."""

    @property
    def gap(self) -> float | None:
        """Relative distance of the makespan above the bound (0 when proven optimal)."""
        if self.makespan is None or self.lower_bound is None:
            return None
        if self.makespan == 0:
            return 0.0
        return float((self.makespan - self.lower_bound) / self.makespan)
