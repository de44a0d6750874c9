"""Hand-made fact sequences of small missions, for the observe tests (no ROS).

The mission clock: schedule time t is wall time START + t (time scale 1 s per unit), so every
expected time below can be checked by eye.
"""

import math

from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.observe.facts import (
    MissionEventFact,
    PlanFact,
    PlannedTask,
    RobotStateFact,
    StatusFact,
    TaskEventFact,
)

START = 1_000_000.0
MISSION = 'demo-1'
ROBOTS = (('A', 'Arm'), ('B', 'Arm'), ('C', 'Rover'))


def at(t: float) -> float:
    """Wall stamp of schedule time t."""
    return START + t


def task(robot, job, start, end, continued=False, held=False, co_workers=(),
         predecessors=()):
    return PlannedTask(robot=robot, job=job, operation='weld', location=f'at_{job}',
                       travel_start=start - 1, arrival=start, start=start, operation_end=end,
                       end=end, co_workers=tuple(co_workers), predecessors=tuple(predecessors),
                       held_into_next=held, continued=continued)


def plan(revision, published, tasks, reasons=(), mission=MISSION, makespan=10.0):
    return PlanFact(stamp=at(published), mission_id=mission, revision=revision,
                    scenario_id='demo', mission_start=START, time_scale=1.0, cancelled=False,
                    makespan=makespan, solver_status='optimal', lower_bound=makespan,
                    reasons=tuple(reasons), robots=ROBOTS, tasks=tuple(tasks))


_count = iter(range(1, 1_000_000))


def event(kind: EventKind, robot, job, revision, t, reason='', mission=MISSION):
    return TaskEventFact(stamp=at(t), event_id=f'{robot or "planner"}/{next(_count)}',
                         mission_id=mission, kind=kind, robot=robot, job=job,
                         revision=revision, time=t, reason=reason)


def work(robots, job, revision, start, end, done=True):
    """The events of robots doing `job` from start to end (JOB_DONE if `done`)."""
    facts = []
    for robot in robots:
        facts += [event(EventKind.ARRIVED, robot, job, revision, start),
                  event(EventKind.STARTED, robot, job, revision, start)]
    if done:
        facts += [event(EventKind.OPERATION_DONE, robot, job, revision, end)
                  for robot in robots]
        facts.append(event(EventKind.JOB_DONE, '', job, revision, end))
    return facts


def state(robot, t, mode=RobotMode.IDLE, job='', revision=1, location='', mission=MISSION,
          progress=0.0, destination=''):
    return RobotStateFact(stamp=at(t), robot=robot, robot_type=dict(ROBOTS)[robot],
                          incarnation=1, mission_id=mission, mode=mode, revision=revision,
                          refusal='', failures=int(mode == RobotMode.FAILED), current_job=job,
                          location=location, destination=destination, progress=progress,
                          busy_until=math.nan)


def heartbeats(robot, start, end, period=0.2, **fields):
    """A robot's state repeated every `period` from start to end (inclusive)."""
    count = int(round((end - start) / period))
    return [state(robot, start + i * period, **fields) for i in range(count + 1)]


def status(t, state_, done, total, revision=1, mission=MISSION, blocked=(), warnings=(),
           replan_reasons=()):
    return StatusFact(stamp=at(t), mission_id=mission, state=state_, revision=revision,
                      scenario_id='demo', jobs_done=done, jobs_running=0, jobs_total=total,
                      planned_makespan=10.0, projected_makespan=10.0, elapsed=t,
                      blocked_reasons=tuple(blocked), replan_reasons=tuple(replan_reasons),
                      warnings=tuple(warnings), ignored=(0, 0, 0))


def mission_event(kind: MissionEventKind, t, revision=1, robot='', job='', reasons=(),
                  mission=MISSION):
    return MissionEventFact(stamp=at(t), event_id=f'planner/{next(_count)}',
                            mission_id=mission, kind=kind, revision=revision, time=t,
                            robot=robot, job=job, reasons=tuple(reasons))


def faulty_mission() -> list:
    """Three jobs on robots A, B, C with a failure of C mid-mission:

    - J1 (A, C) done at t=3 under revision 1; it is a jig job whose hold C keeps into J2.
    - J2 (B, C) started at t=4; C fails at t=5 (ABORTED); C's hold on J1 is lost too.
    - Revision 2 (published at t=5.5, "robot 'C' failed") redoes J1 on A, B from t=6 to 8
      (so J1's first attempt is voided) and J2 on A, B from t=8 to 10.
    - J3 (A) was done at t=2 under revision 1 and is left out of revision 2.
    - A goes silent from t=10.4 to t=13 (its heartbeat stops), then reports again.
    - The planner reports the mission complete at t=13: 3/3 jobs.
    """
    revision_1 = plan(1, -0.5, [
        task('A', 'J3', 0, 2), task('A', 'J1', 2, 3, held=False, co_workers=['C']),
        task('C', 'J1', 2, 3, held=True, co_workers=['A']),
        task('B', 'J2', 4, 6, co_workers=['C'], predecessors=['J1']),
        task('C', 'J2', 4, 6, co_workers=['B'], predecessors=['J1'])])
    revision_2 = plan(2, 5.5, [
        task('A', 'J1', 6, 8, co_workers=['B']), task('B', 'J1', 6, 8, co_workers=['A']),
        task('A', 'J2', 8, 10, co_workers=['B'], predecessors=['J1']),
        task('B', 'J2', 8, 10, co_workers=['A'], predecessors=['J1'])],
        reasons=["robot 'C' failed", "job 'J2' aborted"])
    facts = [revision_1, revision_2]
    facts += work(['A'], 'J3', 1, 0, 2)
    facts += work(['A', 'C'], 'J1', 1, 2, 3)
    facts += work(['B', 'C'], 'J2', 1, 4, 6, done=False)
    facts.append(event(EventKind.ABORTED, 'C', 'J2', 1, 5, reason="robot 'C' failed"))
    facts += work(['A', 'B'], 'J1', 2, 6, 8)
    facts += work(['A', 'B'], 'J2', 2, 8, 10)
    facts += heartbeats('A', 0, 10.4, mode=RobotMode.WORKING, job='J2')
    facts += heartbeats('A', 13, 13.4, revision=2)
    facts += heartbeats('B', 0, 13.4, revision=2)
    facts += heartbeats('C', 0, 4.8, mode=RobotMode.HOLDING, job='J2')
    facts += heartbeats('C', 5, 13.4, mode=RobotMode.FAILED)
    facts += [status(0, MissionState.EXECUTING, 0, 3), status(13, MissionState.COMPLETE, 3, 3,
                                                               revision=2)]
    return facts
