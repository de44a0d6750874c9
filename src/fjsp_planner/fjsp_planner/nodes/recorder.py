"""The flight recorder: every mission topic to an MCAP file, as `ros2 bag record -s mcap`
would write it, for post-mortems without the live system (`ros2 run fjsp_planner replay
FILE.mcap`, Foxglove, `ros2 bag`).

It subscribes with the QoS each topic is published with, so it gets the latched plan and
status and the event histories even when started late, and stores each message's CDR bytes
untouched (raw subscriptions: nothing is decoded or re-encoded). It flushes every
`flush_period` seconds, so a recorder killed without warning loses at most that much.
"""

import sys
import time
from datetime import UTC, datetime
from pathlib import Path

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

from fjsp_common.contract import (
    EVENTS_QOS,
    JOB_STATES_TOPIC,
    LATCHED_QOS,
    MISSION_EVENTS_TOPIC,
    MISSION_STATUS_TOPIC,
    PLAN_TOPIC,
    ROBOT_STATES_QOS,
    ROBOT_STATES_TOPIC,
    TASK_EVENTS_TOPIC,
)
from fjsp_common.diagnostics import DIAGNOSTICS_QOS, DIAGNOSTICS_TOPIC
from fjsp_common.fleet import RECORDER_NODE
from fjsp_common.running import ParameterError, declare, run_node
from fjsp_msgs.msg import JobStates, MissionEvent, MissionStatus, Plan, RobotState, TaskEvent
from fjsp_planner.observe.recording import (
    COMPRESSIONS,
    Offer,
    RecordingError,
    RecordingWriter,
    message_definition,
)
from fjsp_planner.workspace import default_out_dir

TOPICS = ((PLAN_TOPIC, Plan, LATCHED_QOS),
          (ROBOT_STATES_TOPIC, RobotState, ROBOT_STATES_QOS),
          (TASK_EVENTS_TOPIC, TaskEvent, EVENTS_QOS),
          (MISSION_EVENTS_TOPIC, MissionEvent, EVENTS_QOS),
          (MISSION_STATUS_TOPIC, MissionStatus, LATCHED_QOS),
          (JOB_STATES_TOPIC, JobStates, LATCHED_QOS),
          (DIAGNOSTICS_TOPIC, DiagnosticArray, DIAGNOSTICS_QOS))
"""Every topic of a mission: (name, type, the QoS its publishers offer)."""


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
        out_dir = declare(self, 'out_dir', '',
                          "directory of the recording; empty: the workspace's out/ (else "
                          '~/.ros/fjsp/out)')
        file_name = declare(self, 'file_name', '',
                            'name of the .mcap file; empty: fjsp_<UTC start time>.mcap')
        compression = declare(self, 'compression', 'zstd',
                              'chunk compression of the MCAP file',
                              constraints='one of: ' + ', '.join(COMPRESSIONS))
        flush_period = declare(self, 'flush_period', 2.0,
                               'seconds between writes to disk (what a crash may lose)',
                               low=0.1, high=3600.0)
        if compression not in COMPRESSIONS:
            raise ParameterError(f"parameter 'compression' must be one of "
                                 f"{', '.join(COMPRESSIONS)}, got {compression!r}")
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
        try:
            for topic, msg_type, qos in TOPICS:
                channel = self.writer.add_topic(
                    self.resolve_topic_name(topic), type_name(msg_type),
                    message_definition(type_name(msg_type), installed_msg),
                    Offer(reliable=qos.reliability == ReliabilityPolicy.RELIABLE,
                          transient_local=qos.durability == DurabilityPolicy.TRANSIENT_LOCAL,
                          depth=qos.depth))
                self.create_subscription(msg_type, topic, self.recording(channel), qos,
                                         raw=True)
        except RecordingError as error:
            self.writer.close()
            raise ParameterError(f'cannot record: {error}') from None
        self.create_timer(flush_period, self.flush)
        self.get_logger().info(f'recording {len(TOPICS)} topics to {self.writer.path}')

    def recording(self, channel: int):
        def record(data: bytes) -> None:
            if self.failed:
                return
            try:
                self.writer.write(channel, data, time.time_ns())
            except OSError as error:
                self.stop_recording(error)
        return record

    def flush(self) -> None:
        if self.failed:
            return
        try:
            self.writer.flush()
        except OSError as error:
            self.stop_recording(error)

    def stop_recording(self, error: OSError) -> None:
        self.failed = True
        self.get_logger().error(f'recording stopped: cannot write {self.writer.path}: '
                                f'{error.strerror or error}')

    def destroy_node(self):
        if not self.failed:
            try:
                self.writer.close()
            except OSError as error:
                self.stop_recording(error)
        counts = ', '.join(f'{topic} {n}' for topic, n in sorted(self.writer.counts.items()))
        self.get_logger().info(f'recorded {self.writer.counts.total()} messages to '
                               f'{self.writer.path}' + (f' ({counts})' if counts else ''))
        return super().destroy_node()


def main(args=None):
    sys.exit(run_node(RecorderNode, RECORDER_NODE, args))
