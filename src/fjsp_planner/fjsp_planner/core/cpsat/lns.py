"""Large-neighbourhood search over the CP-SAT model: keep most of a schedule, re-solve the rest.

With two workers, CP-SAT on a whole 5-panel model spends its time on a search tree too wide
to improve a schedule of 60 jobs; a copy of the model where every job outside a small
neighbourhood keeps its incumbent staffing is solved in a fraction of a second. The
neighbourhoods relax, in turn, one or two panels, the jobs of one robot, or a window of
consecutive jobs in time; the staffing of every other job is fixed, its times and the routes
stay free, and so does the order among them except that jobs outside keep theirs; a
solution of the copy is a solution of the model.
"""

import random
import time

from fjsp_planner.core.cpsat.model import CpsatModel
from fjsp_planner.core.schedule import Schedule

STEP_SECONDS = 1.0
"""Wall time of one neighbourhood solve: long enough to re-sequence two panels (24 jobs)."""
WINDOW_JOBS = 16
MIN_STEP_SECONDS = 0.5


def improve(model: CpsatModel, incumbent: Schedule, deadline: float, workers: int,
            run, seed: int = 0) -> Schedule:
    """The best schedule found from `incumbent` by deadline (time.monotonic())."""
    rng = random.Random(seed)
    best = incumbent
    neighbourhoods = _neighbourhoods(model)
    step = 0
    # A step also spends Python time copying and hinting the model: start one only with room.
    while deadline - time.monotonic() > MIN_STEP_SECONDS and neighbourhoods:
        relaxed = neighbourhoods[step % len(neighbourhoods)](best, rng)
        step += 1
        candidate = _solve_neighbourhood(model, best, relaxed,
                                         min(STEP_SECONDS, deadline - time.monotonic()),
                                         workers, run)
        if candidate is not None and candidate.makespan < best.makespan:
            best = candidate
    return best


def _neighbourhoods(model: CpsatModel):
    p = model.problem
    names = [j.name for j in p.jobs if j.name not in p.fixed]
    out = []
    if len(p.panels) >= 2:
        def two_panels(_, rng):
            first, second = rng.sample(range(len(p.panels)), 2)
            return set(p.panels[first]) | set(p.panels[second])
        out.append(two_panels)

        def one_panel(_, rng):
            return set(p.panels[rng.randrange(len(p.panels))])
        out.append(one_panel)
    robots = [r.name for r in p.robots]

    def one_robot(incumbent, rng):
        robot = rng.choice(robots)
        return {j for j in incumbent.sequences.get(robot, ()) if j not in p.fixed}
    out.append(one_robot)

    def window(incumbent, rng):
        ordered = sorted(names, key=lambda j: incumbent.jobs[j].start)
        size = min(WINDOW_JOBS, len(ordered))
        first = rng.randrange(0, len(ordered) - size + 1)
        return set(ordered[first:first + size])
    out.append(window)
    if len(names) <= WINDOW_JOBS:
        return []
    return out


def _solve_neighbourhood(model: CpsatModel, incumbent: Schedule, relaxed, seconds, workers,
                         run):
    p, v = model.problem, model.jobs
    copy = model.model.clone()
    for name in v.start:
        if name in relaxed or name in p.fixed:
            continue
        a = incumbent.jobs[name]
        copy.add(_same(copy, v.plan[name, a.plan]) == 1)
        for r in v.robots:
            for index, q, lit in v.does.get((name, r), ()):
                if not isinstance(lit, int):
                    copy.add(_same(copy, lit) == int(index == a.plan and a.robots.get(r) == q))
    # Jobs outside the neighbourhood keep their order on each robot: an arc between two of
    # them that are not consecutive in the incumbent stays unused (a relaxed job may still be
    # inserted between consecutive ones). This drops most route arcs from the copy, which
    # otherwise spends its second in presolve.
    successor = {(a, r): b for r, route in incumbent.sequences.items()
                 for a, b in zip(route, route[1:], strict=False)}
    for (a, b, r), arc in model.routes.arcs.items():
        if a in relaxed or b in relaxed or successor.get((a, r)) == b:
            continue
        copy.add(_same(copy, arc) == 0)
    copy.add(_same(copy, model.makespan) < model.grid.ticks(incumbent.makespan))
    copy.clear_hints()
    _hint(copy, model, incumbent)
    solver, _, status = run(copy, seconds, workers, False)
    if status not in ('OPTIMAL', 'FEASIBLE'):
        return None
    return model.read(solver)


def _same(copy, variable):
    """The clone's variable with the index of `variable` in the original model."""
    return copy.get_int_var_from_proto_index(variable.index) if hasattr(
        variable, 'index') else variable


def _hint(copy, model: CpsatModel, incumbent: Schedule):
    """The incumbent as the clone's hint: hints live in the proto, so hint the original and
    copy them over."""
    model.model.clear_hints()
    model.add_hint(incumbent)
    copy.proto.solution_hint.copy_from(model.model.proto.solution_hint)
