"""Which attempt at a job a report is about, and so whether it still counts.

A plan revision either continues a job (it goes on as it is: `PlanTask.continued`) or starts
it afresh. Each attempt at a job begins with the revision that started it afresh; every task
of a later revision that continues the job names that revision (`PlanTask.restarted_in`), so
a receiver that missed it still knows. A report made under a revision older than the one that
last started its job is about an earlier attempt: it is void, whichever revisions in between
the receiver saw. The planner, the agents, the monitor's history and the test harness all
judge reports by this rule. Free of ROS: plan tasks are read by their fields' names.
"""


def attempt_revision(plan_revision: int, continued: bool, restarted_in: int) -> int:
    """The revision that began the attempt at a job a task of plan `plan_revision` belongs
    to: the plan's own when it starts the job afresh, else `restarted_in`, never later than
    the plan (0: the plan does not say)."""
    return plan_revision if not continued else min(restarted_in, plan_revision)


def void(reported_under: int, restarted_in: int) -> bool:
    """Whether a report made under revision `reported_under` is about an attempt older than
    the one begun by revision `restarted_in`."""
    return reported_under < restarted_in


def plan_attempts(plan_revision: int, tasks) -> dict[str, int]:
    """Per job of a plan, the revision that began the attempt the plan goes on with; `tasks`
    are its tasks (anything with `job`, `continued` and `restarted_in`)."""
    attempts: dict[str, int] = {}
    for task in tasks:
        since = attempt_revision(plan_revision, task.continued, task.restarted_in)
        attempts[task.job] = max(attempts.get(task.job, 0), since)
    return attempts


class Restarts:
    """The latest revision that started each job afresh, as the plans received tell it."""

    def __init__(self):
        self._latest: dict[str, int] = {}

    def restart(self, job: str, revision: int) -> bool:
        """`revision` started `job` afresh; whether that is later than any restart known."""
        if revision <= self._latest.get(job, 0):
            return False
        self._latest[job] = revision
        return True

    def latest(self, job: str) -> int:
        """The latest revision known to have started `job` afresh (0: none)."""
        return self._latest.get(job, 0)

    def void(self, job: str, revision: int) -> bool:
        """Whether a report about `job` made under `revision` is about an earlier attempt."""
        return void(revision, self.latest(job))
