"""Between the domain core's objects and fjsp_msgs messages."""

import math

from fjsp_msgs.msg import JobState, Place, Plan, PlanTask, RobotPlan
from fjsp_planner.execution.tracking import MissionTracker
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Result, Schedule


def _float(value) -> float:
    return math.nan if value is None else float(value)


def plan_msg(scenario: Problem, posed: Problem, schedule: Schedule, result: Result,
             mission_id: str, revision: int, mission_start, time_scale: float, stamp,
             restarted_in=None, reasons=(), incarnations=None) -> Plan:
    """The plan message of a schedule of `posed`: every robot's tasks with travel, times and
    partners. `posed` is the scenario itself, or what remained of it at a re-plan; every
    robot of the scenario is listed with where `posed` starts it (the ones left out of
    `posed` with no task and no place) and the agent incarnation its tasks are for
    (`incarnations`; 0 where not given).
    `restarted_in` maps a job to the revision that last started it afresh, `revision` (a
    job not continued) where not given."""
    restarted_in = restarted_in or {}
    holds = {(a, q): b for a, b, q in posed.holding}
    in_posed = {r.name: r for r in posed.robots}
    robots = []
    for robot in scenario.robots:
        sequence = schedule.sequences.get(robot.name, ()) if robot.name in in_posed else ()
        tasks = []
        visits = schedule.visits(posed, robot.name) if sequence else ()
        for index, visit in enumerate(visits):
            a = schedule.jobs[visit.job]
            q = a.robots[robot.name]
            following = sequence[index + 1] if index + 1 < len(sequence) else None
            tasks.append(PlanTask(
                job=visit.job, process_plan=a.plan, operation_type=q,
                operation_name=posed.operation_types[q],
                location=posed.job(visit.job).location,
                travel_start=float(visit.travel_start), arrival=float(visit.arrival),
                start=float(a.start),
                operation_end=float(a.start + posed.duration(robot.name, q)),
                end=float(a.end),
                co_workers=sorted(r for r in a.robots if r != robot.name),
                predecessors=_predecessors(scenario, posed, visit.job),
                held_into_next=following is not None
                and holds.get((visit.job, q)) == following,
                continued=restarted_in.get(visit.job, revision) < revision,
                restarted_in=min(restarted_in.get(visit.job, revision), revision)))
        start = in_posed[robot.name].start_location if robot.name in in_posed else None
        robots.append(RobotPlan(robot=robot.name, robot_type=robot.type,
                                start_location=start or '', tasks=tasks,
                                incarnation=(incarnations or {}).get(robot.name, 0)))
    return Plan(stamp=stamp, mission_id=mission_id, revision=revision,
                scenario_id=scenario.name, reasons=list(reasons),
                mission_start=mission_start, time_scale=time_scale,
                makespan=float(result.makespan), solver_status=str(result.status),
                lower_bound=_float(result.lower_bound), robots=robots,
                places=places(scenario))


def places(scenario: Problem) -> list[Place]:
    """The scenario's map: every location it gives coordinates (2-D ones at z = 0)."""
    return [Place(name=name, x=float(point[0]), y=float(point[1]),
                  z=float(point[2]) if len(point) > 2 else 0.0)
            for name, point in scenario.coordinates.items()]


def _predecessors(scenario: Problem, posed: Problem, job: str) -> list[str]:
    """Every job that must complete before `job`, those done before a re-plan included: a
    job that goes on from an older revision may have its robots there since before the
    last of them ended, and must not start before it."""
    return list(dict.fromkeys(scenario.predecessors(job) + posed.predecessors(job)))


def cancel_msg(scenario: Problem, mission_id: str, revision: int, mission_start,
               time_scale: float, stamp, reasons=()) -> Plan:
    """The revision that cancels a mission: every robot listed, with no task."""
    return Plan(stamp=stamp, mission_id=mission_id, revision=revision,
                scenario_id=scenario.name, mission_start=mission_start, time_scale=time_scale,
                cancelled=True, makespan=math.nan, solver_status='cancelled',
                lower_bound=math.nan, reasons=list(reasons),
                robots=[RobotPlan(robot=r.name, robot_type=r.type) for r in scenario.robots],
                places=places(scenario))


def job_states(tracker: MissionTracker) -> list[JobState]:
    states = []
    for name, record in tracker.jobs.items():
        planned = record.done_as
        if planned is None and tracker.plan is not None:
            planned = tracker.plan.jobs.get(name)
        if record.end is not None:
            state = JobState.STATE_DONE
        elif record.aborted:
            state = JobState.STATE_ABORTED
        elif record.started:
            state = JobState.STATE_RUNNING
        else:
            state = JobState.STATE_PENDING
        states.append(JobState(
            job=name, state=state, robots=sorted(planned.robots) if planned else [],
            planned_start=_float(planned.start if planned else None),
            planned_end=_float(planned.end if planned else None),
            actual_start=_float(record.start), actual_end=_float(record.end)))
    return states
