"""The story of a mission: one line per thing that happened, in order, in plain words.

When the planner publishes mission events for the mission, they are the story: it decided
them, with its reasons. A mission without any (a planner that does not publish them, or a
recording made before they existed) is told from its history instead: each revision with its
reasons, robots failed, offline and back, attempts aborted and voided, blocks, warnings, and
the end of the mission.
"""

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from fjsp_common.clock import ScheduleClock
from fjsp_common.decimals import decimal
from fjsp_common.vocabulary import MissionEventKind, MissionState
from fjsp_planner.observe.history import Counts, MissionHistory, Outcome


@dataclass(frozen=True)
class StoryItem:
    """One line of the mission's story."""

    time: float
    kind: MissionEventKind
    text: str
    key: str
    """Unique and stable: a line is told once however often the story is derived."""
    stamp: float
    """Wall time of the fact it comes from (the event's publication)."""
    robot: str = ''
    job: str = ''


_TELLING_ORDER = {kind: index for index, kind in enumerate(MissionEventKind)}
"""Of things at the same time, causes first: a robot fails, its job aborts, a re-plan."""

_ENDINGS = {MissionState.COMPLETE: MissionEventKind.MISSION_COMPLETE,
            MissionState.CANCELLED: MissionEventKind.MISSION_CANCELLED,
            MissionState.FAILED: MissionEventKind.MISSION_FAILED}


def story(mission: MissionHistory, silent: Mapping[str, float] = {}) -> list[StoryItem]:  # noqa: B006  (read only)
    """The mission's story; `silent` names robots silent right now (robot -> last stamp)."""
    if mission.mission_events:
        items = mission.cached('told', lambda: _told(mission))
    else:
        items = mission.cached('derived', lambda: _derived(mission)) + _silent(mission, silent)
    return sorted(items, key=lambda i: (i.time, _TELLING_ORDER[i.kind], i.stamp, i.key))


def tell(kind: MissionEventKind, robot: str, job: str, revision: int,
         reasons: Iterable[str], counts: Counts) -> str:
    """The line of one event."""
    why = '; '.join(r for r in reasons if r)
    because = f': {why}' if why else ''
    lines = {
        MissionEventKind.PLAN_PUBLISHED: f'revision {revision} planned{because}',
        MissionEventKind.MISSION_STARTED: f'mission started{because}',
        MissionEventKind.ROBOT_FAILED: f'{robot} failed{because}',
        MissionEventKind.ROBOT_OFFLINE: f'{robot} offline: heartbeat lost{because}',
        MissionEventKind.ROBOT_BACK: f'{robot} back in service{because}',
        MissionEventKind.JOB_ABORTED: f'job {job} aborted{because}',
        MissionEventKind.JOB_VOIDED: f'job {job} voided{because}',
        MissionEventKind.BLOCKED: f'blocked{because}',
        MissionEventKind.WARNING: f'warning{because}',
        MissionEventKind.JOBS_ADDED: f'jobs added: {job}{because}',
    }
    return lines.get(kind, f'{kind}: {counts.done}/{counts.total} jobs done{because}')


def _told(mission: MissionHistory) -> list[StoryItem]:
    counts = mission.counts()
    return [StoryItem(e.time, e.kind, tell(e.kind, e.robot, e.job, e.revision, e.reasons,
                                           counts), e.event_id, e.stamp, e.robot, e.job)
            for e in mission.mission_events.values()]


def _derived(mission: MissionHistory) -> list[StoryItem]:
    items = []
    counts = mission.counts()
    stamps = {p.revision: p.stamp for p in mission.plans.values()}
    for revision in mission.revisions():
        reasons = revision.reasons or (
            (f'makespan {decimal(revision.makespan)} ({revision.solver_status})',)
            if revision.number == 1 else ())
        items.append(StoryItem(revision.published, MissionEventKind.PLAN_PUBLISHED,
                               tell(MissionEventKind.PLAN_PUBLISHED, '', '', revision.number,
                                    reasons, counts),
                               f'revision/{revision.number}',
                               stamps.get(revision.number, math.nan)))
    for span in mission.spans():
        kind = (MissionEventKind.ROBOT_FAILED if span.kind == 'failed'
                else MissionEventKind.ROBOT_OFFLINE)
        items.append(StoryItem(span.start, kind, tell(kind, span.robot, '', 0, (), counts),
                               f'{span.kind}/{span.robot}/{span.start:.6f}',
                               _stamp_at(mission, span.start), span.robot))
        if span.end is not None:
            items.append(StoryItem(span.end, MissionEventKind.ROBOT_BACK,
                                   tell(MissionEventKind.ROBOT_BACK, span.robot, '', 0, (),
                                        counts),
                                   f'back/{span.robot}/{span.end:.6f}',
                                   _stamp_at(mission, span.end), span.robot))
    for attempt in mission.attempts():
        if attempt.outcome in (Outcome.ABORTED, Outcome.VOIDED) \
                and attempt.outcome_time is not None:
            kind = (MissionEventKind.JOB_ABORTED if attempt.outcome == Outcome.ABORTED
                    else MissionEventKind.JOB_VOIDED)
            items.append(StoryItem(attempt.outcome_time, kind,
                                   tell(kind, '', attempt.job, 0, (attempt.reason,), counts),
                                   f'{attempt.outcome}/{attempt.job}/{attempt.number}',
                                   _stamp_at(mission, attempt.outcome_time), job=attempt.job))
    return items + _from_statuses(mission, counts)


def _from_statuses(mission: MissionHistory, counts: Counts) -> list[StoryItem]:
    """Blocks, warnings and the end, from the changes of the planner's status."""
    items = []
    warned: set[str] = set()
    previous = None
    for status in mission.status_changes:
        if status.state == MissionState.BLOCKED and (
                previous is None or previous.state != MissionState.BLOCKED
                or previous.blocked_reasons != status.blocked_reasons):
            items.append(StoryItem(status.elapsed, MissionEventKind.BLOCKED,
                                   tell(MissionEventKind.BLOCKED, '', '', status.revision,
                                        status.blocked_reasons, counts),
                                   f'blocked/{status.stamp:.6f}', status.stamp))
        for warning in status.warnings:
            if warning not in warned:
                warned.add(warning)
                items.append(StoryItem(status.elapsed, MissionEventKind.WARNING,
                                       tell(MissionEventKind.WARNING, '', '', 0, (warning,),
                                            counts),
                                       f'warning/{warning}', status.stamp))
        if status.state in _ENDINGS and (previous is None or previous.state != status.state):
            kind = _ENDINGS[status.state]
            items.append(StoryItem(status.elapsed, kind,
                                   tell(kind, '', '', status.revision, status.blocked_reasons,
                                        counts),
                                   f'{status.state}', status.stamp))
        previous = status
    return items


def _silent(mission: MissionHistory, silent: Mapping[str, float]) -> list[StoryItem]:
    """Robots silent right now, whose offline span is still open."""
    items = []
    for span in mission.spans(silent):
        if span.end is None and span.kind == 'offline' and span.robot in silent:
            items.append(StoryItem(span.start, MissionEventKind.ROBOT_OFFLINE,
                                   tell(MissionEventKind.ROBOT_OFFLINE, span.robot, '', 0, (),
                                        mission.counts()),
                                   f'offline/{span.robot}/{span.start:.6f}',
                                   silent[span.robot], span.robot))
    return items


def _stamp_at(mission: MissionHistory, time: float) -> float:
    """The wall time of schedule time `time` (NaN before any plan)."""
    plan = mission.first_plan
    return ScheduleClock(plan.mission_start, plan.time_scale).wall(time) if plan else math.nan
