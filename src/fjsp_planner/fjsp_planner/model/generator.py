"""Random scenarios shaped like a user's own, valid by construction: the test corpus and the
benchmarks' instances.

`random_scenario(seed, ...)` returns a scenario mapping in the file format of
docs/scenario-format.md (`yaml.safe_dump` writes it as a file a user could have written;
`parse_scenario` reads it back). The same seed and shape always give the same scenario.

What it covers, drawn from the seed: 2-5 robot types and 3-10 robots with names of their own,
start locations (a few robots may start anywhere), release times, per-robot time overrides,
operation types with names of their own and a travel type that is not called `locomote`,
jobs at several places, plans of one to three robots at once, alternative plans, a layered
precedence DAG, and holding arcs within one place and across two.

Valid by construction means every scenario loads and has a schedule:
- every plan can be staffed by distinct robots able to do its operations;
- a holding arc (j, j', q) joins a job of one layer to a job of the next, every plan of both
  has the same number of q-operations, and some robots able to do q leave enough others to
  staff the rest of both jobs; a job is in at most one holding arc, so no robot is sent
  directly from one job to two;
- j' has no predecessor that follows j, so no precedence path runs around the arc: the
  holders never wait for a job that needs j done and them free;
- with every holding arc's two jobs taken as one, the precedence graph has no cycle: two arcs
  must not each need the other's first job done before their held job, or robots holding in
  both could do neither first. Doing the merged jobs one at a time in a topological order is
  then a schedule.
"""

import itertools
import math
import random
from dataclasses import dataclass
from fractions import Fraction

OPERATION_WORDS = ('grip', 'weld', 'scan', 'bolt', 'lift', 'seal', 'drill', 'inspect',
                   'fasten', 'hold panel', 'route cable', 'torque', 'align', 'clamp')
TRAVEL_WORDS = ('drive', 'fly', 'roll', 'crawl', 'move', 'traverse')
TYPE_WORDS = ('Crane', 'Rover', 'Drone', 'Arm', 'Spider', 'Tug', 'Gantry', 'Crawler',
              'Hexapod', 'Welder')
PLACE_WORDS = ('pad', 'depot', 'site', 'bay', 'yard', 'dock', 'ridge', 'hangar', 'tower',
               'crater')
JOB_WORDS = ('Lift', 'Place', 'Join', 'Set', 'Fix', 'Brace', 'Check', 'Haul', 'Mount',
             'Seal', 'Wire', 'Test')
SPEEDS = (5, 10, 15, 20, 25, 30, 40)
STAFF_ATTEMPTS = 200


@dataclass(frozen=True)
class Shape:
    """What a generated scenario looks like; `None` fields are drawn from the seed."""

    jobs: int | None = None
    """Jobs in all (default 8-30)."""
    robots: int | None = None
    """Robots (default 3-10)."""
    robot_types: int | None = None
    """Robot types (default 2-5, at most `robots`)."""
    places: int | None = None
    """Places the jobs are at (default 2-6, more for many jobs)."""
    multi_robot: float | None = None
    """Share of jobs whose plans need 2-3 robots at once (default 0.3-0.5)."""
    alternatives: float = 0.3
    """Share of jobs with 2-3 alternative plans."""
    holding: float = 0.15
    """Share of jobs that are the first job of a holding arc, where one fits."""
    across_places: float = 0.5
    """Share of holding arcs whose held job is at another place."""
    fractions: bool = True
    """Some efficiencies and overrides are fractions such as '5/2'."""


def random_scenario(seed: int, shape: Shape = Shape()) -> dict:
    """A valid scenario mapping drawn from `seed` with the given shape."""
    return _Draw(random.Random(seed), shape, seed).scenario()


class _Draw:
    def __init__(self, rng: random.Random, shape: Shape, seed: int):
        self.rng, self.shape, self.seed = rng, shape, seed

    def scenario(self) -> dict:
        rng, shape = self.rng, self.shape
        robot_count = shape.robots or rng.randint(3, 10)
        type_count = min(shape.robot_types or rng.randint(2, 5), robot_count)
        job_count = shape.jobs or rng.randint(8, 30)
        place_count = shape.places or min(rng.randint(2, 6) + job_count // 60, 40)
        multi_robot = shape.multi_robot if shape.multi_robot is not None \
            else rng.uniform(0.3, 0.5)

        work = self._names(OPERATION_WORDS, rng.randint(2, 6))
        travel = rng.choice(TRAVEL_WORDS)
        operations = work + [travel]
        rng.shuffle(operations)
        self.work = work
        types = self._robot_types(self._names(TYPE_WORDS, type_count), work, travel)
        places = self._names(PLACE_WORDS, place_count)
        robots = self._robots(types, robot_count, places)
        self.able = {q: [r['name'] for r in robots if q in types[r['type']]] for q in work}
        jobs, layers = self._jobs(job_count, places, multi_robot)
        precedence = self._precedence(layers)
        holding = self._holding(jobs, layers, precedence, places)
        starts = sorted({r['start_location'] for r in robots if 'start_location' in r})
        return {
            'name': f'generated-{self.seed}',
            'operation_types': dict(enumerate(operations)),
            'locomote': travel,
            'robot_types': types,
            'robots': robots,
            'jobs': [jobs[name] for name in itertools.chain(*layers)],
            'distances': {'pairs': self._distances(places + [p for p in starts
                                                               if p not in places])},
            'precedence': precedence,
            'holding': holding,
            'time_overrides': self._overrides(robots, types),
        }

    # --- names -------------------------------------------------------------------------

    def _names(self, words, count: int) -> list[str]:
        """`count` distinct names made from `words` (numbered once the words run out)."""
        pool = list(words)
        self.rng.shuffle(pool)
        return [pool[i % len(pool)] + ('' if i < len(pool) else str(i // len(pool) + 1))
                for i in range(count)]

    def _time(self, low: int, high: int):
        """A time in [low, high]; with `fractions`, now and then a fraction like '7/2'."""
        value = self.rng.randint(low, high)
        if self.shape.fractions and self.rng.random() < 0.15:
            return str(Fraction(2 * value + 1, 2))
        return value

    # --- fleet -------------------------------------------------------------------------

    def _robot_types(self, names, work, travel) -> dict:
        rng = self.rng
        types = {}
        for index, name in enumerate(names):
            able = [q for q in work if rng.random() < 0.5]
            # Between them, the types can do every operation.
            able.append(work[index % len(work)])
            types[name] = {q: self._time(1, 9) for q in dict.fromkeys(able)}
            types[name][travel] = rng.randint(1, 10)
        for q in work[len(names):]:
            types[rng.choice(names)][q] = self._time(1, 9)
        return types

    def _robots(self, types, count: int, places) -> list[dict]:
        rng = self.rng
        names = list(types)
        robots = []
        for i in range(count):
            kind = names[i] if i < len(names) else rng.choice(names)
            robot = {'name': f'{kind[:3].upper()}{i + 1}', 'type': kind,
                     'speed': rng.choice(SPEEDS)}
            if rng.random() < 0.85:
                robot['start_location'] = (rng.choice(places) if rng.random() < 0.7
                                           else f'base{rng.randint(1, 2)}')
            if rng.random() < 0.3:
                robot['release_time'] = rng.randint(1, 10)
            robots.append(robot)
        return robots

    def _overrides(self, robots, types) -> list[dict]:
        overrides = []
        for robot in self.rng.sample(robots, k=min(len(robots), self.rng.randint(0, 3))):
            work = [q for q in types[robot['type']] if q in self.work]
            q = self.rng.choice(work)
            overrides.append({'robot': robot['name'], 'operation': q, 'time': self._time(1, 12)})
        return overrides

    # --- jobs --------------------------------------------------------------------------

    def _jobs(self, count: int, places, multi_robot: float):
        rng = self.rng
        layer_count = max(2, min(count, round(math.sqrt(count) * rng.uniform(0.8, 1.5))))
        layers = [[] for _ in range(layer_count)]
        jobs = {}
        words = self._names(JOB_WORDS, len(JOB_WORDS))
        for i in range(count):
            name = f'{words[i % len(words)]}-{i + 1}'
            layers[i * layer_count // count].append(name)
            alternatives = rng.choice((2, 3)) if rng.random() < self.shape.alternatives else 1
            plans = _distinct([self._plan(multi_robot) for _ in range(alternatives)])
            jobs[name] = {'name': name, 'location': rng.choice(places), 'plans': plans}
        return jobs, layers

    def _plan(self, multi_robot: float, fixed=()) -> list[str]:
        """A plan staffable by distinct robots, holding the operations `fixed` among others."""
        size = self.rng.choice((2, 2, 3)) if self.rng.random() < multi_robot else 1
        size = max(size, len(fixed))
        for _ in range(STAFF_ATTEMPTS):
            plan = list(fixed) + [self.rng.choice(self.work) for _ in range(size - len(fixed))]
            if _staffable(plan, self.able, frozenset()):
                return plan
        return list(fixed) or [self.work[0]]

    def _precedence(self, layers) -> list[list[str]]:
        arcs = []
        for k in range(1, len(layers)):
            for job in layers[k]:
                earlier = layers[k - 1] if self.rng.random() < 0.8 else \
                    list(itertools.chain(*layers[:k]))
                for before in self.rng.sample(earlier, k=min(len(earlier),
                                                            self.rng.choice((0, 1, 1, 2)))):
                    arcs.append([before, job])
        return arcs

    def _holding(self, jobs, layers, precedence, places) -> list[list[str]]:
        """Holding arcs from a job of one layer to one of the next (see the module's
        docstring for why these are feasible); the jobs' plans are redrawn to fit."""
        rng = self.rng
        used, arcs = set(), []
        for k in range(len(layers) - 1):
            for source in layers[k]:
                if source in used or rng.random() >= self.shape.holding:
                    continue
                free = [j for j in layers[k + 1] if j not in used]
                if not free:
                    continue
                target = rng.choice(free)
                if target in _cycle_closers(source, arcs, precedence):
                    continue
                held = self._held_plans(rng.choice(self.work), jobs[source], jobs[target])
                if held is None:
                    continue
                q, source_plans, target_plans = held
                jobs[source]['plans'], jobs[target]['plans'] = source_plans, target_plans
                if rng.random() < self.shape.across_places:
                    elsewhere = [p for p in places if p != jobs[source]['location']]
                    jobs[target]['location'] = rng.choice(elsewhere or places)
                else:
                    jobs[target]['location'] = jobs[source]['location']
                used |= {source, target}
                arcs.append([source, target, q])
                if rng.random() < 0.5 and [source, target] not in precedence:
                    precedence.append([source, target])
        return arcs

    def _held_plans(self, q, source: dict, target: dict):
        """Plans of both jobs with the same number of q-operations, staffable with some
        holders in common (None if none are found)."""
        holders = self.rng.choice((1, 1, 2))
        if len(self.able[q]) < holders:
            return None
        fixed = [q] * holders
        for _ in range(STAFF_ATTEMPTS // 10):
            plans = [_distinct([self._plan(0.5, fixed) for _ in source['plans']]),
                     _distinct([self._plan(0.5, fixed) for _ in target['plans']])]
            if all(plan.count(q) == holders for plan in plans[0] + plans[1]) and \
                    _holdable(q, holders, plans[0] + plans[1], self.able):
                return q, plans[0], plans[1]
        return None

    # --- places ------------------------------------------------------------------------

    def _distances(self, places) -> list[list]:
        """Integer distances between points drawn on a 100 x 100 map, at least 1 apart."""
        points = {p: (self.rng.uniform(0, 100), self.rng.uniform(0, 100)) for p in places}
        return [[a, b, max(1, round(math.dist(points[a], points[b])))]
                for a, b in itertools.combinations(places, 2)]


def _distinct(plans) -> list[list[str]]:
    """The plans, each multiset of operations once."""
    return list({tuple(sorted(plan)): plan for plan in plans}.values())


def _staffable(plan, able, taken) -> bool:
    """Whether distinct robots outside `taken` can do every operation of `plan`."""
    return _matching(sorted(plan, key=lambda q: len(able[q])), able, set(taken))


def _matching(operations, able, taken) -> bool:
    if not operations:
        return True
    q, rest = operations[0], operations[1:]
    return any(_matching(rest, able, taken | {robot})
               for robot in able[q] if robot not in taken)


def _cycle_closers(source: str, arcs, precedence) -> set[str]:
    """The jobs that, held from `source`, would close a cycle in the precedence graph where
    each of `arcs` is one node: those reached from `source` through another node, and those
    `source` is reached from."""
    merged = {held: first for first, held, *_ in arcs}
    successors, predecessors = {}, {}
    for before, after in precedence:
        before, after = merged.get(before, before), merged.get(after, after)
        if before != after:
            successors.setdefault(before, set()).add(after)
            predecessors.setdefault(after, set()).add(before)
    source = merged.get(source, source)
    through = {far for near in successors.get(source, ()) for far in successors.get(near, ())}
    return _reached(through, successors) | _reached(predecessors.get(source, set()),
                                                    predecessors)


def _reached(starts: set[str], edges: dict[str, set[str]]) -> set[str]:
    """`starts` and every node reached from them along `edges`."""
    seen, todo = set(starts), list(starts)
    while todo:
        for nxt in edges.get(todo.pop(), ()):
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


def _holdable(q, holders: int, plans, able) -> bool:
    """Some `holders` robots able to do q leave, in every plan, enough other robots for its
    other operations."""
    rest = [[o for o in plan if o != q] + [o for o in plan if o == q][holders:] for plan in plans]
    return any(all(_staffable(r, able, frozenset(group)) for r in rest)
               for group in itertools.combinations(able[q], holders))
