"""The test harness's observer in a fleet with a key: what it hears is screened as the nodes
screen it."""

import time

from fjsp_common.auth import UNSIGNED_DECODED, Signer, new_key, read_key
from fjsp_common.contract import ROBOT_STATES, publisher
from fjsp_msgs.msg import RobotState
from fjsp_planner.testing import DomainClaim, Observer

FLOOD = 2000


def test_a_keyed_observer_decodes_the_signed_and_only_the_first_unsigned_states(tmp_path):
    key_file = new_key(tmp_path / 'fleet.key')
    claim = DomainClaim()
    observer = Observer(claim.domain, key_file=key_file)
    try:
        out = publisher(observer.node, ROBOT_STATES)
        observer.wait_for(lambda o: out.get_subscription_count() >= 1, 10,
                          'the observer to hear itself')
        signer = Signer(read_key(key_file), 'R1')
        started = time.monotonic()
        for _ in range(FLOOD):
            out.publish(RobotState(robot='R1', mode=RobotState.MODE_FAILED))
        out.publish(signer.sign(RobotState(robot='R1', mode=RobotState.MODE_IDLE),
                                '/robot_states'))
        observer.wait_for(lambda o: o.robots['R1'].mode == RobotState.MODE_IDLE, 10,
                          'the signed state')
        seconds = time.monotonic() - started
    finally:
        observer.close()
        claim.release()
    unsigned = [s for s in observer.robot_history if not s.auth.mac]
    # The flood may straddle a second or two: each second lets its first few through.
    assert 0 < len(unsigned) <= UNSIGNED_DECODED * (int(seconds) + 2) < FLOOD, len(unsigned)
