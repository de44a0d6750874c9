"""Where jobs lie and the least a robot can spend moving between them, for every bound and
for the mission tracker.

A distance table need not obey the triangle inequality (the paper's does not: `M1` to `Ja`
is 43, through `Ac` 35), so the direct distance is no bound on the time between two jobs of a
robot that works elsewhere in between: bounds read least distances along the table
(`LeastDistances`), computed by one shortest-path routine.
"""

import math
from fractions import Fraction

from fjsp_planner.model.problem import Problem


class LeastDistances:
    """Least distances along the arcs of a square matrix (`None`: no arc), one source row at
    a time, each computed once (Dijkstra on a dense graph).

    The search runs on integers (every entry times their common denominator): sums of
    Fractions would make the all-pairs search most of a bound's time."""

    def __init__(self, matrix):
        self._scale = math.lcm(*(d.denominator for row in matrix for d in row
                                 if d is not None))
        self._arcs = [[None if d is None else d.numerator * self._scale // d.denominator
                       for d in row] for row in matrix]
        self._rows = {}

    def row(self, source: int) -> list[Fraction | None]:
        """Least distance from node `source` to each node (None: unreachable)."""
        found = self._rows.get(source)
        if found is None:
            arcs = self._arcs
            best = list(arcs[source])
            best[source] = 0
            todo = set(range(len(arcs))) - {source}
            while todo:
                nearest = min(todo, key=lambda k: math.inf if best[k] is None else best[k])
                todo.remove(nearest)
                if best[nearest] is None:
                    break
                onward = arcs[nearest]
                for k in todo:
                    step = onward[k]
                    if step is not None and (best[k] is None or best[nearest] + step < best[k]):
                        best[k] = best[nearest] + step
            found = [None if d is None else Fraction(d, self._scale) for d in best]
            self._rows[source] = found
        return found


def travel_factor(problem: Problem, robot: str) -> Fraction:
    """Time the robot takes per unit of distance (0 when travel is free)."""
    if problem.locomote is None:
        return Fraction(0)
    r = problem.robot(robot)
    return problem.robot_types[r.type][problem.locomote] / r.speed


def location_distance(problem: Problem, a: str, b: str) -> Fraction:
    """Least distance from location `a` to location `b` along the distance table, through
    any locations of the problem (0 if b cannot be reached), computed once per problem and
    source."""
    cached = problem.__dict__.get('_location_distances')
    if cached is None:
        places = problem.locations()
        matrix = [[Fraction(0) if p == q else problem.distances.get((p, q)) for q in places]
                  for p in places]
        cached = ({p: k for k, p in enumerate(places)}, LeastDistances(matrix))
        object.__setattr__(problem, '_location_distances', cached)
    index, least = cached
    return least.row(index[a])[index[b]] or Fraction(0)


def least_job_travel(problem: Problem, robot: str, first: str, second: str) -> Fraction:
    """Least time for the robot from job `first`'s place to job `second`'s, whatever it does
    in between."""
    return least_location_travel(problem, robot, problem.job(first).location,
                                 problem.job(second).location)


def least_location_travel(problem: Problem, robot: str, a: str, b: str) -> Fraction:
    """Least time for the robot from location `a` to location `b`, whatever it does in
    between."""
    if problem.locomote is None:
        return Fraction(0)
    return location_distance(problem, a, b) * travel_factor(problem, robot)


def panel_distance(problem: Problem) -> Fraction:
    """Least distance between locations of jobs in two different panels, computed once per
    problem (pairs of panels times pairs of jobs: ~500 000 look-ups on 84 panels)."""
    cached = problem.__dict__.get('_panel_distance')
    if cached is None:
        places = [{problem.job(j).location for j in names} for names in problem.panels]
        cached = min(problem.distance(a, b) for k, first in enumerate(places)
                     for second in places[k + 1:] for a in first for b in second)
        object.__setattr__(problem, '_panel_distance', cached)
    return cached


def crossing_cost(problem: Problem, robot: str) -> Fraction:
    """Least travel time for the robot between jobs of two different panels."""
    return panel_distance(problem) * travel_factor(problem, robot)


def least_travel(problem: Problem, robot: str, a: str, b: str, across: bool = False
                 ) -> Fraction:
    """Least time for the robot from job a's place to job b's place, naming the jobs by
    their copies in the first panel: both in one panel, or `across`, a in one panel and b in
    another, whatever it does in between (`panel_paths`)."""
    if problem.locomote is None or (a == b and not across):
        return Fraction(0)
    return panel_paths(problem)[across][a, b] * travel_factor(problem, robot)


def panel_paths(problem: Problem) -> dict[bool, dict[tuple[str, str], Fraction]]:
    """{False: inside, True: across}, each (job, job) of the first panel -> a least distance
    along job places, computed once per problem (at least two panels).

    A path from one place to another either stays in a panel or crosses at least once, and
    one that leaves a panel and comes back crosses twice, each at least the least distance D
    between two panels: so inside one panel, the shortest path over its job places, each
    step at most 2 D, the least over panels. From a panel to another: a way inside the first
    to its last place x there, a single step to the first place z in the second (at least the
    least distance from a copy of x to a copy of z in another panel) or two crossings, then a
    way inside the second."""
    cached = problem.__dict__.get('_panel_paths')
    if cached is None:
        names = problem.panels[0]
        copies = [[problem.job(name).location for name in panel] for panel in problem.panels]
        detour = 2 * panel_distance(problem)
        indices = range(len(names))
        inside = {}
        for places in copies:
            least = LeastDistances([[min(problem.distance(places[i], places[j]), detour)
                                     for j in indices] for i in indices])
            paths = {(i, j): least.row(i)[j] for i in indices for j in indices}
            inside = {key: min(found, inside.get(key, found)) for key, found in paths.items()}
        step = {(i, j): min(min(problem.distance(first[i], second[j])
                                for k, first in enumerate(copies)
                                for m, second in enumerate(copies) if k != m), detour)
                for i in indices for j in indices}
        # The least over x and z, taken one at a time: n^3 steps, not n^4.
        to_other = {(i, z): min(inside[i, x] + step[x, z] for x in indices)
                    for i in indices for z in indices}
        across = {(i, j): min(to_other[i, z] + inside[z, j] for z in indices)
                  for i in indices for j in indices}
        cached = {False: {(names[i], names[j]): found for (i, j), found in inside.items()},
                  True: {(names[i], names[j]): found for (i, j), found in across.items()}}
        object.__setattr__(problem, '_panel_paths', cached)
    return cached


def least_leg_into(problem: Problem, robot: str, place: str) -> Fraction:
    """Least time for the robot to reach `place` from any other place it could be at (a job's
    location or its start location): a robot goes straight from one job to the next, so it
    enters a place it works at, other than where it starts, by such a leg."""
    sources = {job.location for job in problem.jobs}
    start = problem.robot(robot).start_location
    if start is not None:
        sources.add(start)
    sources.discard(place)
    return min((problem.travel(robot, source, place) for source in sources),
               default=Fraction(0))
