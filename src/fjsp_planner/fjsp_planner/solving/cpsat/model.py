"""The CP-SAT model of the problem of docs/model.md (see docs/solver.md): variables,
constraints and objective put together, a schedule turned into a hint, and a solution read
back as an exact schedule.

Per job: one master start/end shared by an optional interval on every robot able to work on
it. Per robot: one circuit over a depot and its jobs; an arc a -> b forces
end_a + travel(a, b) <= start_b, and a holding arc (j, j', q) forces the arc j -> j' for every
robot doing type q in j.
"""

import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.solving.cpsat import constraints, objective
from fjsp_planner.solving.cpsat.grid import choose_grid
from fjsp_planner.solving.cpsat.variables import JobVariables, RouteVariables, check


class CpsatModel:
    def __init__(self, problem: Problem, upper_bound: Schedule | None, deadline=None,
                 delay: Fraction = Fraction(0), pairwise_travel: bool = False):
        """`upper_bound` is a valid schedule: its makespan bounds the horizon and the panel
        cuts. Without one, the horizon is that of doing the jobs one after another, `delay`
        later (for a caller that holds jobs back until then). `pairwise_travel` adds the
        travel between every two jobs of a robot (`constraints.travel_between_jobs`; small
        scenarios: it is quadratic). Building past `deadline` (time.monotonic()) raises
        `OutOfTimeError`."""
        from fjsp_planner.solving.greedy import serial_upper_bound

        clock = time.monotonic
        self.problem = p = problem
        self.model = m = cp_model.CpModel()
        locations = p.locations()
        self.legs = {}
        for r in p.robots:
            for a in locations:
                check(deadline, clock)
                self.legs.update({(r.name, a, b): p.travel(r.name, a, b) for b in locations})
        incumbent = upper_bound.makespan if upper_bound is not None else None
        bound = incumbent if incumbent is not None else serial_upper_bound(p) + delay
        self.grid = grid = choose_grid(p, list(self.legs.values()), bound)
        self.notes = (grid.note,)
        slack = 0 if grid.exact or incumbent is None else 2 * len(p.jobs) + 2
        self.horizon = grid.ticks(bound) + slack
        self.jobs = JobVariables(m, p, grid, self.horizon, deadline, clock)
        routed = bool(p.holding) or any(leg > 0 for leg in self.legs.values())
        self.routes = RouteVariables(m, p, self.jobs, routed, deadline, clock)
        constraints.no_overlap(m, self.jobs)
        constraints.precedence(m, p, self.jobs)
        constraints.routes(m, p, grid, self.jobs, self.routes, self.legs, deadline, clock)
        constraints.holding(m, p, self.jobs, self.routes)
        self.orders = (constraints.travel_between_jobs(m, p, grid, self.jobs, self.routes,
                                                       deadline, clock)
                       if pairwise_travel and routed else {})
        self.makespan = objective.makespan(m, self.jobs, self.horizon)
        self.places_visited = constraints.makespan_covers_work(m, p, grid, self.jobs,
                                                               self.makespan, self.legs)
        self.panels = constraints.panels(m, p, grid, self.jobs, self.makespan,
                                         incumbent if grid.exact else None)
        check(deadline, clock)

    def minimize_makespan(self):
        self.model.minimize(self.makespan)

    def _respecting_symmetry(self, schedule: Schedule) -> Schedule:
        """The schedule, or its mirror image if that is the one the symmetry cut allows."""
        if self.panels.symmetry is None:
            return schedule
        robot, first, last = self.panels.symmetry
        route = set(schedule.sequences.get(robot, ()))
        if len(route & set(first)) >= len(route & set(last)):
            return schedule
        panels = self.problem.panels
        mirror = {job: panels[-1 - k][i] for k, names in enumerate(panels)
                  for i, job in enumerate(names)}
        if any(job not in mirror for job in schedule.jobs):
            return schedule
        return Schedule(
            {mirror[j]: JobAssignment(mirror[j], a.plan, a.start, a.end, a.robots)
             for j, a in schedule.jobs.items()},
            {r: tuple(mirror[j] for j in route) for r, route in schedule.sequences.items()})

    def add_hint(self, schedule: Schedule, deadline=None):
        """Hint every variable that `schedule` determines, skipping what the problem lacks.

        A complete hint lets CP-SAT start from it at once instead of repairing it by search.
        Past `deadline` (time.monotonic()) raises `OutOfTimeError`.
        """
        m, p, v, grid = self.model, self.problem, self.jobs, self.grid
        arcs_of = {}
        for (a, b, owner), arc in self.routes.arcs.items():
            arcs_of.setdefault(owner, []).append((a, b, arc))
        schedule = self._respecting_symmetry(schedule)
        ends, hinted_start = {}, {}
        for name, a in schedule.jobs.items():
            if name not in v.start or a.plan >= len(p.job(name).plans):
                continue
            if name in p.fixed:
                ends[name] = grid.ticks(p.fixed[name].end)
                continue
            start = hinted_start[name] = grid.ticks(a.start)
            robots = {r: q for r, q in a.robots.items() if (name, r) in v.does}
            longest = max((grid.ticks(p.duration(r, q)) for r, q in robots.items()
                           if p.duration(r, q) is not None), default=0)
            ends[name] = start + longest
            m.add_hint(v.start[name], start)
            m.add_hint(v.end[name], ends[name])
            m.add_hint(v.duration[name], longest)
            for index in range(len(p.job(name).plans)):
                m.add_hint(v.plan[name, index], int(index == a.plan))
            for r in v.robots:
                for index, q, lit in v.does.get((name, r), ()):
                    m.add_hint(lit, int(index == a.plan and robots.get(r) == q))
        panel_of = {j: k for k, names in enumerate(p.panels) for j in names}
        for r, mine in self.routes.nodes.items():
            check(deadline, time.monotonic)
            route = [j for j in schedule.sequences.get(r, ())
                     if j in ends and r in schedule.jobs[j].robots]
            successor = dict(zip(route, route[1:], strict=False))
            for j in mine:
                m.add_hint(v.on_job[j, r], int(j in route))
            places = {p.job(j).location for j in route}
            for (owner, place), visit in self.places_visited.items():
                if owner == r:
                    m.add_hint(visit, int(place in places))
            if r in self.routes.used:
                for j in mine:
                    m.add_hint(self.routes.first[j, r], int(bool(route) and route[0] == j))
                    m.add_hint(self.routes.last[j, r], int(bool(route) and route[-1] == j))
                m.add_hint(self.routes.used[r], int(bool(route)))
            if r in self.panels.visits:
                stays = [panel_of[j] for j in route]
                for k, visit in enumerate(self.panels.visits[r]):
                    m.add_hint(visit, int(k in stays))
                m.add_hint(self.panels.crossings[r], sum(a != b for a, b in zip(
                    stays, stays[1:], strict=False)))
            for a, b, arc in arcs_of.get(r, ()):
                m.add_hint(arc, int(successor.get(a) == b))
        for (a, b, _), a_first in self.orders.items():
            check(deadline, time.monotonic)
            m.add_hint(a_first, int(hinted_start.get(a, 0) <= hinted_start.get(b, 0)))
        if len(ends) == len(v.start):
            m.add_hint(self.makespan, max(ends.values(), default=0))

    def read(self, solver) -> Schedule:
        p, v = self.problem, self.jobs
        jobs = {}
        for job in p.jobs:
            name = job.name
            fixed = p.fixed.get(name)
            if fixed is not None:
                jobs[name] = JobAssignment(name, fixed.plan, fixed.start, fixed.end,
                                           dict(fixed.robots))
                continue
            plan = next(i for i in range(len(job.plans)) if solver.value(v.plan[name, i]))
            robots = {r: q for r in v.robots for index, q, lit in v.does.get((name, r), ())
                      if index == plan and solver.value(lit)}
            start = Fraction(solver.value(v.start[name]), self.grid.scale)
            end = start + max(p.duration(r, q) for r, q in robots.items())
            jobs[name] = JobAssignment(name, plan, start, end, robots)
        sequences = {}
        for r in v.robots:
            mine = [j for j in self.routes.nodes[r] if r in jobs[j].robots]
            if not self.routes.routed:
                sequences[r] = tuple(sorted(mine, key=lambda j: (jobs[j].start, jobs[j].end)))
                continue
            successor = {a: b for (a, b, robot), arc in self.routes.arcs.items()
                         if robot == r and solver.value(arc)}
            first = [j for j in mine if not any(successor.get(o) == j for o in mine)]
            order = []
            current = first[0] if first else None
            while current is not None:
                order.append(current)
                current = successor.get(current)
            sequences[r] = tuple(order)
        return Schedule(jobs, sequences)
