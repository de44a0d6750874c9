"""The flight recorder: every mission topic to an MCAP file, as `ros2 bag record -s mcap`
would write it, for post-mortems without the live system (`ros2 run fjsp_planner replay
FILE.mcap`, Foxglove, `ros2 bag`).

It subscribes with the QoS each topic is published with, so it gets the latched plan and
status and the event histories even when started late, and stores each message's CDR bytes
untouched (raw subscriptions: nothing is re-encoded). With the fleet key (`fleet_key_file`)
it stores only what verifies, as the fleet's nodes believe only that: the rest is dropped,
counted per topic in the recording's metadata and in its log, so that a recording tells the
mission the fleet ran rather than what a forger said. It flushes every `flush_period`
seconds, so a recorder killed without warning loses at most that much.
"""

import sys
import time
from collections import Counter
from datetime import UTC, datetime
from pathlib import Path

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy
from rclpy.serialization import deserialize_message

from fjsp_common.auth import NodeAuth, signers_of
from fjsp_common.contract import TOPICS, subscription, take_waiting
from fjsp_common.fleet import RECORDER_NODE
from fjsp_common.parameters import ParameterSpec, table
from fjsp_common.running import ParameterError, declare, run_node
from fjsp_planner.observe.recording import (
    COMPRESSIONS,
    Offer,
    RecordingError,
    RecordingWriter,
    message_definition,
)
from fjsp_planner.workspace import default_out_dir

PARAMETERS = table(
    ParameterSpec('out_dir', '', "directory of the recording; empty: the workspace's out/ "
                  '(else ~/.ros/fjsp/out)'),
    ParameterSpec('file_name', '', 'name of the .mcap file; empty: fjsp_<UTC start time>.mcap'),
    ParameterSpec('compression', 'zstd', 'chunk compression of the MCAP file',
                  choices=tuple(COMPRESSIONS)),
    ParameterSpec('flush_period', 2.0, 'seconds between writes to disk (what a crash may lose)',
                  low=0.1, high=3600.0),
)
"""The recorder's parameters, in the order it declares them."""


def type_name(msg_type) -> str:
    """'fjsp_msgs/msg/Plan' for fjsp_msgs.msg.Plan."""
    return f"{msg_type.__module__.split('.')[0]}/msg/{msg_type.__name__}"


def installed_msg(package: str, name: str) -> str:
    """The `.msg` text of `package/msg/name` from its install space."""
    try:
        path = Path(get_package_share_directory(package)) / 'msg' / f'{name}.msg'
        return path.read_text()
    except (PackageNotFoundError, LookupError, ValueError, OSError) as error:
        raise RecordingError(f"no definition of '{package}/msg/{name}' installed: "
                             f'{error}') from None


class RecorderNode(Node):
    def __init__(self):
        super().__init__(RECORDER_NODE)
        value = {name: declare(self, spec) for name, spec in PARAMETERS.items()}
        out_dir, file_name = value['out_dir'], value['file_name']
        compression = value['compression']
        directory = Path(out_dir).expanduser() if out_dir else default_out_dir()
        name = file_name or f"fjsp_{datetime.now(UTC).strftime('%Y%m%dT%H%M%S')}.mcap"
        if Path(name).name != name:
            raise ParameterError(f"parameter 'file_name' must be a file name without "
                                 f"directories (use out_dir), got {name!r}")
        try:
            directory.mkdir(parents=True, exist_ok=True)
            self.writer = RecordingWriter(directory / name, compression)
        except OSError as error:
            raise ParameterError(f'cannot record to {directory / name}: '
                                 f'{error.strerror or error}') from None
        self.failed = False
        self.auth = NodeAuth(self, RECORDER_NODE)
        self.dropped: Counter[str] = Counter()
        """Messages per topic that did not verify with the fleet key: not written."""
        self.noted: Counter[str] = Counter()
        """`dropped` as the recording's metadata last said it."""
        try:
            for topic in TOPICS:
                # The QoS its readers use: a replay's one writer stands for all the fleet's.
                qos = topic.qos
                channel = self.writer.add_topic(
                    self.resolve_topic_name(topic.name), type_name(topic.type),
                    message_definition(type_name(topic.type), installed_msg),
                    Offer(reliable=qos.reliability == ReliabilityPolicy.RELIABLE,
                          transient_local=qos.durability == DurabilityPolicy.TRANSIENT_LOCAL,
                          depth=qos.depth))
                signed = self.auth.enabled and 'auth' in topic.type.get_fields_and_field_types()
                subscription(self, topic, self.recording(channel, topic if signed else None),
                             raw=True)
        except RecordingError as error:
            self.writer.close()
            raise ParameterError(f'cannot record: {error}') from None
        self.create_timer(value['flush_period'], self.flush)
        self.get_logger().info(f'recording {len(TOPICS)} topics to {self.writer.path}')

    def recording(self, channel: int, signed=None):
        """The callback writing a topic's messages to `channel`; for a `signed` topic, only
        those that verify."""
        def record(data: bytes) -> None:
            if self.failed or (signed is not None and not self.verifies(signed, data)):
                return
            try:
                self.writer.write(channel, data, time.time_ns())
            except OSError as error:
                self.stop_recording(error)
        return record

    def verifies(self, topic, data: bytes) -> bool:
        if not self.auth.screen(data, topic.name):
            self.dropped[self.resolve_topic_name(topic.name)] += 1
            return False
        try:
            msg = deserialize_message(data, topic.type)
        except Exception:  # noqa: BLE001  bytes rclpy cannot read, whatever it raises
            self.dropped[self.resolve_topic_name(topic.name)] += 1
            return False
        if self.auth.accept(msg, topic.name, signers_of(msg)):
            return True
        self.dropped[self.resolve_topic_name(topic.name)] += 1
        return False

    def flush(self) -> None:
        if self.failed:
            return
        try:
            if self.dropped != self.noted:
                self.writer.note_dropped(self.dropped)
                self.noted = Counter(self.dropped)
            self.writer.flush()
        except OSError as error:
            self.stop_recording(error)

    def stop_recording(self, error: OSError) -> None:
        self.failed = True
        self.get_logger().error(f'recording stopped: cannot write {self.writer.path}: '
                                f'{error.strerror or error}')

    def destroy_node(self):
        # Stopped (Ctrl-C, the launcher), it keeps what had arrived: a mission's last
        # messages come just before it is stopped.
        for sub in self.subscriptions:
            take_waiting(sub, sub.callback)
        if not self.failed:
            try:
                if self.dropped != self.noted:
                    self.writer.note_dropped(self.dropped)
                self.writer.close()
            except OSError as error:
                self.stop_recording(error)
        counts = ', '.join(f'{topic} {n}' for topic, n in sorted(self.writer.counts.items()))
        self.get_logger().info(f'recorded {self.writer.counts.total()} messages to '
                               f'{self.writer.path}' + (f' ({counts})' if counts else ''))
        if self.dropped:
            self.get_logger().warning(
                f'dropped {self.dropped.total()} messages that do not verify with the fleet '
                'key: ' + ', '.join(f'{t} {n}' for t, n in sorted(self.dropped.items())))
        return super().destroy_node()


def main(args=None):
    sys.exit(run_node(RecorderNode, RECORDER_NODE, args))
