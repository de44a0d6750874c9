"""When the launcher starts a node of its fleet again, and when it gives up on one.

A robot's computer reboots, a process runs out of memory or is killed: a fleet manager must
not die of it. As a ROS 2 launch file's `respawn=True, respawn_delay=...`, a node that ended
is started again `delay` seconds later; as systemd's start limit, a node that ended `limit`
times within `window` seconds is not started again, and the launcher says so: a node that
keeps dying (a broken install, a driver that crashes at once) would otherwise be restarted
forever. A node that exits with code 2 refused its parameters: starting it again with the
same ones cannot help, so it is given up on at once.

Giving up on the planner ends the fleet: no one else plans. Giving up on an agent, the
monitor or the recorder does not: the planner re-plans around a robot whose agent is gone,
and a mission needs neither its view nor its recording to run. Without respawning, a node
that ends ends the fleet, except one allowed to finish on its own (the monitor once it has
drawn the mission, with --exit-on-complete).

No ROS and no processes here: `Supervisor` is told which node ended, how and when, and says
what to do; `Fleet` and the `fleet` command carry it out.
"""

import signal
from collections import deque
from dataclasses import dataclass

EXIT_BAD_PARAMETERS = 2
"""The exit code of a node that refused its parameters (`fjsp_common.running.run_node`)."""


@dataclass(frozen=True)
class RespawnPolicy:
    delay: float = 1.0
    """Seconds between a node's end and its new start."""
    limit: int = 5
    """Ends within `window` seconds after which a node is not started again."""
    window: float = 60.0


@dataclass(frozen=True)
class Verdict:
    """What to do about a node that ended."""

    node: str
    code: int
    respawn_at: float | None = None
    """When to start it again; None: not again."""
    ends_fleet: bool = False
    why_not: str = ''
    """Why it is not started again ('' when it is, or when it finished its work)."""

    @property
    def finished(self) -> bool:
        """It ended on its own, its work done: nothing to do."""
        return self.respawn_at is None and not self.why_not

    def describe(self, now: float) -> str:
        """One line: which node, how it ended, and when it comes back or why it does not."""
        line = f"node '{self.node}' {how_it_ended(self.code)}"
        if self.finished:
            return line
        if self.respawn_at is not None:
            return f'{line}; starting it again in {max(0.0, self.respawn_at - now):g} s'
        then = 'the fleet stops' if self.ends_fleet else 'the fleet goes on without it'
        return f'{line}; not starting it again: {self.why_not}; {then}'


class Supervisor:
    """The respawn decisions of one fleet, on a clock its caller passes (seconds).

    A node is *watched* from its start until it ends; then it waits for its new start
    (`due`), has finished, or has been given up on. `policy` None: no node is started
    again. `essential` nodes end the fleet when given up on; `may_finish` nodes may exit
    with code 0 on their own, their work done."""

    def __init__(self, policy: RespawnPolicy | None, essential=(), may_finish=()):
        self.policy = policy
        self.essential = frozenset(essential)
        self.may_finish = frozenset(may_finish)
        self._ends: dict[str, deque[float]] = {}
        self._waiting: dict[str, float] = {}
        self._done: set[str] = set()
        """Nodes finished or given up on."""

    def watches(self, node: str) -> bool:
        """Whether `node` is expected to run: an end of it is news."""
        return node not in self._waiting and node not in self._done

    def settled(self, node: str) -> bool:
        """Whether `node` has finished or been given up on: it will not run again."""
        return node in self._done

    def ended(self, node: str, code: int, now: float) -> Verdict:
        """`node`, watched, ended at `now` with exit `code` (negative: killed by that
        signal)."""
        if node in self.may_finish and code == 0:
            self._done.add(node)
            return Verdict(node, code)
        why_not = self._why_not(node, code, now)
        if why_not:
            self._done.add(node)
            return Verdict(node, code, ends_fleet=self.policy is None or node in self.essential,
                           why_not=why_not)
        self._waiting[node] = now + self.policy.delay
        return Verdict(node, code, respawn_at=self._waiting[node])

    def _why_not(self, node: str, code: int, now: float) -> str:
        if self.policy is None:
            return 'respawning is off'
        if code == EXIT_BAD_PARAMETERS:
            return 'it refused its parameters (its log says why)'
        ends = self._ends.setdefault(node, deque())
        ends.append(now)
        while now - ends[0] > self.policy.window:
            ends.popleft()
        if len(ends) >= self.policy.limit:
            return f'it ended {len(ends)} times within {self.policy.window:g} s'
        return ''

    def due(self, now: float) -> list[str]:
        """The nodes to start again now; they are watched from here on."""
        due = sorted(n for n, at in self._waiting.items() if at <= now)
        for node in due:
            del self._waiting[node]
        return due


def how_it_ended(code: int) -> str:
    """A process's exit code in words: `killed by SIGKILL`, `exited with 1`."""
    if code < 0:
        try:
            return f'killed by {signal.Signals(-code).name}'
        except ValueError:
            return f'killed by signal {-code}'
    return f'exited with {code}'
