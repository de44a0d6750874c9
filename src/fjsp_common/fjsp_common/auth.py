"""Who may direct the fleet: messages signed with a fleet key (see docs/security.md).

The Fast DDS shipped as PyPI wheels has no security plugins, so SROS2 cannot be used; this is
authentication at the application level. Every node of a fleet reads the same secret key
(`fleet_key_file`); senders put an `fjsp_msgs/Auth` in each message — their name, their
process incarnation, a counter — and an HMAC-SHA256 over the resolved topic (or service) name
and the message's content (every field, in definition order) with the MAC left empty.
Receivers drop, count and warn about (once per sender and reason) what does not verify: no
MAC, a wrong MAC, a sender that may not say this (a robot reporting for another robot, anyone
but the planner publishing plans or job completions), or a counter that does not increase
(a replay).

Without a key nothing is signed or checked, and every node says so when it starts.

The key files and the checking need no ROS (a recording is checked by `replay` on a machine
without it); signing, and a node's parameter, import it when used.
"""

import hashlib
import hmac
import json
import numbers
import os
import secrets
import stat
import time
from collections import Counter
from pathlib import Path

from fjsp_common.fleet import PLANNER_NODE
from fjsp_common.parameters import ParameterSpec

KEY_BYTES = 32
CLIENT_ID_BYTES = 4
"""Random bytes in the name each client signs under (`client_signer`)."""
SENDERS_KEPT = 4096
"""Senders a receiver remembers the latest message of, per topic or service; beyond them, the
least recently heard is forgotten. Clients sign under names of their own, so a long-running
planner hears a new sender at every command a user types."""
MAC_BYTES = 32
"""An HMAC-SHA256."""
HMAC_BUDGET = 100
"""Failed signature checks a second per name and claimed sender (see `Verifier`): a few tens
of milliseconds of one core."""
UNSIGNED_DECODED = 20
"""Unsigned messages a second per name still decoded from their bytes (`Verifier.screen`), so
that a sender without the key is named: an agent started without it is reported as unsigned,
not as silent. More than a fleet of agents sends on a name in a second."""
KEY_FILE_VARIABLE = 'FJSP_FLEET_KEY_FILE'
"""Where command-line tools and scripts find the fleet key when not told otherwise."""
FLEET_KEY_FILE = ParameterSpec('fleet_key_file', '',
                               'file holding the fleet key (hex); empty: unauthenticated')
"""The parameter every node that signs or checks messages has."""


class FleetKeyError(ValueError):
    """A fleet key file that cannot be used; the message names the file and why."""


def read_key(path) -> bytes:
    """The fleet key in `path`: hex text of at least 32 bytes (what `new_key` writes), in a
    file no one but its owner may read or write."""
    path = Path(path).expanduser()
    try:
        text = path.read_text().strip()
    except (OSError, UnicodeDecodeError) as error:
        raise FleetKeyError(f'{path}: cannot read the fleet key: {error}') from None
    try:
        key = bytes.fromhex(text)
    except ValueError:
        raise FleetKeyError(f'{path}: a fleet key is hex text, {2 * KEY_BYTES} digits or more'
                        ) from None
    if len(key) < KEY_BYTES:
        raise FleetKeyError(f'{path}: the fleet key has {len(key)} bytes; at least {KEY_BYTES} '
                        'are needed')
    mode = path.stat().st_mode & 0o777
    if mode & 0o077:
        # As ssh refuses a private key others can read: whoever reads it can direct the fleet.
        raise FleetKeyError(f'{path}: the fleet key is readable or writable by others (mode '
                            f'{mode:04o}); it must be private to its owner: chmod 600 {path}')
    return key


def new_key(path) -> Path:
    """Write a fresh random fleet key to `path`, readable by its owner only."""
    path = Path(path).expanduser()
    path.parent.mkdir(parents=True, exist_ok=True)
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(descriptor, 'w') as f:
        f.write(secrets.token_hex(KEY_BYTES) + '\n')
    os.chmod(path, stat.S_IRUSR | stat.S_IWUSR)
    return path


def _digest(key: bytes, name: str, msg) -> bytes:
    mac, msg.auth.mac = msg.auth.mac, []
    try:
        data = json.dumps(_canonical(msg), separators=(',', ':')).encode()
    finally:
        msg.auth.mac = mac
    return hmac.new(key, name.encode() + b'\0' + data, hashlib.sha256).digest()


def _canonical(value):
    """The message's content, field by field in definition order, floats exact. Not its CDR
    serialization: that carries whatever happened to be in memory in its padding bytes, so
    the same message serializes differently from one call to the next. A message decoded
    from a recording (`mcap_ros2`) lists its fields in `__slots__`, in the same order."""
    if hasattr(value, 'get_fields_and_field_types'):
        return [_canonical(getattr(value, field)) for field in value.get_fields_and_field_types()]
    if hasattr(value, '__slots__') and hasattr(value, '__dict__'):
        return [_canonical(getattr(value, field)) for field in value.__slots__]
    if isinstance(value, bool | str):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value).hex()
    if isinstance(value, bytes):
        return value.hex()
    return [_canonical(item) for item in value]


def signers_of(msg, job_done: bool | None = None) -> frozenset[str]:
    """Who may sign `msg` (a live message, or one decoded from a recording): the robot a
    robot state, or a robot's task event, is about; the planner for everything else (plans,
    job completions, mission events, statuses, job states). `job_done` says whether a task
    event declares a job done; by default the message's class constant tells (a live message
    has it, one decoded from a recording does not)."""
    kind = type(msg).__name__
    if kind == 'TaskEvent' and job_done is None:
        job_done = msg.kind == getattr(type(msg), 'KIND_JOB_DONE', None)
    if kind == 'RobotState' or (kind == 'TaskEvent' and not job_done):
        return frozenset({msg.robot})
    return frozenset({PLANNER_NODE})


def client_signer(key_file, role: str) -> 'Signer':
    """The signer of a tool or script: the key in `key_file`, else in the file named by
    $FJSP_FLEET_KEY_FILE, else none (unsigned requests, for an unauthenticated fleet).

    Each client signs under a name of its own, `<role>/<random id>`: replay protection orders
    the messages of each sender, so clients sharing a name would order each other's, and a
    long-lived client's requests would be refused as replays once a newer client had spoken."""
    path = key_file or os.environ.get(KEY_FILE_VARIABLE) or None
    return Signer(read_key(path) if path else None,
                  f'{role}/{secrets.token_hex(CLIENT_ID_BYTES)}')


def could_be_signed(data: bytes) -> bool:
    """Whether a fleet message serialized as `data` (CDR after its 4-byte encapsulation header,
    as a subscription takes it raw) ends with a MAC of MAC_BYTES. Every fleet message ends with
    its `Auth`, and `Auth` with its MAC, a sequence: a 4-byte length, then the bytes. An
    unsigned message ends with the length 0; only MAC_BYTES can verify."""
    if len(data) < 4 + 4 + MAC_BYTES:
        return False
    order = 'little' if data[1] & 1 else 'big'
    return int.from_bytes(data[-MAC_BYTES - 4:-MAC_BYTES], order) == MAC_BYTES


class Signer:
    """Signs what one process sends as `sender`."""

    def __init__(self, key: bytes | None, sender: str):
        self.key = key
        self.sender = sender
        self.incarnation = time.time_ns()
        self._counters = Counter()

    def sign(self, msg, name: str):
        """`msg` with its `auth` filled for resolved topic or service `name`. Without a key
        it names its sender all the same (receivers tell senders apart by it), unsigned."""
        from fjsp_msgs.msg import Auth

        self._counters[name] += 1
        msg.auth = Auth(sender=self.sender, incarnation=self.incarnation,
                        counter=self._counters[name], mac=[])
        if self.key is not None:
            msg.auth.mac = list(_digest(self.key, name, msg))
        return msg


class Verifier:
    """Checks what one process receives; remembers the latest (incarnation, counter) of each
    sender on each name, so a replayed message is refused.

    What costs nothing is checked first — a MAC missing or not 32 bytes long, a sender that
    may not say this, a counter not above the sender's latest — so a flood of unsigned or
    stale messages costs no HMAC. A flood of forged signatures does: each name and claimed
    sender gets HMAC_BUDGET failed checks a second, after which messages claiming that sender
    are refused unchecked until the second is over. A forger can so silence the sender it
    impersonates (its messages are refused with the forger's meanwhile), not the process.

    Cheaper still, `screen` refuses from its bytes a message that cannot carry a signature,
    before it is decoded into a message at all."""

    def __init__(self, key: bytes | None, clock=time.monotonic):
        self.key = key
        self.rejected = 0
        self._latest: dict[tuple[str, str], tuple[int, int]] = {}
        self._clock = clock
        self._second = -1
        self._failed: Counter[tuple[str, str]] = Counter()
        self._unsigned: Counter[str] = Counter()

    def screen(self, data: bytes, name: str) -> bool:
        """Whether a message received on resolved `name` as its serialized `data` is worth
        decoding and `check`ing: it ends with a MAC of the right size, or it is one of the
        first UNSIGNED_DECODED unsigned ones this second on `name` (its sender gets named).
        The others are refused and counted here: decoding a message costs several times
        what refusing its bytes does."""
        if self.key is None or could_be_signed(data):
            return True
        self._start_second()
        self._unsigned[name] += 1
        if self._unsigned[name] <= UNSIGNED_DECODED:
            return True
        self.rejected += 1
        return False

    def _start_second(self) -> None:
        second = int(self._clock())
        if second != self._second:
            self._second = second
            self._failed.clear()
            self._unsigned.clear()

    def check(self, msg, name: str, senders=None) -> str:
        """Why `msg`, received on resolved `name`, must be dropped ('' if it verifies).
        `senders`, if given, are the only sender names that may say it."""
        if self.key is None:
            return ''
        why = self._why(msg, name, senders)
        if why:
            self.rejected += 1
        return why

    def _why(self, msg, name, senders) -> str:
        auth = msg.auth
        if not auth.mac:
            return 'not signed'
        sender = auth.sender
        if len(auth.mac) != MAC_BYTES:
            return f"a MAC of {len(auth.mac)} bytes from '{sender[:80]}', not {MAC_BYTES}"
        if senders is not None and sender not in senders:
            return f"'{sender[:80]}' may not send this"
        stamp = (auth.incarnation, auth.counter)
        latest = self._latest.get((name, sender))
        if latest is not None and stamp <= latest:
            return f"replayed message of '{sender[:80]}' (counter {auth.counter})"
        self._start_second()
        if self._failed[name, sender] >= HMAC_BUDGET:
            return (f"more than {HMAC_BUDGET} messages a second of '{sender[:80]}' do not "
                    'verify: refused unchecked')
        if not hmac.compare_digest(bytes(auth.mac), _digest(self.key, name, msg)):
            self._failed[name, sender] += 1
            return f"signature of '{sender[:80]}' does not verify with the fleet key"
        self._latest.pop((name, sender), None)  # re-inserted: the most recently heard last
        self._latest[name, sender] = stamp
        if len(self._latest) > SENDERS_KEPT:
            del self._latest[next(iter(self._latest))]
        return ''


class NodeAuth:
    """A node's signing and checking, with its `fleet_key_file` parameter: names resolved as
    the node resolves them, and one warning per sender and reason for what is dropped."""

    def __init__(self, node, sender: str):
        from fjsp_common.running import ParameterError, declare

        self.node = node
        path = declare(node, FLEET_KEY_FILE)
        key = None
        if path:
            try:
                key = read_key(path)
            except FleetKeyError as error:
                raise ParameterError(f"parameter 'fleet_key_file': {error}") from None
            node.get_logger().info(f'authenticated fleet: messages signed and checked with '
                                   f'the key in {path}')
        else:
            node.get_logger().warning(
                'unauthenticated: no fleet key (parameter fleet_key_file), so any node on this '
                'ROS domain can send plans, reports and faults that this node believes')
        self.signer = Signer(key, sender)
        self.verifier = Verifier(key)
        self._names: dict[str, str] = {}
        self._warned: set[tuple[str, str, str]] = set()

    @property
    def enabled(self) -> bool:
        return self.verifier.key is not None

    @property
    def rejected(self) -> int:
        return self.verifier.rejected

    def resolve(self, name: str, service: bool = False) -> str:
        if name not in self._names:
            resolve = self.node.resolve_service_name if service else \
                self.node.resolve_topic_name
            self._names[name] = resolve(name)
        return self._names[name]

    def sign(self, msg, name: str, service: bool = False):
        return self.signer.sign(msg, self.resolve(name, service))

    def screen(self, data: bytes, name: str) -> bool:
        """Whether a message received on topic `name` as its serialized `data` is worth
        decoding (`Verifier.screen`); if not, it is counted."""
        return self.verifier.screen(data, self.resolve(name))

    def unreadable(self, name: str) -> None:
        """Count, and warn about once, a message on topic `name` that cannot be decoded."""
        self.verifier.rejected += 1
        if (name, '', 'unreadable') not in self._warned:
            self._warned.add((name, '', 'unreadable'))
            self.node.get_logger().warning(f'dropping a message on {name} that cannot be '
                                           'decoded; further ones are only counted')

    def accept(self, msg, name: str, senders=None, service: bool = False) -> bool:
        """Whether `msg` received on `name` verifies; if not, it is counted and warned about
        once per sender and reason."""
        return not self.refusal(msg, name, senders, service)

    def refusal(self, msg, name: str, senders=None, service: bool = False) -> str:
        """Why `msg` received on `name` does not verify ('' if it does), counted and warned
        about once per sender and reason."""
        why = self.verifier.check(msg, self.resolve(name, service), senders)
        if not why:
            return ''
        kind = why.split(':')[0].split("'")[0]
        key = (name, msg.auth.sender[:80], kind)
        if key not in self._warned:
            self._warned.add(key)
            self.node.get_logger().warning(f'dropping an unauthenticated message on {name} '
                                           f'({why}); further ones like it are only counted')
        return why
