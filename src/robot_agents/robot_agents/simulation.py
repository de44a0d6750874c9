"""A simulated robot, without ROS: how long its legs and operations really take, whether they
fail, and where it is (the `sim_robot` node serves it as the robot's action servers).

Durations are drawn around the nominal ones a goal gives: a factor `1 + bias + spread * u`,
`u` uniform in [-1, 1], from a stream seeded by the seed and the robot's name, so a run is
repeated exactly by the same seed whatever the other robots do. An operation may end early
(the factor is at least 0), a leg may not: the robot drives at its speed at most, and the plan
reckons a leg at that speed, so a leg's factor is at least 1. With `failure_rate`, a leg or an
operation fails part way (at a uniform share of it) with that probability.
"""

import math
import random
from collections.abc import Mapping
from dataclasses import dataclass

Point = tuple[float, ...]


@dataclass(frozen=True)
class Noise:
    spread: float = 0.0
    """Half the width of the band actual durations are drawn in, as a share of nominal."""
    bias: float = 0.0
    """Share by which durations run long on average (negative: short)."""
    failure_rate: float = 0.0
    """Chance that a leg or an operation fails part way."""


@dataclass(frozen=True)
class Draw:
    duration: float
    """Seconds it takes (or would have taken, had it not failed)."""
    fails_at: float | None
    """Share of it done when it fails; None: it does not."""


class SimulatedRobot:
    def __init__(self, robot: str, noise: Noise, seed: int,
                 places: Mapping[str, Point] | None = None):
        self.robot = robot
        self.noise = noise
        self._random = random.Random(f'{seed}/{robot}')
        self.places = dict(places or {})
        self.position: Point | None = None
        """Where it is, once a place with coordinates placed it (None before)."""
        self._way: tuple[Point, Point] | None = None

    def draw(self, nominal: float, leg: bool) -> Draw:
        """How a leg (or an operation) of `nominal` seconds goes."""
        noise = self.noise
        factor = 1 + noise.bias + noise.spread * self._random.uniform(-1.0, 1.0)
        factor = max(1.0, factor) if leg else max(0.0, factor)
        fails = self._random.random() < noise.failure_rate
        return Draw(max(nominal, 0.0) * factor, self._random.random() if fails else None)

    def set_off(self, origin: str, destination: str) -> None:
        """Leave for `destination`: from where it is, else from `origin`'s coordinates."""
        start = self.position if self.position is not None else self.places.get(origin)
        end = self.places.get(destination)
        self._way = (start, end) if start is not None and end is not None else None
        if self._way is None and end is not None:
            self.position = None     # it cannot be drawn until it arrives

    def move(self, share: float) -> None:
        """`share` of the way behind it."""
        if self._way is not None:
            start, end = self._way
            share = min(1.0, max(0.0, share))
            self.position = tuple(a + (b - a) * share for a, b in zip(start, end, strict=True))

    def arrive(self, destination: str) -> None:
        self._way = None
        if destination in self.places:
            self.position = self.places[destination]


def parse_places(text: str) -> dict[str, Point]:
    """`name=x,y[,z];...` as {name: (x, y[, z])}; ValueError naming the first bad entry."""
    places = {}
    for entry in filter(None, (part.strip() for part in text.split(';'))):
        name, _, numbers = entry.rpartition('=')
        try:
            point = tuple(float(n) for n in numbers.split(','))
        except ValueError:
            point = ()
        if not name or len(point) not in (2, 3) or not all(map(math.isfinite, point)):
            raise ValueError(f'place {entry!r} is not name=x,y or name=x,y,z')
        places[name] = point
    return places


def format_places(places: Mapping[str, Point]) -> str:
    """The text `parse_places` reads."""
    return ';'.join(f'{name}=' + ','.join(repr(float(c)) for c in point)
                    for name, point in places.items())
