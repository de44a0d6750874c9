"""An independent check of a schedule against the model of docs/model.md, in exact arithmetic.

It shares no code with the solvers on purpose: a mistake in a solver's model must not hide
itself by being repeated here. Only the problem and schedule data classes are used, and
travel is recomputed from `Problem.travel` rather than read from `Schedule.visits`.
"""

from collections import Counter

from fjsp_planner.model.problem import Problem, Robot
from fjsp_planner.model.schedule import JobAssignment, Schedule


def validate(problem: Problem, schedule: Schedule) -> list[str]:
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


def _coverage(problem: Problem, schedule: Schedule) -> list[str]:
    messages = []
    job_names = {j.name for j in problem.jobs}
    robot_names = {r.name for r in problem.robots}
    for job in problem.jobs:
        if job.name not in schedule.jobs:
            messages.append(f"job '{job.name}' is not scheduled")
    for key, assignment in schedule.jobs.items():
        if key not in job_names:
            messages.append(f"schedule has unknown job '{key}'")
        if assignment.job != key:
            messages.append(f"schedule entry '{key}' holds the assignment of job "
                            f"'{assignment.job}'")
        for robot in assignment.robots:
            if robot not in robot_names:
                messages.append(f"job '{key}' names unknown robot '{robot}'")
    for robot in schedule.sequences:
        if robot not in robot_names:
            messages.append(f"schedule has a sequence for unknown robot '{robot}'")
    return messages


def _staffing(problem: Problem, known: dict[str, JobAssignment]) -> list[str]:
    """Plan choice, who does what, and whether the job lasts long enough for each robot."""
    messages = []
    robot_names = {r.name for r in problem.robots}
    for name, a in known.items():
        plans = problem.job(name).plans
        if not 0 <= a.plan < len(plans):
            messages.append(f"job '{name}' uses plan {a.plan} but has only plans "
                            f'0..{len(plans) - 1}')
        elif sorted(a.robots.values()) != sorted(plans[a.plan]):
            messages.append(f"job '{name}': its robots do operation types "
                            f'{sorted(a.robots.values())} but plan {a.plan} is '
                            f'{sorted(plans[a.plan])}')
        if a.start < 0:
            messages.append(f"job '{name}' starts at negative time {a.start}")
        for robot, q in a.robots.items():
            if robot not in robot_names:
                continue
            duration = problem.duration(robot, q)
            if duration is None:
                messages.append(f"robot '{robot}' cannot do operation type {q} "
                                f"(job '{name}')")
            elif a.end < a.start + duration:
                messages.append(f"job '{name}' ends at {a.end} before robot '{robot}' "
                                f'finishes its type-{q} operation at {a.start + duration}')
    return messages


def _precedence(problem: Problem, known: dict[str, JobAssignment]) -> list[str]:
    messages = []
    for before, after in problem.precedence:
        if before in known and after in known and known[after].start < known[before].end:
            messages.append(f"job '{after}' starts at {known[after].start} before its "
                            f"predecessor '{before}' completes at {known[before].end}")
    return messages


def _sequences(problem: Problem, schedule: Schedule,
               known: dict[str, JobAssignment]) -> list[str]:
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
                messages.append(f"robot '{name}': sequence lists job '{job}' it has no "
                                'operation in')
            elif count > 1:
                messages.append(f"robot '{name}': sequence lists job '{job}' {count} times")
        for job in assigned:
            if job not in counts:
                messages.append(f"robot '{name}' has an operation in job '{job}' but its "
                                'sequence omits it')
        timed = [j for j in sequence if j in known]
        if timed and timed[0] not in problem.fixed:
            messages += _first_job(problem, robot, timed[0], known[timed[0]])
        for job in timed[1:]:
            if job not in problem.fixed and known[job].start < robot.release_time:
                messages.append(f"robot '{name}': job '{job}' starts at {known[job].start} "
                                f'before its release time {robot.release_time}')
        for prev, nxt in zip(timed, timed[1:], strict=False):
            start, end = known[nxt].start, known[prev].end
            if start < end:
                messages.append(f"robot '{name}': job '{nxt}' starts at {start}, overlapping "
                                f"'{prev}' which ends at {end}")
                continue
            here, there = problem.job(prev).location, problem.job(nxt).location
            travel = problem.travel(name, here, there)
            if start < end + travel:
                messages.append(f"robot '{name}': job '{nxt}' starts at {start} but the "
                                f"robot ends '{prev}' at {end} and travels {travel} from "
                                f"'{here}' to '{there}', arriving at {end + travel}")
    return messages


def _first_job(problem: Problem, robot: Robot, job: str, a: JobAssignment) -> list[str]:
    """A robot is free only from its release time, at its start location if it has one."""
    if robot.start_location is None:
        if a.start < robot.release_time:
            return [f"robot '{robot.name}': first job '{job}' starts at {a.start} before "
                    f'its release time {robot.release_time}']
        return []
    there = problem.job(job).location
    arrival = robot.release_time + problem.travel(robot.name, robot.start_location, there)
    if a.start < arrival:
        return [f"robot '{robot.name}': first job '{job}' starts at {a.start} but the "
                f'robot is released at {robot.release_time} at '
                f"'{robot.start_location}' and arrives at '{there}' at {arrival}"]
    return []


def _fixed(problem: Problem, known: dict[str, JobAssignment]) -> list[str]:
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
                messages.append(f"fixed job '{name}' has {field} {got} but is fixed "
                                f'with {want}')
    return messages


def _holding(problem: Problem, schedule: Schedule,
             known: dict[str, JobAssignment]) -> list[str]:
    messages = []
    for a, b, q in problem.holding:
        if a not in known or b not in known:
            continue
        arc = f"holding arc ('{a}', '{b}', {q})"
        holders = {r for r, t in known[a].robots.items() if t == q}
        held_by = {r for r, t in known[b].robots.items() if t == q}
        if holders != held_by:
            messages.append(f"{arc}: type-{q} robots of '{a}' are {sorted(holders)} but of "
                            f"'{b}' are {sorted(held_by)}")
        for robot in sorted(holders & held_by):
            sequence = tuple(schedule.sequences.get(robot, ()))
            if (a, b) not in zip(sequence, sequence[1:], strict=False):
                messages.append(f"{arc}: robot '{robot}' does not go directly from '{a}' "
                                f"to '{b}'")
    return messages
