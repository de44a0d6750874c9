"""What the mission tests check of a mission that ran on real processes, from the test's
observer: its own plans and events, every job done once, its executed timeline valid."""

from collections import Counter

from fjsp_msgs.msg import TaskEvent
from fjsp_planner.testing import executed_timeline, validate_executed


def of_mission(observer, mission_id):
    """The plans and task events of one mission, as the observer heard them."""
    with observer.lock:
        plans = [p for p in observer.plans if p.mission_id == mission_id]
        events = [e for e in observer.events if e.mission_id == mission_id]
    return plans, events


def check_done_once(problem, observer, mission_id):
    """Every job of `problem` started and completed exactly once by each of its robots, and
    the executed timeline is valid."""
    jobs = sorted(j.name for j in problem.jobs)

    def all_heard(o) -> bool:
        # The planner's job-done and the robots' own reports come from different writers:
        # the test may hear a job declared done before the last report it was declared from
        # (and a robot's start before the plan that gave it the job).
        plans, events = of_mission(o, mission_id)
        if sum(e.kind == TaskEvent.KIND_JOB_DONE for e in events) < len(jobs):
            return False
        try:
            return sorted(executed_timeline(problem, plans, events).jobs) == jobs
        except AssertionError:
            return False

    observer.wait_for(all_heard, 10, "every job-done event and every robot's report")
    plans, events = of_mission(observer, mission_id)
    starts = Counter((e.job, e.robot) for e in events if e.kind == TaskEvent.KIND_STARTED)
    assert set(starts.values()) == {1}, starts
    executed = executed_timeline(problem, plans, events)
    assert sorted(executed.jobs) == jobs
    assert validate_executed(problem, executed) == []
