"""YAML scenarios (format: docs/scenario-format.md) and the N-panel repetition of
docs/model.md ("Several panels").

Reading a scenario reports every problem at once: what cannot be read (a value that is not a
number, an unknown key), what lies outside the limits of `fjsp_planner.model.limits`, and what
the model check of `Problem` finds (unknown ids, cycles, holding arcs, staffing). An entry
that cannot be read is kept in a neutral form where it can be, so that it is reported once
rather than once more by every arc that names it.
"""

from fractions import Fraction
from pathlib import Path

from fjsp_common.decimals import decimals
from fjsp_planner.model import limits
from fjsp_planner.model.limits import MAX_COORDINATE, MAX_TIME, load_yaml, shown
from fjsp_planner.model.places import euclidean_distances, on_grid, panel_coordinates
from fjsp_planner.model.problem import (
    Job,
    Problem,
    ProblemError,
    Robot,
    holding_deadlocks,
    listed,
    suggestion,
)

DEFAULT_SHIFT = Fraction(60)

SECTIONS = ('name', 'operation_types', 'locomote', 'robot_types', 'robots', 'jobs',
            'locations', 'distances', 'precedence', 'holding', 'time_overrides', 'panels')
ROBOT_KEYS = ('name', 'type', 'speed', 'start_location', 'release_time')
JOB_KEYS = ('name', 'location', 'plans')
OVERRIDE_KEYS = ('robot', 'operation', 'time')
PANEL_KEYS = ('count', 'shift')
DISTANCE_KEYS = ('table', 'pairs')
TABLE_KEYS = ('names', 'rows')


class ScenarioError(ProblemError):
    """A scenario file that cannot be read; every problem found is listed."""


def load_scenario(path, panels: int | None = None, shift=None) -> Problem:
    """Read a scenario file; `panels`/`shift` override the file's own `panels` section.

    Raises `ScenarioError` listing every problem, each prefixed with the file's path.
    """
    path = Path(path)
    try:
        # Refused before reading the file: nothing is built for a size beyond the limits.
        shift = _checked_overrides(panels, shift)
        return _from_text(limits.read_input_file(path, 'scenario'), path.stem, panels, shift)
    except ProblemError as error:
        raise ScenarioError([p if p.startswith(f'{path}:') else f'{path}: {p}'
                             for p in error.problems]) from None


def scenario_from_text(text: str, name: str = 'mission', panels: int | None = None,
                       shift=None) -> Problem:
    """A scenario given as YAML text (e.g. in a mission goal), read as `load_scenario` reads
    files; `name` names it when the text has no `name` of its own."""
    try:
        shift = _checked_overrides(panels, shift)
        return _from_text(text, name, panels, shift)
    except ProblemError as error:
        raise ScenarioError(error.problems) from None


def _checked_overrides(panels, shift) -> Fraction | None:
    """`shift` read exactly; ProblemError for overrides beyond the limits."""
    problems = []
    if panels is not None:
        if isinstance(panels, bool) or not isinstance(panels, int) or panels < 1:
            problems.append(f'panels must be at least 1, got {shown(panels)}')
        else:
            problems += limits.count_problem('panels', panels, limits.MAX_PANELS)
    if shift is not None:
        try:
            shift = limits.number(shift, 'shift', Fraction(0), MAX_TIME)
        except ProblemError as error:
            problems += error.problems
    if problems:
        raise ProblemError(problems)
    return shift


def _from_text(text: str, name: str, panels, shift) -> Problem:
    problem, file_panels = _from_mapping(load_yaml(text), default_name=name, panels=panels,
                                         shift=shift)
    count = panels if panels is not None else file_panels['count']
    distance = shift if shift is not None else file_panels['shift']
    return repeat_panels(problem, count, distance)


def parse_scenario(data, name='scenario') -> Problem:
    """Build a problem from an already-parsed mapping (same format as the YAML file)."""
    return _from_mapping(data, default_name=name)[0]


def repeat_panels(problem: Problem, panels: int, shift=DEFAULT_SHIFT) -> Problem:
    """Repeat every job per panel; panels k and l are `shift * |k - l|` further apart.

    Sizes beyond `fjsp_planner.model.limits` raise `ProblemError` before anything is built.
    """
    shift = Fraction(shift)
    too_large = limits.count_problem('panels', panels, limits.MAX_PANELS) or \
        limits.scale_problems(problem.robots, problem.robot_types, problem.jobs,
                              problem.distances, problem.locomote, problem.time_overrides,
                              panels, shift)
    if too_large:
        raise ProblemError(too_large)
    if panels == 1:
        return problem

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
    used = {j.location for j in jobs} | {r.start_location for r in robots}
    return Problem(
        operation_types=problem.operation_types, robot_types=problem.robot_types,
        robots=robots, jobs=tuple(jobs), distances=distances, precedence=tuple(precedence),
        holding=tuple(holding), locomote=problem.locomote,
        time_overrides=problem.time_overrides, name=f'{problem.name} x{panels}',
        coordinates={name: point for name, point in panel_coordinates(
            problem.coordinates, panels, shift, tag).items() if name in used},
        panels=tuple(tuple(tag(j.name, k) for j in problem.jobs)
                     for k in range(1, panels + 1)))


class _Reader:
    """Collects every problem of a scenario mapping instead of stopping at the first.

    `consequences` holds what the model check would say about entries found wrong and kept
    in a neutral form (a job without plans, a robot type without efficiencies), so that it is
    not said as well: it would only repeat the problem already reported.
    """

    def __init__(self):
        self.problems = []
        self.consequences = set()

    def report(self, item: str, message: str):
        self.problems.append(message)
        self.explained(item)

    def explained(self, item: str):
        """What follows from `item` (`"job 'Aa'"`, `"robot 'R1'"`, `"robot type 'T'"`) being
        kept in its neutral form."""
        if item.startswith('job '):
            self.consequences.update({f'{item} has no process plan', f'{item}: plan ',
                                      f'{item} cannot be staffed',
                                      f'but {item} has no such operation'})
        elif item.startswith('robot type '):
            self.consequences.add(f'{item} has no efficiency for the locomote')
        else:
            self.consequences.add(f'{item}: unknown robot type')

    def attempt(self, read, fallback, item: str | None = None):
        """`read()`, or `fallback` with its problems recorded (against `item`)."""
        try:
            return read()
        except ProblemError as error:
            self.problems += error.problems
            if item is not None:
                self.explained(item)
            return fallback

    def number(self, value, what, low, high, default=None):
        if value is None and default is not None:
            return default
        fallback = default if default is not None else low
        return self.attempt(lambda: limits.number(value, what, low, high), fallback)

    def name(self, value, what):
        """The name, or None (reported) if it is not one."""
        return self.attempt(lambda: limits.name(value, what), None)

    def keys(self, entry: dict, allowed, what: str):
        """Report keys a user may have misspelt (`sped`), with the allowed ones."""
        for key in entry:
            if key in allowed:
                continue
            self.problems.append(f'{what}: unknown key {shown(key)} (allowed: '
                                 f'{", ".join(allowed)})' + suggestion(str(key), allowed))

    def mapping(self, data, key, what, required=True, limit=None):
        value = data.get(key)
        if value is None:
            if required:
                self.problems.append(f"{what}: missing '{key}'")
            return {}
        if not isinstance(value, dict):
            self.problems.append(f"{what}: '{key}' must be a mapping")
            return {}
        if limit is not None and len(value) > limit:
            self.problems += limits.count_problem(f"{what}: '{key}' entries", len(value), limit)
            return {}
        return value

    def sequence(self, data, key, what, required=True, limit=None):
        value = data.get(key)
        if value is None:
            if required:
                self.problems.append(f"{what}: missing '{key}'")
            return []
        if not isinstance(value, list):
            self.problems.append(f"{what}: '{key}' must be a list")
            return []
        if limit is not None and len(value) > limit:
            # Refused before any entry is built: a list of a million aliases costs nothing
            # to write and a great deal to read.
            self.problems += limits.count_problem(f"{what}: '{key}' entries", len(value), limit)
            return []
        return value


def _from_mapping(data, default_name, panels=None, shift=None):
    if not isinstance(data, dict):
        raise ProblemError(['the scenario must be a mapping of sections (operation_types, '
                            'robot_types, robots, jobs, ...)'])
    read = _Reader()
    read.keys(data, SECTIONS, 'scenario')

    operation_types = {}
    for key, value in read.mapping(data, 'operation_types', 'scenario',
                                   limit=limits.MAX_OPERATION_TYPES).items():
        if not isinstance(key, int) or isinstance(key, bool) or key < 0:
            read.problems.append(f'operation type id {shown(key)} must be a non-negative '
                                 'integer')
            continue
        name = read.name(value, f'operation type {key}')
        if name is not None:
            operation_types[key] = name
    by_name = {name: q for q, name in operation_types.items()}

    def operation(ref, what, item=None):
        if isinstance(ref, int) and not isinstance(ref, bool) and ref in operation_types:
            return ref
        if isinstance(ref, str) and ref in by_name:
            return by_name[ref]
        read.problems.append(f'{what}: unknown operation type {shown(ref)}'
                             + suggestion(ref, by_name))
        if item is not None:
            read.explained(item)
        return None

    locomote = data.get('locomote')
    if locomote is None and 'locomote' in by_name:
        locomote = 'locomote'
    locomote = operation(locomote, 'locomote') if locomote is not None else None

    robot_types = {}
    for key, efficiency in read.mapping(data, 'robot_types', 'scenario',
                                        limit=limits.MAX_ROBOTS).items():
        type_name = read.name(key, 'robot type')
        if type_name is None:
            continue
        item = f"robot type '{type_name}'"
        times = robot_types[type_name] = {}
        if not isinstance(efficiency, dict):
            read.report(item, f'{item}: efficiencies must be a mapping operation -> time')
            continue
        if len(efficiency) > limits.MAX_OPERATION_TYPES:
            read.report(item, f'{item}: more efficiencies than operation types')
            continue
        for ref, time in efficiency.items():
            q = operation(ref, item, item)
            if q is not None:
                times[q] = read.number(time, f'{item}, operation {shown(ref)}', Fraction(0),
                                       MAX_TIME)

    robots = []
    for index, entry in enumerate(read.sequence(data, 'robots', 'scenario',
                                                limit=limits.MAX_ROBOTS)):
        what = f'robot #{index + 1}'
        if not isinstance(entry, dict) or 'name' not in entry:
            read.problems.append(f"{what}: needs at least 'name' and 'type'")
            continue
        name = read.name(entry['name'], what)
        if name is None:
            continue
        item = f"robot '{name}'"
        read.keys(entry, ROBOT_KEYS, item)
        type_name = ''
        if 'type' not in entry:
            read.report(item, f"{item}: missing 'type'")
        else:
            type_name = read.name(entry['type'], f'{item} type')
            if type_name is None:
                read.explained(item)
                type_name = ''
        start = entry.get('start_location')
        if start is not None:
            start = read.name(start, f'{item} start_location')
        robots.append(Robot(
            name=name, type=type_name,
            speed=read.number(entry.get('speed'), f'{item} speed', limits.MIN_SPEED,
                              limits.MAX_SPEED, Fraction(1)),
            start_location=start,
            release_time=read.number(entry.get('release_time'), f'{item} release_time',
                                     Fraction(0), MAX_TIME, Fraction(0))))

    jobs = []
    for index, entry in enumerate(read.sequence(data, 'jobs', 'scenario',
                                                limit=limits.MAX_JOBS)):
        what = f'job #{index + 1}'
        if not isinstance(entry, dict) or 'name' not in entry:
            read.problems.append(f"{what}: needs at least 'name' and 'plans'")
            continue
        name = read.name(entry['name'], what)
        if name is None:
            continue
        item = f"job '{name}'"
        read.keys(entry, JOB_KEYS, item)
        location = read.name(entry.get('location', name), f'{item} location') or name
        plans = entry.get('plans')
        resolved = []
        if not isinstance(plans, list) or not all(isinstance(p, list) for p in plans):
            read.report(item, f'{item}: plans must be a list of lists of operation types')
        elif len(plans) > limits.MAX_PLANS:
            read.problems += limits.count_problem(f'{item}: plans', len(plans),
                                                  limits.MAX_PLANS)
            read.explained(item)
        elif any(len(plan) > limits.MAX_ROBOTS for plan in plans):
            read.report(item, f'{item}: a plan has more operations than the limit of '
                              f'{limits.MAX_ROBOTS} robots could ever staff')
        else:
            for plan in plans:
                ops = tuple(operation(ref, item, item) for ref in plan)
                resolved.append(tuple(q for q in ops if q is not None))
        jobs.append(Job(name, location, tuple(resolved)))

    coordinates = _locations(read, data.get('locations'), jobs, robots)
    distances = {**_placed_distances(read, coordinates),
                 **_distances(read, data.get('distances'))}

    def arcs(key, size):
        result = []
        for arc in read.sequence(data, key, 'scenario', required=False,
                                 limit=limits.MAX_ARCS):
            if not isinstance(arc, list) or len(arc) != size:
                read.problems.append(f'{key} entry {shown(arc)} must be a list of {size} '
                                     'items')
                continue
            names = [read.name(x, f'{key} entry {shown(arc)}') for x in arc[:2]]
            if None not in names:
                result.append(tuple(names) + tuple(arc[2:]))
        return result

    precedence = arcs('precedence', 2)
    holding = []
    for a, b, ref in arcs('holding', 3):
        q = operation(ref, f"holding arc ('{a}', '{b}')")
        if q is not None:
            holding.append((a, b, q))

    overrides = {}
    for entry in read.sequence(data, 'time_overrides', 'scenario', required=False,
                               limit=limits.MAX_ARCS):
        if not isinstance(entry, dict) or set(OVERRIDE_KEYS) - set(entry):
            read.problems.append(f'time override {shown(entry)} needs '
                                 f"'robot', 'operation' and 'time'")
            continue
        robot = read.name(entry['robot'], 'time override robot')
        if robot is None:
            continue
        what = f"time override for '{robot}'"
        read.keys(entry, OVERRIDE_KEYS, what)
        q = operation(entry['operation'], what)
        if q is not None:
            overrides[robot, q] = read.number(entry['time'], what, Fraction(0), MAX_TIME)

    section = read.mapping(data, 'panels', 'scenario', required=False)
    read.keys(section, PANEL_KEYS, 'panels')
    count = section.get('count', 1)
    if not isinstance(count, int) or isinstance(count, bool) or count < 1:
        read.problems.append(f'panels count must be a positive integer, got {shown(count)}')
        count = 1
    elif panels is None:
        read.problems += limits.count_problem('panels count', count, limits.MAX_PANELS)
    file_panels = {'count': count,
                   'shift': read.number(section.get('shift'), 'panels shift', Fraction(0),
                                        MAX_TIME, DEFAULT_SHIFT)}
    read.problems += limits.scale_problems(
        robots, robot_types, jobs, distances, locomote, overrides,
        panels if panels is not None else min(count, limits.MAX_PANELS),
        shift if shift is not None else file_panels['shift'])

    problem = None
    try:
        problem = Problem(
            operation_types=operation_types, robot_types=robot_types, robots=tuple(robots),
            jobs=tuple(jobs), distances=distances, precedence=tuple(precedence),
            holding=tuple(holding), locomote=locomote, time_overrides=overrides,
            coordinates=coordinates,
            name=read.attempt(lambda: limits.name(data['name'], 'name'), str(default_name))
            if 'name' in data else str(default_name))
    except ProblemError as error:
        read.problems += [p for p in error.problems
                          if not any(c in p for c in read.consequences)]
    else:
        read.problems += holding_deadlocks(problem)
    if read.problems:
        raise ProblemError(list(dict.fromkeys(read.problems)))
    return problem, file_panels


def _locations(read, section, jobs, robots) -> dict:
    """The `locations` section: each location's coordinates, read exactly. A location whose
    coordinates cannot be read is left off the map, and its missing distances that follow
    are not reported again."""
    if section is None:
        return {}
    if not isinstance(section, dict):
        read.problems.append("'locations' must be a mapping of location -> [x, y] or "
                             '[x, y, z]')
        return {}
    most = limits.MAX_JOBS + limits.MAX_ROBOTS      # every job and start at its own place
    if len(section) > most:
        read.problems += limits.count_problem('locations', len(section), most)
        return {}
    used = {j.location for j in jobs} | {r.start_location for r in robots if r.start_location}
    coordinates, unreadable = {}, set()
    for key, point in section.items():
        name = read.name(key, 'locations')
        if name is None:
            continue
        what = f"location '{name}'"
        if name not in used:
            read.problems.append(f'{what} in locations: no job is there and no robot starts '
                                 'there' + suggestion(name, used))
            continue
        if not isinstance(point, list) or len(point) not in (2, 3):
            read.problems.append(f'{what}: coordinates must be [x, y] or [x, y, z], got '
                                 f'{shown(point)}')
            unreadable.add(name)
            continue
        values = tuple(read.attempt(lambda value=value, where=f'{what} {axis}': _coordinate(
            value, where), None) for axis, value in zip('xyz', point, strict=False))
        if None in values:
            unreadable.add(name)
        else:
            coordinates[name] = values
    dimensions = {}
    for name, point in coordinates.items():
        dimensions.setdefault(len(point), name)
    if len(dimensions) > 1:
        read.problems.append(f"locations: '{dimensions[2]}' has 2 coordinates (x, y) but "
                             f"'{dimensions[3]}' has 3 (x, y, z); give every location the "
                             'same number')
        unreadable |= set(coordinates)
        coordinates = {}
    if unreadable:
        read.consequences.add('no distances are given')
    for name in unreadable:
        read.consequences.update({f"location '{name}' (",
                                  f"no distance between locations '{name}' and ",
                                  f" and '{name}'"})
    return coordinates


def _coordinate(value, what) -> Fraction:
    exact = limits.number(value, what, -MAX_COORDINATE, MAX_COORDINATE)
    if not on_grid(exact):
        raise ProblemError([f'{what}: {shown(value)} is not a whole number of millionths '
                            '(coordinates take at most 6 decimal places)'])
    return exact


def _placed_distances(read, coordinates) -> dict:
    """The Euclidean distances between placed locations; those beyond the distance limit are
    reported (the farthest pair, and how many there are)."""
    distances = euclidean_distances(coordinates)
    far = [(d, a, b) for (a, b), d in distances.items() if d > MAX_TIME and a < b]
    if far:
        d, a, b = max(far)
        more = f' ({len(far)} pairs are)' if len(far) > 1 else ''
        read.problems.append(f"locations '{a}' and '{b}' are {float(d):g} apart by their "
                             f'coordinates, more than the limit of {float(MAX_TIME):g} for a '
                             f'distance{more}')
    return distances


def _distances(read, section):
    """A full table (`names` + `rows`) and/or sparse `pairs`; both made symmetric."""
    distances = {}
    if section is None:
        return distances
    if not isinstance(section, dict):
        read.problems.append("'distances' must be a mapping with 'table' and/or 'pairs'")
        return distances
    read.keys(section, DISTANCE_KEYS, 'distances')
    most = limits.MAX_JOBS + limits.MAX_ROBOTS      # every job and start at its own place
    table = section.get('table')
    if table is not None:
        names = table.get('names') if isinstance(table, dict) else None
        rows = table.get('rows') if isinstance(table, dict) else None
        if isinstance(table, dict):
            read.keys(table, TABLE_KEYS, 'distances table')
        if not isinstance(names, list) or not isinstance(rows, list):
            read.problems.append("distances table needs 'names' and 'rows' lists")
        elif len(names) > most:
            read.problems += limits.count_problem('distances table names', len(names), most)
        elif len(rows) != len(names):
            read.problems.append(f'distances table has {len(names)} names but {len(rows)} rows')
        else:
            names = [read.name(a, 'distances table name') for a in names]
            for a, row in zip(names, rows, strict=True):
                if a is None:
                    continue
                if not isinstance(row, list) or len(row) != len(names):
                    read.problems.append(f"distances table row '{a}' must have {len(names)} "
                                         'entries')
                    continue
                for b, value in zip(names, row, strict=True):
                    if b is not None and a != b:
                        _distance(read, distances, a, b, value, symmetric=False)
    pairs = section.get('pairs') or []
    if not isinstance(pairs, list):
        read.problems.append("distances: 'pairs' must be a list of [from, to, distance]")
        pairs = []
    elif len(pairs) > most * most:
        read.problems += limits.count_problem('distance pairs', len(pairs), most * most)
        pairs = []
    for pair in pairs:
        if not isinstance(pair, list) or len(pair) != 3:
            read.problems.append(f'distance pair {shown(pair)} must be [from, to, distance]')
            continue
        a, b = (read.name(x, f'distance pair {shown(pair)}') for x in pair[:2])
        if a is None or b is None:
            continue
        _distance(read, distances, a, b, pair[2], symmetric=True)
    return distances


def _distance(read, distances, a, b, value, symmetric):
    """Record one distance; one that cannot be read is left out, and the pair's missing or
    asymmetric entry that follows is not reported again."""
    value = read.attempt(lambda: limits.number(value, f"distance '{a}'-'{b}'", Fraction(0),
                                               MAX_TIME), None)
    if value is None:
        read.consequences.update({f"'{a}'-'{b}' is not symmetric",
                                  f"'{b}'-'{a}' is not symmetric",
                                  f"no distance between locations '{a}' and '{b}'",
                                  f"no distance between locations '{b}' and '{a}'"})
        return
    for key in ((a, b), (b, a)) if symmetric else ((a, b),):
        if symmetric and key in distances and distances[key] != value:
            read.problems.append("distance '{}'-'{}' is given twice: {} and {}".format(
                a, b, *decimals(distances[key], value)))
        distances[key] = value


def scenario_warnings(problem: Problem) -> list[str]:
    """What a scenario says that probably does not mean what its author meant, though it is a
    valid problem: each names the items and what to write instead. Printed by `fjsp-solve`
    and logged by the planner and the launcher, never refused."""
    warnings = []
    placed = [r.name for r in problem.robots if r.start_location]
    if problem.locomote is None and (problem.distances or placed):
        given = [what for what, there in (
            ('distances', problem.distances),
            (f"the start location{'s' if len(placed) > 1 else ''} of "
             f"robot{'s' if len(placed) > 1 else ''} {listed(placed)}", placed)) if there]
        # The travel type is an operation type robot types have a time for but no job uses.
        used = {q for job in problem.jobs for plan in job.plans for q in plan}
        travel = [name for q, name in problem.operation_types.items() if q not in used
                  and any(q in times for times in problem.robot_types.values())]
        hint = (f"; did you mean 'locomote: {travel[0]}'?" if len(travel) == 1 else
                "; name it with 'locomote: <operation type>', or call it 'locomote'")
        warnings.append(' and '.join(given) + ' are given, but no operation type is the '
                        "travel type (none is called 'locomote', and no 'locomote:' names "
                        f'one): travel takes no time{hint}')
    return warnings


def problem_mapping(problem: Problem) -> dict:
    """`problem` as a scenario mapping (the YAML format's sections), exact numbers as
    'a/b' strings: what `parse_scenario` reads back into the same problem."""
    return {
        'name': problem.name,
        'operation_types': dict(problem.operation_types),
        **({'locomote': problem.locomote} if problem.locomote is not None else {}),
        'robot_types': {name: {q: str(t) for q, t in times.items()}
                        for name, times in problem.robot_types.items()},
        'robots': [{'name': r.name, 'type': r.type, 'speed': str(r.speed),
                    **({'start_location': r.start_location} if r.start_location else {}),
                    'release_time': str(r.release_time)} for r in problem.robots],
        'jobs': [{'name': j.name, 'location': j.location, 'plans': [list(p) for p in j.plans]}
                 for j in problem.jobs],
        **({'locations': {name: [str(c) for c in point]
                          for name, point in problem.coordinates.items()}}
           if problem.coordinates else {}),
        'distances': {'pairs': [[a, b, str(d)] for (a, b), d in problem.distances.items()
                                if a < b]},
        'precedence': [list(arc) for arc in problem.precedence],
        'holding': [list(arc) for arc in problem.holding],
        'time_overrides': [{'robot': r, 'operation': q, 'time': str(t)}
                           for (r, q), t in problem.time_overrides.items()],
    }
