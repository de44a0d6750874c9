"""Clients of the fleet (the `mission` tool, `MissionClient`, fault scripts) each sign under a
name of their own, so replay protection, which orders each sender's messages, never takes one
client's requests for replays of another's."""

import time

from fjsp_common import auth
from fjsp_common.auth import Verifier, client_signer, new_key, read_key
from fjsp_msgs.srv import CancelMission

SERVICE = '/cancel_mission'


def test_an_older_client_is_heard_after_a_newer_one(tmp_path):
    """Found in the field: every MissionClient signed as 'mission_client', so once a newer
    client process had used a service, a long-lived older one was refused as a replayer."""
    key_file = new_key(tmp_path / 'fleet.key')
    old = client_signer(key_file, 'mission_client')
    time.sleep(0.001)
    new = client_signer(key_file, 'mission_client')
    assert old.sender != new.sender
    assert old.sender.startswith('mission_client/') and new.sender.startswith('mission_client/')
    verifier = Verifier(read_key(key_file))
    for signer in (new, old, new, old):
        request = signer.sign(CancelMission.Request(mission_id='m1'), SERVICE)
        assert verifier.check(request, SERVICE) == ''
    assert 'replayed' in verifier.check(request, SERVICE)


def test_a_receiver_remembers_a_bounded_number_of_senders(tmp_path, monkeypatch):
    """A new sender at every command a user types must not grow a long-running planner's
    memory without end: the least recently heard sender is forgotten."""
    monkeypatch.setattr(auth, 'SENDERS_KEPT', 2)
    key = read_key(new_key(tmp_path / 'fleet.key'))
    verifier = Verifier(key)
    sent = []
    for _ in range(3):
        signer = client_signer(tmp_path / 'fleet.key', 'mission_client')
        sent.append(signer.sign(CancelMission.Request(mission_id='m1'), SERVICE))
        assert verifier.check(sent[-1], SERVICE) == ''
    assert 'replayed' in verifier.check(sent[-1], SERVICE)
    assert verifier.check(sent[0], SERVICE) == ''  # forgotten: only mission ids guard it
