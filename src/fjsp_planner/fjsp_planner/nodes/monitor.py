"""The fleet's mission monitor, built only on the public topics.

It keeps the whole history of every mission it sees (`fjsp_planner.observe`) and shows it
three ways: in its log, a line per event (faults, re-plans with their reasons, aborted and
voided jobs, robots offline and back) and a frame of the mission whenever something changed;
on a live web page (`web_port`); and, once a mission ended, as a summary and a Gantt chart of
the whole mission in `out_dir`. It also publishes each robot's health on `/diagnostics` as
the fleet sees it, which is how a robot whose agent died shows up there, and, when the
scenario places its locations on a map, each robot's pose on it (`robot_poses`, `fleet_map`)
for Foxglove's 3D panel and other tools.

Everything it reads is latched (plan, robot states, status) or kept for late joiners (task
and mission events), so it can be started at any time, even after a mission ended.
"""

import sys
import time
from pathlib import Path

from rclpy.node import Node
from std_msgs.msg import Header

from fjsp_common.auth import NodeAuth, signers_of
from fjsp_common.contract import (
    DIAGNOSTICS,
    FLEET_MAP,
    MISSION_EVENTS,
    MISSION_STATUS,
    PLAN,
    ROBOT_POSES,
    ROBOT_STATES,
    TASK_EVENTS,
    publisher,
    subscription,
)
from fjsp_common.diagnostics import diagnostic_array, robot_diagnostic
from fjsp_common.fleet import (
    DIAGNOSTICS_PERIOD,
    HEARTBEAT_TIMEOUT,
    LATE_THRESHOLD,
    MONITOR_NODE,
)
from fjsp_common.parameters import ParameterSpec, table
from fjsp_common.running import declare, run_node, shorten
from fjsp_common.vocabulary import RobotMode
from fjsp_msgs.msg import MissionEvent, MissionStatus, RobotState, TaskEvent
from fjsp_planner.nodes.map_markers import marker_array, pose_array
from fjsp_planner.observe import fleet_map, text, views
from fjsp_planner.observe.dashboard import Dashboard
from fjsp_planner.observe.facts import Decoder, UnreadableMessageError
from fjsp_planner.observe.history import FleetHistory, MissionHistory, Outcome
from fjsp_planner.observe.mission_chart import write_mission
from fjsp_planner.workspace import default_out_dir, safe_file_name

DECODER = Decoder.from_classes(RobotState, TaskEvent, MissionStatus, MissionEvent)
TIMELINE_PERIOD = 1.0
"""Seconds between page updates when only the clock moved (offline robots, the timeline)."""

PARAMETERS = table(
    ParameterSpec('out_dir', '', "directory of the Gantt charts and histories; empty: the "
                  "workspace's out/ (else ~/.ros/fjsp/out)"),
    ParameterSpec('refresh_period', 1.0, 'seconds between checks for a new frame of the log '
                  'view', low=0.05, high=60.0),
    ParameterSpec('heartbeat_timeout', HEARTBEAT_TIMEOUT,
                  'seconds without a robot state before the robot shows offline', low=0.05,
                  high=600.0),
    ParameterSpec('exit_on_complete', False, 'exit once a mission has ended and is drawn'),
    # Events may reach a late joiner after the status saying the mission ended.
    ParameterSpec('event_grace', 3.0, 'seconds to wait for late events once a mission ended '
                  'before drawing it', low=0.0, high=600.0),
    ParameterSpec('web_port', 8080, 'port of the live web page; 0: no web page', low=0,
                  high=65535),
    ParameterSpec('web_host', '127.0.0.1',
                  'address the web page is served on (0.0.0.0: every interface)'),
    ParameterSpec('web_period', 0.1, 'seconds between checks for changes to push to the web '
                  'page', low=0.02, high=10.0),
    ParameterSpec('diagnostics_period', DIAGNOSTICS_PERIOD,
                  'seconds between per-robot diagnostics on /diagnostics', low=0.1, high=60.0),
    ParameterSpec('late_threshold', LATE_THRESHOLD, "schedule units a robot's operation may run "
                  'past its plan before its diagnostic is WARN', low=0.0, high=1e6),
    ParameterSpec('map_frame', 'map', 'frame of the robot poses and map markers'),
    ParameterSpec('pose_period', 0.1, 'seconds between checks for robots that moved on the '
                  'map, to publish their poses', low=0.02, high=60.0),
)
"""The monitor's parameters, in the order it declares them."""


class MonitorNode(Node):
    def __init__(self, context=None, parameter_overrides=None):
        super().__init__(MONITOR_NODE, context=context, parameter_overrides=parameter_overrides)
        value = {name: declare(self, spec) for name, spec in PARAMETERS.items()}
        out_dir = value['out_dir']
        self.out_dir = Path(out_dir).expanduser() if out_dir else default_out_dir()
        self.exit_on_complete = value['exit_on_complete']
        self.event_grace = value['event_grace']
        self.late_threshold = value['late_threshold']
        web_port, web_host = value['web_port'], value['web_host']

        self.fleet = FleetHistory(value['heartbeat_timeout'])
        self.told: set[tuple[str, str]] = set()
        """(mission, story key) of every line already logged."""
        self.frame_key = None
        self.ended_since: dict[str, float] = {}
        self.drawn: set[str] = set()
        self.unreadable: set[str] = set()
        self.finished = False
        self.pushed_version = (-1, 0.0)
        self.pushed_timeline = (None, -1, 0.0)
        self.map_frame = value['map_frame']
        self.published_map = None

        self.dashboard = None
        if web_port:
            try:
                self.dashboard = Dashboard(web_host, web_port)
                self.get_logger().info(f'live mission page: {self.dashboard.url}')
            except OSError as error:
                self.get_logger().error(
                    f'no live web page: cannot serve on {web_host}:{web_port} '
                    f'({error.strerror or error}); set web_port to a free port, or 0')

        self.auth = NodeAuth(self, MONITOR_NODE)
        for topic in (PLAN, ROBOT_STATES, TASK_EVENTS, MISSION_EVENTS, MISSION_STATUS):
            subscription(self, topic, self.receiver(topic.type.__name__, topic.name), self.auth)
        self.diagnostics_pub = publisher(self, DIAGNOSTICS)
        self.poses_pub = publisher(self, ROBOT_POSES)
        self.map_pub = publisher(self, FLEET_MAP)
        self.create_timer(value['refresh_period'], self.refresh)
        self.create_timer(value['diagnostics_period'], self.publish_diagnostics)
        self.create_timer(value['pose_period'], self.publish_map)
        if self.dashboard is not None:
            self.create_timer(value['web_period'], self.push_page)

    def receiver(self, type_name: str, topic: str):
        def receive(msg) -> None:
            if not self.auth.accept(msg, topic, signers_of(msg)):
                return
            try:
                fact = DECODER.read(type_name, msg)
            except UnreadableMessageError as error:
                if type_name not in self.unreadable:
                    self.unreadable.add(type_name)
                    self.get_logger().warning(f'ignoring {type_name} messages it cannot read '
                                              f'(logged once): {shorten(str(error))}')
                return
            self.fleet.add(fact)
        return receive

    # --- the log ---------------------------------------------------------------------

    def refresh(self) -> None:
        wall = time.time()
        log = self.get_logger()
        for mission in self.missions_by_start():
            for item in views.story(self.fleet, mission, wall):
                if (mission.mission_id, item['key']) not in self.told:
                    self.told.add((mission.mission_id, item['key']))
                    log.info(text.story_line(item))
        current = self.fleet.current()
        shown, key = text.frame(views.header(current, wall) if current is not None else None,
                                views.robot_rows(self.fleet, current, wall))
        if key != self.frame_key:
            self.frame_key = key
            log.info('\n' + shown)
        self.draw_ended(wall)

    def missions_by_start(self) -> list[MissionHistory]:
        return sorted(self.fleet.missions.values(), key=lambda m: m.last_stamp)

    def draw_ended(self, wall: float) -> None:
        """Summarise and draw each mission once it ended and its last events came in."""
        for mission in list(self.fleet.missions.values()):
            if not mission.ended or mission.mission_id in self.drawn:
                continue
            since = self.ended_since.setdefault(mission.mission_id, wall)
            if not mission.agrees_with_status() and wall - since < self.event_grace:
                continue
            self.drawn.add(mission.mission_id)
            self.report(mission, wall)
            if self.exit_on_complete:
                self.finished = True

    def report(self, mission: MissionHistory, wall: float) -> None:
        """Log the summary; write the Gantt chart and the history (JSON) to out_dir."""
        log = self.get_logger()
        path = self.out_dir / f'{safe_file_name(mission.mission_id)}.png'
        try:
            write_mission(self.fleet, mission, wall, path)
            where = f'Gantt chart: {path}'
        except OSError as error:
            where = f'could not write the Gantt chart {path}: {error.strerror or error}'
        log.info(text.summary(mission) + f'; {where}')

    # --- the web page ----------------------------------------------------------------

    def push_page(self) -> None:
        """Send the page what changed since the last push."""
        wall = time.time()
        version, at = self.pushed_version
        if self.fleet.version == version and wall - at < TIMELINE_PERIOD:
            return
        self.pushed_version = (self.fleet.version, wall)
        current = self.fleet.current()
        parts = {'missions': views.missions(self.fleet)}
        parts['robots'] = views.robot_rows(self.fleet, current, wall)
        if current is None:
            parts['mission'] = {'mission_id': '', 'scenario': '', 'state': 'no mission yet',
                                'planner': views.planner_state(self.fleet)}
        else:
            header = views.header(current, wall)
            header['planner'] = views.planner_state(self.fleet)
            parts['mission'] = header
            parts['story'] = views.story(self.fleet, current, wall)
            parts['map'] = fleet_map.view(self.fleet, current, wall)
            # The timeline is the largest part: rebuilt when the mission's facts changed, else
            # only as often as its clock needs.
            mission_id, version, at = self.pushed_timeline
            if (mission_id, version) != (current.mission_id, current.version) \
                    or wall - at >= TIMELINE_PERIOD:
                self.pushed_timeline = (current.mission_id, current.version, wall)
                parts['timeline'] = views.timeline(self.fleet, current, wall)
        self.dashboard.publish(parts)

    # --- the map ---------------------------------------------------------------------

    def publish_map(self) -> None:
        """The robots' poses and the map's markers, whenever a robot moved or changed mode;
        once empty when the current mission has no map but an earlier one had, so that no
        viewer keeps showing that one's robots."""
        current = self.fleet.current()
        if current is None:
            return
        places = fleet_map.places(current)
        robots = fleet_map.robots_on_map(self.fleet, current, time.time()) if places else []
        key = (current.mission_id, tuple(places.values()), tuple(robots)) if places else None
        if key == self.published_map:
            return
        self.published_map = key
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id=self.map_frame)
        self.poses_pub.publish(pose_array(header, robots))
        self.map_pub.publish(marker_array(header, list(places.values()), robots,
                                          fleet_map.size(places)))

    # --- diagnostics -----------------------------------------------------------------

    def publish_diagnostics(self) -> None:
        current = self.fleet.current()
        if current is None:
            return
        wall = time.time()
        silent = self.fleet.silent(current, wall)
        statuses = []
        for robot in current.robot_names():
            state = self.fleet.robots.get(robot)
            statuses.append(robot_diagnostic(
                f'{self.get_name()}: robot {robot}', robot,
                state.mode if state is not None else None,
                job=state.current_job if state is not None else '',
                late_by=self.lateness(current, state) if state is not None else 0.0,
                late_threshold=self.late_threshold,
                refusal=state.refusal if state is not None else '',
                silent_for=wall - silent[robot] if robot in silent else None,
                values={'mission': current.mission_id,
                        'plan revision': state.revision if state is not None else 0,
                        'location': state.location if state is not None else ''}))
        self.diagnostics_pub.publish(diagnostic_array(self.get_clock().now().to_msg(),
                                                      statuses))

    @staticmethod
    def lateness(mission: MissionHistory, state) -> float:
        """Schedule units a working robot expects to end after its plan said (0 if not)."""
        if state.mode != RobotMode.WORKING or not state.current_job:
            return 0.0
        task = next((t for t in mission.tasks_of(state.revision, state.current_job)
                     if t.robot == state.robot), None)
        attempt = mission.latest_attempts().get(state.current_job)
        if task is None or attempt is None or attempt.outcome != Outcome.RUNNING:
            return 0.0
        started = attempt.started.get(state.robot, task.start)
        planned = max(task.operation_end, started + task.operation_end - task.start)
        late = state.busy_until - planned
        return late if late > 0 else 0.0

    def destroy_node(self):
        if self.dashboard is not None:
            self.dashboard.close()
        return super().destroy_node()


def main(args=None):
    sys.exit(run_node(MonitorNode, MONITOR_NODE, args, done=lambda node: node.finished))
