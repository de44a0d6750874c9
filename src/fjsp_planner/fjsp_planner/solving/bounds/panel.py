"""The panel decomposition bounds: lower bounds on the makespan of identical panels that
hold whatever a solver found, for honest gaps.

CP-SAT's own bound on several panels stays near the one-panel critical path
(`jobs.critical_path_bound`): its linear relaxation spreads fractional robots over all
panels. The panel decomposition sees further:

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

from dataclasses import replace
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.geometry import crossing_cost
from fjsp_planner.solving.bounds.jobs import heads_and_tails, staffings


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
    heads, tails = heads_and_tails(problem)
    total, firsts, lasts, panels_in = Fraction(0), [], [], 0
    for count, allowed in ((unhelped_panels, group), (helped_panels, group | set(limits))):
        if count == 0:
            continue
        found = False
        for name in problem.panels[0]:
            ways = [s for plan in problem.job(name).plans
                    for s in staffings(problem, plan, sorted(allowed))]
            if not ways:
                return None
            if min(sum(r in group for r, _ in s) for s in ways) * 2 <= len(group):
                continue
            total += count * min(max(problem.duration(r, q) for r, q in s) for s in ways)
            firsts.append(heads[name])
            lasts.append(tails[name])
            found = True
        panels_in += count if found else 0
    if not firsts:
        return None
    moves = (panels_in - 1) * min(crossing_cost(problem, r) for r in group)
    return min(min(firsts) + total + moves + min(lasts), incumbent)


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
            for staffing in staffings(problem, plan, sorted(allowed)):
                length = max(problem.duration(r, q) for r, q in staffing)
                busy = length * sum(r in counted for r, _ in staffing)
                best = busy if best is None else min(best, busy)
        if best is None:
            return None
        total += best
    return total
