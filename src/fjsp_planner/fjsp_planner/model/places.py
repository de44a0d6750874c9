"""Places on a map: locations given coordinates, and the distances they imply.

A scenario may place its locations at coordinates, 2-D or 3-D (docs/scenario-format.md,
"Places on a map"), instead of, or besides, giving distances pair by pair: two placed
locations are then their Euclidean distance apart. The solvers and the validator work on
exact rationals, and a Euclidean distance is mostly irrational, so it is kept on the grid of
a millionth, the precision of every number a scenario gives: exact when it lies on that grid
(3-4-5 gives 5), else rounded to the nearest millionth (a square root of an integer that is
not a perfect square is irrational, so it is never half-way). Coordinates lie on that grid
too, so every distance is computed in integer arithmetic, exactly, and fast enough for the
largest table the format allows.
"""

from collections.abc import Callable, Mapping
from fractions import Fraction
from math import ceil, isqrt

GRID = 10**6
"""Coordinates and the distances they imply are whole multiples of 1/GRID."""

Coordinates = tuple[Fraction, ...]
"""(x, y) or (x, y, z)."""


def on_grid(value: Fraction) -> bool:
    return (value * GRID).denominator == 1


def _grid_distance(squared: int) -> Fraction:
    """The square root of `squared` grid steps squared, to the nearest grid step."""
    root = isqrt(squared)
    if root * root != squared:
        root = (isqrt(4 * squared) + 1) // 2      # floor(sqrt + 1/2), in integers
    return Fraction(root, GRID)


def euclidean_distances(coordinates: Mapping[str, Coordinates]
                        ) -> dict[tuple[str, str], Fraction]:
    """Both directions of every pair of placed locations, at their Euclidean distance."""
    # In grid steps, 2-D points at z = 0: one loop of plain integer arithmetic.
    steps = [(name, *(int(c * GRID) for c in point), *(0,) * (3 - len(point)))
             for name, point in coordinates.items()]
    distances = {}
    for i, (a, x, y, z) in enumerate(steps):
        for b, u, v, w in steps[i + 1:]:
            distances[a, b] = distances[b, a] = _grid_distance(
                (x - u) ** 2 + (y - v) ** 2 + (z - w) ** 2)
    return distances


def panel_coordinates(coordinates: Mapping[str, Coordinates], panels: int, shift: Fraction,
                      tag: Callable[[str, int], str]) -> dict[str, Coordinates]:
    """Where the copies of N panels are drawn: side by side along x, panel k moved right by
    (k - 1) times the panel's width plus `shift`, so copies never overlap and lie `shift`
    apart (rounded up to the grid). The distances between panels follow the panel rule, not
    this drawing."""
    if not coordinates:
        return {}
    xs = [point[0] for point in coordinates.values()]
    step = Fraction(ceil((max(xs) - min(xs) + shift) * GRID), GRID)
    return {tag(name, k): (point[0] + (k - 1) * step, *point[1:])
            for k in range(1, panels + 1) for name, point in coordinates.items()}
