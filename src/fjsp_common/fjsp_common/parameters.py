"""A node's parameters, each defined once: name, default, description, range, read-only.

A node declares its parameters from its table (`fjsp_common.running.declare`), and the logic
it drives takes its defaults from the same table (the planner's `Settings`), as Nav2's
parameter definitions serve both its nodes and their logic. Free of ROS, so the domain core
reads the tables too.
"""

from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter. Its type is its default's.

    Numbers need both ends of their range (`low`, `high`): rclpy checks the range on every
    set, and NaN or an infinity is outside any finite range. `read_only` parameters are the
    ones the node reads once: a set at run time is refused instead of being accepted and
    ignored. A text parameter may be restricted to `choices`."""

    name: str
    default: bool | int | float | str
    description: str
    low: int | float | None = None
    high: int | float | None = None
    read_only: bool = True
    choices: tuple[str, ...] = ()

    def __post_init__(self):
        numeric = isinstance(self.default, int | float) and not isinstance(self.default, bool)
        if not numeric and (self.low is not None or self.high is not None):
            raise TypeError(f"parameter '{self.name}': a range needs a numeric default")
        if numeric and (self.low is None or self.high is None):
            raise TypeError(f"parameter '{self.name}': a number needs both ends of its range")
        if self.choices and self.default not in self.choices:
            raise TypeError(f"parameter '{self.name}': its default is not one of its choices")

    @property
    def constraints(self) -> str:
        """What `ros2 param describe` shows beyond the range."""
        return 'one of: ' + ', '.join(self.choices) if self.choices else ''


def table(*specs: ParameterSpec) -> Mapping[str, ParameterSpec]:
    """`specs` by name, in the order the node declares them; a name given twice is refused."""
    names = [spec.name for spec in specs]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise TypeError('parameters defined twice: ' + ', '.join(twice))
    return {spec.name: spec for spec in specs}
