"""A mission a previous planner process ran, rebuilt from its journal.

The journal keeps what the fleet does not: the plans published (with where the robots started
and the agent incarnations they were planned for) and the jobs declared done. A resumed mission
starts from them; what the robots did while no planner ran comes from their event histories,
and the mission is re-planned from where they are once those have arrived.
"""

from dataclasses import replace

from fjsp_common.vocabulary import MissionEventKind
from fjsp_planner.execution.journal import DoneRecord, PlanRecord, Record
from fjsp_planner.execution.mission.effects import Effect, Note
from fjsp_planner.execution.mission.liveness import Liveness
from fjsp_planner.model.problem import Problem


def started_where(problem: Problem, records: list[Record]) -> Problem:
    """`problem` with its robots starting where the journaled plans say the mission began."""
    starts = next((r.starts for r in reversed(records)
                   if isinstance(r, PlanRecord) and r.starts), {})
    if starts:
        # The mission began where the robots were, not where the scenario starts them.
        problem = replace(problem, robots=tuple(
            replace(r, start_location=starts.get(r.name, r.start_location))
            for r in problem.robots))
    return problem


def restore(mission, records: list[Record], wall: float) -> None:
    """Replay the journal's plan and done records into a `controller.Mission` just made."""
    tracker = mission.tracker
    for record in records:
        if isinstance(record, PlanRecord) and record.schedule is not None:
            tracker.set_plan(record.schedule, record.revision, record.continued)
            mission.schedule, mission.start = record.schedule, record.start
            mission.planned_makespan = float(record.schedule.makespan)
            mission.replan_reasons = record.reasons
            mission.journaled = dict(record.incarnations)
        elif isinstance(record, DoneRecord):
            tracker.restore_done(record.assignment)
    mission.published_at = wall


def restarted_while_down(mission, liveness: Liveness, now_units: float) -> list[Effect]:
    """Agents that restarted while no planner ran: the operations their previous
    processes had under way died with them. Their co-workers may have begun those jobs
    with them, so the jobs are aborted and redone together, as when the planner sees a
    restart itself. Told once the histories have arrived, so that every job begun is
    known to have begun."""
    effects: list[Effect] = []
    for robot, planned in sorted(mission.journaled.items()):
        agent = liveness.agents.get(robot)
        if not planned or agent is None or agent.report.incarnation == planned:
            continue
        effects += [Note(MissionEventKind.JOB_ABORTED,
                         (f"robot '{robot}' restarted while the planner was down: its "
                          'agent lost the operation',), job=job)
                    for job in mission.tracker.agent_restarted(robot, at=now_units)]
    mission.journaled = {}
    return effects
