"""The integer time grid CP-SAT works on, and why it can neither overflow nor be optimistic.

Times are scaled by the least common multiple of the durations' and travel times'
denominators (exact for the paper: 30), capped at MAX_SCALE; beyond that, and whenever the
horizon would need more than MAX_TICKS grid units, durations are rounded up on a coarser grid,
so the exact schedule read back can only be looser than the grid, never infeasible.

MAX_TICKS keeps every variable and every linear expression CP-SAT builds (a start plus a
travel leg, a robot's summed work) far inside int64: with the input bounds of the scenario
checks (every duration, travel time and release time at most 1e6 schedule units, at most
about 1000 jobs) the serial horizon is below 4e9 units, so the scale never drops below one
grid unit per schedule unit and the sums stay below 2^45.
"""

import math
from dataclasses import dataclass
from fractions import Fraction

from fjsp_planner.model.problem import Problem

MAX_SCALE = 1000
MAX_TICKS = 2**40
OBJECTIVE_NOISE = 1e-9
"""Relative rounding noise in the objective values and bounds CP-SAT reports as floats."""


def objective_ticks(value: float) -> int:
    """The integer an integer objective's value or bound, reported by CP-SAT as a float,
    stands for (rounded up when it is not one). They come back with rounding noise
    (6048.000000000001 for 6048): their ceiling would claim a bound one grid unit above
    what is proven, above a reachable makespan, and make the search with that floor
    infeasible."""
    nearest = round(value)
    if abs(value - nearest) <= OBJECTIVE_NOISE * max(1.0, abs(value)):
        return nearest
    return math.ceil(value)


@dataclass(frozen=True)
class TimeGrid:
    scale: int
    """Grid units per schedule unit."""
    exact: bool
    """Every duration, travel time, release and fixed time lies on the grid."""

    def ticks(self, value: Fraction) -> int:
        """Grid units, rounded up (integer arithmetic: this runs for every route arc)."""
        return -(-value.numerator * self.scale // value.denominator)

    def floor(self, value: Fraction) -> int:
        return value.numerator * self.scale // value.denominator

    def time(self, ticks: int) -> Fraction:
        return Fraction(ticks, self.scale)

    @property
    def note(self) -> str:
        if self.exact:
            return f'exact on a 1/{self.scale} time grid'
        return (f'durations rounded up to a 1/{self.scale} time grid; the lower bound is that '
                'of the rounded model')


def choose_grid(problem: Problem, legs, horizon: Fraction) -> TimeGrid:
    """The finest grid within MAX_SCALE on which `horizon` stays below MAX_TICKS units.

    `legs` are the travel times the model will use; `horizon` bounds every time in it.
    """
    values = [problem.duration(r.name, q) for r in problem.robots for q in problem.operation_types]
    values += legs
    denominators = {v.denominator for v in values if v is not None}
    scale = math.lcm(*denominators) if denominators else 1
    limit = max(1, int(MAX_TICKS // max(horizon, Fraction(1))))
    if scale > min(MAX_SCALE, limit):
        return TimeGrid(min(MAX_SCALE, limit), False)
    # Release and fixed times (wall-clock `now` when re-planning) join the grid while it stays
    # small enough; beyond that they are rounded, which costs exactness, not validity.
    others = [r.release_time for r in problem.robots]
    others += [t for f in problem.fixed.values() for t in (f.start, f.end)]
    finer = math.lcm(scale, *(v.denominator for v in others))
    if finer <= min(MAX_SCALE, limit):
        return TimeGrid(finer, True)
    return TimeGrid(scale, all((v * scale).denominator == 1 for v in others))
