"""The paper's §IV mixed integer program, solved through OR-Tools' `pywraplp` (SCIP or HiGHS).

Variables (names as printed): s_j, c_j, c_max; binaries x_jp (plan p of job j), x_jm (robot m
works on j), x_jj'm (m goes from j directly to j'), x_jpom (m does operation o of plan p),
x^start_jm / x^end_jm (j is m's first / last job). The unused c_jpo and c_jm of the paper's
variable list are left out: no printed constraint needs them beyond c_j >= s_j + T x_jpom.

Where the printed model slips, this module implements the evident intent:

1. Travel (printed `s_j >= c_j' + (S_jj'm + L) x_jj'm - L`, with x_jj'm = "m moves from j to
   j'"): the arc must be the one *into* j, so we write
   `s_j >= c_j' + (S_j'jm + L) x_j'jm - L`. In our model (docs/model.md) every robot of j'
   is busy until c_j', so c_j' (not the robot's own operation end) is right.
2. Per-operation assignment (printed `x_jp = Σ_m Σ_o x_jpom  ∀ j,p`, which would staff only one
   operation of a plan): `Σ_m x_jpom = x_jp  ∀ j,p,o`.
3. Robot on job (printed `Σ_p Σ_o x_jpom <= x_jm  ∀ j,p,m`): `=` and `∀ j,m`, so x_jm is 1
   exactly when m does an operation of j; with x_jm binary this is also the model's "a robot does
   at most one operation of a job".
4. Path ends (printed `Σ_j x^start_jm = Σ_j x^end_jm = 1`): `<= 1`, so a robot may stay idle
   (an FJSP machine nobody needs, a spare robot).
5. Holding (printed over `ō` and `P_j` on both sides): ō is the arc's operation *type* q, the
   right-hand sum runs over the plans P_j' of j', and operations are counted by type because
   plans are multisets: `Σ_p Σ_{o: type q} x_jpom = Σ_p' Σ_{o: type q} x_j'p'om` and
   `x_jj'm >= Σ_p Σ_{o: type q} x_jpom  ∀ m, (j, j', q) ∈ H` (no arc variable: no holder m).

Extensions (docs/model.md) the paper does not print: a robot with a start location travels from it
to its first job, and no robot starts a new job before its release time (a robot released
after the running job it is on ends cannot start its next job before then); a fixed (already
running) job keeps its plan, robots and times and is the first job of its robots. Arcs
j -> j' with j' a precedence ancestor of j cannot be used and are not created.

Durations are rational. Every time is scaled by the LCM of the denominators so the model has
integer data and its bound can be rounded up to the grid. The schedule itself is rebuilt in
exact `Fraction` arithmetic from the solver's decisions (plans, robots, robot sequences) as
the earliest-start schedule of those decisions, so it never depends on solver tolerances.
"""

import math
import time
from fractions import Fraction

from ortools.linear_solver import pywraplp

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.compact import earliest_schedule

BACKENDS = ('SCIP', 'HIGHS')
MAX_GRID = 10 ** 6
"""Finer grids than this give badly scaled models; the times then stay unscaled floats."""


def solve_mip(problem: Problem, time_limit: float = 10.0, backend: str = 'SCIP',
              workers: int = 1, hint: Schedule | None = None, log: bool = False) -> Result:
    """Minimise the makespan of `problem` with the §IV MIP on `backend` ('SCIP' or 'HIGHS').

    `log` lets the backend print its progress to standard output (benchmarks read it).
    """
    backend = backend.upper()
    if backend not in BACKENDS:
        raise ValueError(f"unknown MIP backend '{backend}'; choose one of {', '.join(BACKENDS)}")
    solver = pywraplp.Solver.CreateSolver(backend)
    if solver is None:
        raise RuntimeError(f"OR-Tools was built without the '{backend}' MIP backend")
    if log:
        solver.EnableOutput()
    if backend == 'HIGHS':
        # OR-Tools does not pass RELATIVE_MIP_GAP on to HiGHS, and HiGHS prints a banner even
        # when output is suppressed; its own options do both (the call reports failure but
        # takes effect).
        options = ['mip_rel_gap = 0'] + ([] if log else ['output_flag = false'])
        solver.SetSolverSpecificParametersAsString('\n'.join(options))
    started = time.perf_counter()
    # OR-Tools 9.15 crashes (segfault) when a MIP start is given to HiGHS; it gets the
    # hint's horizon only.
    model = _Model(problem, solver, hint, start_hint=backend != 'HIGHS')
    solver.SetTimeLimit(max(1, int(time_limit * 1000)))
    solver.SetNumThreads(max(1, workers))
    params = pywraplp.MPSolverParameters()
    # The default relative gap (1e-4) would let the solver call a non-optimal makespan optimal
    # once times are scaled to a fine grid.
    params.SetDoubleParam(pywraplp.MPSolverParameters.RELATIVE_MIP_GAP, 0.0)
    code = solver.Solve(params)
    seconds = time.perf_counter() - started
    return model.result(code, seconds, f'mip-{backend.lower()}')


def _grid(values) -> int:
    scale = 1
    for value in values:
        scale = math.lcm(scale, Fraction(value).denominator)
    return scale


class _Model:
    def __init__(self, problem: Problem, solver, hint, start_hint=True):
        self.p = problem
        self.solver = solver
        self.robots = [r.name for r in problem.robots]
        self.jobs = [j.name for j in problem.jobs]
        self._durations()
        self._scale()
        self._variables()
        self._constraints()
        if hint is not None:
            self._hint(hint, start_hint)
        solver.Minimize(self.c_max)

    # ----- data -------------------------------------------------------------------------
    def _durations(self):
        p = self.p
        self.ops = {}
        """(j, plan, o) -> (type, {robot: exact time}) for robots able to do it."""
        for job in p.jobs:
            for plan_index, plan in enumerate(job.plans):
                for o, q in enumerate(plan):
                    able = {m: p.duration(m, q) for m in self.robots}
                    self.ops[job.name, plan_index, o] = (
                        q, {m: t for m, t in able.items() if t is not None})
        self.travel = {}
        """(robot, j', j) -> exact travel time from j' to j."""
        for m in self.robots:
            for a in p.jobs:
                for b in p.jobs:
                    if a.name != b.name:
                        self.travel[m, a.name, b.name] = p.travel(m, a.location, b.location)
        self.ready = {}
        """(robot, j) -> earliest start of j if it is the robot's first job."""
        for r in p.robots:
            for job in p.jobs:
                leg = (p.travel(r.name, r.start_location, job.location)
                       if r.start_location else Fraction(0))
                self.ready[r.name, job.name] = r.release_time + leg

    def _scale(self):
        values = [t for _, times in self.ops.values() for t in times.values()]
        values += list(self.travel.values()) + list(self.ready.values())
        for fixed in self.p.fixed.values():
            values += [fixed.start, fixed.end]
        scale = _grid(values)
        if scale > MAX_GRID:
            self.scale = None
            self.notes = (f'times not scaled: their common grid 1/{scale} is too fine; the '
                          'model uses floats and the schedule is recomputed exactly',)
        else:
            self.scale = scale
            self.notes = (f'times scaled by {scale} to an integer grid (unit 1/{scale}); the '
                          'schedule is recomputed exactly from the chosen plans and sequences',)

    def _num(self, value) -> float:
        return float(value * self.scale) if self.scale else float(value)

    def _horizon(self, hint) -> float:
        """An upper bound on the optimal makespan: every earliest-start schedule is a chain of
        distinct jobs, each adding at most its longest duration and longest trip in."""
        p = self.p
        longest_trip = max(self.travel.values(), default=Fraction(0))
        total = max([Fraction(0)] + [f.end for f in p.fixed.values()])
        total += max(self.ready.values(), default=Fraction(0))
        for job in p.jobs:
            if job.name in p.fixed:
                continue
            total += longest_trip + max(
                max(times.values(), default=Fraction(0))
                for (j, _, _), (_, times) in self.ops.items() if j == job.name)
        if hint is not None:
            total = min(total, hint.makespan)
        return math.ceil(self._num(total))

    # ----- model ------------------------------------------------------------------------
    def _variables(self):
        s, p = self.solver, self.p
        self.H = self._horizon(None)
        self.L = self.H + math.ceil(max(
            (self._num(t) for t in self.travel.values()), default=0.0))
        self.c_max = s.NumVar(0, self.H, 'c_max')
        self.start = {j: s.NumVar(0, self.H, f's_{j}') for j in self.jobs}
        self.end = {j: s.NumVar(0, self.H, f'c_{j}') for j in self.jobs}
        self.x_plan = {(j.name, k): s.BoolVar(f'x_{j.name}_{k}')
                       for j in p.jobs for k in range(len(j.plans))}
        self.x_op = {(j, k, o, m): s.BoolVar(f'x_{j}_{k}_{o}_{m}')
                     for (j, k, o), (_, times) in self.ops.items() for m in times}
        able = {j: set() for j in self.jobs}
        for (j, _, _, m) in self.x_op:
            able[j].add(m)
        self.able = able
        self.x_on = {(j, m): s.BoolVar(f'x_{j}_{m}') for j in self.jobs for m in able[j]}
        ancestors = self.p.ancestors()
        self.x_arc = {(a, b, m): s.BoolVar(f'x_{a}_{b}_{m}')
                      for m in self.robots for a in self.jobs for b in self.jobs
                      if a != b and m in able[a] and m in able[b] and b not in ancestors[a]}
        self.ops_of = {j: {} for j in self.jobs}
        for (j, k, o, m), x in self.x_op.items():
            self.ops_of[j][k, o, m] = x
        self.arcs_out = {key: [] for key in self.x_on}
        self.arcs_in = {key: [] for key in self.x_on}
        for (a, b, m), x in self.x_arc.items():
            self.arcs_out[a, m].append(x)
            self.arcs_in[b, m].append(x)
        self.x_first = {(j, m): s.BoolVar(f'xstart_{j}_{m}') for (j, m) in self.x_on}
        self.x_last = {(j, m): s.BoolVar(f'xend_{j}_{m}') for (j, m) in self.x_on}

    def _constraints(self):
        s, p = self.solver, self.p
        fixed = p.fixed
        for j in self.jobs:
            s.Add(self.c_max >= self.end[j])
        for a, b in p.precedence:
            s.Add(self.start[b] >= self.end[a])
        for (a, b, m), x in self.x_arc.items():
            if b in fixed:
                continue  # a running job's robots are already there
            leg = self._num(self.travel[m, a, b])
            s.Add(self.start[b] >= self.end[a] + (leg + self.L) * x - self.L)
        for (j, k, o, m), x in self.x_op.items():
            if j not in fixed:
                s.Add(self.end[j] >= self.start[j] + self._num(self.ops[j, k, o][1][m]) * x)
        for job in p.jobs:
            s.Add(s.Sum(self.x_plan[job.name, k] for k in range(len(job.plans))) == 1)
        for (j, k, o), (_, times) in self.ops.items():
            for m in times:
                s.Add(self.x_op[j, k, o, m] <= self.x_plan[j, k])
            s.Add(s.Sum(self.x_op[j, k, o, m] for m in times) == self.x_plan[j, k])
        for (j, m), x in self.x_on.items():
            s.Add(s.Sum(v for (_, _, mm), v in self.ops_of[j].items() if mm == m) == x)
            s.Add(x == self.x_last[j, m] + s.Sum(self.arcs_out[j, m]))
            s.Add(x == self.x_first[j, m] + s.Sum(self.arcs_in[j, m]))
            if j not in fixed:
                s.Add(self.start[j] >= self._num(self.ready[m, j]) * self.x_first[j, m])
                s.Add(self.start[j] >= self._num(self.p.robot(m).release_time) * x)
        for m in self.robots:
            s.Add(s.Sum(self.x_first[j, m] for j in self.jobs if (j, m) in self.x_first) <= 1)
            s.Add(s.Sum(self.x_last[j, m] for j in self.jobs if (j, m) in self.x_last) <= 1)
        for a, b, q in p.holding:
            for m in self.robots:
                held = self._doing(a, q, m)
                if not held:
                    # m cannot do q in j: it must not do it in j' either.
                    s.Add(s.Sum(self._doing(b, q, m)) == 0)
                    continue
                s.Add(s.Sum(held) == s.Sum(self._doing(b, q, m)))
                arc = self.x_arc.get((a, b, m))
                s.Add((arc if arc is not None else 0) >= s.Sum(held))
        for name, job in fixed.items():
            self._fix(name, job)

    def _doing(self, j, q, m):
        """The terms of Σ_p Σ_{o of type q} x_jpom: robot m does a type-q operation of j."""
        return [v for (k, o, mm), v in self.ops_of[j].items()
                if mm == m and self.ops[j, k, o][0] == q]

    def _operations_of(self, job, plan, robots):
        """{(o, m): x_jpom} giving each robot of `robots` (robot -> type) its own operation
        of that type in the plan; robots that fit no operation are left out."""
        free_ops = dict(enumerate(self.p.job(job).plans[plan]))
        chosen = {}
        for robot, q in robots.items():
            o = next((o for o, t in free_ops.items() if t == q), None)
            if o is not None and (job, plan, o, robot) in self.x_op:
                chosen[o, robot] = self.x_op[job, plan, o, robot]
                del free_ops[o]
        return chosen

    def _fix(self, name, fixed):
        for k in range(len(self.p.job(name).plans)):
            self.x_plan[name, k].SetBounds(int(k == fixed.plan), int(k == fixed.plan))
        chosen = self._operations_of(name, fixed.plan, fixed.robots)
        for (j, k, o, m), x in self.x_op.items():
            if j == name:
                value = int(k == fixed.plan and (o, m) in chosen)
                x.SetBounds(value, value)
        for robot in fixed.robots:
            if (name, robot) in self.x_first:
                self.x_first[name, robot].SetBounds(1, 1)
        self.start[name].SetBounds(self._num(fixed.start), self._num(fixed.start))
        self.end[name].SetBounds(self._num(fixed.end), self._num(fixed.end))

    def _hint(self, hint: Schedule, start_hint: bool):
        """Pass the parts of `hint` that name this problem's jobs and robots as a MIP start;
        a hint that is a valid schedule of this very problem also caps the horizon (a plan
        of an earlier problem, e.g. before a re-plan, bounds nothing)."""
        if not validate(self.p, hint):
            self.c_max.SetUb(self._horizon(hint))
        if not start_hint:
            return
        # SCIP ignores a start that leaves most variables open, so every binary gets a value:
        # 0 unless the hint sets it.
        values = {}
        for group in (self.x_plan, self.x_op, self.x_on, self.x_arc, self.x_first,
                      self.x_last):
            for x in group.values():
                values[x.index()] = (x, 0.0)
        for j, a in hint.jobs.items():
            if j not in self.start or not 0 <= a.plan < len(self.p.job(j).plans):
                continue
            chosen = [self.x_plan[j, a.plan], *self._operations_of(j, a.plan, a.robots).values()]
            chosen += [self.x_on[j, m] for m in a.robots if (j, m) in self.x_on]
            for x in chosen:
                values[x.index()] = (x, 1.0)
            for x, time_ in ((self.start[j], a.start), (self.end[j], a.end)):
                values[x.index()] = (x, self._num(time_))
        for m, sequence in hint.sequences.items():
            sequence = [j for j in sequence if (j, m) in self.x_first]
            chosen = [self.x_first[sequence[0], m], self.x_last[sequence[-1], m]] \
                if sequence else []
            chosen += [self.x_arc[a, b, m] for a, b in zip(sequence, sequence[1:], strict=False)
                       if (a, b, m) in self.x_arc]
            for x in chosen:
                values[x.index()] = (x, 1.0)
        values[self.c_max.index()] = (self.c_max, self._num(hint.makespan))
        variables = [x for x, _ in values.values()]
        values = [v for _, v in values.values()]
        self.solver.SetHint(variables, values)

    # ----- answer -----------------------------------------------------------------------
    def result(self, code, seconds, name) -> Result:
        found = code in (pywraplp.Solver.OPTIMAL, pywraplp.Solver.FEASIBLE)
        if code == pywraplp.Solver.INFEASIBLE:
            return Result(Status.INFEASIBLE, None, None, seconds, None, name, notes=self.notes)
        if not found:
            # pywraplp reports no bound without a solution (SCIP's own is lost: BestBound()
            # answers 0). OR-Tools 9.15 answers an undocumented code (99) when HiGHS stops at
            # the time limit and drops its incumbent too (google/or-tools#5016, #5372).
            known = code in (pywraplp.Solver.NOT_SOLVED, pywraplp.Solver.ABNORMAL,
                             pywraplp.Solver.UNBOUNDED, pywraplp.Solver.MODEL_INVALID)
            notes = self.notes if known else self.notes + (
                f'the backend stopped with status code {code} and returned no solution '
                '(HiGHS at a time limit: OR-Tools 9.15 drops its incumbent)',)
            return Result(Status.UNKNOWN, None, None, seconds, None, name, notes=notes)
        schedule = self._schedule()
        bound = self._bound()
        bound = min(bound, schedule.makespan) if bound is not None else None
        # Proven only when the bound, rounded up to the grid, meets the exact makespan; the
        # backend's own verdict allows for its tolerances.
        status = Status.OPTIMAL if bound == schedule.makespan else Status.FEASIBLE
        return Result(status, schedule.makespan, bound, seconds, schedule, name,
                      notes=self.notes)

    def _bound(self) -> Fraction | None:
        value = self.solver.Objective().BestBound()
        if not math.isfinite(value):
            return None
        if self.scale:
            # Every earliest-start makespan lies on the grid, so a bound rounds up to it.
            return Fraction(max(0, math.ceil(value - 1e-6)), self.scale)
        # Without a grid, round down to a millionth so the bound stays a bound.
        return max(Fraction(0), Fraction(math.floor((value - 1e-6) * 10 ** 6), 10 ** 6))

    def _schedule(self) -> Schedule:
        p = self.p
        plan = {j: next(k for k in range(len(p.job(j).plans))
                        if self.x_plan[j, k].solution_value() > 0.5) for j in self.jobs}
        robots = {j: {} for j in self.jobs}
        for (j, k, o, m), x in self.x_op.items():
            if k == plan[j] and x.solution_value() > 0.5:
                robots[j][m] = self.ops[j, k, o][0]
        sequences = {m: self._sequence(m) for m in self.robots}
        return earliest_schedule(p, plan, robots, sequences)

    def _sequence(self, m):
        mine = [j for (j, mm), x in self.x_on.items() if mm == m and x.solution_value() > 0.5]
        after = {a: b for (a, b, mm), x in self.x_arc.items()
                 if mm == m and x.solution_value() > 0.5}
        first = [j for j in mine if self.x_first[j, m].solution_value() > 0.5]
        path, seen = [], set()
        j = first[0] if first else None
        while j is not None and j not in seen:
            path.append(j)
            seen.add(j)
            j = after.get(j)
        if len(path) == len(mine):
            return tuple(path)
        # Only zero-length jobs can close a cycle of arcs; order by the solver's times then.
        return tuple(sorted(mine, key=lambda j: (round(self.start[j].solution_value(), 6),
                                                 round(self.end[j].solution_value(), 6))))
