"""Left-shifting: every job as early as its robots, predecessors and travel allow.

A solver's schedule may leave a job later than it could start (CP-SAT minimises the
makespan, not each start): the robots would then stand idle before it for nothing.
`left_shifted` keeps each job's plan, robots and each robot's order and recomputes the
earliest times; it is applied after every solver, and kept only when the validator accepts
it.
"""

from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate


def left_shifted(problem: Problem, schedule: Schedule) -> Schedule:
    """`schedule` with every job at its earliest start, or `schedule` itself when that is
    not valid or not shorter or equal (orders that only zero-length jobs make consistent)."""
    try:
        shifted = earliest_schedule(
            problem, {j: a.plan for j, a in schedule.jobs.items()},
            {j: a.robots for j, a in schedule.jobs.items()}, schedule.sequences)
    except ValueError:
        return schedule
    if shifted.makespan > schedule.makespan or validate(problem, shifted):
        return schedule
    return shifted


def earliest_schedule(problem: Problem, plan, robots, sequences) -> Schedule:
    """The earliest-start schedule, in exact time, of given plans, robots and robot sequences.

    A job starts when its predecessors are complete and each of its robots has finished its
    previous job and travelled over (or, for its first job, has come from its start location)
    and is released; it completes when its slowest operation ends. Fixed jobs keep their times.
    Raises ValueError when the sequences and precedence form a cycle.
    """
    p = problem
    blockers = {j.name: set() for j in p.jobs}
    predecessors = {j.name: [] for j in p.jobs}
    for a, b in p.precedence:
        blockers[b].add(a)
        predecessors[b].append(a)
    previous = {}
    for m, sequence in sequences.items():
        for a, b in zip(sequence, sequence[1:], strict=False):
            blockers[b].add(a)
            previous[m, b] = a
    start, end = {}, {}
    order = _topological(blockers)
    for j in order:
        if j in p.fixed:
            start[j], end[j] = p.fixed[j].start, p.fixed[j].end
            continue
        here = p.job(j).location
        times = [end[a] for a in predecessors[j]]
        for m in robots[j]:
            before = previous.get((m, j))
            if before is None:
                r = p.robot(m)
                leg = p.travel(m, r.start_location, here) if r.start_location else 0
                times.append(r.release_time + leg)
            else:
                times.append(end[before] + p.travel(m, p.job(before).location, here))
                times.append(p.robot(m).release_time)
        start[j] = max(times, default=Fraction(0))
        end[j] = start[j] + max(p.duration(m, q) for m, q in robots[j].items())
    jobs = {j: JobAssignment(j, plan[j], start[j], end[j], dict(robots[j])) for j in order}
    return Schedule(jobs, {m: tuple(seq) for m, seq in sequences.items()})


def _topological(blockers) -> list[str]:
    """The jobs, each after its blockers (Kahn's algorithm)."""
    waiting = {j: len(b) for j, b in blockers.items()}
    unblocks = {j: [] for j in blockers}
    for j, found in blockers.items():
        for a in found:
            unblocks[a].append(j)
    ready = sorted(j for j, count in waiting.items() if not count)
    order = []
    while ready:
        j = ready.pop()
        order.append(j)
        for other in unblocks[j]:
            waiting[other] -= 1
            if not waiting[other]:
                ready.append(other)
    if len(order) != len(waiting):
        stuck = sorted(set(waiting) - set(order))
        raise ValueError(f'robot sequences and precedence form a cycle among {stuck}')
    return order
