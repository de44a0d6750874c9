"""CP-SAT model of SPEC §1.

Per job: one master start/end shared by an optional interval on every robot able to work
on it (a robot on a job is busy from the job's start to its end). Per robot: one circuit
over a depot and its jobs; an arc a -> b forces end_a + travel(a, b) <= start_b, and a
holding arc (j, j', q) forces the arc j -> j' for every robot doing type q in j.

CP-SAT needs integers: times are scaled by the least common multiple of the durations'
and travel times' denominators (exact for the paper: 30), capped at MAX_SCALE, beyond which
durations are rounded up so the exact schedule read back can only be looser than the grid.
"""

import math
import time
from fractions import Fraction

from ortools.sat.python import cp_model

from fjsp_planner.core.problem import Problem
from fjsp_planner.core.schedule import JobAssignment, Result, Schedule, Status

MAX_SCALE = 1000
KEEP_SHARE = 0.3
"""At most this share of the time limit goes, once the makespan is proven, to keeping
previous assignments; an unproven makespan gets the whole limit."""


def solve_cpsat(problem: Problem, time_limit=10.0, workers=2, hint: Schedule | None = None,
                keep: Schedule | None = None, upper_bound: Schedule | None = None,
                log=False) -> Result:
    """Minimise the makespan; with `keep`, then prefer `keep`'s (job, robot) assignments.

    `upper_bound` is a valid schedule (e.g. greedy) that sets the horizon and is hinted
    unless `hint` is given.
    """
    began = time.monotonic()
    model = _Model(problem, upper_bound)
    if hint is not None or upper_bound is not None:
        model.add_hint(hint or upper_bound)
    model.model.minimize(model.makespan)
    setup = time.monotonic() - began
    # The limit bounds the whole call: a re-plan's latency is what the fleet waits for.
    solver, recorder, status = _run(model.model, time_limit - setup, workers, log)
    if status in ('INFEASIBLE',):
        return Result(Status.INFEASIBLE, None, None, time.monotonic() - began, None, 'cpsat',
                      notes=model.notes)
    if status not in ('OPTIMAL', 'FEASIBLE'):
        if status == 'MODEL_INVALID':
            raise RuntimeError(f'CP-SAT rejected the model: {model.model.validate()}')
        return Result(Status.UNKNOWN, None, None, time.monotonic() - began, None, 'cpsat',
                      notes=model.notes)
    best = solver.value(model.makespan)
    bound = Fraction(math.ceil(solver.best_objective_bound), model.scale)
    schedule = model.read(solver)
    if keep is not None and status == 'OPTIMAL':
        keep_time = min(time_limit * KEEP_SHARE, time_limit - setup - solver.wall_time)
        if keep_time > 0.01:
            schedule = _keep_assignments(model, solver, best, keep, keep_time, workers,
                                         log) or schedule
    proven = status == 'OPTIMAL'
    makespan = schedule.makespan
    lower_bound = min(bound, makespan) if model.exact else bound
    return Result(
        Status.OPTIMAL if proven and model.exact else Status.FEASIBLE,
        makespan, lower_bound, time.monotonic() - began, schedule, 'cpsat',
        first_solution_seconds=_since_call(recorder.first, setup),
        best_solution_seconds=_since_call(recorder.best, setup), notes=model.notes)


def _since_call(solver_seconds, setup):
    return None if solver_seconds is None else setup + solver_seconds


def _run(model, time_limit, workers, log):
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(0.01, time_limit)
    solver.parameters.num_workers = workers
    solver.parameters.log_search_progress = log
    # CP-SAT otherwise replaces the process's SIGINT handler, so a node that solved once
    # dies of Ctrl-C instead of shutting down cleanly.
    solver.parameters.catch_sigint_signal = False
    # Presolve probing took the whole budget at 5 panels before any search (and slowed the
    # 1-panel proof 2x), while it did not tighten the bound measurably at 2 panels.
    solver.parameters.cp_model_probing_level = 0
    recorder = _SolutionTimes()
    # status_name() without an argument is broken in ortools 9.15; name the returned status.
    status = solver.solve(model, recorder).name
    return solver, recorder, status


class _SolutionTimes(cp_model.CpSolverSolutionCallback):
    """When the first and the last (best) solutions arrived, in solver wall time."""

    def __init__(self):
        super().__init__()
        self.first = self.best = None

    def on_solution_callback(self):
        if self.first is None:
            self.first = self.wall_time
        self.best = self.wall_time


def _keep_assignments(model, solver, best, keep, time_limit, workers, log):
    """Among schedules no longer than `best`, the one keeping most of `keep`'s robots."""
    kept = [model.on_job[j, r] for j, a in keep.jobs.items() for r in a.robots
            if (j, r) in model.on_job]
    if not kept:
        return None
    model.model.clear_hints()
    model.add_hint(model.read(solver))
    model.model.add(model.makespan <= best)
    model.model.maximize(sum(kept))
    second, _, status = _run(model.model, time_limit, workers, log)
    if status not in ('OPTIMAL', 'FEASIBLE'):
        return None
    return model.read(second)


class _Model:
    def __init__(self, problem: Problem, upper_bound: Schedule | None):
        self.problem = problem
        self.model = cp_model.CpModel()
        self.notes = ()
        self.scale, self.exact = self._choose_scale()
        if not self.exact:
            self.notes += (f'durations rounded up to a 1/{self.scale} time grid; the lower '
                           'bound is that of the rounded model',)
        else:
            self.notes += (f'exact on a 1/{self.scale} time grid',)
        self.horizon = self._horizon(upper_bound)
        self.robots = [r.name for r in problem.robots]
        self.start, self.end, self.plan = {}, {}, {}
        self.does = {}
        """(job, robot) -> [(plan, op type, literal)]: the robot does a type-q operation."""
        self.on_job = {}
        self.arcs = {}
        self.route_nodes = {}
        """robot -> the jobs on its circuit, in circuit node order."""
        self.symmetry = None
        """(robot, first panel, last panel) when mirrored panels are cut off."""
        self.duration, self.used, self.first_arc, self.last_arc = {}, {}, {}, {}
        self.panel_visits, self.crossings = {}, {}
        self.busy = {}
        """robot -> its optional job intervals, which must not overlap."""
        self._jobs()
        for intervals in self.busy.values():
            self.model.add_no_overlap(intervals)
        self._precedence()
        self._routes()
        self._holding()
        self.makespan = self.model.new_int_var(0, self.horizon, 'makespan')
        for name in self.end:
            self.model.add(self.makespan >= self.end[name])
        self._panels()

    def ticks(self, value: Fraction) -> int:
        """Grid units, rounded up (integer arithmetic: this runs for every route arc)."""
        return -(-value.numerator * self.scale // value.denominator)

    def _choose_scale(self):
        p = self.problem
        values = [p.duration(r.name, q) for r in p.robots for q in p.operation_types]
        locations = p.locations()
        self.legs = {(r.name, a, b): p.travel(r.name, a, b) for r in p.robots
                     for a in locations for b in locations}
        values += self.legs.values()
        denominators = {v.denominator for v in values if v is not None}
        scale = math.lcm(*denominators) if denominators else 1
        if scale > MAX_SCALE:
            return MAX_SCALE, False
        # Release and fixed times (wall-clock `now` when re-planning) join the grid while it
        # stays small enough; beyond that they are rounded, which costs exactness, not validity.
        others = [r.release_time for r in p.robots]
        others += [t for f in p.fixed.values() for t in (f.start, f.end)]
        finer = math.lcm(scale, *(v.denominator for v in others))
        if finer <= MAX_SCALE:
            return finer, True
        return scale, all((v * scale).denominator == 1 for v in others)

    def _horizon(self, upper_bound):
        from fjsp_planner.core.greedy import serial_upper_bound

        if upper_bound is None:
            return self.ticks(serial_upper_bound(self.problem))
        slack = 0 if self.exact else 2 * len(self.problem.jobs) + 2
        return self.ticks(upper_bound.makespan) + slack

    def _jobs(self):
        p, m = self.problem, self.model
        for job in p.jobs:
            name = job.name
            fixed = p.fixed.get(name)
            if fixed is not None:
                fixed_ticks = (math.floor(fixed.start * self.scale), self.ticks(fixed.end))
                start, end = (m.new_constant(t) for t in fixed_ticks)
            else:
                start = m.new_int_var(0, self.horizon, f'start_{name}')
                end = m.new_int_var(0, self.horizon, f'end_{name}')
            self.start[name], self.end[name] = start, end
            plans = []
            for index, plan in enumerate(job.plans):
                chosen = (m.new_constant(int(index == fixed.plan)) if fixed is not None
                          else m.new_bool_var(f'plan_{name}_{index}'))
                self.plan[name, index] = chosen
                plans.append(chosen)
                for q in set(plan):
                    able = [r for r in self.robots if p.duration(r, q) is not None]
                    literals = []
                    for r in able:
                        if fixed is not None:
                            value = int(index == fixed.plan and fixed.robots.get(r) == q)
                            literal = m.new_constant(value)
                        else:
                            literal = m.new_bool_var(f'does_{name}_{index}_{q}_{r}')
                        self.does.setdefault((name, r), []).append((index, q, literal))
                        literals.append(literal)
                    m.add(sum(literals) == plan.count(q) * chosen)
            m.add_exactly_one(plans)
            if fixed is None:
                duration = self.duration[name] = m.new_int_var(0, self.horizon,
                                                               f'duration_{name}')
                m.add(end == start + duration)
            else:
                duration = fixed_ticks[1] - fixed_ticks[0]
            longest = []
            for r in self.robots:
                mine = [(lit, q) for _, q, lit in self.does.get((name, r), ())]
                if not mine:
                    continue
                on = m.new_bool_var(f'on_{name}_{r}')
                m.add(on == sum(lit for lit, _ in mine))
                self.on_job[name, r] = on
                longest.append(sum(lit * self.ticks(p.duration(r, q)) for lit, q in mine))
                self.busy.setdefault(r, []).append(
                    m.new_optional_interval_var(start, duration, end, on, f'busy_{name}_{r}'))
            if fixed is None:
                m.add_max_equality(duration, longest)

    def _precedence(self):
        for a, b in self.problem.precedence:
            self.model.add(self.start[b] >= self.end[a])

    def _routes(self):
        """A circuit per robot, needed only when travel or holding makes order matter beyond
        no-overlap (classic FJSP instances have neither, and are much faster without)."""
        p, m = self.problem, self.model
        ancestors = p.ancestors()
        self.routed = bool(p.holding) or any(leg > 0 for leg in self.legs.values())
        for robot in p.robots:
            r = robot.name
            jobs = [j.name for j in p.jobs if (j.name, r) in self.on_job]
            self.route_nodes[r] = jobs
            if not jobs:
                continue
            if not self.routed:
                if robot.release_time > 0:
                    for a in jobs:
                        if a not in p.fixed:
                            m.add(self.start[a] >= self.ticks(robot.release_time)
                                  ).only_enforce_if(self.on_job[a, r])
                continue
            node = {name: i + 1 for i, name in enumerate(jobs)}
            used = self.used[r] = m.new_bool_var(f'used_{r}')
            m.add_max_equality(used, [self.on_job[j, r] for j in jobs])
            arcs = [(0, 0, ~used)]
            for a in jobs:
                on = self.on_job[a, r]
                arcs.append((node[a], node[a], ~on))
                first = self.first_arc[a, r] = m.new_bool_var(f'first_{a}_{r}')
                last = self.last_arc[a, r] = m.new_bool_var(f'last_{a}_{r}')
                arcs.append((0, node[a], first))
                arcs.append((node[a], 0, last))
                if a not in p.fixed:
                    ready = robot.release_time
                    if robot.start_location is not None:
                        ready += p.travel(r, robot.start_location, p.job(a).location)
                    m.add(self.start[a] >= self.ticks(ready)).only_enforce_if(first)
                    # After a fixed (running) job the route bounds the start only by that
                    # job's end, which may lie before the release time.
                    if robot.release_time > 0:
                        m.add(self.start[a] >= self.ticks(robot.release_time)).only_enforce_if(
                            on)
                for b in jobs:
                    if a == b or b in ancestors[a] or (b in p.fixed and a not in p.fixed):
                        continue
                    arc = m.new_bool_var(f'next_{a}_{b}_{r}')
                    self.arcs[a, b, r] = arc
                    arcs.append((node[a], node[b], arc))
                    leg = self.ticks(self.legs[r, p.job(a).location, p.job(b).location])
                    m.add(self.start[b] >= self.end[a] + leg).only_enforce_if(arc)
            m.add_circuit(arcs)

    def _holding(self):
        p, m = self.problem, self.model
        for a, b, q in p.holding:
            for r in self.robots:
                in_a = sum(lit for _, t, lit in self.does.get((a, r), ()) if t == q)
                in_b = sum(lit for _, t, lit in self.does.get((b, r), ()) if t == q)
                if isinstance(in_a, int) and isinstance(in_b, int):
                    continue
                m.add(in_a == in_b)
                if (a, b, r) in self.arcs:
                    m.add(self.arcs[a, b, r] >= in_a)
                else:
                    m.add(in_a == 0)

    def _panels(self):
        """Cuts for identical panels: a robot's work plus its moves between panels fits in
        the makespan, and mirrored solutions (panel k <-> N+1-k) are searched only once."""
        p, m = self.problem, self.model
        if len(p.panels) < 2 or p.fixed:
            return
        crossing_cost = {}
        for robot in p.robots:
            r = robot.name
            visits = []
            for k, names in enumerate(p.panels):
                on = [self.on_job[j, r] for j in names if (j, r) in self.on_job]
                visit = m.new_bool_var(f'visits_panel_{k + 1}_{r}')
                m.add_max_equality(visit, on or [0])
                visits.append(visit)
            self.panel_visits[r] = visits
            cost = min(p.travel(r, p.job(a).location, p.job(b).location)
                       for k, first in enumerate(p.panels) for second in p.panels[k + 1:]
                       for a in first for b in second)
            crossing_cost[r] = cost
            crossings = self.crossings[r] = m.new_int_var(0, len(p.panels),
                                                          f'panel_crossings_{r}')
            m.add(crossings >= sum(visits) - 1)
            work = sum(lit * self.ticks(p.duration(r, q)) for j in self.route_nodes[r]
                       for _, q, lit in self.does[j, r])
            m.add(work + self.ticks(cost) * crossings + self.ticks(robot.release_time)
                  <= self.makespan)
        if any(r.start_location for r in p.robots):
            return
        slowest = max(crossing_cost, key=crossing_cost.get)
        first, last = p.panels[0], p.panels[-1]
        m.add(sum(self.on_job[j, slowest] for j in first if (j, slowest) in self.on_job)
              >= sum(self.on_job[j, slowest] for j in last if (j, slowest) in self.on_job))
        self.symmetry = (slowest, first, last)

    def _respecting_symmetry(self, schedule: Schedule) -> Schedule:
        """The schedule, or its mirror image if that is the one the symmetry cut allows."""
        if self.symmetry is None:
            return schedule
        robot, first, last = self.symmetry
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

    def add_hint(self, schedule: Schedule):
        """Hint every variable that `schedule` determines, skipping what the problem lacks.

        A complete hint lets CP-SAT start from it at once instead of repairing it by search.
        """
        m, p = self.model, self.problem
        schedule = self._respecting_symmetry(schedule)
        ends = {}
        for name, a in schedule.jobs.items():
            if name not in self.start or a.plan >= len(p.job(name).plans):
                continue
            if name in p.fixed:
                ends[name] = self.ticks(p.fixed[name].end)
                continue
            start = self.ticks(a.start)
            robots = {r: q for r, q in a.robots.items() if (name, r) in self.does}
            longest = max((self.ticks(p.duration(r, q)) for r, q in robots.items()
                           if p.duration(r, q) is not None), default=0)
            ends[name] = start + longest
            m.add_hint(self.start[name], start)
            m.add_hint(self.end[name], ends[name])
            m.add_hint(self.duration[name], longest)
            for index in range(len(p.job(name).plans)):
                m.add_hint(self.plan[name, index], int(index == a.plan))
            for r in self.robots:
                for index, q, lit in self.does.get((name, r), ()):
                    m.add_hint(lit, int(index == a.plan and robots.get(r) == q))
        for r, jobs in self.route_nodes.items():
            route = [j for j in schedule.sequences.get(r, ())
                     if j in ends and r in schedule.jobs[j].robots]
            successor = dict(zip(route, route[1:], strict=False))
            for j in jobs:
                m.add_hint(self.on_job[j, r], int(j in route))
            if r in self.used:
                for j in jobs:
                    m.add_hint(self.first_arc[j, r], int(bool(route) and route[0] == j))
                    m.add_hint(self.last_arc[j, r], int(bool(route) and route[-1] == j))
                for (a, b, robot), arc in self.arcs.items():
                    if robot == r:
                        m.add_hint(arc, int(successor.get(a) == b))
                m.add_hint(self.used[r], int(bool(route)))
            if r in self.panel_visits:
                panel_of = {j: k for k, names in enumerate(p.panels) for j in names}
                stays = [panel_of[j] for j in route]
                for k, visit in enumerate(self.panel_visits[r]):
                    m.add_hint(visit, int(k in stays))
                m.add_hint(self.crossings[r], sum(a != b for a, b in zip(
                    stays, stays[1:], strict=False)))
        if len(ends) == len(self.start):
            m.add_hint(self.makespan, max(ends.values(), default=0))

    def read(self, solver) -> Schedule:
        p = self.problem
        jobs = {}
        for job in p.jobs:
            name = job.name
            fixed = p.fixed.get(name)
            if fixed is not None:
                jobs[name] = JobAssignment(name, fixed.plan, fixed.start, fixed.end,
                                           dict(fixed.robots))
                continue
            plan = next(i for i in range(len(job.plans)) if solver.value(self.plan[name, i]))
            robots = {r: q for r in self.robots for index, q, lit in self.does.get((name, r), ())
                      if index == plan and solver.value(lit)}
            start = Fraction(solver.value(self.start[name]), self.scale)
            end = start + max(p.duration(r, q) for r, q in robots.items())
            jobs[name] = JobAssignment(name, plan, start, end, robots)
        sequences = {}
        for r in self.robots:
            mine = [j for j in self.route_nodes[r] if r in jobs[j].robots]
            if not self.routed:
                sequences[r] = tuple(sorted(mine, key=lambda j: (jobs[j].start, jobs[j].end)))
                continue
            successor = {a: b for (a, b, robot), arc in self.arcs.items()
                         if robot == r and solver.value(arc)}
            first = [j for j in mine if not any(successor.get(o) == j for o in mine)]
            order = []
            current = first[0] if first else None
            while current is not None:
                order.append(current)
                current = successor.get(current)
            sequences[r] = tuple(order)
        return Schedule(jobs, sequences)
