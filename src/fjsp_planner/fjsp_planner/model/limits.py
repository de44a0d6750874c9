"""How large and how extreme an input may be, checked before anything is built from it.

The solvers work on integers: CP-SAT scales every time onto a grid and sums them into a
horizon, so a duration of 1e300 or a speed of 1e-300 overflows its 64-bit arithmetic, and a
decimal with a huge exponent makes `Fraction` itself compute a number with a billion digits.
Sizes matter as much: N panels make N^2 distance entries, so an innocent `--panels 100000`
would exhaust the machine's memory. (The CP-SAT routing model, with one arc per robot and
ordered pair of jobs it could do, is built only where it fits; larger problems are scheduled
by greedy passes, see `solving/large.py`.) Every reader of user input (YAML
scenarios, `.fjs` files, command-line overrides) refuses, naming the item, what lies outside
these bounds; docs/scenario-format.md ("Limits") explains the figures.
"""

import os
import re
import reprlib
import stat
from fractions import Fraction
from pathlib import Path

from fjsp_common import bounded_yaml
from fjsp_common.decimals import decimal
from fjsp_planner.model.problem import ProblemError

MAX_TIME = Fraction(10**6)
"""Schedule units: every duration, derived travel time, release time and distance."""
MAX_COORDINATE = Fraction(10**6)
"""Of a location on the map, on each axis, either way; the distances its coordinates imply
are held to MAX_TIME like any other."""
MIN_SPEED = Fraction(1, 10**6)
MAX_SPEED = Fraction(10**6)
MAX_DENOMINATOR = 10**6
"""Of a number as written (six decimal places, or a fraction such as '10/3')."""
MAX_JOBS = 1000
"""After repeating the panels."""
MAX_ROBOTS = 100
MAX_PANELS = 50
MAX_PLANS = 20
"""Alternative process plans of one job."""
MAX_OPERATION_TYPES = 1000
"""A `.fjs` file makes one operation type per benchmark operation, so as many as jobs."""
MAX_ARCS = 10_000
"""Precedence arcs, holding arcs, time overrides: each list."""
MAX_NAME_LENGTH = 100
MAX_FILE_BYTES = 4 * 2**20
MAX_WORKERS = 64
"""More search workers than this only thrash on any machine the fleet's planner runs on, and
CP-SAT rejects absurd counts with an opaque "model invalid"."""

_show = reprlib.Repr()
_show.maxstring = _show.maxother = 60
_show.maxlist = _show.maxdict = 4
_show.maxlevel = 2

# Written numbers: a decimal with an optional exponent, or an integer fraction 'a/b'.
_NUMBER = re.compile(r'\s*[-+]?(?:(?:\d+(?:\.\d*)?|\.\d+)(?:[eE](?P<exp>[-+]?\d+))?'
                     r'|\d+\s*/\s*\d+)\s*')
# Fraction() expands the exponent into an integer: bound it before it does.
_MAX_EXPONENT = 400


def shown(value) -> str:
    """A user's value, shortened for a message: a 1 MB string or a nested alias bomb of a
    YAML file must not become a 1 MB message."""
    return _show.repr(value)


def number(value, what: str, low: Fraction, high: Fraction) -> Fraction:
    """The exact value of an integer, decimal or 'a/b' string within [low, high].

    Raises `ProblemError` naming `what` for anything else: not a number, NaN, infinite,
    outside the range, or written more precisely than 1/MAX_DENOMINATOR.
    """
    if isinstance(value, bool) or not isinstance(value, int | float | str | Fraction):
        raise ProblemError([f'{what}: expected a number, got {shown(value)}'])
    if isinstance(value, Fraction):
        exact = value
    else:
        text = str(value)
        match = _NUMBER.fullmatch(text) if len(text) <= 100 else None
        if match is None or abs(int(match['exp'] or 0)) > _MAX_EXPONENT:
            raise ProblemError([f'{what}: expected a finite number, got {shown(value)}'])
        try:
            exact = Fraction(text.replace(' ', ''))
        except ZeroDivisionError:
            raise ProblemError([f'{what}: {shown(value)} divides by zero']) from None
    if not low <= exact <= high:
        raise ProblemError([f'{what}: {shown(value)} is outside [{_g(low)}, {_g(high)}]'])
    if exact.denominator > MAX_DENOMINATOR:
        raise ProblemError([f'{what}: {shown(value)} is too precise: at most 6 decimal '
                            f'places, or a fraction with a denominator up to '
                            f'{MAX_DENOMINATOR}'])
    return exact


def _g(value: Fraction) -> str:
    return f'{float(value):g}'


def name(value, what: str) -> str:
    """A name as the user wrote it: a string or an integer, at most MAX_NAME_LENGTH long."""
    if isinstance(value, bool) or not isinstance(value, str | int):
        raise ProblemError([f'{what}: a name must be a string, got {shown(value)}'])
    text = str(value)
    if not text:
        raise ProblemError([f'{what}: a name must not be empty'])
    if len(text) > MAX_NAME_LENGTH:
        raise ProblemError([f'{what}: name {shown(text)} is longer than {MAX_NAME_LENGTH} '
                            'characters'])
    return text


def count_problem(what: str, count: int, limit: int, why: str = '') -> list[str]:
    """A message if `count` items exceed `limit`."""
    if count <= limit:
        return []
    return [f'{what}: {count} is more than the limit of {limit}' + (f' ({why})' if why else '')]


def load_yaml(text: str, max_bytes: int = MAX_FILE_BYTES):
    """The data of one YAML document, read within the bounds of `fjsp_common.bounded_yaml`
    (nesting, values, size); ProblemError saying which it passes, and where."""
    try:
        return bounded_yaml.load_yaml(text, max_bytes)
    except bounded_yaml.YamlError as error:
        raise ProblemError([str(error)]) from None


def read_input_file(path, kind: str) -> str:
    """The UTF-8 text of a regular file of at most MAX_FILE_BYTES; a `ProblemError` saying
    why not otherwise (missing, a directory, a device or pipe, too large, not UTF-8)."""
    path = Path(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise ProblemError([f'{path}: no such file']) from None
    except OSError as error:
        raise ProblemError([f'{path}: cannot read {kind}: {error.strerror}']) from None
    if stat.S_ISDIR(info.st_mode):
        raise ProblemError([f'{path}: is a directory, not a {kind} file'])
    if not stat.S_ISREG(info.st_mode):
        # A pipe or a device could block or never end.
        raise ProblemError([f'{path}: is not a regular file'])
    if info.st_size > MAX_FILE_BYTES:
        raise ProblemError([f'{path}: {info.st_size} bytes is larger than the limit of '
                            f'{MAX_FILE_BYTES} bytes for a {kind} file'])
    try:
        with open(path, 'rb') as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except OSError as error:
        raise ProblemError([f'{path}: cannot read {kind}: {error.strerror}']) from None
    if len(data) > MAX_FILE_BYTES:
        raise ProblemError([f'{path}: larger than the limit of {MAX_FILE_BYTES} bytes for a '
                            f'{kind} file'])
    try:
        return data.decode('utf-8-sig')
    except UnicodeDecodeError as error:
        raise ProblemError([f'{path}: not UTF-8 text (byte 0x{data[error.start]:02x} at '
                            f'offset {error.start})']) from None


def scale_problems(robots, robot_types, jobs, distances, locomote, time_overrides,
                   panels: int = 1, shift: Fraction = Fraction(0)) -> list[str]:
    """What makes the problem, repeated over `panels`, too large for the solvers: too many
    jobs, or a travel time beyond MAX_TIME. Takes the parts of a
    `Problem` so that it can be checked before one is built; ids that do not resolve are
    skipped (they are reported elsewhere)."""
    problems = count_problem('jobs' + (f' ({len(jobs)} x {panels} panels)' if panels > 1
                                       else ''), len(jobs) * panels, MAX_JOBS)
    if locomote is None or not distances:
        return problems
    (a, b), farthest = max(distances.items(), key=lambda item: item[1])
    farthest += shift * (panels - 1)
    where = (f"from '{a}' of panel 1 to '{b}' of panel {panels}" if panels > 1
             else f"from '{a}' to '{b}'")
    for robot in robots:
        efficiency = robot_types.get(robot.type, {}).get(locomote)
        if efficiency is None or robot.speed <= 0:
            continue
        travel = farthest * efficiency / robot.speed
        if travel > MAX_TIME:
            problems.append(f"robot '{robot.name}': travelling {where} would take "
                            f'{decimal(travel)} units (distance {float(farthest):g} x locomote '
                            f'efficiency {float(efficiency):g} / speed {float(robot.speed):g}), '
                            f'more than the limit of {_g(MAX_TIME)}')
    return problems
