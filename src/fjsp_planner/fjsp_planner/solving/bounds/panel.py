"""Lower bounds on the makespan that hold whatever a solver found, for honest gaps.

CP-SAT's own bound on several panels stays near the one-panel critical path: its linear
relaxation spreads fractional robots over all panels. Two arguments see further:

- Critical path: the longest precedence chain at the fastest durations.
- Panel decomposition (identical panels, no running jobs): a robot whose moves between panels
  are slow (the paper's Assembler: 200 units to cross) reaches only a few panels in any
  schedule shorter than a known one. So some panels are done by the other robots alone, and
  the others' busy time is at least that many times the least busy time one panel costs them
  without help, plus what a panel costs them with every slow robot helping, for the rest.
  Spread over the other robots from their release times, that bounds the makespan. One panel
  done by the others alone also bounds it by its own optimum (solved as a 1-panel problem;
  only the proven bound of that solve is used).

The premise holds for every schedule shorter than a known one (a robot visiting m panels
needs m - 1 moves between them), so min(bound, known makespan) bounds every schedule and no
bound claims more than is proven. `panel_limits` counts the panels each slow robot can reach.
docs/solver.md gives the argument with the paper's numbers; test/solving/bounds/test_bounds.py
checks each against optima found by brute force and by the MIP.
"""

import itertools
from dataclasses import replace
from fractions import Fraction

from fjsp_planner.model.problem import Problem


def critical_path_bound(problem: Problem) -> Fraction:
    """Longest precedence chain, each job at its fastest possible duration."""
    fastest = {}
    for job in problem.jobs:
        fixed = problem.fixed.get(job.name)
        if fixed is not None:
            fastest[job.name] = fixed.end - fixed.start
            continue
        per_plan = []
        for plan in job.plans:
            times = [min((t for r in problem.robots
                          if (t := problem.duration(r.name, q)) is not None),
                         default=Fraction(0)) for q in plan]
            per_plan.append(max(times))
        fastest[job.name] = min(per_plan)
    starts = {job.name: Fraction(0) for job in problem.jobs}
    for name, fixed in problem.fixed.items():
        starts[name] = fixed.start
    ends = {}
    order = _topological(problem)
    for name in order:
        ready = max((ends[a] for a in problem.predecessors(name)), default=starts[name])
        ends[name] = max(ready, starts[name]) + fastest[name]
    return max(ends.values(), default=Fraction(0))


def _topological(problem: Problem) -> list[str]:
    before = problem.ancestors()
    return sorted(before, key=lambda name: len(before[name]))


def crossing_cost(problem: Problem, robot: str) -> Fraction:
    """Least travel time for the robot between jobs of two different panels."""
    if problem.locomote is None:
        return Fraction(0)
    r = problem.robot(robot)
    return (_panel_distance(problem) * problem.robot_types[r.type][problem.locomote]
            / r.speed)


def _panel_distance(problem: Problem) -> Fraction:
    """Least distance between locations of jobs in two different panels, computed once per
    problem (pairs of panels times pairs of jobs: ~500 000 look-ups on 84 panels)."""
    cached = problem.__dict__.get('_panel_distance')
    if cached is None:
        places = [{problem.job(j).location for j in names} for names in problem.panels]
        cached = min(problem.distance(a, b) for k, first in enumerate(places)
                     for second in places[k + 1:] for a in first for b in second)
        object.__setattr__(problem, '_panel_distance', cached)
    return cached


def least_travel(problem: Problem, robot: str, a: str, b: str, across: bool = False
                 ) -> Fraction:
    """Least time for the robot from job a's place to job b's place, naming the jobs by
    their copies in the first panel: both in one panel, or `across`, a in one panel and b in
    another. Whatever it does in between: the distance table need not obey the triangle
    inequality (the paper's does not: `M1` to `Ja` is 43, through `Ac` 35), so the direct
    travel is no bound on the time between two jobs of a robot that works elsewhere in
    between (`_panel_paths`)."""
    if problem.locomote is None or (a == b and not across):
        return Fraction(0)
    r = problem.robot(robot)
    return (_panel_paths(problem)[across][a, b]
            * problem.robot_types[r.type][problem.locomote] / r.speed)


def _panel_paths(problem: Problem) -> dict[bool, dict[tuple[str, str], Fraction]]:
    """{False: inside, True: across}, each (job, job) of the first panel -> a least distance
    along job places, computed once per problem (at least two panels).

    A path from one place to another either stays in a panel or crosses at least once, and
    one that leaves a panel and comes back crosses twice, each at least the least distance D
    between two panels: so inside one panel, the shortest path (Floyd-Warshall, over its job
    places, each step at most 2 D), the least over panels. From a panel to another: a way
    inside the first to its last place x there, a single step to the first place z in the
    second (at least the least distance from a copy of x to a copy of z in another panel)
    or two crossings, then a way inside the second."""
    cached = problem.__dict__.get('_panel_paths')
    if cached is None:
        names = problem.panels[0]
        copies = [[problem.job(name).location for name in panel] for panel in problem.panels]
        detour = 2 * _panel_distance(problem)
        indices = range(len(names))
        inside = {}
        for places in copies:
            paths = {(i, j): min(problem.distance(places[i], places[j]), detour)
                     for i in indices for j in indices}
            for via in indices:
                for i in indices:
                    for j in indices:
                        paths[i, j] = min(paths[i, j], paths[i, via] + paths[via, j])
            inside = {key: min(found, inside.get(key, found)) for key, found in paths.items()}
        step = {(i, j): min(min(problem.distance(first[i], second[j])
                                for k, first in enumerate(copies)
                                for m, second in enumerate(copies) if k != m), detour)
                for i in indices for j in indices}
        # The least over x and z, taken one at a time: n^3 steps, not n^4 (a 2-panel problem
        # of 75 jobs a panel would spend half a minute here).
        to_other = {(i, z): min(inside[i, x] + step[x, z] for x in indices)
                    for i in indices for z in indices}
        across = {(i, j): min(to_other[i, z] + inside[z, j] for z in indices)
                  for i in indices for j in indices}
        cached = {False: {(names[i], names[j]): found for (i, j), found in inside.items()},
                  True: {(names[i], names[j]): found for (i, j), found in across.items()}}
        object.__setattr__(problem, '_panel_paths', cached)
    return cached


def panel_limits(problem: Problem, incumbent: Fraction) -> dict[str, int]:
    """robot -> how many panels it can work in without ending after `incumbent`, for the
    robots that cannot reach every panel: visiting m panels takes m - 1 moves between panels,
    so (m - 1) * crossing + release <= incumbent."""
    if len(problem.panels) < 2 or problem.fixed:
        return {}
    limits = {}
    for robot in problem.robots:
        cost = crossing_cost(problem, robot.name)
        if cost <= 0:
            continue
        most = int((incumbent - robot.release_time) // cost) + 1
        if most < len(problem.panels):
            limits[robot.name] = max(most, 1)
    return limits


def panel_energy_bound(problem: Problem, incumbent: Fraction) -> Fraction | None:
    """The busy-time bound of the module docstring, or None when the premise fails.

    Valid for every schedule shorter than `incumbent`, so min(bound, incumbent) bounds all."""
    limits = panel_limits(problem, incumbent)
    others = [r for r in problem.robots if r.name not in limits]
    helped_panels = sum(limits.values())
    unhelped_panels = len(problem.panels) - helped_panels
    if not limits or not others or unhelped_panels < 1:
        return None
    names = {r.name for r in others}
    unhelped = _panel_energy(problem, names, names)
    helped = _panel_energy(problem, names, names | set(limits))
    if unhelped is None:
        return None
    energy = unhelped_panels * unhelped + helped_panels * helped
    releases = sum(r.release_time for r in others)
    return min((energy + releases) / len(others), incumbent)


def panel_clique_bound(problem: Problem, incumbent: Fraction) -> Fraction | None:
    """The robots `panel_limits` does not limit, G, run every job needing more than half of
    them one after another: two such jobs together would need more robots of G than exist.

    So the makespan is at least the earliest such a job can start, plus their least
    durations over all panels (panels the limited robots cannot reach counted without them),
    plus one move between panels per panel change (two consecutive such jobs share a robot of
    G), plus the least time after such a job ends. Valid for every schedule shorter than
    `incumbent`, so min(bound, incumbent) bounds all. None when the premise fails."""
    limits = panel_limits(problem, incumbent)
    group = {r.name for r in problem.robots if r.name not in limits}
    helped_panels = min(len(problem.panels), sum(limits.values()))
    unhelped_panels = len(problem.panels) - helped_panels
    if not limits or not group or unhelped_panels < 1:
        return None
    heads, tails = _heads_and_tails(problem)
    total, firsts, lasts, panels_in = Fraction(0), [], [], 0
    for count, allowed in ((unhelped_panels, group), (helped_panels, group | set(limits))):
        if count == 0:
            continue
        found = False
        for name in problem.panels[0]:
            staffings = [s for plan in problem.job(name).plans
                         for s in _staffings(problem, plan, sorted(allowed))]
            if not staffings:
                return None
            if min(sum(r in group for r, _ in s) for s in staffings) * 2 <= len(group):
                continue
            total += count * min(max(problem.duration(r, q) for r, q in s) for s in staffings)
            firsts.append(heads[name])
            lasts.append(tails[name])
            found = True
        panels_in += count if found else 0
    if not firsts:
        return None
    moves = (panels_in - 1) * min(crossing_cost(problem, r) for r in group)
    return min(min(firsts) + total + moves + min(lasts), incumbent)


def _heads_and_tails(problem: Problem):
    """job -> least time before it can start / after it ends, along precedence chains at the
    fastest durations (panel copies have the same heads and tails as panel 0)."""
    fastest = {}
    for job in problem.jobs:
        fastest[job.name] = min(
            max(min((t for r in problem.robots if (t := problem.duration(r.name, q)) is not None),
                    default=Fraction(0)) for q in plan) for plan in job.plans)
    order = _topological(problem)
    heads = {}
    for name in order:
        heads[name] = max((heads[a] + fastest[a] for a in problem.predecessors(name)),
                          default=Fraction(0))
    successors = {name: [] for name in order}
    for a, b in problem.precedence:
        successors[a].append(b)
    tails = {}
    for name in reversed(order):
        tails[name] = max((fastest[b] + tails[b] for b in successors[name]),
                          default=Fraction(0))
    return heads, tails


def unhelped_panel(problem: Problem, incumbent: Fraction) -> Problem | None:
    """One panel as a problem of its own, staffed without the robots `panel_limits` keeps
    from some panel, or None when every panel may get them all or the others cannot staff
    it. Its optimum bounds every schedule shorter than `incumbent`."""
    limits = panel_limits(problem, incumbent)
    if not limits or len(problem.panels) <= sum(limits.values()):
        return None
    return one_panel(problem, without=set(limits))


def one_panel(problem: Problem, without=frozenset()) -> Problem | None:
    """The first panel as a problem of its own, without the robots `without` (None if the
    others cannot staff it)."""
    from fjsp_planner.model.problem import ProblemError

    names = set(problem.panels[0])
    try:
        return replace(
            problem, robots=tuple(r for r in problem.robots if r.name not in without),
            jobs=tuple(j for j in problem.jobs if j.name in names),
            precedence=tuple((a, b) for a, b in problem.precedence if a in names),
            holding=tuple(h for h in problem.holding if h[0] in names),
            time_overrides={k: v for k, v in problem.time_overrides.items()
                            if k[0] not in without},
            panels=(), name=f'{problem.name}: one panel' + (
                f' without {", ".join(sorted(without))}' if without else ''))
    except ProblemError:
        return None


def _panel_energy(problem: Problem, counted, allowed) -> Fraction | None:
    """Least busy time of the `counted` robots over one panel's jobs, staffed from `allowed`.

    A robot on a job is busy for the whole job, which lasts as long as its slowest operation.
    """
    total = Fraction(0)
    for name in problem.panels[0]:
        best = None
        for plan in problem.job(name).plans:
            for staffing in _staffings(problem, plan, sorted(allowed)):
                length = max(problem.duration(r, q) for r, q in staffing)
                busy = length * sum(r in counted for r, _ in staffing)
                best = busy if best is None else min(best, busy)
        if best is None:
            return None
        total += best
    return total


def _staffings(problem, plan, robots):
    for chosen in itertools.permutations(robots, len(plan)):
        staffing = tuple(zip(chosen, plan, strict=True))
        if all(problem.duration(r, q) is not None for r, q in staffing):
            yield staffing


