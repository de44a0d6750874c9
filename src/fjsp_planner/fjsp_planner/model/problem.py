"""The scheduling problem of docs/model.md: plain, immutable data checked at construction.

Times are exact `Fraction`s: travel times such as distance * 10/3 must not be rounded
before a solver decides how to put them on its own grid.
"""

import difflib
import itertools
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from fractions import Fraction

from fjsp_common.decimals import decimal, decimals


class ProblemError(ValueError):
    """A scenario that cannot describe a scheduling problem; `problems` lists every reason."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__('\n'.join(self.problems))


def suggestion(word, names: Iterable) -> str:
    """`; did you mean 'X'?` naming the one of `names` closest to a misspelt `word`, or ''
    when none is close."""
    if not isinstance(word, str):
        return ''
    # Compared regardless of case: 'r1' is a slip for 'R1' whatever difflib's ratio says.
    by_lower = {n.lower(): n for n in names if isinstance(n, str)}
    close = difflib.get_close_matches(word.lower(), by_lower, n=1)
    return f"; did you mean '{by_lower[close[0]]}'?" if close else ''


@dataclass(frozen=True)
class Robot:
    name: str
    type: str
    speed: Fraction = Fraction(1)
    start_location: str | None = None
    release_time: Fraction = Fraction(0)


@dataclass(frozen=True)
class Job:
    name: str
    location: str
    plans: tuple[tuple[int, ...], ...]
    """Each plan is a multiset of operation types, done at once by distinct robots."""


@dataclass(frozen=True)
class FixedJob:
    """A job already running when the problem is posed: it keeps its plan, robots and times."""

    plan: int
    start: Fraction
    end: Fraction
    robots: Mapping[str, int]
    """robot name -> operation type it performs."""


@dataclass(frozen=True)
class Problem:
    operation_types: Mapping[int, str]
    robot_types: Mapping[str, Mapping[int, Fraction]]
    """robot type -> operation type -> time to perform it (absent: cannot)."""
    robots: tuple[Robot, ...]
    jobs: tuple[Job, ...]
    distances: Mapping[tuple[str, str], Fraction] = field(default_factory=dict)
    """Symmetric; a pair that is absent is at distance 0 only if both names are equal."""
    precedence: tuple[tuple[str, str], ...] = ()
    """(before, after): after starts no earlier than before completes."""
    holding: tuple[tuple[str, str, int], ...] = ()
    """(from, to, operation type): type-q robots of `from` do type q in `to`, directly."""
    locomote: int | None = None
    """Operation type whose efficiency scales travel; None means travel is free."""
    time_overrides: Mapping[tuple[str, int], Fraction] = field(default_factory=dict)
    """(robot, operation type) -> time, replacing the robot type's efficiency."""
    fixed: Mapping[str, FixedJob] = field(default_factory=dict)
    panels: tuple[tuple[str, ...], ...] = ()
    """Identical copies of one job set (docs/model.md, "Several panels"), job k of each
    copy matching; solvers may use this to break the symmetry between copies and to bound
    moves between them."""
    name: str = 'problem'
    coordinates: Mapping[str, tuple[Fraction, ...]] = field(default_factory=dict)
    """location -> where it is on the map, (x, y) or (x, y, z), the same for every location
    given one. `distances` already hold the Euclidean distances they imply (`places`)."""

    def __post_init__(self):
        object.__setattr__(self, '_robot_by_name', {r.name: r for r in self.robots})
        object.__setattr__(self, '_job_by_name', {j.name: j for j in self.jobs})
        object.__setattr__(self, '_travel_cache', {})
        # Every check skips what an earlier one already reported (an unknown job in an arc,
        # a robot of an unknown type), so one pass names every problem, each once.
        problems = (_structural_problems(self) + _cycle_problems(self)
                    + _holding_problems(self) + _staffing_problems(self))
        if problems:
            raise ProblemError(problems)

    def robot(self, name: str) -> Robot:
        return self._robot_by_name[name]

    def job(self, name: str) -> Job:
        return self._job_by_name[name]

    def duration(self, robot: str, operation_type: int) -> Fraction | None:
        """Time `robot` takes for one operation of the type, or None if it cannot do it."""
        override = self.time_overrides.get((robot, operation_type))
        if override is not None:
            return override
        return self.robot_types[self.robot(robot).type].get(operation_type)

    def distance(self, a: str, b: str) -> Fraction:
        if a == b:
            return Fraction(0)
        return self.distances[(a, b)]

    def travel(self, robot: str, a: str, b: str) -> Fraction:
        """Time for `robot` to move from location a to location b."""
        if self.locomote is None or a == b:
            return Fraction(0)
        key = (robot, a, b)
        if key not in self._travel_cache:
            r = self.robot(robot)
            self._travel_cache[key] = (self.distance(a, b)
                                       * self.robot_types[r.type][self.locomote] / r.speed)
        return self._travel_cache[key]

    def operation_label(self, q: int) -> str:
        """An operation type as the user wrote it, with its id: `'weld' (2)`."""
        name = self.operation_types.get(q)
        return f"'{name}' ({q})" if name is not None else str(q)

    def plan_label(self, plan) -> str:
        """A plan (a multiset of operation types) by name: `['hold' (0) x2, 'weld' (2)]`."""
        counts = Counter(plan)
        return '[' + ', '.join(self.operation_label(q) + (f' x{n}' if n > 1 else '')
                               for q, n in sorted(counts.items())) + ']'

    def locations(self) -> list[str]:
        names = {j.location for j in self.jobs}
        names.update(r.start_location for r in self.robots if r.start_location)
        return sorted(names)

    def predecessors(self, job: str) -> list[str]:
        return [a for a, b in self.precedence if b == job]

    def ancestors(self) -> dict[str, set[str]]:
        """job -> every job that must complete before it starts (holding arcs order too)."""
        before = {j.name: set() for j in self.jobs}
        arcs = list(self.precedence) + [(a, b) for a, b, _ in self.holding]
        changed = True
        while changed:
            changed = False
            for a, b in arcs:
                grown = before[b] | before[a] | {a}
                if grown != before[b]:
                    before[b], changed = grown, True
        return before


def _structural_problems(p: Problem) -> list[str]:
    """Every inconsistency of ids and numbers, each naming what is wrong."""
    problems = []
    robot_names = [r.name for r in p.robots]
    job_names = [j.name for j in p.jobs]
    for kind, names in (('robot', robot_names), ('job', job_names)):
        for name, count in Counter(names).items():
            if count > 1:
                problems.append(f"{kind} '{name}' is defined {count} times")
    jobs = set(job_names)
    robots = set(robot_names)
    if p.locomote is not None and p.locomote not in p.operation_types:
        problems.append(f'locomote operation type {p.locomote} is not a defined operation type')
    for type_name, efficiency in p.robot_types.items():
        for q, time in efficiency.items():
            if q not in p.operation_types:
                problems.append(f"robot type '{type_name}': unknown operation type {q}")
            elif time < 0:
                problems.append(f"robot type '{type_name}': negative time {decimal(time)} for "
                                f'operation type {p.operation_label(q)}')
        if p.locomote in p.operation_types and p.locomote not in efficiency:
            problems.append(f"robot type '{type_name}' has no efficiency for the locomote "
                            f'operation type {p.operation_label(p.locomote)}, so it cannot '
                            'travel')
    for r in p.robots:
        if r.type not in p.robot_types:
            problems.append(f"robot '{r.name}': unknown robot type '{r.type}'"
                            + suggestion(r.type, p.robot_types))
        if r.speed <= 0:
            problems.append(f"robot '{r.name}': speed must be positive, got "
                            f'{decimal(r.speed)}')
        if r.release_time < 0:
            problems.append(f"robot '{r.name}': negative release time "
                            f'{decimal(r.release_time)}')
    for (robot, q), time in p.time_overrides.items():
        if robot not in robots:
            problems.append(f"time override names unknown robot '{robot}'"
                            + suggestion(robot, robots))
        if q not in p.operation_types:
            problems.append(f"time override for '{robot}' names unknown operation type {q}")
        if time < 0:
            problems.append(f"time override for '{robot}', operation type "
                            f'{p.operation_label(q)}: negative time {decimal(time)}')
    for j in p.jobs:
        if not j.plans:
            problems.append(f"job '{j.name}' has no process plan")
        for index, plan in enumerate(j.plans):
            if not plan:
                problems.append(f"job '{j.name}': plan {index} has no operation")
            for q in plan:
                if q not in p.operation_types:
                    problems.append(f"job '{j.name}': plan {index} uses unknown operation "
                                    f'type {q}')
    for (a, b), d in p.distances.items():
        if d < 0:
            problems.append(f"distance '{a}'-'{b}' is negative ({decimal(d)})")
    if p.locomote in p.operation_types:
        problems.extend(_missing_distances(p))
    dimensions = {len(point) for point in p.coordinates.values()}
    if dimensions - {2, 3} or len(dimensions) > 1:
        problems.append('coordinates must all be (x, y) or all be (x, y, z); found '
                        + ' and '.join(str(d) for d in sorted(dimensions)) + ' numbers')
    for a, b in p.precedence:
        for name in (a, b):
            if name not in jobs:
                problems.append(f"precedence arc ('{a}', '{b}') names unknown job '{name}'"
                                + suggestion(name, jobs))
    for a, b, q in p.holding:
        arc = _holding_label(p, a, b, q)
        for name in (a, b):
            if name not in jobs:
                problems.append(f"{arc} names unknown job '{name}'" + suggestion(name, jobs))
        if q not in p.operation_types:
            problems.append(f'{arc}: unknown operation type {q}')
    sizes = {len(panel) for panel in p.panels}
    if len(sizes) > 1:
        problems.append(f'panels must be copies of one job set; their sizes differ: {sizes}')
    for panel in p.panels:
        for name in panel:
            if name not in jobs:
                problems.append(f"panel lists unknown job '{name}'")
    for name, fixed in p.fixed.items():
        if name not in jobs:
            problems.append(f"fixed job '{name}' is not a job")
        if fixed.end < fixed.start:
            problems.append(f"fixed job '{name}' ends before it starts")
        for robot in fixed.robots:
            if robot not in robots:
                problems.append(f"fixed job '{name}' names unknown robot '{robot}'")
    return problems


def _missing_distances(p: Problem) -> list[str]:
    """Every two places robots may travel between need a distance. A place in no distance at
    all is named once, with whatever is there, rather than once per other place: a misspelt
    name, or a start location the table forgot."""
    ordered = p.locations()
    if len(ordered) < 2:
        return []
    if not p.distances:
        return [f'no distances are given, but robots travel (operation type '
                f'{p.operation_label(p.locomote)}) between {len(ordered)} locations: '
                "'distances' must give one between every two of them"]
    named = {a for a, _ in p.distances} | {b for _, b in p.distances}
    unused = named - set(ordered)
    # On a map, such a place most likely lacks its coordinates.
    lacks = 'no coordinates and no distance' if p.coordinates else 'no distance'
    missing = [f"location '{place}' ({_there(p, place)}) has {lacks} to any other location"
               + suggestion(place, unused or named) for place in ordered if place not in named]
    placed = [place for place in ordered if place in named]
    for i, a in enumerate(placed):
        for b in placed[i + 1:]:
            if (a, b) not in p.distances or (b, a) not in p.distances:
                missing.append(f"no distance between locations '{a}' and '{b}'")
            elif p.distances[(a, b)] != p.distances[(b, a)]:
                missing.append("distance '{}'-'{}' is not symmetric: {} vs {}".format(
                    a, b, *decimals(p.distances[(a, b)], p.distances[(b, a)])))
    return missing


def _there(p: Problem, place: str) -> str:
    """What is at `place`: `jobs 'A', 'B'; start of robot 'R1'`."""
    parts = []
    for one, many, names in (('job', 'jobs', [j.name for j in p.jobs if j.location == place]),
                             ('start of robot', 'start of robots',
                              [r.name for r in p.robots if r.start_location == place])):
        if names:
            parts.append(f'{one if len(names) == 1 else many} {listed(names)}')
    return '; '.join(parts)


def listed(names, most: int = 3) -> str:
    """`'A', 'B', 'C' and 2 more`: names for a message, the first `most` of them."""
    more = f' and {len(names) - most} more' if len(names) > most else ''
    return ', '.join(f"'{n}'" for n in names[:most]) + more


def _cycle_problems(p: Problem) -> list[str]:
    """Name one cycle of the precedence graph (holding arcs order jobs too), if any."""
    successors = {j.name: [] for j in p.jobs}
    for a, b in list(p.precedence) + [(a, b) for a, b, _ in p.holding]:
        if a in successors and b in successors:
            successors[a].append(b)
    state = {}
    for root in successors:
        if root in state:
            continue
        path = [root]
        state[root] = 'open'
        stack = [iter(successors[root])]
        while stack:
            nxt = next(stack[-1], None)
            if nxt is None:
                state[path.pop()] = 'closed'
                stack.pop()
            elif state.get(nxt) == 'open':
                cycle = path[path.index(nxt):] + [nxt]
                return ['precedence cycle: ' + ' -> '.join(cycle)]
            elif nxt not in state:
                state[nxt] = 'open'
                path.append(nxt)
                stack.append(iter(successors[nxt]))
    return []


def _holding_label(p: Problem, a: str, b: str, q: int) -> str:
    return f"holding arc ('{a}', '{b}', {p.operation_label(q)})"


def _holding_problems(p: Problem) -> list[str]:
    problems = []
    seen_from, seen_to = {}, {}
    for a, b, q in p.holding:
        if a not in p._job_by_name or b not in p._job_by_name or q not in p.operation_types:
            continue
        arc = _holding_label(p, a, b, q)
        if a == b:
            problems.append(f'{arc} joins a job to itself')
            continue
        for name in (a, b):
            if not any(q in plan for plan in p.job(name).plans):
                problems.append(f'{arc} needs operation type {p.operation_label(q)} but job '
                                f"'{name}' has no such operation")
        if (a, q) in seen_from:
            problems.append(f"{arc}: job '{a}' already holds operation type "
                            f"{p.operation_label(q)} into '{seen_from[a, q]}'; a robot cannot "
                            'go directly to both')
        if (b, q) in seen_to:
            problems.append(f"{arc}: job '{b}' is already held with operation type "
                            f"{p.operation_label(q)} from '{seen_to[b, q]}'; a robot cannot "
                            'come directly from both')
        seen_from[a, q] = b
        seen_to[b, q] = a
    return problems


def holding_deadlocks(p: Problem) -> list[str]:
    """Pairs of holding arcs no schedule can hold: each held job waits (along precedence and
    holding arcs) for the other arc's first job, and the arcs need more holders than there
    are robots able to hold in either, so some robot holds in both. Doing its arcs in either
    order, it would start one held job before the first job that job waits for. Arcs into or
    out of fixed jobs are left out: their holders are given."""
    arcs = [(a, b, q) for a, b, q in p.holding if a not in p.fixed and b not in p.fixed]
    if len(arcs) < 2:
        return []
    before = p.ancestors()
    problems = []
    for (a, b, q), (c, d, r) in itertools.combinations(arcs, 2):
        if not (a in before[d] and c in before[b]):
            continue
        able = {robot.name for robot in p.robots
                if p.duration(robot.name, q) is not None or p.duration(robot.name, r) is not None}
        holders = _least_count(p, a, q) + _least_count(p, c, r)
        if holders > len(able):
            either = p.operation_label(q) + ('' if q == r else f' or {p.operation_label(r)}')
            problems.append(
                f"holding arcs ('{a}', '{b}', {p.operation_label(q)}) and ('{c}', '{d}', "
                f'{p.operation_label(r)}) cannot both be held: '
                f"'{b}' waits for '{c}' and '{d}' for '{a}', and {holders} holders among the "
                f'{len(able)} robots able to do {either} put one in both arcs, which it could '
                'do neither of first')
    return problems


def _least_count(p: Problem, job: str, q: int) -> int:
    """The fewest operations of type q in a plan of `job`: its fewest holders."""
    return min(plan.count(q) for plan in p.job(job).plans)


def _staffing_problems(p: Problem) -> list[str]:
    """A job none of whose plans can be given distinct, able robots."""
    robots = [r.name for r in p.robots if r.type in p.robot_types]
    untyped = sorted({r.name for r in p.robots} - set(robots))
    # A robot of an unknown type (reported already) may be the one meant to do the job.
    besides = (' (not counting ' + ', '.join(f"'{r}'" for r in untyped)
               + ', of unknown type)') if untyped else ''
    problems = []
    for job in p.jobs:
        if job.name in p.fixed or not job.plans:
            continue
        shortfalls = []
        for index, plan in enumerate(job.plans):
            staffed = max_staffed(p, plan, robots)
            if staffed < len(plan):
                shortfalls.append(f'plan {index} {p.plan_label(plan)} needs '
                                  f'{robots_needed(len(plan))}; {how_many_can(staffed)}')
        if len(shortfalls) == len(job.plans):
            problems.append(f"job '{job.name}' cannot be staffed: " + '; '.join(shortfalls)
                            + besides)
    return problems


def robots_needed(count: int, work: str = '') -> str:
    """`a robot able to do it`, `3 distinct robots able to do its operations`; `work` names
    what they must do instead."""
    if count == 1:
        return f"a robot able to do {work or 'it'}"
    return f"{count} distinct robots able to do {work or 'its operations'}"


def how_many_can(count: int, which: str = '') -> str:
    """`no robot can`, `2 can`; `which` qualifies them (`healthy`)."""
    who = f'{which} ' if which else ''
    return f'no {who}robot can' if count == 0 else f'{count} {who}can'


def max_staffed(p: Problem, plan, robots) -> int:
    """How many operations of `plan` can go to distinct robots among `robots` (a matching)."""
    able = [[r for r in robots if p.duration(r, q) is not None] for q in plan]
    owner = {}

    def augment(op, visited):
        for r in able[op]:
            if r in visited:
                continue
            visited.add(r)
            if r not in owner or augment(owner[r], visited):
                owner[r] = op
                return True
        return False

    return sum(augment(op, set()) for op in range(len(plan)))
