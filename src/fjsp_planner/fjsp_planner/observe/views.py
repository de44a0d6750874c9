"""What a person is shown of a mission, as plain data: the same for the terminal, the PNG chart
and the web page, so the three never tell different stories.

Every function takes the fleet's history, one mission and `wall`, the moment shown (wall
seconds since the epoch; for a recording: its last message), and returns JSON-ready dicts.
Times in them are schedule units.
"""

import math

from fjsp_common.decimals import decimal
from fjsp_common.revisions import void
from fjsp_common.vocabulary import EventKind, MissionState, RobotMode
from fjsp_planner.observe.history import FleetHistory, MissionHistory, Outcome
from fjsp_planner.observe.story import story as told

SHOWN_PLANS = 2
"""Planned lanes in the timeline: the first revision and the latest one."""

REASONS_LABELS = {MissionState.FAILED: 'Failed', MissionState.CANCELLED: 'Cancelled',
                  MissionState.WAITING_FOR_ROBOTS: 'Waiting'}
"""What the status's `blocked_reasons` are, by mission state: why it failed, why it was
cancelled, whom it waits for; in any other state, what blocks it."""


def _number(value: float | None) -> float | None:
    """JSON has no NaN: unknown numbers are null."""
    return None if value is None or not math.isfinite(value) else round(value, 6)


def now_units(mission: MissionHistory, wall: float) -> float | None:
    """Schedule time at wall time `wall`; the mission's last known moment once it ended."""
    if mission.ended_at is not None:
        return max(mission.ended_at, mission.executed_makespan() or 0.0)
    return mission.units(wall)


def header(mission: MissionHistory, wall: float) -> dict:
    """The mission line: state, revision, progress, makespans and the reasons in force."""
    s = mission.status
    counts = mission.counts()
    last = mission.last_plan
    return {
        'mission_id': mission.mission_id,
        'scenario': mission.scenario_id,
        'state': str(s.state) if s else 'unknown',
        'ended': mission.ended,
        'revision': max(s.revision if s else 0, last.revision if last else 0),
        'jobs_done': counts.done,
        'jobs_running': counts.running,
        'jobs_total': counts.total,
        'status_jobs': [s.jobs_done, s.jobs_total] if s else None,
        'agrees': mission.agrees_with_status(),
        'aborted_attempts': counts.aborted,
        'voided_attempts': counts.voided,
        'planned_makespan': _number(last.makespan if last else None),
        'first_makespan': _number(mission.first_plan.makespan if last else None),
        'projected_makespan': _number(s.projected_makespan if s else None),
        'executed_makespan': _number(mission.executed_makespan()),
        'time': _number(now_units(mission, wall)),
        'replan_reasons': list(s.replan_reasons if s and s.replan_reasons
                               else last.reasons if last else ()),
        'warnings': list(s.warnings) if s else [],
        'blocked_reasons': list(s.blocked_reasons) if s else [],
        'reasons_label': REASONS_LABELS.get(s.state, 'Blocked') if s else 'Blocked',
        'ignored': list(s.ignored) if s else [0, 0, 0],
    }


def robot_rows(fleet: FleetHistory, mission: MissionHistory | None, wall: float) -> list[dict]:
    """One row per robot: what it does, where, and what it waits for. The robots of
    `mission` (with their last state in it once it ended), then any robot following no
    mission (e.g. refusing its plan); with no mission, every robot that reported."""
    ended = mission is not None and mission.ended
    silent = fleet.silent(mission, wall) if not ended else {}
    names = mission.robot_names() if mission is not None else []
    names += sorted(r for r, s in fleet.robots.items() if r not in names
                    and (mission is None or not s.mission_id))
    rows = []
    for name in names:
        state = fleet.robots.get(name)
        if mission is not None and (state is None or state.mission_id not in
                                    ('', mission.mission_id)):
            state = mission.last_state(name)
        if state is None:
            rows.append({'robot': name, 'mode': 'no report', 'detail': 'has not reported'})
            continue
        mode = RobotMode.OFFLINE if name in silent else state.mode
        trail = mission.trails.get(name, []) if mission is not None else []
        since = mission.units(trail[-1].stamp) if trail else None
        rows.append({
            'robot': name,
            'type': state.robot_type,
            'mode': str(mode),
            'healthy': mode.healthy,
            'job': state.current_job,
            'progress': _number(state.progress),
            'location': state.location,
            'destination': state.destination,
            'revision': state.revision,
            'refusal': state.refusal,
            'failures': state.failures,
            'since': _number(since),
            'detail': _detail(mission, state, mode) if mission is not None else
            (f'refuses its plan: {state.refusal}' if state.refusal else ''),
        })
    return rows


def _detail(mission: MissionHistory, state, mode: RobotMode) -> str:
    """What a waiting or holding robot waits for; why a robot does nothing."""
    if state.refusal:
        return f'refuses its plan: {state.refusal}'
    if mode not in (RobotMode.WAITING, RobotMode.HOLDING) or not state.current_job:
        return ''
    job = state.current_job
    tasks = mission.tasks_of(state.revision, job)
    mine = next((t for t in tasks if t.robot == state.robot), None)
    if mine is None:
        return ''
    attempt = mission.latest_attempts().get(job)
    running = attempt is not None and attempt.outcome == Outcome.RUNNING
    holding = ' (holding its part)' if mode == RobotMode.HOLDING else ''
    if running and state.robot in attempt.started:
        busy = [r for r in mine.co_workers if r not in attempt.operation_done]
        return (f'{job}: waits for {", ".join(busy)} to finish{holding}' if busy
                else f'{job}: finishing{holding}')
    arrived = _arrived(mission, job, state.revision)
    done = {j for j, a in mission.latest_attempts().items() if a.outcome == Outcome.DONE}
    # A revision leaves out the jobs done before it but still names them as predecessors;
    # the monitor may not have seen them done (it started later).
    planned = {t.job for t in mission.plans[state.revision].tasks}
    waits = [f'{r} to arrive' for r in mine.co_workers if r not in arrived]
    waits += [f'{j} to be done' for j in mine.predecessors if j in planned and j not in done]
    start = f', planned start t={decimal(mine.start)}'
    return (f'{job}: waits for {", ".join(waits)}{start}{holding}' if waits
            else f'{job}: starting{holding}')


def _arrived(mission: MissionHistory, job: str, revision: int) -> set[str]:
    """Robots that reported arriving at `job` for the attempt `revision` works on."""
    restarted = max((t.attempt_since(r) for r, p in mission.plans.items() if r <= revision
                     for t in p.tasks if t.job == job), default=0)
    return {e.robot for e in mission.task_events.values()
            if e.job == job and e.kind == EventKind.ARRIVED
            and not void(e.revision, restarted)}


def timeline(fleet: FleetHistory, mission: MissionHistory, wall: float) -> dict:
    """The whole mission per robot: plans of the first and latest revisions, the work done
    in every attempt, activities, health spans and revision boundaries."""
    t_now = now_units(mission, wall)
    revisions = mission.revisions()
    shown = sorted({revisions[0].number, revisions[-1].number}) if revisions else []
    plans = []
    for number in shown[:SHOWN_PLANS]:
        plan = mission.plans.get(number)
        if plan is None:
            continue
        plans.append({'revision': number, 'makespan': _number(plan.makespan), 'tasks': [
            {'robot': t.robot, 'job': t.job, 'travel_start': _number(t.travel_start),
             'arrival': _number(t.arrival), 'start': _number(t.start),
             'end': _number(t.end), 'held': t.held_into_next, 'continued': t.continued}
            for t in plan.tasks]})
    work = []
    for attempt in mission.attempts():
        for robot in attempt.robots:
            work.append({'robot': robot, 'job': attempt.job, 'attempt': attempt.number,
                         'start': _number(attempt.started[robot]), 'end': _number(attempt.finish),
                         'open': attempt.finish is None, 'outcome': str(attempt.outcome),
                         'outcome_time': _number(attempt.outcome_time),
                         'reason': attempt.reason})
    silent = fleet.silent(mission, wall) if not mission.ended else {}
    health = [{'robot': s.robot, 'kind': s.kind, 'start': _number(s.start),
               'end': _number(s.end), 'open': s.end is None} for s in mission.spans(silent)]
    activities = [{'robot': a.robot, 'mode': str(a.mode), 'job': a.job,
                   'start': _number(a.start), 'end': _number(a.end), 'open': a.end is None}
                  for a in mission.activities()
                  if a.mode not in (RobotMode.WORKING, RobotMode.OFFLINE, RobotMode.FAILED)]
    ends = [t_now or 0.0] + [r.makespan for r in revisions if math.isfinite(r.makespan)]
    ends += [w['end'] for w in work if w['end'] is not None]
    return {
        'robots': mission.robot_names(),
        'now': _number(t_now),
        'end': _number(max(ends)),
        'revisions': [{'number': r.number, 'time': _number(r.published),
                       'reasons': list(r.reasons), 'makespan': _number(r.makespan)}
                      for r in revisions],
        'plans': plans,
        'work': work,
        'activities': activities,
        'health': health,
    }


def story(fleet: FleetHistory, mission: MissionHistory, wall: float) -> list[dict]:
    silent = fleet.silent(mission, wall) if not mission.ended else {}
    return [{'key': i.key, 'time': _number(i.time), 'kind': str(i.kind), 'text': i.text,
             'robot': i.robot, 'job': i.job, 'stamp': _number(i.stamp)}
            for i in told(mission, silent)]


def missions(fleet: FleetHistory) -> list[dict]:
    """Every mission seen, oldest first, with how it stands."""
    rows = []
    for m in fleet.missions.values():
        if not m.plans and m.status is None:
            continue
        counts = m.counts()
        rows.append({'mission_id': m.mission_id, 'scenario': m.scenario_id,
                     'state': str(m.state) if m.state else 'unknown',
                     'jobs_done': counts.done, 'jobs_total': counts.total,
                     'started': _number(m.first_plan.mission_start if m.plans else None)})
    return sorted(rows, key=lambda r: (r['started'] is None, r['started'] or 0.0))


def planner_state(fleet: FleetHistory) -> str:
    """What the planner does while it runs no mission ('' while it runs one, or when it has
    not been heard)."""
    idle = fleet.idle_status
    current = fleet.current()
    latest = current.status.stamp if current is not None and current.status is not None \
        else -math.inf
    return str(idle.state) if idle is not None and idle.stamp > latest else ''
