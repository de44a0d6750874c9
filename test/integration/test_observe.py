"""Watching a mission over real processes: the flight recording read back into the same
history the live monitor built, diagnostics of failed and offline robots, the monitor's story
in its log, and `ros2 topic list` / `ros2 topic echo` of the front end.

The mission runs at 0.1 s per schedule unit so that a failure lands mid-mission.
"""

import json
import math
import subprocess
import time
import urllib.request

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from mcap.reader import make_reader

from fjsp_msgs.msg import MissionStatus
from fjsp_planner.missions import MissionClient
from fjsp_planner.observe.recording import RecordingError, read_recording

from browser import free_port, wait_listening
from repo_paths import PAPER, SCENARIOS

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')

SLOW = 0.1
"""Wall seconds per schedule unit."""
RECORDED = {'/plan': 'fjsp_msgs/msg/Plan', '/robot_states': 'fjsp_msgs/msg/RobotState',
            '/task_events': 'fjsp_msgs/msg/TaskEvent',
            '/mission_events': 'fjsp_msgs/msg/MissionEvent',
            '/mission_status': 'fjsp_msgs/msg/MissionStatus',
            '/job_states': 'fjsp_msgs/msg/JobStates',
            '/diagnostics': 'diagnostic_msgs/msg/DiagnosticArray'}
MAP = {'/robot_poses': 'geometry_msgs/msg/PoseArray',
       '/fleet_map': 'visualization_msgs/msg/MarkerArray'}
"""Recorded too, published only for a scenario with places on a map."""
YARD_PLACES = {'depot': (0, 0, 0), 'gate': (30, 40, 0), 'mount': (60, 0, 0),
               'mast_head': (60, 0, 12), 'pad': (30, -40, 0)}


def start_fleet(fleet):
    fleet.start_planner()
    for robot in ROBOTS:
        fleet.start_agent(robot)
    fleet.wait_for(lambda o: o.plans and all(
        r in o.robots and o.robots[r].plan_revision >= 1 for r in ROBOTS), 60,
        'every agent to follow the first plan')


def wait_until_elapsed(observer, units):
    observer.wait_for(lambda o: o.status.state == MissionStatus.STATE_EXECUTING
                      and o.status.elapsed >= units, 60, f'schedule time {units}')


def heard_by_recorder(path) -> set[str]:
    """The robots whose states, and 'planner' if its status, the recording holds so far."""
    heard = set()
    try:
        for message in read_recording(path):
            if message.topic == '/robot_states':
                heard.add(message.message.robot)
            elif message.topic == '/mission_status':
                heard.add('planner')
    except (RecordingError, OSError):
        pass  # not written yet
    return heard


def latest_revision(observer) -> int:
    return max(p.revision for p in observer.plans)


def test_recording_replays_into_the_history_the_monitor_built(fjsp_fleet, tmp_path):
    out, replayed = tmp_path / 'out', tmp_path / 'replayed'
    fleet = fjsp_fleet(PAPER, time_scale=SLOW)
    observer = fleet.observer
    fleet.start_node('recorder', 'fjsp_planner', 'recorder',
                     {'out_dir': out, 'file_name': 'mission.mcap', 'flush_period': 0.5})
    fleet.start_monitor(out_dir=out, web_port=0, exit_on_complete=True, refresh_period=0.2)
    fleet.start_planner(scenario='')
    for robot in ROBOTS:
        fleet.start_agent(robot)
    # Discovery between fresh processes can take seconds: a recorder that met the planner
    # after its second plan revision never got the first (the plan is latched one deep). The
    # mission starts once the recording holds every robot and the idle planner, and the
    # monitor has shown every robot.
    deadline = time.monotonic() + 60
    while not (heard_by_recorder(out / 'mission.mcap') >= {*ROBOTS, 'planner'}
               and all(f'  {robot} ' in fleet.log('monitor') for robot in ROBOTS)):
        assert time.monotonic() < deadline, 'the recorder or the monitor did not hear the fleet'
        time.sleep(0.2)
    with MissionClient(domain_id=fleet.domain) as client:
        client.submit(PAPER)
    fleet.wait_for(lambda o: o.plans and all(
        r in o.robots and o.robots[r].plan_revision >= 1 for r in ROBOTS), 60,
        'every agent to follow the first plan')
    wait_until_elapsed(observer, 8)
    fleet.inject_fault('MARC1', 'fail')
    fleet.wait_for(lambda o: latest_revision(o) >= 2, 30, 'a re-plan after the failure')
    wait_until_elapsed(observer, observer.status.elapsed + 4)
    fleet.inject_fault('MARC1', 'recover')
    fleet.wait_for(lambda o: o.complete(), 90, 'the mission to complete')
    code = fleet.processes['monitor'].wait(timeout=60)
    monitor_log = fleet.log('monitor')
    assert code == 0, monitor_log
    assert fleet.stop('recorder')['recorder'] == 0, fleet.log('recorder')

    # The file holds every topic of the mission, with its ROS 2 type, in CDR.
    with (out / 'mission.mcap').open('rb') as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
    channels = {c.topic: c for c in summary.channels.values()}
    types = {topic: summary.schemas[c.schema_id].name for topic, c in channels.items()}
    assert types == {**RECORDED, **MAP}
    assert {c.message_encoding for c in channels.values()} == {'cdr'}
    counts = {topic: summary.statistics.channel_message_counts.get(c.id, 0)
              for topic, c in channels.items()}
    assert all(counts[topic] > 0 for topic in RECORDED), counts

    done = subprocess.run(['ros2', 'run', 'fjsp_planner', 'replay', str(out / 'mission.mcap'),
                           '--out', str(replayed)], env=fleet.env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert 'complete: 12/12 jobs done (planner: 12/12)' in done.stdout, done.stdout

    [live_file] = out.glob('*.json')
    [replay_file] = replayed.glob('*.replay.json')
    live, again = json.loads(live_file.read_text()), json.loads(replay_file.read_text())
    assert (live['mission']['jobs_done'], live['mission']['jobs_total']) == (12, 12)
    assert live['mission']['agrees'] and again['mission']['agrees']
    for part in ('work', 'health', 'revisions', 'plans'):
        assert live['timeline'][part] == again['timeline'][part], part
    assert [(i['time'], i['text']) for i in live['story']] == \
        [(i['time'], i['text']) for i in again['story']]
    # What the history holds: MARC1's failed span, closed by its recovery, and the re-plan.
    # (On a loaded machine a starved agent may also have gone offline for a moment.)
    assert ('MARC1', 'failed', False) in [(h['robot'], h['kind'], h['open'])
                                          for h in live['timeline']['health']]
    assert len(live['timeline']['revisions']) >= 2
    assert (replayed / live_file.name.replace('.json', '.replay.png')).is_file()
    assert live_file.with_suffix('.png').is_file()

    # The log tells the story, one line per event.
    for line in ('MARC1 failed', 'revision 2 planned', 'MARC1 back in service',
                 'mission complete: 12/12 jobs done'):
        assert line in monitor_log, line


def test_diagnostics_show_failed_and_offline_robots(fjsp_fleet):
    fleet = fjsp_fleet(PAPER, time_scale=SLOW)
    observer = fleet.observer
    statuses: list[DiagnosticStatus] = []

    def collect(msg: DiagnosticArray):
        with observer.lock:
            statuses.extend(msg.status)
            observer.lock.notify_all()

    observer.node.create_subscription(DiagnosticArray, '/diagnostics', collect, 10)
    fleet.start_monitor(web_port=0, diagnostics_period=0.3, heartbeat_timeout=0.8)
    start_fleet(fleet)

    # The agents report on /diagnostics too (`agent_MARC1: robot`): what is tested here is
    # what the monitor says of each robot.
    def reported(robot, level, words):
        return lambda o: any(s.name == f'monitor: robot {robot}' and s.hardware_id == robot
                             and s.level == level and words in s.message for s in statuses)

    def heard_every_robot(o):
        # A monitor that never heard a robot says STALE of it, whatever happens to it after.
        return all(any(s.name == f'monitor: robot {robot}' and s.level != DiagnosticStatus.STALE
                       for s in statuses) for robot in ROBOTS)

    def last_said(robot) -> str:
        with observer.lock:
            said = [s for s in statuses if s.name == f'monitor: robot {robot}']
        return f'{said[-1].level!r} {said[-1].message!r}' if said else 'nothing'

    fleet.wait_for(reported('Assembler', DiagnosticStatus.OK, ''), 30,
                   'an OK diagnostic of the Assembler')
    fleet.wait_for(heard_every_robot, 30, 'the monitor to hear every robot')
    fleet.inject_fault('MARC1', 'fail')
    fleet.wait_for(reported('MARC1', DiagnosticStatus.ERROR, 'failed'), 20,
                   'an ERROR diagnostic of the failed MARC1')
    fleet.kill('agent_MARC2')
    try:
        fleet.wait_for(reported('MARC2', DiagnosticStatus.ERROR, 'offline'), 20,
                       'an ERROR diagnostic of MARC2, killed')
    except pytest.fail.Exception as failure:
        pytest.fail(f'{failure}; the monitor last said of MARC2: {last_said("MARC2")}',
                    pytrace=False)
    failed = next(s for s in statuses if s.name == 'monitor: robot MARC1'
                  and s.level == DiagnosticStatus.ERROR)
    assert {v.key: v.value for v in failed.values}['mode'] == 'failed'


def test_ros2_topic_list_and_echo(fjsp_fleet):
    fleet = fjsp_fleet(PAPER, time_scale=SLOW)
    fleet.start_planner()
    fleet.wait_for(lambda o: o.status is not None, 30, "the planner's first status")

    def ros2(*args):
        return subprocess.run(['ros2', 'topic', *args], env=fleet.env, capture_output=True,
                              text=True, timeout=60)

    listing = ros2('list', '-t', '--spin-time', '3')
    assert listing.returncode == 0, listing.stderr
    assert '/mission_status [fjsp_msgs/msg/MissionStatus]' in listing.stdout.splitlines()
    assert '/plan [fjsp_msgs/msg/Plan]' in listing.stdout.splitlines()

    # Latched: a reader joining now still gets the planner's latest status.
    echo = ros2('echo', 'mission_status', '--once')
    assert echo.returncode == 0, echo.stderr
    assert 'scenario_id: solar_panel' in echo.stdout
    assert echo.stdout.rstrip().endswith('---')
    field = ros2('echo', '/mission_status', '--once', '--field', 'jobs_total')
    assert field.stdout.splitlines()[0] == '12', field.stdout

    missing = ros2('echo', '/no_such_topic', '--spin-time', '1')
    assert missing.returncode == 1
    assert "topic '/no_such_topic' not found" in missing.stderr
    assert 'Traceback' not in missing.stderr
    wrong = ros2('echo', '/mission_status', '--once', '--field', 'no_such_field')
    assert wrong.returncode == 1 and "has no field 'no_such_field'" in wrong.stderr


def valid_pose(pose) -> bool:
    """On the yard's map (its bounding box), facing along x-y: or nowhere (all NaN)."""
    p, q = pose.position, pose.orientation
    if all(math.isnan(v) for v in (p.x, p.y, p.z)):
        return True
    return (0 <= p.x <= 60 and -40 <= p.y <= 40 and 0 <= p.z <= 12 and q.x == q.y == 0
            and math.isclose(q.z ** 2 + q.w ** 2, 1.0))


def test_a_mission_on_a_map_is_recorded_for_foxglove_and_served(fjsp_fleet, tmp_path):
    """The yard's robots on its map: their poses and the map's markers in the recording,
    as Foxglove reads them; and the live page, fetched as curl would, holds the mission."""
    out, port = tmp_path / 'out', free_port()
    fleet = fjsp_fleet(SCENARIOS / 'yard.yaml', time_scale=SLOW)
    robots = [r.name for r in fleet.problem.robots]
    fleet.start_node('recorder', 'fjsp_planner', 'recorder',
                     {'out_dir': out, 'file_name': 'yard.mcap', 'flush_period': 0.5})
    fleet.start_monitor(out_dir=out, web_port=port, exit_on_complete=True)
    assert wait_listening(port, 30), f'the monitor did not serve its page on port {port}'
    fleet.start()
    wait_until_elapsed(fleet.observer, 5)
    mission_id = fleet.observer.plans[0].mission_id
    # The monitor hears the fleet as the test does, not necessarily as soon.
    deadline = time.monotonic() + 30
    while True:
        page = urllib.request.urlopen(f'http://127.0.0.1:{port}/', timeout=10).read().decode()
        if f'<span id="mission-id">{mission_id}</span>' in page \
                or time.monotonic() > deadline:
            break
        time.sleep(0.2)
    assert f'<span id="mission-id">{mission_id}</span>' in page
    assert '<span id="state" class="state" data-state="executing">executing</span>' in page
    assert all(f'<tr data-robot="{robot}">' in page for robot in robots)
    fleet.check_mission_complete(timeout=90)
    assert fleet.processes['monitor'].wait(timeout=60) == 0, fleet.log('monitor')
    assert fleet.stop('recorder')['recorder'] == 0, fleet.log('recorder')

    recorded = list(read_recording(out / 'yard.mcap'))
    poses = [m.message for m in recorded if m.topic == '/robot_poses']
    maps = [m.message for m in recorded if m.topic == '/fleet_map']
    assert {m.type_name for m in recorded if m.topic in MAP} == set(MAP.values())
    assert poses and maps
    assert all(p.header.frame_id == 'map' and len(p.poses) == len(robots) for p in poses)
    assert all(valid_pose(pose) for p in poses for pose in p.poses)
    spots = {(x, y, z) for x, y, z in YARD_PLACES.values()}
    # Robots were seen on their legs, between places, and all end at one.
    assert any((pose.position.x, pose.position.y, pose.position.z) not in spots
               and not math.isnan(pose.position.x) for p in poses for pose in p.poses)
    assert {(q.position.x, q.position.y, q.position.z) for q in poses[-1].poses} <= spots
    for markers in maps:
        assert markers.markers[0].action == 3       # DELETEALL: each is a whole picture
        assert {m.text for m in markers.markers if m.ns == 'place_names'} == set(YARD_PLACES)
    assert {m.text for m in maps[-1].markers if m.ns == 'robot_names'} == set(robots)
