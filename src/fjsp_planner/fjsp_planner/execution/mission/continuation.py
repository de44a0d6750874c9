"""Which jobs a new plan revision lets go on as they are, rather than start afresh.

A revision continues the jobs under way when it was posed (they are fixed in what it solves).
Two more kinds of job go on: those that progressed while it was solved (`progressed`), if the
new plan can let them (`goes_on`), and those not begun that it leaves as the old plan had them
(`unchanged`). Starting either afresh would void reports still on their way and have robots
redo work. Judged from the tracker alone, in schedule units.
"""

from fjsp_planner.execution.replan import ExecutionState
from fjsp_planner.execution.tracking import MissionTracker
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Schedule

DUE_GRACE = 1.0
"""Seconds after a job's start fell due (its robots arrived, its predecessors complete, by
the reports the planner has) during which its robots' start reports are expected on their
way: a new plan must let it go on as if it had been reported started. Longer, a report
must be missing, and the plan is not held back for it."""


def progressed(tracker: MissionTracker, posed: Problem, state: ExecutionState,
               fleet: dict[str, tuple[int, int]], now_units: float, time_scale: float
               ) -> list[str]:
    """Jobs the new plan starts afresh that started or completed since it was posed (from
    `state`, for the robots of `fleet`), or whose start fell due within the last DUE_GRACE
    seconds: their robots, all available when it was posed and none failed or restarted
    since the current plan, start them on reports the planner has too, so their start
    reports are on their way."""
    recent = now_units - DUE_GRACE / time_scale
    shaken = tracker.failed_since(tracker.revision)
    moved = []
    for job in posed.jobs:
        if job.name in posed.fixed:
            continue
        if job.name in state.running or job.name in state.done:
            continue
        if tracker.jobs[job.name].begun:
            moved.append(job.name)
            continue
        due = tracker.due_start(job.name)
        if due is None or due < recent:
            continue
        robots = tracker.plan.jobs[job.name].robots
        if not shaken & set(robots) and all(r in fleet for r in robots):
            moved.append(job.name)
    return moved


def completed_after_all(tracker: MissionTracker, posed: Problem, state: ExecutionState
                        ) -> list[str]:
    """Jobs running when the new plan was posed, which it starts afresh (their robot had
    failed), that completed since: the robot finished its operation before it failed, and
    its report came after its failure (states and events travel apart). The new plan would
    have the job done twice."""
    return [job.name for job in posed.jobs
            if job.name in state.running and job.name not in posed.fixed
            and tracker.jobs[job.name].end is not None]


def goes_on(tracker: MissionTracker, schedule: Schedule, progressed, continued) -> bool:
    """Whether the new plan can let the jobs that progressed while it was solved go on
    as they are (continued, not redone): it gives each the plan and robots it runs with,
    and each of those robots does them first, in the order it began them, before any
    job the plan starts afresh — so every robot's next leg leaves from where it is."""
    order = sorted(progressed, key=lambda job: tracker.jobs[job].start
                   if tracker.jobs[job].begun else tracker.due_start(job))
    for job in order:
        running, new = tracker.plan.jobs[job], schedule.jobs.get(job)
        if new is None or new.plan != running.plan \
                or dict(new.robots) != dict(running.robots):
            return False
    for robot in {r for job in order for r in tracker.plan.jobs[job].robots}:
        mine = [job for job in order if robot in tracker.plan.jobs[job].robots]
        fresh = [job for job in schedule.sequences.get(robot, ()) if job not in continued]
        if fresh[:len(mine)] != mine:
            return False
    return True


def unchanged(tracker: MissionTracker, schedule: Schedule, continued) -> frozenset[str]:
    """Jobs not begun that the new plan leaves as the old one had them: the same plan and
    robots, none of which failed or restarted since the old plan, and for each of those
    robots next in both the old and the new order, after what goes on. They go on rather
    than start afresh: a robot may have arrived at one, or started it, on reports still
    on their way to the planner, and starting it afresh would void those arrivals and
    have its robots do it twice."""
    old = tracker.plan
    # What a robot that failed or restarted since reported no longer holds.
    shaken = tracker.failed_since(tracker.revision)

    def same(job: str) -> bool:
        was, new, record = old.jobs.get(job), schedule.jobs.get(job), tracker.jobs[job]
        return (was is not None and new is not None and not record.begun
                and not record.aborted and new.plan == was.plan
                and dict(new.robots) == dict(was.robots) and not shaken & set(new.robots))

    heads = {}
    for robot, sequence in schedule.sequences.items():
        # A job begun and started afresh is still ahead of its robots in both orders.
        before = [job for job in old.sequences.get(robot, ())
                  if job not in continued and tracker.jobs[job].end is None]
        after = [job for job in sequence if job not in continued]
        head = []
        for a, b in zip(before, after, strict=False):
            if a != b or not same(a):
                break
            head.append(a)
        heads[robot] = head
    while True:
        kept = {job for head in heads.values() for job in head
                if all(job in heads.get(r, ()) for r in schedule.jobs[job].robots)}
        cut = {robot: head[:next((i for i, job in enumerate(head) if job not in kept),
                                 len(head))]
               for robot, head in heads.items()}
        if cut == heads:
            return frozenset(kept)
        heads = cut
