"""An independent check of a schedule against the model of docs/model.md, in exact arithmetic.

It shares no code with the solvers on purpose: a mistake in a solver's model must not hide
itself by being repeated here. Only the problem and schedule data classes are used, and
travel is recomputed from `Problem.travel` rather than read from `Schedule.visits`.
"""

from collections import Counter
from fractions import Fraction

from fjsp_common.decimals import decimals
from fjsp_planner.model.problem import Problem, Robot
from fjsp_planner.model.schedule import JobAssignment, Schedule


class Violation(str):
    """One way a schedule breaks its problem, as a person reads it: its times written as
    decimals (`fjsp_common.decimals`). `exact` says the same with exact fractions,
    and `values` holds what it names, times as exact `Fraction`s."""

    exact: str
    values: dict

    def __new__(cls, template: str, **values):
        times = [name for name, value in values.items() if isinstance(value, Fraction)]
        written = dict(zip(times, decimals(*(values[t] for t in times)), strict=True))
        self = super().__new__(cls, template.format(**{**values, **written}))
        self.exact = template.format(**values)
        self.values = values
        self._template = template
        return self

    def __reduce__(self):
        # Copies and pickles are rebuilt from the template, which str's own way would lose.
        return _rebuilt, (self._template, self.values)


def _rebuilt(template: str, values: dict) -> Violation:
    return Violation(template, **values)


def validate(problem: Problem, schedule: Schedule) -> list[Violation]:
    """Every way `schedule` breaks `problem`, one message per violation; empty means valid."""
    messages = _coverage(problem, schedule)
    # Later checks look only at jobs both known and scheduled, so one missing or unknown job
    # is reported once instead of breaking every check that would mention it.
    known = {j.name: schedule.jobs[j.name] for j in problem.jobs if j.name in schedule.jobs}
    messages += _staffing(problem, known)
    messages += _precedence(problem, known)
    messages += _sequences(problem, schedule, known)
    messages += _fixed(problem, known)
    messages += _holding(problem, schedule, known)
    return messages


def _coverage(problem: Problem, schedule: Schedule) -> list[Violation]:
    messages = []
    job_names = {j.name for j in problem.jobs}
    robot_names = {r.name for r in problem.robots}
    for job in problem.jobs:
        if job.name not in schedule.jobs:
            messages.append(Violation("job '{job}' is not scheduled", job=job.name))
    for key, assignment in schedule.jobs.items():
        if key not in job_names:
            messages.append(Violation("schedule has unknown job '{job}'", job=key))
        if assignment.job != key:
            messages.append(Violation("schedule entry '{key}' holds the assignment of job "
                                      "'{job}'", key=key, job=assignment.job))
        for robot in assignment.robots:
            if robot not in robot_names:
                messages.append(Violation("job '{job}' names unknown robot '{robot}'",
                                          job=key, robot=robot))
    for robot in schedule.sequences:
        if robot not in robot_names:
            messages.append(Violation("schedule has a sequence for unknown robot '{robot}'",
                                      robot=robot))
    return messages


def _staffing(problem: Problem, known: dict[str, JobAssignment]) -> list[Violation]:
    """Plan choice, who does what, and whether the job lasts long enough for each robot."""
    messages = []
    robot_names = {r.name for r in problem.robots}
    for name, a in known.items():
        plans = problem.job(name).plans
        if not 0 <= a.plan < len(plans):
            messages.append(Violation("job '{job}' uses plan {plan} but has only plans "
                                      '0..{last}', job=name, plan=a.plan, last=len(plans) - 1))
        elif sorted(a.robots.values()) != sorted(plans[a.plan]):
            messages.append(Violation("job '{job}': its robots do operation types {done} but "
                                      'plan {plan} is {types}', job=name,
                                      done=sorted(a.robots.values()), plan=a.plan,
                                      types=sorted(plans[a.plan])))
        if a.start < 0:
            messages.append(Violation("job '{job}' starts at negative time {start}", job=name,
                                      start=a.start))
        for robot, q in a.robots.items():
            if robot not in robot_names:
                continue
            duration = problem.duration(robot, q)
            if duration is None:
                messages.append(Violation("robot '{robot}' cannot do operation type {q} "
                                          "(job '{job}')", robot=robot, q=q, job=name))
            elif a.end < a.start + duration:
                messages.append(Violation("job '{job}' ends at {end} before robot '{robot}' "
                                          'finishes its type-{q} operation at {finish}',
                                          job=name, end=a.end, robot=robot, q=q,
                                          finish=a.start + duration))
    return messages


def _precedence(problem: Problem, known: dict[str, JobAssignment]) -> list[Violation]:
    messages = []
    for before, after in problem.precedence:
        if before in known and after in known and known[after].start < known[before].end:
            messages.append(Violation("job '{job}' starts at {start} before its predecessor "
                                      "'{before}' completes at {end}", job=after,
                                      start=known[after].start, before=before,
                                      end=known[before].end))
    return messages


def _sequences(problem: Problem, schedule: Schedule,
               known: dict[str, JobAssignment]) -> list[Violation]:
    """Each robot's route: the right jobs, once each, reachable in time from where it was."""
    messages = []
    for robot in problem.robots:
        name = robot.name
        # A robot without a sequence entry is read as idle; any job it works on then shows
        # up below as omitted.
        sequence = tuple(schedule.sequences.get(name, ()))
        assigned = [j for j, a in known.items() if name in a.robots]
        counts = Counter(sequence)
        for job, count in counts.items():
            if job not in assigned:
                messages.append(Violation("robot '{robot}': sequence lists job '{job}' it has "
                                          'no operation in', robot=name, job=job))
            elif count > 1:
                messages.append(Violation("robot '{robot}': sequence lists job '{job}' "
                                          '{count} times', robot=name, job=job, count=count))
        for job in assigned:
            if job not in counts:
                messages.append(Violation("robot '{robot}' has an operation in job '{job}' "
                                          'but its sequence omits it', robot=name, job=job))
        timed = [j for j in sequence if j in known]
        if timed and timed[0] not in problem.fixed:
            messages += _first_job(problem, robot, timed[0], known[timed[0]])
        for job in timed[1:]:
            if job not in problem.fixed and known[job].start < robot.release_time:
                messages.append(Violation("robot '{robot}': job '{job}' starts at {start} "
                                          'before its release time {release}', robot=name,
                                          job=job, start=known[job].start,
                                          release=robot.release_time))
        for prev, nxt in zip(timed, timed[1:], strict=False):
            start, end = known[nxt].start, known[prev].end
            if start < end:
                messages.append(Violation("robot '{robot}': job '{job}' starts at {start}, "
                                          "overlapping '{prev}' which ends at {end}",
                                          robot=name, job=nxt, start=start, prev=prev, end=end))
                continue
            here, there = problem.job(prev).location, problem.job(nxt).location
            travel = problem.travel(name, here, there)
            if start < end + travel:
                messages.append(Violation("robot '{robot}': job '{job}' starts at {start} but "
                                          "the robot ends '{prev}' at {end} and travels "
                                          "{travel} from '{here}' to '{there}', arriving at "
                                          '{arrival}', robot=name, job=nxt, start=start,
                                          prev=prev, end=end, travel=travel, here=here,
                                          there=there, arrival=end + travel))
    return messages


def _first_job(problem: Problem, robot: Robot, job: str, a: JobAssignment) -> list[Violation]:
    """A robot is free only from its release time, at its start location if it has one."""
    if robot.start_location is None:
        if a.start < robot.release_time:
            return [Violation("robot '{robot}': first job '{job}' starts at {start} before "
                              'its release time {release}', robot=robot.name, job=job,
                              start=a.start, release=robot.release_time)]
        return []
    there = problem.job(job).location
    arrival = robot.release_time + problem.travel(robot.name, robot.start_location, there)
    if a.start < arrival:
        return [Violation("robot '{robot}': first job '{job}' starts at {start} but the robot "
                          "is released at {release} at '{home}' and arrives at '{there}' at "
                          '{arrival}', robot=robot.name, job=job, start=a.start,
                          release=robot.release_time, home=robot.start_location, there=there,
                          arrival=arrival)]
    return []


def _fixed(problem: Problem, known: dict[str, JobAssignment]) -> list[Violation]:
    """Jobs already running when the problem was posed must be kept exactly as they are."""
    messages = []
    for name, fixed in problem.fixed.items():
        if name not in known:
            continue
        a = known[name]
        for field, got, want in (('plan', a.plan, fixed.plan),
                                 ('start', a.start, fixed.start),
                                 ('end', a.end, fixed.end),
                                 ('robots', dict(a.robots), dict(fixed.robots))):
            if got != want:
                messages.append(Violation("fixed job '{job}' has {field} {got} but is fixed "
                                          'with {want}', job=name, field=field, got=got,
                                          want=want))
    return messages


def _holding(problem: Problem, schedule: Schedule,
             known: dict[str, JobAssignment]) -> list[Violation]:
    messages = []
    for a, b, q in problem.holding:
        if a not in known or b not in known:
            continue
        holders = {r for r, t in known[a].robots.items() if t == q}
        held_by = {r for r, t in known[b].robots.items() if t == q}
        if holders != held_by:
            messages.append(Violation("holding arc ('{a}', '{b}', {q}): type-{q} robots of "
                                      "'{a}' are {holders} but of '{b}' are {held_by}", a=a,
                                      b=b, q=q, holders=sorted(holders),
                                      held_by=sorted(held_by)))
        for robot in sorted(holders & held_by):
            sequence = tuple(schedule.sequences.get(robot, ()))
            if (a, b) not in zip(sequence, sequence[1:], strict=False):
                messages.append(Violation("holding arc ('{a}', '{b}', {q}): robot '{robot}' "
                                          "does not go directly from '{a}' to '{b}'", a=a, b=b,
                                          q=q, robot=robot))
    return messages
