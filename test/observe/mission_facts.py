"""Hand-made fact sequences of small missions, and recordings of them, for the observe tests
(no ROS: messages are CDR-encoded from the interface files by mcap-ros2-support).

The mission clock: schedule time t is wall time START + t (time scale 1 s per unit), so every
expected time below can be checked by eye.
"""

import math
import re
import sys
from pathlib import Path

from mcap_ros2._dynamic import serialize_dynamic

from fjsp_common.vocabulary import EventKind, MissionEventKind, MissionState, RobotMode
from fjsp_planner.observe.facts import (
    MissionEventFact,
    PlanFact,
    PlannedTask,
    RobotStateFact,
    StatusFact,
    TaskEventFact,
)
from fjsp_planner.observe.recording import (
    Offer,
    RecordingWriter,
    message_definition,
    msg_files_under,
)

from repo_paths import REPO

START = 1_000_000.0
MISSION = 'demo-1'
ROBOTS = (('A', 'Arm'), ('B', 'Arm'), ('C', 'Rover'))


def at(t: float) -> float:
    """Wall stamp of schedule time t."""
    return START + t


def task(robot, job, start, end, continued=False, held=False, co_workers=(),
         predecessors=(), restarted_in=1):
    """A task of a job that, when continued, was last started afresh in `restarted_in`."""
    return PlannedTask(robot=robot, job=job, operation='weld', location=f'at_{job}',
                       travel_start=start - 1, arrival=start, start=start, operation_end=end,
                       end=end, co_workers=tuple(co_workers), predecessors=tuple(predecessors),
                       held_into_next=held, continued=continued,
                       restarted_in=restarted_in if continued else 0)


def plan(revision, published, tasks, reasons=(), mission=MISSION, makespan=10.0, places=()):
    return PlanFact(stamp=at(published), mission_id=mission, revision=revision,
                    scenario_id='demo', mission_start=START, time_scale=1.0, cancelled=False,
                    makespan=makespan, solver_status='optimal', lower_bound=makespan,
                    reasons=tuple(reasons), robots=ROBOTS, tasks=tuple(tasks),
                    places=tuple(places))


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


READ_MSG = msg_files_under(REPO / 'src', Path(sys.prefix) / 'share')
TOPICS = {PlanFact: ('/plan', 'Plan'), TaskEventFact: ('/task_events', 'TaskEvent'),
          RobotStateFact: ('/robot_states', 'RobotState'),
          StatusFact: ('/mission_status', 'MissionStatus')}


def constant(type_name: str, prefix: str, word) -> int:
    text = (REPO / 'src' / 'fjsp_msgs' / 'msg' / f'{type_name}.msg').read_text()
    return int(re.search(rf'^\w+\s+{prefix}_{word.name}\s*=\s*(\d+)', text, re.M).group(1))


def time(seconds: float) -> dict:
    whole = int(seconds // 1)
    return {'sec': whole, 'nanosec': int(round((seconds - whole) * 1e9))}


def as_message(fact) -> dict:
    """The message a fact came from, as mcap-ros2-support encodes it."""
    if isinstance(fact, PlanFact):
        return {'stamp': time(fact.stamp), 'mission_id': fact.mission_id,
                'revision': fact.revision, 'scenario_id': fact.scenario_id,
                'mission_start': time(fact.mission_start), 'time_scale': fact.time_scale,
                'cancelled': fact.cancelled, 'makespan': fact.makespan,
                'solver_status': fact.solver_status, 'lower_bound': fact.lower_bound,
                'reasons': list(fact.reasons),
                'robots': [{'robot': robot, 'robot_type': kind, 'tasks': [
                    {'job': t.job, 'process_plan': 0, 'operation_type': 0,
                     'operation_name': t.operation, 'location': t.location,
                     'travel_start': t.travel_start, 'arrival': t.arrival, 'start': t.start,
                     'operation_end': t.operation_end, 'end': t.end,
                     'co_workers': list(t.co_workers), 'predecessors': list(t.predecessors),
                     'held_into_next': t.held_into_next, 'continued': t.continued,
                     'restarted_in': t.restarted_in}
                    for t in fact.tasks if t.robot == robot]} for robot, kind in fact.robots],
                'places': [{'name': p.name, 'x': p.x, 'y': p.y, 'z': p.z} for p in fact.places]}
    if isinstance(fact, TaskEventFact):
        return {'stamp': time(fact.stamp), 'event_id': fact.event_id,
                'mission_id': fact.mission_id, 'kind': constant('TaskEvent', 'KIND', fact.kind),
                'robot': fact.robot, 'job': fact.job, 'plan_revision': fact.revision,
                'time': fact.time, 'reason': fact.reason}
    if isinstance(fact, RobotStateFact):
        return {'stamp': time(fact.stamp), 'robot': fact.robot, 'robot_type': fact.robot_type,
                'incarnation': fact.incarnation, 'mission_id': fact.mission_id,
                'mode': constant('RobotState', 'MODE', fact.mode),
                'plan_revision': fact.revision, 'refusal': fact.refusal,
                'failures': fact.failures, 'current_job': fact.current_job,
                'location': fact.location, 'destination': fact.destination,
                'progress': fact.progress, 'busy_until': fact.busy_until}
    return {'stamp': time(fact.stamp), 'mission_id': fact.mission_id,
            'state': constant('MissionStatus', 'STATE', fact.state),
            'plan_revision': fact.revision, 'scenario_id': fact.scenario_id,
            'jobs_done': fact.jobs_done, 'jobs_running': fact.jobs_running,
            'jobs_total': fact.jobs_total, 'planned_makespan': fact.planned_makespan,
            'projected_makespan': fact.projected_makespan, 'elapsed': fact.elapsed,
            'blocked_reasons': list(fact.blocked_reasons),
            'replan_reasons': list(fact.replan_reasons), 'warnings': list(fact.warnings),
            'ignored_stale': 0, 'ignored_duplicate': 0, 'ignored_unknown': 0}


def record(path: Path, facts, cut=False) -> None:
    writer = RecordingWriter(path, chunk_size=4096)
    channels, encoders = {}, {}
    for kind, (topic, name) in TOPICS.items():
        type_name = f'fjsp_msgs/msg/{name}'
        definition = message_definition(type_name, READ_MSG)
        channels[kind] = writer.add_topic(topic, type_name, definition,
                                          Offer(reliable=True, transient_local=True, depth=1))
        encoders[kind] = serialize_dynamic(type_name, definition)[type_name]
    for fact in facts:
        data = encoders[type(fact)](as_message(fact))
        writer.write(channels[type(fact)], data, int(fact.stamp * 1e9))
    if cut:
        writer.flush()
        return
    writer.close()
