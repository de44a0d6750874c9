"""What a message must hold to be acted on at all: times that are numbers, a time scale a
clock can run on.

A signature says who sent a message, not that it makes sense: in a fleet without a key anyone
can publish a plan with a NaN time scale or an event at t=inf, and a recording can hold
anything. Every reader (the agents, the planner, monitors, a replay) drops such a message as
malformed, naming the field, instead of acting on it or failing on it. Free of ROS: it reads
anything shaped like the messages.
"""

import math

MIN_TIME_SCALE = 1e-4
MAX_TIME_SCALE = 1000.0
"""Wall seconds per schedule unit a plan may give: the range of the planner's parameter."""

MAX_UNITS = 1e12
"""Schedule units a time may reach either side of the mission start: far beyond any
schedule a scenario within its limits gives, well inside what a chart can draw."""


def time_problem(value, what: str) -> str:
    """Why `value` cannot be a schedule time ('' if it can)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return f'{what} is not a number'
    if not math.isfinite(value) or abs(value) > MAX_UNITS:
        return f'{what} is {value!r}, not a finite time within ±{MAX_UNITS:g} units'
    return ''


def plan_problem(plan) -> str:
    """Why `plan` (a Plan message, live or decoded) cannot be followed or shown ('' if it
    can): its time scale, or a task time, is not a usable number."""
    scale = plan.time_scale
    if isinstance(scale, bool) or not isinstance(scale, int | float) \
            or not MIN_TIME_SCALE <= scale <= MAX_TIME_SCALE:
        return (f'time_scale {scale!r} is outside [{MIN_TIME_SCALE:g}, {MAX_TIME_SCALE:g}] '
                'wall seconds per schedule unit')
    for robot in plan.robots:
        for task in robot.tasks:
            for name in ('travel_start', 'arrival', 'start', 'operation_end', 'end'):
                why = time_problem(getattr(task, name), f"task '{str(task.job)[:80]}' {name}")
                if why:
                    return why
    return ''
