"""YAML scenarios (format: docs/scenario-format.md) and the N-panel repetition of
docs/model.md ("Several panels")."""

from fractions import Fraction
from pathlib import Path

import yaml

from fjsp_planner.core.problem import Job, Problem, ProblemError, Robot

DEFAULT_SHIFT = Fraction(60)


class ScenarioError(ProblemError):
    """A scenario file that cannot be read; every problem found is listed."""


def load_scenario(path, panels: int | None = None, shift=None) -> Problem:
    """Read a scenario file; `panels`/`shift` override the file's own `panels` section."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as error:
        raise ScenarioError([f'{path}: cannot read scenario: {error.strerror}']) from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, 'problem_mark', None)
        where = f'line {mark.line + 1}, column {mark.column + 1}' if mark else 'unknown place'
        reason = getattr(error, 'problem', None) or str(error)
        raise ScenarioError([f'{path}: YAML syntax error at {where}: {reason}']) from None
    try:
        problem, file_panels = _from_mapping(data, default_name=path.stem)
    except ProblemError as error:
        raise ScenarioError([f'{path}: {p}' for p in error.problems]) from None
    count = panels if panels is not None else file_panels['count']
    distance = _number(shift, 'shift') if shift is not None else file_panels['shift']
    if count < 1:
        raise ScenarioError([f'{path}: panels must be at least 1, got {count}'])
    if distance < 0:
        raise ScenarioError([f'{path}: shift must not be negative, got {distance}'])
    return repeat_panels(problem, count, distance)


def parse_scenario(data, name='scenario') -> Problem:
    """Build a problem from an already-parsed mapping (same format as the YAML file)."""
    return _from_mapping(data, default_name=name)[0]


def repeat_panels(problem: Problem, panels: int, shift=DEFAULT_SHIFT) -> Problem:
    """Repeat every job per panel; panels k and l are `shift * |k - l|` further apart."""
    if panels == 1:
        return problem
    shift = Fraction(shift)

    def tag(name, k):
        return f'{name}_p{k}'

    jobs, precedence, holding = [], [], []
    for k in range(1, panels + 1):
        jobs += [Job(tag(j.name, k), tag(j.location, k), j.plans) for j in problem.jobs]
        precedence += [(tag(a, k), tag(b, k)) for a, b in problem.precedence]
        holding += [(tag(a, k), tag(b, k), q) for a, b, q in problem.holding]
    base = problem.locations()
    distances = {}
    for k in range(1, panels + 1):
        for m in range(1, panels + 1):
            for a in base:
                for b in base:
                    if (k, a) != (m, b):
                        distances[tag(a, k), tag(b, m)] = (
                            problem.distance(a, b) + shift * abs(k - m))
    robots = tuple(
        Robot(r.name, r.type, r.speed,
              tag(r.start_location, 1) if r.start_location else None, r.release_time)
        for r in problem.robots)
    return Problem(
        operation_types=problem.operation_types, robot_types=problem.robot_types,
        robots=robots, jobs=tuple(jobs), distances=distances, precedence=tuple(precedence),
        holding=tuple(holding), locomote=problem.locomote,
        time_overrides=problem.time_overrides, name=f'{problem.name} x{panels}',
        panels=tuple(tuple(tag(j.name, k) for j in problem.jobs)
                     for k in range(1, panels + 1)))


def _number(value, what) -> Fraction:
    """Integers, decimals and 'a/b' strings, kept exact."""
    if isinstance(value, bool) or not isinstance(value, int | float | str | Fraction):
        raise ProblemError([f'{what}: expected a number, got {value!r}'])
    try:
        return Fraction(str(value))
    except (ValueError, ZeroDivisionError):
        raise ProblemError([f'{what}: expected a number, got {value!r}']) from None


class _Reader:
    """Collects every problem of a scenario mapping instead of stopping at the first."""

    def __init__(self):
        self.problems = []

    def number(self, value, what, default=None):
        if value is None and default is not None:
            return default
        try:
            return _number(value, what)
        except ProblemError as error:
            self.problems += error.problems
            return default if default is not None else Fraction(0)

    def mapping(self, data, key, what, required=True):
        value = data.get(key)
        if value is None:
            if required:
                self.problems.append(f"{what}: missing '{key}'")
            return {}
        if not isinstance(value, dict):
            self.problems.append(f"{what}: '{key}' must be a mapping")
            return {}
        return value

    def sequence(self, data, key, what, required=True):
        value = data.get(key)
        if value is None:
            if required:
                self.problems.append(f"{what}: missing '{key}'")
            return []
        if not isinstance(value, list):
            self.problems.append(f"{what}: '{key}' must be a list")
            return []
        return value


def _from_mapping(data, default_name):
    if not isinstance(data, dict):
        raise ProblemError(['the scenario must be a mapping of sections (operation_types, '
                            'robot_types, robots, jobs, ...)'])
    read = _Reader()
    known = {'name', 'operation_types', 'locomote', 'robot_types', 'robots', 'jobs',
             'distances', 'precedence', 'holding', 'time_overrides', 'panels'}
    for key in data:
        if key not in known:
            read.problems.append(f"unknown section '{key}' (expected one of {sorted(known)})")

    operation_types = {}
    for key, name in read.mapping(data, 'operation_types', 'scenario').items():
        if not isinstance(key, int) or isinstance(key, bool) or key < 0:
            read.problems.append(f'operation type id {key!r} must be a non-negative integer')
        else:
            operation_types[key] = str(name)
    by_name = {name: q for q, name in operation_types.items()}

    def operation(ref, what):
        if isinstance(ref, int) and not isinstance(ref, bool) and ref in operation_types:
            return ref
        if isinstance(ref, str) and ref in by_name:
            return by_name[ref]
        read.problems.append(f'{what}: unknown operation type {ref!r}')
        return None

    locomote = data.get('locomote')
    if locomote is None and 'locomote' in by_name:
        locomote = 'locomote'
    locomote = operation(locomote, 'locomote') if locomote is not None else None

    robot_types = {}
    for type_name, efficiency in read.mapping(data, 'robot_types', 'scenario').items():
        what = f"robot type '{type_name}'"
        if not isinstance(efficiency, dict):
            read.problems.append(f'{what}: efficiencies must be a mapping operation -> time')
            continue
        times = {}
        for ref, time in efficiency.items():
            q = operation(ref, what)
            if q is not None:
                times[q] = read.number(time, f'{what}, operation {ref!r}')
        robot_types[str(type_name)] = times

    robots = []
    for index, entry in enumerate(read.sequence(data, 'robots', 'scenario')):
        what = f'robot #{index + 1}'
        if not isinstance(entry, dict) or 'name' not in entry or 'type' not in entry:
            read.problems.append(f"{what}: needs at least 'name' and 'type'")
            continue
        what = f"robot '{entry['name']}'"
        start = entry.get('start_location')
        robots.append(Robot(
            name=str(entry['name']), type=str(entry['type']),
            speed=read.number(entry.get('speed'), f'{what} speed', Fraction(1)),
            start_location=str(start) if start is not None else None,
            release_time=read.number(entry.get('release_time'), f'{what} release_time',
                                     Fraction(0))))

    jobs = []
    for index, entry in enumerate(read.sequence(data, 'jobs', 'scenario')):
        what = f'job #{index + 1}'
        if not isinstance(entry, dict) or 'name' not in entry:
            read.problems.append(f"{what}: needs at least 'name' and 'plans'")
            continue
        what = f"job '{entry['name']}'"
        plans = entry.get('plans')
        if not isinstance(plans, list) or not all(isinstance(p, list) for p in plans):
            read.problems.append(f'{what}: plans must be a list of lists of operation types')
            continue
        resolved = []
        for plan in plans:
            ops = tuple(operation(ref, what) for ref in plan)
            resolved.append(tuple(q for q in ops if q is not None))
        jobs.append(Job(str(entry['name']), str(entry.get('location', entry['name'])),
                        tuple(resolved)))

    distances = _distances(read, data.get('distances'))

    def arcs(key, size):
        result = []
        for arc in read.sequence(data, key, 'scenario', required=False):
            if not isinstance(arc, list) or len(arc) != size:
                read.problems.append(f'{key} entry {arc!r} must be a list of {size} items')
                continue
            result.append(tuple(str(x) for x in arc[:2]) + tuple(arc[2:]))
        return result

    precedence = arcs('precedence', 2)
    holding = []
    for a, b, ref in arcs('holding', 3):
        q = operation(ref, f"holding arc ('{a}', '{b}')")
        if q is not None:
            holding.append((a, b, q))

    overrides = {}
    for entry in read.sequence(data, 'time_overrides', 'scenario', required=False):
        if not isinstance(entry, dict) or {'robot', 'operation', 'time'} - set(entry):
            read.problems.append(f"time override {entry!r} needs 'robot', 'operation' and "
                                 "'time'")
            continue
        q = operation(entry['operation'], f"time override for '{entry['robot']}'")
        if q is not None:
            overrides[str(entry['robot']), q] = read.number(
                entry['time'], f"time override for '{entry['robot']}'")

    panels = read.mapping(data, 'panels', 'scenario', required=False)
    count = panels.get('count', 1)
    if not isinstance(count, int) or isinstance(count, bool) or count < 1:
        read.problems.append(f'panels count must be a positive integer, got {count!r}')
        count = 1
    file_panels = {'count': count,
                   'shift': read.number(panels.get('shift'), 'panels shift', DEFAULT_SHIFT)}

    if read.problems:
        raise ProblemError(read.problems)
    problem = Problem(
        operation_types=operation_types, robot_types=robot_types, robots=tuple(robots),
        jobs=tuple(jobs), distances=distances, precedence=tuple(precedence),
        holding=tuple(holding), locomote=locomote, time_overrides=overrides,
        name=str(data.get('name', default_name)))
    return problem, file_panels


def _distances(read, section):
    """A full table (`names` + `rows`) and/or sparse `pairs`; both made symmetric."""
    distances = {}
    if section is None:
        return distances
    if not isinstance(section, dict):
        read.problems.append("'distances' must be a mapping with 'table' and/or 'pairs'")
        return distances
    for key in section:
        if key not in ('table', 'pairs'):
            read.problems.append(f"distances: unknown key '{key}' (expected table, pairs)")
    table = section.get('table')
    if table is not None:
        names = table.get('names') if isinstance(table, dict) else None
        rows = table.get('rows') if isinstance(table, dict) else None
        if not isinstance(names, list) or not isinstance(rows, list):
            read.problems.append("distances table needs 'names' and 'rows' lists")
        elif len(rows) != len(names):
            read.problems.append(f'distances table has {len(names)} names but {len(rows)} rows')
        else:
            for a, row in zip(names, rows, strict=True):
                if not isinstance(row, list) or len(row) != len(names):
                    read.problems.append(f"distances table row '{a}' must have {len(names)} "
                                         'entries')
                    continue
                for b, value in zip(names, row, strict=True):
                    if a != b:
                        distances[str(a), str(b)] = read.number(
                            value, f"distance '{a}'-'{b}'")
    for pair in section.get('pairs') or []:
        if not isinstance(pair, list) or len(pair) != 3:
            read.problems.append(f'distance pair {pair!r} must be [from, to, distance]')
            continue
        a, b, value = str(pair[0]), str(pair[1]), read.number(pair[2], f'distance {pair!r}')
        for key in ((a, b), (b, a)):
            if key in distances and distances[key] != value:
                read.problems.append(f"distance '{a}'-'{b}' is given twice: "
                                     f'{distances[key]} and {value}')
            distances[key] = value
    return distances

