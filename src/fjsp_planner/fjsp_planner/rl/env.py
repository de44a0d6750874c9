"""The paper's reinforcement-learning view of a `Problem` (§V, §VI-B) as a Gymnasium env.

An episode builds a schedule one job at a time. An action picks the next job *and* how it is
done (a process plan and which robot does each of its operations); the job is then placed at
the earliest time its predecessors, its robots (after travelling) allow. The state is the
(job, assignment) pair completed last, plus one start state before anything is done, so
states and actions share one numbering: state = 1 + the action that led to it.

Reward: minus the makespan increase the job causes (-1 per time unit spent), and
-`penalty` (10^4 in the paper) for an action that breaks the problem, which also ends the
episode: a job scheduled twice, before one of its predecessors (precedence or holding arc),
a holding arc whose type-q robots differ between its jobs, a held robot sent to another job
first, a robot given an operation it cannot do, or an assignment index the job lacks.

Assignments, `assignments='permutations'` (the paper's): every ordering of the whole fleet,
per plan; operation o of the plan goes to the o-th robot of the ordering, so orderings that
differ only after the plan's length give the same assignment. The paper's subset
{M2, Ja, Aa, Jb, Ab} with its 4 robots has 1 plan × 4! = 24 assignments per job, hence
5 × 24 = 120 job-assignment states and 120 actions (this env adds the start state: 121
observations). `assignments='distinct'` lists each feasible assignment once instead (plans
are multisets, so robots swapping two operations of one type count once): 4 + 6 + 12 + 6 + 12
= 40 for the same subset (the action space pads every job to the largest count: 5 × 12).
"""

import itertools
from dataclasses import dataclass, field
from fractions import Fraction

import gymnasium
from gymnasium import spaces

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule

PENALTY = 10_000
MAX_ASSIGNMENTS = 100_000
"""Largest action space the tabular setting is meant for."""


@dataclass(frozen=True)
class Assignment:
    plan: int
    robots: tuple[str | None, ...]
    """robots[o] does operation o of the plan (None: nobody, not enough robots)."""


def assignments_of(problem: Problem, job: str, mode: str) -> list[Assignment]:
    robots = [r.name for r in problem.robots]
    plans = problem.job(job).plans
    if mode == 'permutations':
        return [Assignment(k, tuple(order[:len(plan)]) + (None,) * (len(plan) - len(order)))
                for k, plan in enumerate(plans)
                for order in itertools.permutations(robots)]
    if mode == 'distinct':
        found = []
        for k, plan in enumerate(plans):
            seen = set()
            for chosen in itertools.permutations(robots, len(plan)):
                key = frozenset(zip(chosen, plan, strict=True))
                able = all(problem.duration(m, q) is not None for m, q in key)
                if able and key not in seen:
                    seen.add(key)
                    found.append(Assignment(k, chosen))
        return found
    raise ValueError(f"unknown assignment mode '{mode}'; use 'permutations' or 'distinct'")


@dataclass
class _Progress:
    free: dict
    """robot -> time it is free."""
    where: dict
    """robot -> location (None: anywhere, before its first job)."""
    jobs: dict = field(default_factory=dict)
    sequences: dict = field(default_factory=dict)
    held: dict = field(default_factory=dict)
    """robot -> job it must go to next (holding arc)."""
    makespan: Fraction = Fraction(0)


class AssemblyEnv(gymnasium.Env):
    """Observation: Discrete(1 + actions), 0 = start; action: Discrete(jobs × assignments)."""

    metadata = {'render_modes': []}

    def __init__(self, problem: Problem, assignments: str = 'permutations',
                 penalty: float = PENALTY):
        if problem.fixed:
            raise ValueError(f"the RL environment plans from scratch; problem '{problem.name}' "
                             f'has running (fixed) jobs {sorted(problem.fixed)}')
        self.problem = problem
        self.penalty = penalty
        self.job_names = [j.name for j in problem.jobs]
        self.options = {j: assignments_of(problem, j, assignments) for j in self.job_names}
        self.width = max(len(options) for options in self.options.values())
        if self.width * len(self.job_names) > MAX_ASSIGNMENTS:
            raise ValueError(f"problem '{problem.name}' has {self.width} assignments per job; "
                             "too many for a table (try assignments='distinct')")
        self.action_space = spaces.Discrete(len(self.job_names) * self.width)
        self.observation_space = spaces.Discrete(1 + len(self.job_names) * self.width)
        self._state = None

    def decode(self, action: int) -> tuple[str, Assignment | None]:
        job = self.job_names[action // self.width]
        options = self.options[job]
        index = action % self.width
        return job, options[index] if index < len(options) else None

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        robots = self.problem.robots
        self._state = _Progress(free={r.name: r.release_time for r in robots},
                                where={r.name: r.start_location for r in robots},
                                sequences={r.name: [] for r in robots})
        return 0, {}

    def step(self, action):
        if self._state is None:
            raise RuntimeError('call reset() before step()')
        job, assignment = self.decode(int(action))
        reason = self._violation(job, assignment)
        if reason is not None:
            self._state = None
            return 1 + int(action), -float(self.penalty), True, False, {'violation': reason}
        increase = self._place(job, assignment)
        done = len(self._state.jobs) == len(self.job_names)
        info = {'schedule': self.schedule()} if done else {}
        return 1 + int(action), -float(increase), done, False, info

    def schedule(self) -> Schedule:
        state = self._state
        return Schedule(dict(state.jobs), {m: tuple(s) for m, s in state.sequences.items()})

    def _violation(self, job, assignment) -> str | None:
        p, state = self.problem, self._state
        if assignment is None:
            return f"job '{job}' has no assignment with that index"
        if job in state.jobs:
            return f"job '{job}' is already done"
        plan = p.job(job).plans[assignment.plan]
        for m, q in zip(assignment.robots, plan, strict=True):
            if m is None:
                return f"job '{job}' needs more robots than the fleet has"
            if p.duration(m, q) is None:
                return f"robot '{m}' cannot do operation type {q} of job '{job}'"
        for before in p.predecessors(job):
            if before not in state.jobs:
                return f"precedence: job '{job}' before its predecessor '{before}'"
        doing = dict(zip(assignment.robots, plan, strict=True))
        for a, b, q in p.holding:
            if b != job:
                continue
            if a not in state.jobs:
                return f"holding: job '{job}' before '{a}', which holds into it"
            holders = {m for m, t in state.jobs[a].robots.items() if t == q}
            if holders != {m for m, t in doing.items() if t == q}:
                return (f"holding: type-{q} robots of '{a}' are {sorted(holders)} but of "
                        f"'{job}' would be {sorted(m for m, t in doing.items() if t == q)}")
        for m in doing:
            if state.held.get(m, job) != job:
                return f"holding: robot '{m}' must go to '{state.held[m]}' before '{job}'"
        return None

    def _place(self, job, assignment) -> Fraction:
        p, state = self.problem, self._state
        plan = p.job(job).plans[assignment.plan]
        here = p.job(job).location
        ready = [state.jobs[a].end for a in p.predecessors(job)]
        for m in assignment.robots:
            there = state.where[m]
            ready.append(state.free[m] + (p.travel(m, there, here) if there else 0))
        start = max(ready, default=Fraction(0))
        end = start + max(p.duration(m, q)
                          for m, q in zip(assignment.robots, plan, strict=True))
        robots = dict(zip(assignment.robots, plan, strict=True))
        state.jobs[job] = JobAssignment(job, assignment.plan, start, end, robots)
        for m in robots:
            state.free[m], state.where[m] = end, here
            state.sequences[m].append(job)
            state.held.pop(m, None)
        for a, b, q in p.holding:
            if a == job:
                for m, t in robots.items():
                    if t == q:
                        state.held[m] = b
        increase = max(Fraction(0), end - state.makespan)
        state.makespan = max(state.makespan, end)
        return increase


def restrict(problem: Problem, jobs) -> Problem:
    """The sub-problem on `jobs` only: arcs and distances among them, the same fleet."""
    keep = set(jobs)
    missing = sorted(keep - {j.name for j in problem.jobs})
    if missing:
        raise ValueError(f"problem '{problem.name}' has no job(s) {missing}")
    chosen = tuple(j for j in problem.jobs if j.name in keep)
    places = {j.location for j in chosen} | {r.start_location for r in problem.robots}
    return Problem(
        operation_types=problem.operation_types, robot_types=problem.robot_types,
        robots=problem.robots, jobs=chosen,
        distances={k: d for k, d in problem.distances.items()
                   if k[0] in places and k[1] in places},
        precedence=tuple(arc for arc in problem.precedence if set(arc) <= keep),
        holding=tuple(arc for arc in problem.holding if {arc[0], arc[1]} <= keep),
        locomote=problem.locomote, time_overrides=problem.time_overrides,
        fixed={k: f for k, f in problem.fixed.items() if k in keep},
        name=f'{problem.name}[{",".join(j.name for j in chosen)}]')
