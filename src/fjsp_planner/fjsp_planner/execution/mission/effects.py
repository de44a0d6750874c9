"""What the mission controller hands the planner node: effects to carry out, and views.

Every call of `MissionController` returns the `Effect`s the node must carry out, in order: run a
solve off the executor (`Solve`), publish a plan (`PublishPlan`) or publish the latest one
again (`ResendPlan`), declare a job done (`JobDone`), tell the story of the mission (`Note`),
answer for a queued mission that ended before its turn (`LeftQueue`).
`StatusView` is the mission's summary the node publishes on `mission_status`.
"""

from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum

from fjsp_common.vocabulary import MissionEventKind, MissionState
from fjsp_planner.execution.replan import ExecutionState, Replan
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import JobAssignment, Result, Schedule


class SolveKind(StrEnum):
    """Which solve a `Solve` asks for, and so what its outcome is."""

    PLAN = 'plan'
    """The mission's first plan: `solve(problem)`, a `Result`."""
    REPAIR = 'repair'
    """A valid plan of what remains, at once and without search: `repair(problem, previous,
    state)`, a `Replan`."""
    IMPROVE = 'improve'
    """A search for a better plan from the one just published: `improve(published)`, an
    `Improvement`."""


@dataclass(frozen=True)
class Solve:
    """Run a solve off the executor and hand its outcome to `MissionController.solved`."""

    token: int
    kind: SolveKind
    problem: Problem
    time_limit: float
    previous: Schedule | None = None
    state: ExecutionState | None = None
    reasons: tuple[str, ...] = ()
    """Why a re-plan is needed."""
    published: Replan | None = None
    """For IMPROVE: the repaired plan to search from."""
    frozen_until: float | None = None
    """For IMPROVE: the schedule time by which its plan reaches the robots; what the
    published plan has them do until then is kept (`replan.frozen`)."""
    started: frozenset[str] = frozenset()
    """For IMPROVE: the jobs the robots have started or done; they are kept too."""


@dataclass(frozen=True)
class PublishPlan:
    revision: int
    posed: Problem
    """What was solved: the mission's problem, or what remained of it."""
    result: Result | None
    """None for the revision that cancels a mission."""
    continued: frozenset[str]
    reasons: tuple[str, ...]
    mission_start: float
    """Wall seconds of schedule time 0."""
    cancelled: bool = False
    restarted_in: Mapping[str, int] = field(default_factory=dict)
    """Per job of the plan, the revision that last started it afresh (this one for a job
    not continued): a robot that missed that revision still knows which reports are void."""
    incarnations: Mapping[str, int] = field(default_factory=dict)
    """The agent incarnation each robot's tasks are planned for: the one it reported."""
    starts: Mapping[str, str | None] = field(default_factory=dict)
    """Where each robot started the mission (None: anywhere), which need not be where the
    scenario starts it: journaled, so a resumed mission is judged from the same places."""


@dataclass(frozen=True)
class JobDone:
    job: str
    time: float
    revision: int
    assignment: JobAssignment
    """How it was done: its plan, robots and actual times."""


@dataclass(frozen=True)
class Note:
    """Something the mission's story must tell (a MissionEvent)."""

    kind: MissionEventKind
    reasons: tuple[str, ...] = ()
    robot: str = ''
    job: str = ''
    revision: int | None = None
    """The plan revision it is about, when not the one in force when it is told (a voided
    job: the revision its completion was reported under)."""


@dataclass(frozen=True)
class ResendPlan:
    """Publish the plan of `revision` again, on a new writer: a robot has not taken it."""

    revision: int


@dataclass(frozen=True)
class LeftQueue:
    """A queued mission ended before its turn: its requester gets `state` and `reasons`."""

    mission_id: str
    state: MissionState
    reasons: tuple[str, ...]


Effect = Solve | PublishPlan | JobDone | Note | ResendPlan | LeftQueue


@dataclass(frozen=True)
class StatusView:
    mission_id: str
    scenario: str
    state: MissionState
    revision: int
    jobs_done: int
    jobs_running: int
    jobs_total: int
    planned_makespan: float
    projected_makespan: float
    elapsed: float
    blocked: tuple[str, ...]
    replan_reasons: tuple[str, ...]
    warnings: tuple[str, ...]
    ignored: Counter
    blocked_too_long: bool
    """The mission failed because it stayed blocked beyond its `blocked_timeout`."""
    queue: tuple[str, ...] = ()
    """The missions waiting their turn, the next first."""
