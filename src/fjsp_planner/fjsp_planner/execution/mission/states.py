"""The states a mission goes through, and the one table of the moves between them.

A mission is accepted WAITING_FOR_ROBOTS, or QUEUED behind the running one until its turn,
and ends COMPLETE, CANCELLED or FAILED (IDLE is the planner's state while it has no mission).
`TRANSITIONS` lists every move the controller may make; `check_transition` refuses any other:
an illegal move is a bug in the controller, not something the fleet did, so it raises. A
mission not ended may stay where it is (a better plan is published while it is EXECUTING; a
blocked mission is found blocked again).
"""

from collections.abc import Mapping

from fjsp_common.vocabulary import MissionState

INITIAL = MissionState.WAITING_FOR_ROBOTS
"""The state of a mission just accepted (or rebuilt after a planner restart)."""

_ENDS = (MissionState.COMPLETE, MissionState.FAILED, MissionState.CANCELLED)

TRANSITIONS: Mapping[MissionState, frozenset[MissionState]] = {
    MissionState.IDLE: frozenset(),
    MissionState.QUEUED: frozenset({
        MissionState.WAITING_FOR_ROBOTS,    # its turn: the missions before it ended
        MissionState.CANCELLED,             # taken out of the queue
        MissionState.FAILED,                # the planner stood down for another one
    }),
    MissionState.WAITING_FOR_ROBOTS: frozenset({
        MissionState.PLANNING,      # every robot reported, or the robot wait is over
        MissionState.BLOCKED,       # the robots there cannot staff some job
        MissionState.EXECUTING,     # resumed: the robots' histories arrived; re-planned next
        *_ENDS,                     # resumed: its last job done; or cancelled
    }),
    MissionState.PLANNING: frozenset({
        MissionState.EXECUTING,             # the first plan is published
        MissionState.WAITING_FOR_ROBOTS,    # jobs added while it was solved: planned again
        MissionState.FAILED,                # no valid first plan
        MissionState.CANCELLED,
    }),
    MissionState.EXECUTING: frozenset({
        MissionState.REPLANNING,    # the fleet changed, a job aborted or runs late
        MissionState.BLOCKED,       # the execution state contradicts itself
        *_ENDS,
    }),
    MissionState.REPLANNING: frozenset({
        MissionState.EXECUTING,     # a new revision, or the re-plan discarded and retried
        MissionState.BLOCKED,       # what remains cannot be staffed or solved
        *_ENDS,                     # its last job done while it was solved; or cancelled
    }),
    MissionState.BLOCKED: frozenset({
        MissionState.PLANNING,      # blocked before its first plan, the fleet changed
        MissionState.REPLANNING,    # the fleet changed
        *_ENDS,                     # the robots finished the plan it had; blocked too long
    }),
    MissionState.COMPLETE: frozenset(),
    MissionState.CANCELLED: frozenset(),
    MissionState.FAILED: frozenset(),
}


class IllegalTransitionError(RuntimeError):
    """The controller moved a mission in a way the table does not allow: a bug."""


def check_transition(current: MissionState, new: MissionState) -> MissionState:
    """`new`, if a mission in state `current` may move to it; IllegalTransitionError if not."""
    if new in TRANSITIONS[current] or (new == current and TRANSITIONS[current]):
        return new
    raise IllegalTransitionError(f'a mission {current} cannot become {new}: allowed from '
                                 f'{current}: ' + (', '.join(sorted(TRANSITIONS[current]))
                                                   or 'nothing, it has ended'))
