"""The decision variables of the CP-SAT model: who does what in which job, and robots' routes.

Per job: one master start/end/duration shared by an optional interval on every robot able to
work on it (a robot on a job is busy from the job's start to its end). Per robot with a
route: a successor literal per ordered pair of its jobs, and first/last literals for the
depot. Variables are named after the ids they stand for.
"""

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.cpsat.grid import TimeGrid


class OutOfTimeError(Exception):
    """Building the model took the whole time limit."""


def check(deadline, clock):
    if deadline is not None and clock() > deadline:
        raise OutOfTimeError


class JobVariables:
    def __init__(self, model, problem: Problem, grid: TimeGrid, horizon: int, deadline=None,
                 clock=None):
        self.robots = [r.name for r in problem.robots]
        self.start, self.end, self.duration, self.plan = {}, {}, {}, {}
        self.does = {}
        """(job, robot) -> [(plan, op type, literal)]: the robot does a type-q operation."""
        self.on_job = {}
        self.busy = {}
        """robot -> its optional intervals, one per job it may work on."""
        self.longest = {}
        """(job, robot) -> the robot's time on the job as a linear expression of `does`."""
        for job in problem.jobs:
            check(deadline, clock)
            self._job(model, problem, grid, horizon, job)

    def _job(self, m, p, grid, horizon, job):
        name = job.name
        fixed = p.fixed.get(name)
        if fixed is not None:
            fixed_ticks = (grid.floor(fixed.start), grid.ticks(fixed.end))
            start, end = (m.new_constant(t) for t in fixed_ticks)
        else:
            start = m.new_int_var(0, horizon, f'start_{name}')
            end = m.new_int_var(0, horizon, f'end_{name}')
        self.start[name], self.end[name] = start, end
        plans = []
        for index, plan in enumerate(job.plans):
            chosen = (m.new_constant(int(index == fixed.plan)) if fixed is not None
                      else m.new_bool_var(f'plan_{name}_{index}'))
            self.plan[name, index] = chosen
            plans.append(chosen)
            for q in set(plan):
                literals = []
                for r in self.robots:
                    if p.duration(r, q) is None:
                        continue
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
            duration = self.duration[name] = m.new_int_var(0, horizon, f'duration_{name}')
            m.add(end == start + duration)
        else:
            duration = fixed_ticks[1] - fixed_ticks[0]
        # A job of single-operation plans lasts as long as its one robot takes: a fixed-size
        # interval per robot then tells no-overlap the size before the choice is made (the
        # classic FJSP is all such jobs).
        alone = fixed is None and all(len(plan) == 1 for plan in job.plans)
        longest = []
        for r in self.robots:
            mine = [(lit, q) for _, q, lit in self.does.get((name, r), ())]
            if not mine:
                continue
            on = m.new_bool_var(f'on_{name}_{r}')
            m.add(on == sum(lit for lit, _ in mine))
            self.on_job[name, r] = on
            sizes = {grid.ticks(p.duration(r, q)) for _, q in mine}
            work = self.longest[name, r] = sum(lit * grid.ticks(p.duration(r, q))
                                               for lit, q in mine)
            longest.append(work)
            if alone and len(sizes) == 1:
                size = sizes.pop()
                m.add(end == start + size).only_enforce_if(on)
                interval = m.new_optional_fixed_size_interval_var(start, size, on,
                                                                  f'busy_{name}_{r}')
            else:
                interval = m.new_optional_interval_var(start, duration, end, on,
                                                       f'busy_{name}_{r}')
            self.busy.setdefault(r, []).append(interval)
        if alone:
            m.add(duration == sum(longest))
        elif fixed is None:
            m.add_max_equality(duration, longest)

    def jobs_of(self, robot: str, names) -> list[str]:
        return [j for j in names if (j, robot) in self.on_job]


class RouteVariables:
    """Successor literals of one circuit per robot, over a depot and the robot's jobs.

    Only needed when travel or holding makes order matter beyond no-overlap (classic FJSP
    instances have neither, and are much faster without)."""

    def __init__(self, model, problem: Problem, jobs: JobVariables, routed: bool, deadline=None,
                 clock=None):
        self.routed = routed
        self.nodes = {}
        """robot -> the jobs on its circuit, in circuit node order."""
        self.arcs, self.first, self.last, self.used = {}, {}, {}, {}
        ancestors = problem.ancestors()
        names = [j.name for j in problem.jobs]
        for robot in problem.robots:
            r = robot.name
            mine = self.nodes[r] = jobs.jobs_of(r, names)
            if not routed or not mine:
                continue
            self.used[r] = model.new_bool_var(f'used_{r}')
            for a in mine:
                check(deadline, clock)
                self.first[a, r] = model.new_bool_var(f'first_{a}_{r}')
                self.last[a, r] = model.new_bool_var(f'last_{a}_{r}')
                for b in mine:
                    # No arc back into an ancestor, nor from a job to plan into a running one.
                    into_running = b in problem.fixed and a not in problem.fixed
                    if a == b or b in ancestors[a] or into_running:
                        continue
                    self.arcs[a, b, r] = model.new_bool_var(f'next_{a}_{b}_{r}')
