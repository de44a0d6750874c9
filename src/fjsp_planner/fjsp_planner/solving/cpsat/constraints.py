"""The constraints of the CP-SAT model, one function per rule of the problem, plus the cuts.

Rules: robots do one job at a time (`no_overlap`), precedence, routes (travel between
consecutive jobs, release times and start locations) and holding arcs. Cuts only remove
schedules no better than a known one, or tighten the linear relaxation; each says why it is
valid (docs/solver.md has the argument in full).
"""

from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds import panel as bounds
from fjsp_planner.solving.bounds.geometry import crossing_cost, least_job_travel
from fjsp_planner.solving.cpsat.grid import TimeGrid
from fjsp_planner.solving.cpsat.variables import JobVariables, RouteVariables, check


def no_overlap(m, jobs: JobVariables):
    for intervals in jobs.busy.values():
        m.add_no_overlap(intervals)


def precedence(m, problem: Problem, jobs: JobVariables):
    for a, b in problem.precedence:
        m.add(jobs.start[b] >= jobs.end[a])


def routes(m, problem: Problem, grid: TimeGrid, jobs: JobVariables, route: RouteVariables,
           legs, deadline=None, clock=None):
    """One circuit per robot; an arc a -> b forces end_a + travel(a, b) <= start_b."""
    by_robot = {}
    for (a, b, owner), arc in route.arcs.items():
        by_robot.setdefault(owner, []).append((a, b, arc))
    for robot in problem.robots:
        r = robot.name
        mine = route.nodes[r]
        if not mine:
            continue
        if not route.routed:
            if robot.release_time > 0:
                for a in mine:
                    if a not in problem.fixed:
                        m.add(jobs.start[a] >= grid.ticks(robot.release_time)
                              ).only_enforce_if(jobs.on_job[a, r])
            continue
        node = {name: i + 1 for i, name in enumerate(mine)}
        used = route.used[r]
        m.add_max_equality(used, [jobs.on_job[j, r] for j in mine])
        arcs = [(0, 0, ~used)]
        for a in mine:
            on, first = jobs.on_job[a, r], route.first[a, r]
            arcs += [(node[a], node[a], ~on), (0, node[a], first), (node[a], 0, route.last[a, r])]
            if a not in problem.fixed:
                ready = robot.release_time
                if robot.start_location is not None:
                    ready += problem.travel(r, robot.start_location, problem.job(a).location)
                m.add(jobs.start[a] >= grid.ticks(ready)).only_enforce_if(first)
                # After a fixed (running) job the route bounds the start only by that job's
                # end, which may lie before the release time.
                if robot.release_time > 0:
                    m.add(jobs.start[a] >= grid.ticks(robot.release_time)).only_enforce_if(on)
        for count, (a, b, arc) in enumerate(by_robot.get(r, ())):
            if count % 200 == 0:
                check(deadline, clock)
            arcs.append((node[a], node[b], arc))
            leg = grid.ticks(legs[r, problem.job(a).location, problem.job(b).location])
            m.add(jobs.start[b] >= jobs.end[a] + leg).only_enforce_if(arc)
        m.add_circuit(arcs)


def travel_between_jobs(m, problem: Problem, grid: TimeGrid, jobs: JobVariables,
                        route: RouteVariables, deadline=None, clock=None):
    """A robot doing two jobs at different places travels between them, whatever it does in
    between: the later starts at least the least travel time along the distance table after
    the earlier ends (the order left open unless precedence fixes it).

    Implied by the routes, which state it only for consecutive jobs once the arcs are
    chosen: stated for every pair, it moves the starts as soon as the robots are, so the
    search prunes staffings whose travel cannot fit (the proof of small scenarios, see
    docs/solver.md). Quadratic in each robot's jobs; running jobs are left out.

    Returns (a, b, robot) -> the literal "a comes before b", for hints."""
    orders = {}
    ancestors = problem.ancestors()
    for robot in problem.robots:
        r = robot.name
        mine = [j for j in route.nodes[r] if j not in problem.fixed]
        for i, a in enumerate(mine):
            check(deadline, clock)
            for b in mine[i + 1:]:
                if problem.job(a).location == problem.job(b).location:
                    continue
                both = [jobs.on_job[a, r], jobs.on_job[b, r]]
                after_a = jobs.end[a] + grid.ticks(least_job_travel(problem, r, a, b))
                after_b = jobs.end[b] + grid.ticks(least_job_travel(problem, r, b, a))
                if a in ancestors[b]:
                    m.add(jobs.start[b] >= after_a).only_enforce_if(both)
                elif b in ancestors[a]:
                    m.add(jobs.start[a] >= after_b).only_enforce_if(both)
                else:
                    a_first = orders[a, b, r] = m.new_bool_var(f'before_{a}_{b}_{r}')
                    m.add(jobs.start[b] >= after_a).only_enforce_if(both + [a_first])
                    m.add(jobs.start[a] >= after_b).only_enforce_if(both + [~a_first])
    return orders


def holding(m, problem: Problem, jobs: JobVariables, route: RouteVariables):
    """(a, b, q): a's type-q robots do type q in b, and go there directly."""
    for a, b, q in problem.holding:
        for r in jobs.robots:
            in_a = sum(lit for _, t, lit in jobs.does.get((a, r), ()) if t == q)
            in_b = sum(lit for _, t, lit in jobs.does.get((b, r), ()) if t == q)
            if isinstance(in_a, int) and isinstance(in_b, int):
                continue
            m.add(in_a == in_b)
            if (a, b, r) in route.arcs:
                m.add(route.arcs[a, b, r] >= in_a)
            else:
                m.add(in_a == 0)


def makespan_covers_work(m, problem: Problem, grid: TimeGrid, jobs: JobVariables, makespan,
                         legs) -> dict:
    """A robot's release time, the jobs it does and one leg into each place it works at fit
    before the makespan.

    Implied by no-overlap and the routes, but as one linear inequality per robot it reaches
    the LP, which otherwise spreads the work thin over fractional assignments. A robot is
    busy for the whole job: at least its own operation and the plan's fastest duration (each
    operation by its fastest robot). A robot goes straight from one job to the next, so it
    enters each place it works at other than its start location at least once, by a leg no
    shorter than the least from any other place (a robot that may start anywhere enters its
    first place for free). With running jobs, where a robot already is at a job's place,
    only the work counts.

    Returns (robot, place) -> the literal "the robot works at the place", for hints."""
    visits = {}
    fastest = {}
    for job in problem.jobs:
        for index, plan in enumerate(job.plans):
            fastest[job.name, index] = max(
                min(t for r in jobs.robots if (t := problem.duration(r, q)) is not None)
                for q in plan)
    places = sorted({job.location for job in problem.jobs})
    for robot in problem.robots:
        r = robot.name
        mine = [j.name for j in problem.jobs
                if (j.name, r) in jobs.does and j.name not in problem.fixed]
        if not mine:
            continue
        work = sum(lit * grid.ticks(max(problem.duration(r, q), fastest[j, index]))
                   for j in mine for index, q, lit in jobs.does[j, r])
        entries = []
        if problem.locomote is not None and not problem.fixed:
            for place in sorted({problem.job(j).location for j in mine}):
                if place == robot.start_location:
                    continue
                sources = [a for a in places if a != place]
                if robot.start_location is not None:
                    sources.append(robot.start_location)
                leg = min((grid.ticks(legs[r, a, place]) for a in sources if a != place),
                          default=0)
                if leg > 0:
                    visit = visits[r, place] = m.new_bool_var(f'visits_{place}_{r}')
                    m.add_max_equality(visit, [jobs.on_job[j, r] for j in mine
                                               if problem.job(j).location == place])
                    entries.append((visit, leg))
        travel = sum(visit * leg for visit, leg in entries)
        if robot.start_location is None and entries:
            travel -= max(leg for _, leg in entries)
        m.add(work + travel + grid.ticks(robot.release_time) <= makespan)
    return visits


class PanelVariables:
    def __init__(self):
        self.visits = {}
        """robot -> one literal per panel: the robot does some job of it."""
        self.crossings = {}
        self.symmetry = None
        """(robot, first panel, last panel) when mirrored panels are cut off."""
        self.limits = {}
        """robot -> most panels it may visit: more would make it no shorter than a known
        schedule (`bounds.panel_limits`)."""


def panels(m, problem: Problem, grid: TimeGrid, jobs: JobVariables, makespan,
           incumbent: Fraction | None) -> PanelVariables:
    """Cuts for identical panels (docs/model.md, "Several panels"; no running jobs):

    - a robot's work, its release time and its moves between panels fit in the makespan;
    - a robot visits at most the panels it can reach within a known schedule's makespan
      (`incumbent`, `bounds.panel_limits`): visiting more makes a schedule no shorter, and
      the known schedule itself stays allowed;
    - mirrored solutions (panel k <-> N+1-k) are searched only once.
    """
    out = PanelVariables()
    if len(problem.panels) < 2 or problem.fixed:
        return out
    costs = {}
    out.limits = bounds.panel_limits(problem, incumbent) if incumbent is not None else {}
    for robot in problem.robots:
        r = robot.name
        visits = []
        for k, names in enumerate(problem.panels):
            on = [jobs.on_job[j, r] for j in names if (j, r) in jobs.on_job]
            visit = m.new_bool_var(f'visits_panel_{k + 1}_{r}')
            m.add_max_equality(visit, on or [0])
            visits.append(visit)
        out.visits[r] = visits
        cost = costs[r] = crossing_cost(problem, r)
        crossings = out.crossings[r] = m.new_int_var(0, len(problem.panels),
                                                     f'panel_crossings_{r}')
        m.add(crossings >= sum(visits) - 1)
        work = sum(jobs.longest[j, r] for j in jobs.jobs_of(r, [j.name for j in problem.jobs]))
        m.add(work + grid.ticks(cost) * crossings + grid.ticks(robot.release_time) <= makespan)
        most = out.limits.get(r)
        if most is not None:
            m.add(sum(visits) <= most)
    if any(r.start_location for r in problem.robots):
        return out
    slowest = max(costs, key=costs.get)
    first, last = problem.panels[0], problem.panels[-1]
    m.add(sum(jobs.on_job[j, slowest] for j in first if (j, slowest) in jobs.on_job)
          >= sum(jobs.on_job[j, slowest] for j in last if (j, slowest) in jobs.on_job))
    out.symmetry = (slowest, first, last)
    return out
