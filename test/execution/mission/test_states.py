"""The one table of mission-state moves (`states.TRANSITIONS`): every state has its entry and
the controller can make no move the table does not allow (that the table allows no move the
controller does not make is checked by the mission tests, `test_controller.py`)."""

import pytest

from fjsp_common.vocabulary import MissionState
from fjsp_planner.execution.mission import controller
from fjsp_planner.execution.mission.settings import Settings
from fjsp_planner.execution.mission.states import (
    INITIAL,
    TRANSITIONS,
    IllegalTransitionError,
    check_transition,
)
from fjsp_planner.execution.tracking import MissionTracker
from fjsp_planner.model.scenario import load_scenario

from repo_paths import PAPER


def test_every_state_has_an_entry_and_only_ended_missions_go_nowhere():
    assert set(TRANSITIONS) == set(MissionState)
    assert INITIAL == MissionState.WAITING_FOR_ROBOTS
    # IDLE is the planner's state without a mission: no mission is ever in it. A mission is
    # queued when it is accepted, never later.
    assert not any({MissionState.IDLE, MissionState.QUEUED} & moves
                   for moves in TRANSITIONS.values())
    assert {s for s, moves in TRANSITIONS.items() if not moves} == {
        MissionState.IDLE, MissionState.COMPLETE, MissionState.CANCELLED, MissionState.FAILED}


@pytest.mark.parametrize('current, new, why', [
    (MissionState.COMPLETE, MissionState.EXECUTING, 'an ended mission never changes'),
    (MissionState.FAILED, MissionState.FAILED, 'an ended mission does not end twice'),
    (MissionState.WAITING_FOR_ROBOTS, MissionState.REPLANNING, 'no plan to re-plan yet'),
    (MissionState.EXECUTING, MissionState.PLANNING, 'the first plan is made once'),
    (MissionState.EXECUTING, MissionState.WAITING_FOR_ROBOTS, 'a mission under way waits '
                                                              'for no robot'),
    (MissionState.PLANNING, MissionState.REPLANNING, 'a first plan is not a re-plan'),
    (MissionState.IDLE, MissionState.PLANNING, 'no mission is ever idle'),
])
def test_an_illegal_transition_raises_naming_both_states(current, new, why):
    with pytest.raises(IllegalTransitionError, match=f'a mission {current} cannot become {new}'):
        check_transition(current, new)


def test_a_mission_moved_illegally_stays_where_it_was():
    problem = load_scenario(PAPER)
    mission = controller.Mission('m1', problem, Settings(), MissionTracker(problem), 0.0)
    assert mission.state == MissionState.WAITING_FOR_ROBOTS
    with pytest.raises(IllegalTransitionError):
        mission.enter(MissionState.REPLANNING)
    assert mission.state == MissionState.WAITING_FOR_ROBOTS
    mission.enter(MissionState.PLANNING)
    assert mission.state == MissionState.PLANNING
