"""Recordings without ROS: definitions as rosbag2 writes them, and a round trip of a mission's
messages (CDR-encoded from the interface files by mcap-ros2-support) through the MCAP writer
and reader into the same history. The round trip over a real fleet is in
test/integration/test_observe.py."""

import re

import pytest
from mcap.reader import make_reader

from fjsp_planner.observe.history import FleetHistory
from fjsp_planner.observe.recording import (
    SEPARATOR,
    RecordingError,
    message_definition,
    replay,
)
from fjsp_planner.observe.story import story

from mission_facts import MISSION, READ_MSG, REPO, faulty_mission, record


def test_definitions_append_each_dependency_once_as_rosbag2_does():
    text = message_definition('fjsp_msgs/msg/Plan', READ_MSG)
    assert text.startswith((REPO / 'src/fjsp_msgs/msg/Plan.msg').read_text())
    sections = re.findall(rf'^{SEPARATOR}\nMSG: (\S+)$', text, re.M)
    assert sorted(sections) == ['builtin_interfaces/Time', 'fjsp_msgs/Auth', 'fjsp_msgs/Place',
                                'fjsp_msgs/PlanTask', 'fjsp_msgs/RobotPlan']


def test_a_missing_definition_is_named():
    with pytest.raises(RecordingError, match='fjsp_msgs/msg/Nothing'):
        message_definition('fjsp_msgs/msg/Nothing', READ_MSG)


def test_round_trip_gives_the_same_history(tmp_path):
    facts = faulty_mission()
    path = tmp_path / 'mission.mcap'
    record(path, facts)
    direct = FleetHistory()
    for fact in facts:
        direct.add(fact)
    fleet, reading = replay(path)
    expected, replayed = direct.missions[MISSION], fleet.missions[MISSION]
    assert replayed.attempts() == expected.attempts()
    assert replayed.spans() == expected.spans()
    assert replayed.counts() == expected.counts()
    assert [i.text for i in story(replayed)] == [i.text for i in story(expected)]
    assert reading.truncated == ''
    assert sum(reading.counts.values()) == len(facts)
    assert reading.types['/plan'] == 'fjsp_msgs/msg/Plan'


def test_the_file_is_what_ros2_bag_and_foxglove_expect(tmp_path):
    path = tmp_path / 'mission.mcap'
    record(path, faulty_mission())
    with path.open('rb') as stream:
        reader = make_reader(stream)
        assert reader.get_header().profile == 'ros2'
        summary = reader.get_summary()
    schemas = {s.name: s.encoding for s in summary.schemas.values()}
    assert schemas['fjsp_msgs/msg/RobotState'] == 'ros2msg'
    channels = {c.topic: c for c in summary.channels.values()}
    assert channels['/plan'].message_encoding == 'cdr'
    assert 'durability: transient_local' in channels['/plan'].metadata['offered_qos_profiles']


def test_a_recording_cut_short_is_read_up_to_its_end(tmp_path):
    path = tmp_path / 'cut.mcap'
    record(path, faulty_mission(), cut=True)
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])
    fleet, reading = replay(path)
    assert reading.truncated
    assert 0 < sum(reading.counts.values()) < len(faulty_mission())
    assert MISSION in fleet.missions


def test_a_file_that_is_no_recording_is_refused_with_its_name(tmp_path):
    path = tmp_path / 'notes.mcap'
    path.write_text('hello')
    with pytest.raises(RecordingError, match='notes.mcap'):
        replay(path)
    with pytest.raises(RecordingError, match='cannot open'):
        replay(tmp_path / 'missing.mcap')
