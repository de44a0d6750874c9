"""Flight recordings: the mission topics in an MCAP file with ROS 2 message encoding.

A recording holds what rosbag2's MCAP storage would: profile `ros2`; one schema per message
type, named like `fjsp_msgs/msg/Plan`, encoding `ros2msg`, its text the `.msg` definition with
the definitions it depends on appended the way rosbag2 appends them; one channel per topic
(message encoding `cdr`, the offered QoS in rosbag2's YAML); and each message's CDR bytes as
the recorder received them. So Foxglove, `ros2 bag` with its MCAP storage and the `mcap`
libraries all open it. Reading one back (`read_recording`) needs only `mcap` and
`mcap-ros2-support`: no ROS, no running fleet.

The writer closes a chunk every time it is flushed, so a recorder killed without warning loses
only what came since its last flush; the reader reads such a truncated file up to where it
stops.
"""

import re
import struct
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import mcap
from mcap.exceptions import McapError
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import CompressionType, Writer
from mcap_ros2.decoder import DecoderFactory

from fjsp_common.auth import Verifier, signers_of
from fjsp_common.fleet import HEARTBEAT_TIMEOUT
from fjsp_common.vocabulary import EventKind
from fjsp_planner.observe.facts import Decoder, TaskEventFact, UnreadableMessageError
from fjsp_planner.observe.history import FleetHistory

SEPARATOR = '=' * 80
PRIMITIVES = frozenset({'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16',
                        'uint16', 'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring'})
COMPRESSIONS = {'zstd': CompressionType.ZSTD, 'lz4': CompressionType.LZ4,
                'none': CompressionType.NONE}
INFINITE = {'sec': 9223372036, 'nsec': 854775807}
"""rmw's 'infinite' duration, as rosbag2 writes it for deadline, lifespan and lease."""
DROPPED = 'fjsp_dropped_unverified'
"""Name of the metadata records in which a recorder with a fleet key says, per topic, how
many messages it dropped because they do not verify (the latest record counts)."""


class RecordingError(ValueError):
    """A file that cannot be read as a recording, or a definition that cannot be found."""


def _field_types(text: str) -> list[str]:
    """The non-primitive field types a `.msg` text uses, as written ('Time', 'pkg/Type')."""
    types = []
    for line in text.splitlines():
        words = line.split('#', 1)[0].split()
        if len(words) < 2:
            continue
        base = re.sub(r'\[.*$', '', words[0])
        base = re.sub(r'<=\d+$', '', base)
        if base not in PRIMITIVES:
            types.append(base)
    return types


def message_definition(type_name: str, read_msg: Callable[[str, str], str]) -> str:
    """The full `ros2msg` definition of `type_name` ('pkg/msg/Type' or 'pkg/Type'):
    its `.msg` text, then each type it depends on, depth first, once each.

    `read_msg(package, type)` returns the text of `<package>/msg/<type>.msg` (from an install
    space's share directory, or a source tree); it raises `RecordingError` if there is none.
    """
    package, _, name = _split(type_name)
    seen = set()

    def expand(package: str, name: str) -> str:
        text = read_msg(package, name)
        dependencies = set()
        for used in _field_types(text):
            dependencies.add(used if '/' in used else f'{package}/{used}')
        result = text
        for dependency in sorted(dependencies):
            if dependency in seen:
                continue
            seen.add(dependency)
            dep_package, _, dep_name = _split(dependency)
            result += f'\n{SEPARATOR}\nMSG: {dependency}\n' + expand(dep_package, dep_name)
        return result

    return expand(package, name)


def _split(type_name: str) -> tuple[str, str, str]:
    parts = type_name.split('/')
    if len(parts) == 2:
        return parts[0], 'msg', parts[1]
    if len(parts) == 3:
        return parts[0], parts[1], parts[2]
    raise RecordingError(f"message type '{type_name}' is not of the form 'package/msg/Type'")


def msg_files_under(*share_directories: Path) -> Callable[[str, str], str]:
    """A `read_msg` for `message_definition` reading `<dir>/<package>/msg/<Type>.msg` from the
    first of `share_directories` that has it."""
    def read_msg(package: str, name: str) -> str:
        for directory in share_directories:
            path = Path(directory) / package / 'msg' / f'{name}.msg'
            if path.is_file():
                return path.read_text()
        raise RecordingError(f"no definition of '{package}/msg/{name}' (looked for "
                             f"{package}/msg/{name}.msg under "
                             + ', '.join(str(d) for d in share_directories) + ')')
    return read_msg


@dataclass(frozen=True)
class Offer:
    """The QoS a topic's publishers offer, as far as recording and replaying it matter."""

    reliable: bool
    transient_local: bool
    depth: int

    def rosbag2_yaml(self) -> str:
        """rosbag2's `offered_qos_profiles` channel metadata (its version 9 spelling)."""
        def duration(name):
            return f"  {name}:\n    sec: {INFINITE['sec']}\n    nsec: {INFINITE['nsec']}\n"
        return ('- history: keep_last\n'
                f'  depth: {self.depth}\n'
                f"  reliability: {'reliable' if self.reliable else 'best_effort'}\n"
                f"  durability: {'transient_local' if self.transient_local else 'volatile'}\n"
                + duration('deadline') + duration('lifespan')
                + '  liveliness: automatic\n' + duration('liveliness_lease_duration')
                + '  avoid_ros_namespace_conventions: false\n')


class RecordingWriter:
    """Appends received messages (CDR bytes) to an MCAP file."""

    def __init__(self, path: Path, compression: str = 'zstd', chunk_size: int = 1 << 20):
        if compression not in COMPRESSIONS:
            raise RecordingError(f"unknown compression '{compression}': expected one of "
                                 + ', '.join(COMPRESSIONS))
        self.path = Path(path)
        self._file = self.path.open('wb')
        self._writer = Writer(self._file, chunk_size=chunk_size,
                              compression=COMPRESSIONS[compression])
        self._writer.start(profile='ros2', library=f'fjsp_planner recorder; mcap '
                                                   f'{getattr(mcap, "__version__", "?")}')
        self._schemas: dict[str, int] = {}
        self.counts: Counter[str] = Counter()
        self._topics: dict[int, str] = {}
        self._closed = False

    def add_topic(self, topic: str, type_name: str, definition: str, offer: Offer) -> int:
        """Register a topic; the channel id to `write` its messages with."""
        if type_name not in self._schemas:
            self._schemas[type_name] = self._writer.register_schema(
                name=type_name, encoding=SchemaEncoding.ROS2, data=definition.encode())
        channel = self._writer.register_channel(
            topic=topic, message_encoding=MessageEncoding.CDR,
            schema_id=self._schemas[type_name],
            metadata={'offered_qos_profiles': offer.rosbag2_yaml()})
        self._topics[channel] = topic
        return channel

    def write(self, channel: int, data: bytes, log_time_ns: int) -> None:
        self._writer.add_message(channel_id=channel, log_time=log_time_ns, data=data,
                                 publish_time=log_time_ns, sequence=self.counts.total())
        self.counts[self._topics[channel]] += 1

    def note_dropped(self, counts) -> None:
        """Record how many messages of each topic were dropped so far (not written)."""
        self._writer.add_metadata(DROPPED, {topic: str(n) for topic, n in counts.items()})

    def flush(self) -> None:
        """Put everything received so far on disk (it survives a crash of the recorder)."""
        self._writer.flush()
        self._file.flush()

    def close(self) -> None:
        """Write the summary (indexes, statistics) and close the file."""
        if not self._closed:
            self._closed = True
            self._writer.finish()
            self._file.close()


@dataclass(frozen=True)
class RecordedMessage:
    topic: str
    type_name: str
    log_time: float
    """When the recorder received it, wall seconds since the epoch."""
    message: object
    """Decoded: attributes named as the message's fields."""


@dataclass
class Reading:
    """What reading a recording found besides the messages."""

    counts: Counter = field(default_factory=Counter)
    """Messages per topic."""
    types: dict[str, str] = field(default_factory=dict)
    """Topic -> message type."""
    definitions: dict[str, str] = field(default_factory=dict)
    """Message type -> its `ros2msg` definition."""
    truncated: str = ''
    """Why reading stopped before the end of the file ('' when it did not)."""
    undecodable: Counter = field(default_factory=Counter)
    """Messages per topic that could not be decoded."""
    unverified: Counter = field(default_factory=Counter)
    """Messages per topic left out because they do not verify with the fleet key."""
    unverified_why: Counter = field(default_factory=Counter)
    """The same, per reason."""
    dropped_by_recorder: dict[str, int] = field(default_factory=dict)
    """Messages per topic the recorder dropped as not verifying (never written)."""
    last_time: float = 0.0


def read_recording(path: Path, reading: Reading | None = None) -> Iterator[RecordedMessage]:
    """Every message of the recording in file order, decoded; fills `reading` as it goes.

    A recording cut short (its recorder was killed) is read up to where it stops, and
    `reading.truncated` says so. Raises `RecordingError` for a file that is not MCAP at all.
    """
    reading = reading if reading is not None else Reading()
    decoders = DecoderFactory()
    try:
        stream = Path(path).open('rb')
    except OSError as error:
        raise RecordingError(f'cannot open recording {path}: {error.strerror}') from None
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    with stream:
        try:
            for record in _until_damaged(iter(StreamReader(stream).records), reading):
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Metadata) and record.name == DROPPED:
                    reading.dropped_by_recorder = {
                        topic: int(n) for topic, n in record.metadata.items() if n.isdigit()}
                elif isinstance(record, Message) and record.channel_id in channels:
                    channel = channels[record.channel_id]
                    schema = schemas.get(channel.schema_id)
                    if schema is None or schema.encoding != SchemaEncoding.ROS2:
                        continue
                    reading.types[channel.topic] = schema.name
                    reading.definitions.setdefault(schema.name, schema.data.decode(
                        errors='replace'))
                    reading.counts[channel.topic] += 1
                    reading.last_time = max(reading.last_time, record.log_time * 1e-9)
                    try:
                        decode = decoders.decoder_for(channel.message_encoding, schema)
                        message = decode(record.data) if decode else None
                    except Exception:  # noqa: BLE001  a damaged or hostile record, of any kind
                        message = None
                    if message is None:
                        reading.undecodable[channel.topic] += 1
                        continue
                    yield RecordedMessage(channel.topic, schema.name, record.log_time * 1e-9,
                                          message)
        except McapError as error:
            raise RecordingError(f'cannot read {path} as an MCAP recording: {error}') from None


def _until_damaged(messages, reading: Reading):
    """The messages up to the first record that cannot be read (a truncated file)."""
    while True:
        try:
            item = next(messages)
        except StopIteration:
            return
        except (McapError, EOFError, ValueError, OSError, struct.error) as error:
            if not reading.counts:
                raise McapError(str(error)) from None
            reading.truncated = str(error) or type(error).__name__
            return
        yield item


def replay(path: Path, heartbeat_timeout: float = HEARTBEAT_TIMEOUT, key: bytes | None = None
           ) -> tuple[FleetHistory, Reading]:
    """The fleet's history as the recording tells it, and what reading it found. With the
    fleet `key`, only what verifies with it is believed, as the fleet's nodes believe it."""
    reading = Reading()
    fleet = FleetHistory(heartbeat_timeout)
    verifier = Verifier(key) if key is not None else None
    decoder, known = None, 0
    unreadable = Counter()
    for recorded in read_recording(path, reading):
        if decoder is None or len(reading.definitions) != known:
            # A new message type brings its constants along.
            decoder, known = Decoder.from_definitions(reading.definitions), \
                len(reading.definitions)
        try:
            fact = decoder.read(recorded.type_name, recorded.message)
        except UnreadableMessageError:
            unreadable[recorded.topic] += 1
            continue
        if fact is None:
            continue
        if verifier is not None:
            why = _unverified(verifier, recorded, fact)
            if why:
                reading.unverified[recorded.topic] += 1
                reading.unverified_why[why] += 1
                continue
        fleet.add(fact)
    reading.undecodable.update(unreadable)
    return fleet, reading


def _unverified(verifier: Verifier, recorded: RecordedMessage, fact) -> str:
    """Why the recorded message does not verify ('' if it does), its sender's name left out
    so that a forger's many names make one reason."""
    msg = recorded.message
    if not hasattr(msg, 'auth'):
        return 'not signed'
    job_done = isinstance(fact, TaskEventFact) and fact.kind == EventKind.JOB_DONE
    try:
        why = verifier.check(msg, recorded.topic, signers_of(msg, job_done))
    except (AttributeError, TypeError, ValueError):
        return 'not signed'
    return re.sub(r"'[^']*'", 'a sender', why.split(' (counter')[0])
