"""`replay` with the fleet key believes what the fleet believed: a recording that holds a
forged hijacking plan and forged events tells the mission as it ran, and says what it left out.
Without the key it says that nothing was verified. (Signing uses the built fjsp_msgs.)"""

import math

import pytest
from mcap_ros2._dynamic import generate_dynamic, serialize_dynamic

from fjsp_common.auth import Signer, new_key, read_key, signers_of
from fjsp_common.fleet import PLANNER_NODE
from fjsp_common.vocabulary import EventKind
from fjsp_planner.observe.facts import PlanFact, TaskEventFact
from fjsp_planner.observe.recording import (
    Offer,
    RecordingWriter,
    message_definition,
    replay,
)
from fjsp_planner.observe.replay import main

from mission_facts import MISSION, READ_MSG, TOPICS, as_message, event, faulty_mission, plan

COMPLETE = 'complete: 3/3 jobs done (planner: 3/3); 2 revisions, 1 aborted attempt, 1 voided'


class Recorder:
    """Writes facts as the fleet's messages, each signed by whoever may sign it."""

    def __init__(self, path, key: bytes):
        self.writer = RecordingWriter(path)
        self.key = key
        self.signers: dict[str, Signer] = {}
        self.channels, self.codecs = {}, {}
        for kind, (topic, name) in TOPICS.items():
            type_name = f'fjsp_msgs/msg/{name}'
            definition = message_definition(type_name, READ_MSG)
            self.channels[kind] = self.writer.add_topic(
                topic, type_name, definition, Offer(reliable=True, transient_local=True,
                                                    depth=1))
            self.codecs[kind] = (serialize_dynamic(type_name, definition)[type_name],
                                 generate_dynamic(type_name, definition)[type_name])

    def write(self, fact, key: bytes | None = None, sender: str | None = None) -> None:
        """`fact` as its message, signed with `key` (default: the fleet's; None: unsigned
        when `sender` is '') as `sender` (default: who may sign it)."""
        encode, decode = self.codecs[type(fact)]
        message = as_message(fact)
        if sender != '':
            decoded = decode(encode(message))
            job_done = isinstance(fact, TaskEventFact) and fact.kind == EventKind.JOB_DONE
            sender = sender or next(iter(signers_of(decoded, job_done)))
            signer = self.signers.setdefault(f'{sender}/{key}', Signer(key or self.key, sender))
            signer.sign(decoded, TOPICS[type(fact)][0])
            auth = decoded.auth
            message['auth'] = {'sender': auth.sender, 'incarnation': auth.incarnation,
                               'counter': auth.counter, 'mac': bytes(auth.mac)}
        self.writer.write(self.channels[type(fact)], encode(message), int(fact.stamp * 1e9))

    def close(self):
        self.writer.close()


@pytest.fixture
def key_file(tmp_path):
    return new_key(tmp_path / 'fleet.key')


@pytest.fixture
def hijacked(tmp_path, key_file):
    """The faulty mission, signed, with a forger's unsigned plan (revision 3, no tasks), a
    job-done signed with another key, and an event at t=inf signed as no robot may be."""
    path = tmp_path / 'hijacked.mcap'
    recorder = Recorder(path, read_key(key_file))
    for fact in faulty_mission():
        recorder.write(fact)
    recorder.write(plan(3, 12.0, []), sender='')
    recorder.write(event(EventKind.JOB_DONE, '', 'J3', 3, 12.0),
                   key=read_key(new_key(tmp_path / 'other.key')), sender=PLANNER_NODE)
    recorder.write(event(EventKind.STARTED, 'A', 'J2', 2, 12.5), sender='B')
    recorder.close()
    return path


def test_with_the_key_the_forged_messages_are_left_out(hijacked, key_file):
    fleet, reading = replay(hijacked, key=read_key(key_file))
    mission = fleet.missions[MISSION]
    assert sorted(mission.plans) == [1, 2]
    assert reading.unverified == {'/plan': 1, '/task_events': 2}
    assert reading.unverified_why == {
        'not signed': 1, 'signature of a sender does not verify with the fleet key': 1,
        'a sender may not send this': 1}


def test_the_replay_command_verifies_with_the_key_file(hijacked, key_file, tmp_path, capsys,
                                                       monkeypatch):
    monkeypatch.delenv('FJSP_FLEET_KEY_FILE', raising=False)
    assert main([str(hijacked), '--no-chart', '--key-file', str(key_file)]) == 0
    out = capsys.readouterr().out
    assert COMPLETE in out
    assert '/plan: 1 message(s) left out: they do not verify with the fleet key' in out
    monkeypatch.setenv('FJSP_FLEET_KEY_FILE', str(key_file))
    assert main([str(hijacked), '--no-chart']) == 0
    assert COMPLETE in capsys.readouterr().out
    monkeypatch.delenv('FJSP_FLEET_KEY_FILE')
    assert main([str(hijacked), '--no-chart']) == 0
    out = capsys.readouterr().out
    assert COMPLETE not in out
    assert 'not verified: no fleet key given' in out


def test_a_bad_key_file_is_a_bad_argument(tmp_path, capsys):
    bad = tmp_path / 'bad.key'
    bad.write_text('zz')
    bad.chmod(0o600)
    assert main([str(tmp_path / 'x.mcap'), '--key-file', str(bad)]) == 2
    assert 'a fleet key is hex text' in capsys.readouterr().err


def test_a_signed_message_verifies_after_a_round_trip_through_a_recording(tmp_path, key_file):
    """Signed as a live message is signed, checked as the recording decodes it: every field
    in definition order, floats exact, NaN included."""
    path = tmp_path / 'one.mcap'
    recorder = Recorder(path, read_key(key_file))
    fact = plan(1, 0.0, [], makespan=math.nan)
    recorder.write(fact)
    recorder.close()
    fleet, reading = replay(path, key=read_key(key_file))
    assert not reading.unverified
    assert isinstance(fleet.missions[MISSION].plans[1], PlanFact)
