"""Recordings without ROS: definitions as rosbag2 writes them, and a round trip of a mission's
messages (CDR-encoded from the interface files by mcap-ros2-support) through the MCAP writer
and reader into the same history. The round trip over a real fleet is in
test/integration/test_observe.py."""

import re
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2._dynamic import serialize_dynamic
from mission_facts import MISSION, faulty_mission

from fjsp_planner.observe.facts import PlanFact, RobotStateFact, StatusFact, TaskEventFact
from fjsp_planner.observe.history import FleetHistory
from fjsp_planner.observe.recording import (
    SEPARATOR,
    Offer,
    RecordingError,
    RecordingWriter,
    message_definition,
    msg_files_under,
    replay,
)
from fjsp_planner.observe.story import story

REPO = Path(__file__).resolve().parents[2]
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
                     'held_into_next': t.held_into_next, 'continued': t.continued}
                    for t in fact.tasks if t.robot == robot]} for robot, kind in fact.robots]}
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


def test_definitions_append_each_dependency_once_as_rosbag2_does():
    text = message_definition('fjsp_msgs/msg/Plan', READ_MSG)
    assert text.startswith((REPO / 'src/fjsp_msgs/msg/Plan.msg').read_text())
    sections = re.findall(rf'^{SEPARATOR}\nMSG: (\S+)$', text, re.M)
    assert sorted(sections) == ['builtin_interfaces/Time', 'fjsp_msgs/PlanTask',
                                'fjsp_msgs/RobotPlan']


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
