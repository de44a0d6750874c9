"""What the launcher believes of `mission_status`, the topic that decides when it stops the
fleet and with which exit code.

It believes what the fleet's agents and monitor believe: in a fleet with a key, only a
status signed by the planner (`fjsp_common.auth`); anything else is dropped and counted, so
a node without the key can neither stop the fleet with a FAILED nor end it early with a
COMPLETE. And only statuses of the mission its planner runs: the first believed status that
names a mission fixes which one; a restarted planner resuming from its journal keeps it.
"""

from collections import Counter

from fjsp_common.auth import Verifier
from fjsp_common.fleet import PLANNER_NODE
from fjsp_common.running import shorten

OTHER_MISSION = 'of another mission'


class MissionWatch:
    """The mission statuses of one fleet received on resolved topic `topic`, checked with
    the fleet key (`key` None: an unauthenticated fleet, every status believed)."""

    def __init__(self, key: bytes | None, topic: str):
        self.verifier = Verifier(key)
        self.topic = topic
        self.mission_id = ''
        """The mission the fleet's planner runs, once a believed status named it."""
        self.latest = None
        """The latest status believed."""
        self.dropped: Counter[str] = Counter()
        """Statuses dropped, per kind of reason."""

    def receive(self, msg) -> str:
        """Take status `msg` in; a line to show the first time a kind of status is dropped
        ('' otherwise)."""
        why = self.verifier.check(msg, self.topic, senders={PLANNER_NODE})
        kind = 'unverified' if why else ''
        if not why and self.mission_id and msg.mission_id != self.mission_id:
            kind, why = OTHER_MISSION, f"mission '{shorten(msg.mission_id, 80)}', not " \
                                       f"'{self.mission_id}'"
        if kind:
            self.dropped[kind] += 1
            if self.dropped[kind] > 1:
                return ''
            return ('dropping a mission status that '
                    + ('does not verify with the fleet key' if kind == 'unverified'
                       else 'is not about the mission its planner runs')
                    + f' ({why}); further ones like it are only counted')
        self.mission_id = self.mission_id or msg.mission_id
        self.latest = msg
        return ''

    def tally(self) -> str:
        """What was dropped, in one line ('' if nothing)."""
        parts = []
        # The verifier counts those dropped from their bytes too (`Verifier.screen`).
        if self.verifier.rejected:
            parts.append(f'{self.verifier.rejected} that did not verify with the fleet key')
        if self.dropped[OTHER_MISSION]:
            parts.append(f'{self.dropped[OTHER_MISSION]} of another mission')
        return f"mission statuses dropped: {', '.join(parts)}" if parts else ''
