"""Lower bounds for any scenario, from what the fleet must do (docs/solver.md, "Bounds").

- Chains: a job starts no earlier than some robot able to do each of its operations can be
  there (its release time, then the least way from its start location along the distance
  table, as it may work on its way), and no earlier than its
  predecessors (precedence and holding arcs) can end, each at its fastest; what must follow
  it takes at least its tail. The longest head + duration + tail bounds the makespan.
- Energy over capability groups: for a set G of robots (those able to do one operation type,
  those of one type, each robot alone, all of them), a plan needs at least
  `len(plan) - max_staffed(plan, others)` robots of G (the operations the others cannot take
  as distinct robots), each busy for the whole job, which lasts at least the plan's fastest
  duration. The least such busy time of every job, summed, must fit in G's time: robot r
  of G has at most C - a_r of it, a_r its release time plus its least leg from its start
  location to a job it could work on (a robot that works travels to its first job first).
  The least C that holds that much bounds the makespan.
- A robot alone: the jobs that cannot be staffed without it are done one after another. Its
  release time, their least durations and one least leg into each of their locations it does
  not start at (from wherever it comes: distances need not obey the triangle inequality,
  and a robot goes straight from one job to the next) fit in the makespan; and, as on one
  machine, for every head h, h plus the durations of the jobs whose heads are at least h
  plus the least of their tails.

Every bound here is computed in exact arithmetic from the problem alone: none needs a known
schedule, so each holds for every schedule. Problems with running (fixed) jobs get none.
"""

from fractions import Fraction

from fjsp_planner.model.problem import Problem, max_staffed
from fjsp_planner.solving.bounds.geometry import least_leg_into, least_location_travel
from fjsp_planner.solving.bounds.jobs import critical_path_bound, topological


def static_bound(problem: Problem) -> Fraction:
    """The best bound known from the problem alone: the critical path or `fleet_bound`,
    computed once per problem."""
    cached = problem.__dict__.get('_static_bound')
    if cached is None:
        cached = max(critical_path_bound(problem), fleet_bound(problem))
        object.__setattr__(problem, '_static_bound', cached)
    return cached


def fleet_bound(problem: Problem) -> Fraction:
    """The best of the bounds of the module docstring (0 with running jobs)."""
    if problem.fixed or not problem.jobs:
        return Fraction(0)
    facts = _Facts(problem)
    return max(facts.chain_bound(), facts.energy_bound(), facts.robot_bound())


def heads_tails_and_fastest(problem: Problem):
    """job -> its head (the chains of the module docstring), job -> its tail, job -> its
    least duration: what holds for every schedule of a problem without running jobs."""
    facts = _Facts(problem)
    return facts.heads, facts.tails, facts.fastest


class _Facts:
    def __init__(self, problem: Problem):
        self.problem = p = problem
        self.robots = [r.name for r in p.robots]
        self.fastest_op = {}
        """operation type -> least time any robot takes for it."""
        for q in {q for job in p.jobs for plan in job.plans for q in plan}:
            self.fastest_op[q] = min(t for r in self.robots
                                     if (t := p.duration(r, q)) is not None)
        self.plan_length = {(job.name, k): max(self.fastest_op[q] for q in plan)
                            for job in p.jobs for k, plan in enumerate(job.plans)}
        self.fastest = {job.name: min(self.plan_length[job.name, k]
                                      for k in range(len(job.plans))) for job in p.jobs}
        self.able = {r: {q for q in self.fastest_op if p.duration(r, q) is not None}
                     for r in self.robots}
        self.able_by_op = {q: frozenset(r for r in self.robots if q in self.able[r])
                           for q in self.fastest_op}
        self.heads, self.tails = self._heads_and_tails()
        self.readiness = {}

    def arrival(self, robot: str, location: str) -> Fraction:
        """Earliest time the robot can be at `location` straight from its start location:
        its first job's."""
        r = self.problem.robot(robot)
        if r.start_location is None:
            return r.release_time
        return r.release_time + self.problem.travel(robot, r.start_location, location)

    def earliest_at(self, robot: str, location: str) -> Fraction:
        """Earliest time the robot can be at `location`, working on its way or not
        (distances need not obey the triangle inequality)."""
        r = self.problem.robot(robot)
        if r.start_location is None:
            return r.release_time
        return r.release_time + least_location_travel(self.problem, robot, r.start_location,
                                                      location)

    def _heads_and_tails(self):
        p = self.problem
        arcs = list(p.precedence) + [(a, b) for a, b, _ in p.holding]
        before = {job.name: [] for job in p.jobs}
        after = {job.name: [] for job in p.jobs}
        for a, b in arcs:
            before[b].append(a)
            after[a].append(b)
        order = topological(p)
        heads = {}
        for name in order:
            job = p.job(name)
            # Each operation of the plan needs some able robot there.
            there = min(max(min(self.earliest_at(r, job.location) for r in self.robots
                                if q in self.able[r]) for q in plan) for plan in job.plans)
            heads[name] = max([there] + [heads[a] + self.fastest[a] for a in before[name]])
        tails = {}
        for name in reversed(order):
            tails[name] = max((self.fastest[b] + tails[b] for b in after[name]),
                              default=Fraction(0))
        return heads, tails

    def chain_bound(self) -> Fraction:
        return max(self.heads[j] + self.fastest[j] + self.tails[j] for j in self.fastest)

    def needed(self, group: frozenset, job) -> list[tuple[int, Fraction]]:
        """Per plan: (robots of `group` it needs at least, its fastest duration)."""
        found = []
        for k, plan in enumerate(job.plans):
            if len(plan) == 1:
                # One operation: needed from G exactly when no other robot can do it.
                count = int(self.able_by_op[plan[0]] <= group)
            else:
                others = [r for r in self.robots if r not in group]
                count = len(plan) - max_staffed(self.problem, plan, others)
            found.append((count, self.plan_length[job.name, k]))
        return found

    def groups(self) -> list[frozenset]:
        p = self.problem
        found = {frozenset(self.robots)}
        found.update(self.able_by_op.values())
        found.update(frozenset(r.name for r in p.robots if r.type == kind)
                     for kind in {r.type for r in p.robots})
        return sorted(found, key=sorted)

    def energy_bound(self) -> Fraction:
        p = self.problem
        best = Fraction(0)
        for group in self.groups():
            energy = sum(min(count * length for count, length in self.needed(group, job))
                         for job in p.jobs)
            if energy == 0:
                continue
            ready = sorted(self.ready(r) for r in group)
            best = max(best, _least_time_holding(energy, ready))
        return best

    def ready(self, robot: str) -> Fraction:
        """Earliest time the robot can be at a job it could work on (its release time if
        there is none)."""
        found = self.readiness.get(robot)
        if found is None:
            p = self.problem
            places = {job.location for job in p.jobs
                      if any(self.able[robot].intersection(plan) for plan in job.plans)}
            found = self.readiness[robot] = min(
                (self.arrival(robot, place) for place in places),
                default=p.robot(robot).release_time)
        return found

    def robot_bound(self) -> Fraction:
        p = self.problem
        best = Fraction(0)
        for robot in p.robots:
            r = robot.name
            alone = frozenset([r])
            mine = [job for job in p.jobs
                    if min(count for count, _ in self.needed(alone, job)) >= 1]
            if not mine:
                continue
            # The least duration of each such job, with r on it: a plan that needs r.
            lengths = {job.name: min(length for count, length in self.needed(alone, job)
                                     if count >= 1) for job in mine}
            places = {job.location for job in mine} - {robot.start_location}
            legs = [least_leg_into(p, r, place) for place in places]
            # A robot that may start anywhere needs no leg into its first place.
            moves = sum(legs) - (max(legs, default=0) if robot.start_location is None else 0)
            best = max(best, robot.release_time + sum(lengths.values()) + moves)
            for head in {self.heads[job.name] for job in mine}:
                later = [job.name for job in mine if self.heads[job.name] >= head]
                best = max(best, head + sum(lengths[j] for j in later)
                           + min(self.tails[j] for j in later))
        return best


def _least_time_holding(energy: Fraction, ready: list[Fraction]) -> Fraction:
    """The least C with sum over r of max(0, C - ready[r]) >= energy (`ready` ascending)."""
    total = Fraction(0)
    for k, at in enumerate(ready):
        total += at
        level = (energy + total) / (k + 1)
        if k + 1 == len(ready) or level <= ready[k + 1]:
            return level
    return Fraction(0)
