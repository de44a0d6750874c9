"""A receiver of an authenticated fleet refuses, from its bytes alone, a message that cannot
carry a signature, so a flood of unsigned messages costs no decoding; what could be signed,
and a few unsigned messages a second (to name their sender), are decoded and checked."""

import math

import pytest
from rclpy.serialization import deserialize_message, serialize_message

from fjsp_common.auth import UNSIGNED_DECODED, Signer, Verifier, could_be_signed
from fjsp_common.contract import ROBOT_STATES, TOPICS, subscription
from fjsp_msgs.msg import RobotState

KEY = bytes(range(32))
NAME = '/robot_states'


def state(robot: str = 'MARC1') -> RobotState:
    return RobotState(robot=robot, mode=RobotState.MODE_FAILED, busy_until=math.nan)


def signed(robot: str = 'MARC1', key: bytes = KEY) -> bytes:
    return serialize_message(Signer(key, robot).sign(state(robot), NAME))


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.mark.parametrize('topic', [t for t in TOPICS
                                   if 'auth' in t.type.get_fields_and_field_types()],
                         ids=lambda t: t.name)
def test_every_signed_message_ends_with_its_mac(topic):
    # The screen reads the MAC's length from the end of the bytes: `auth` must stay last.
    assert list(topic.type.get_fields_and_field_types())[-1] == 'auth'
    msg = topic.type()
    assert not could_be_signed(serialize_message(msg))
    assert could_be_signed(serialize_message(Signer(KEY, 'planner').sign(msg, topic.name)))


def test_only_a_mac_of_32_bytes_could_be_signed():
    msg = state()
    for size, expected in ((0, False), (31, False), (33, False), (32, True)):
        msg.auth.mac = [7] * size
        assert could_be_signed(serialize_message(msg)) is expected, size
    assert not could_be_signed(b'')
    assert not could_be_signed(b'\x00\x01\x00\x00' + (32).to_bytes(4, 'little'))


def test_unsigned_bytes_beyond_a_few_a_second_are_refused_undecoded():
    clock = FakeClock()
    verifier = Verifier(KEY, clock)
    unsigned = serialize_message(state())
    decoded = [verifier.screen(unsigned, NAME) for _ in range(1000)]
    assert decoded == [True] * UNSIGNED_DECODED + [False] * (1000 - UNSIGNED_DECODED)
    assert verifier.rejected == 1000 - UNSIGNED_DECODED
    assert verifier.screen(unsigned, '/task_events')  # counted per topic
    assert verifier.screen(signed(), NAME)  # the flood does not silence signed messages
    clock.now += 1.0
    assert verifier.screen(unsigned, NAME)  # a new second: its sender can be named again


def test_what_the_screen_lets_through_is_still_checked():
    verifier = Verifier(KEY, FakeClock())
    forged = signed(key=bytes(32))
    assert verifier.screen(forged, NAME)
    msg = deserialize_message(forged, RobotState)
    assert 'does not verify' in verifier.check(msg, NAME, {'MARC1'})
    assert verifier.check(deserialize_message(signed(), RobotState), NAME, {'MARC1'}) == ''


def test_without_a_key_everything_is_decoded():
    verifier = Verifier(None, FakeClock())
    unsigned = serialize_message(state())
    assert all(verifier.screen(unsigned, NAME) for _ in range(1000))
    assert verifier.rejected == 0


class FakeAuth:
    enabled = True

    def __init__(self):
        self.verifier = Verifier(KEY, FakeClock())
        self.unreadable_on: list[str] = []

    def screen(self, data: bytes, name: str) -> bool:
        return self.verifier.screen(data, name)

    def unreadable(self, name: str) -> None:
        self.unreadable_on.append(name)


class FakeNode:
    def create_subscription(self, msg_type, name, callback, qos, raw=False):
        self.raw, self.callback = raw, callback
        return FakeSubscription()


class EmptyHandle:
    """An rclpy subscription handle with nothing more waiting."""

    def __enter__(self):
        return self

    def __exit__(self, *_):
        return False

    def take_message(self, msg_type, raw):
        return None


class FakeSubscription:
    handle = EmptyHandle()
    msg_type = RobotState
    raw = True


def test_a_keyed_subscription_decodes_only_what_could_be_signed():
    node, auth, heard = FakeNode(), FakeAuth(), []
    subscription(node, ROBOT_STATES, heard.append, auth)
    assert node.raw
    unsigned = serialize_message(state())
    for _ in range(UNSIGNED_DECODED + 5):
        node.callback(unsigned)
    node.callback(signed())
    assert [len(msg.auth.mac) for msg in heard] == [0] * UNSIGNED_DECODED + [32]
    assert auth.verifier.rejected == 5


def test_bytes_that_end_like_a_signature_but_cannot_be_decoded_are_counted_not_raised():
    node, auth, heard = FakeNode(), FakeAuth(), []
    subscription(node, ROBOT_STATES, heard.append, auth)
    garbage = b'\x00\x01\x00\x00' + b'\xff\xff\xff\x7f' + bytes(8) + (32).to_bytes(4, 'little') \
        + bytes(32)
    node.callback(garbage)
    assert heard == [] and auth.unreadable_on == ['robot_states']
