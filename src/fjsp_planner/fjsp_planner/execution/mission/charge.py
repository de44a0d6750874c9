"""Which planner of a ROS domain is in charge: one directs the fleet, any other stands by.

Two planners on one domain would both take a goal and plan for the same robots: one runs the
mission, the other stays blocked calling healthy robots failed, and a client follows both.
Each planner hears the others on `mission_status`, whose messages name their sender's
incarnation (its process start); this decides what a planner does about them:

- A planner listens for `timeout` seconds before it speaks (it serves no request, publishes
  nothing); one that hears another planner meanwhile stands by.
- Two planners that both speak (started at once, or a link between them came back) settle
  it: one with a mission, running or queued, keeps charge over one without; between equals
  the newer, since every node believes the newest incarnation of the planner's signature
  anyway (replay protection drops the older one's messages once it heard the newer's). The
  other stands down: its missions end FAILED, naming the planner in charge.
- A planner standing by takes charge once it has heard no other for `timeout` seconds.

A status older than `timeout` seconds when it arrives is not taken as a sign of life: a
captured status replayed later cannot keep a planner standing by.
"""

from dataclasses import dataclass
from datetime import UTC, datetime
from enum import StrEnum


class Role(StrEnum):
    LISTENING = 'listening'
    """Just started: hears who else is there before it speaks."""
    IN_CHARGE = 'in charge'
    """Serves mission requests and directs the fleet."""
    STANDING_BY = 'standing by'
    """Another planner is in charge: serves nothing, publishes nothing, waits for its
    silence."""


@dataclass(frozen=True)
class Rival:
    """Another planner of the domain, as its latest status says."""

    incarnation: int
    busy: bool
    """It has a mission running or queued."""
    mission_id: str
    heard: float
    """Wall seconds when its latest status arrived."""

    def __str__(self) -> str:
        started = datetime.fromtimestamp(self.incarnation * 1e-9, UTC)
        doing = f"running mission '{self.mission_id}'" if self.busy and self.mission_id \
            else 'with missions queued' if self.busy else 'idle'
        return (f'the planner started at {started:%Y-%m-%d %H:%M:%S.%f} UTC (incarnation '
                f'{self.incarnation}), {doing}')


@dataclass(frozen=True)
class Change:
    """The planner's role changed to `role`, because of `why`."""

    role: Role
    why: str


class Charge:
    """The role of the planner of incarnation `incarnation`, started at wall seconds
    `wall`."""

    def __init__(self, incarnation: int, wall: float, timeout: float):
        self.incarnation = incarnation
        self.timeout = timeout
        self.role = Role.LISTENING
        self._since = wall
        self._rivals: dict[int, Rival] = {}

    def hear(self, incarnation: int, busy: bool, mission_id: str, stamp: float,
             wall: float) -> None:
        """Another planner's status, stamped `stamp`, arrived at `wall` (both wall seconds);
        this planner's own are ignored."""
        if incarnation == self.incarnation or wall - stamp > self.timeout:
            return
        self._rivals[incarnation] = Rival(incarnation, busy, mission_id[:80], wall)

    def update(self, busy: bool, wall: float) -> Change | None:
        """The change of role due at `wall` (`busy`: this planner has a mission running or
        queued), or None."""
        self._rivals = {i: r for i, r in self._rivals.items() if wall - r.heard <= self.timeout}
        leader = self.leader()
        if self.role == Role.LISTENING:
            if leader is not None:
                return self._become(Role.STANDING_BY, f'{leader} is on this ROS domain')
            if wall - self._since >= self.timeout:
                return self._become(Role.IN_CHARGE, f'no other planner heard in '
                                                    f'{self.timeout:g} s')
        elif self.role == Role.IN_CHARGE:
            if leader is not None and (leader.busy, leader.incarnation) > (busy,
                                                                           self.incarnation):
                return self._become(Role.STANDING_BY, f'{leader} is on this ROS domain and '
                                                      'takes precedence')
        elif leader is None:
            return self._become(Role.IN_CHARGE, f'no other planner heard for '
                                                f'{self.timeout:g} s')
        return None

    def leader(self) -> Rival | None:
        """The other planner that takes precedence among those heard, if any."""
        return max(self._rivals.values(), key=lambda r: (r.busy, r.incarnation), default=None)

    def _become(self, role: Role, why: str) -> Change:
        self.role = role
        return Change(role, why)
