"""`ros2 run fjsp_planner fleet` keeps its fleet up: a node killed mid-mission is started
again and the mission completes, each job done once — an agent (re-planned around and back),
the recorder, the monitor (back on its web port), the planner (resumed from its journal). With
--no-respawn a killed node ends the fleet, as before."""

import subprocess
import time
import urllib.error
import urllib.request
from contextlib import contextmanager

import pytest

from fjsp_msgs.msg import MissionEvent, MissionStatus
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.testing import Observer, check_jobs_done_once, check_nothing_redone

from browser import free_port
from fleet_command import children, launcher, node_pid, still_running, wait_for_nodes
from repo_paths import PAPER

pytestmark = pytest.mark.slow

TIME_SCALE = '0.3'
"""Wall seconds per schedule unit: the paper's mission lasts about 10 s, long enough for a
killed node to come back before it ends."""


@contextmanager
def paper_fleet(tmp_path, domain: int, *args):
    """The launcher running the paper's mission (and its nodes started), and an observer of
    its domain; the launcher is killed if the test ends before it did."""
    observer = Observer(domain)
    fleet = None
    try:
        fleet = launcher(tmp_path, str(PAPER), '--exit-on-complete', '--time-scale', TIME_SCALE,
                         '--timeout', '150', *args, domain=domain)
        wait_for_nodes(fleet)
        yield fleet, observer
    finally:
        observer.close()
        if fleet is not None and fleet.poll() is None:
            fleet.kill()  # its nodes die with it (parent-death signal)
            fleet.communicate(timeout=30)


def kill(fleet: subprocess.Popen, word: str) -> None:
    subprocess.run(['kill', '-9', str(node_pid(fleet, word))], check=True)


def under_way(observer: Observer, jobs: int = 2) -> None:
    observer.wait_for(lambda o: o.status.jobs_done >= jobs
                      and o.status.state == MissionStatus.STATE_EXECUTING, 60,
                      f'the mission under way ({jobs} jobs done)')


def finish(fleet: subprocess.Popen, timeout: float = 180) -> tuple[str, str]:
    out, err = fleet.communicate(timeout=timeout)
    assert fleet.returncode == 0, out + err
    assert 'complete: 12/12 jobs done' in out, out + err
    assert 'Traceback' not in out + err
    return out, err


def check_each_job_done_once(observer: Observer) -> None:
    with observer.lock:
        plans, events = list(observer.plans), list(observer.events)
        story = list(observer.mission_events)
    check_jobs_done_once(load_scenario(PAPER), plans, events)
    check_nothing_redone(events, story)


def test_a_killed_agent_and_recorder_come_back_and_the_mission_completes(tmp_path,
                                                                         ros_domain):
    with paper_fleet(tmp_path, ros_domain, '--web-port', '0') as (fleet, observer):
        under_way(observer)
        kill(fleet, "robot_name:='MARC1'")
        kill(fleet, '/recorder ')
        out, err = finish(fleet)
    check_each_job_done_once(observer)
    for node in ('agent_MARC1', 'recorder'):
        assert f"node '{node}' killed by SIGKILL; starting it again in 1 s" in err
        assert f"node '{node}' started again" in err
    assert len(list(tmp_path.glob('fjsp_*.mcap'))) == 2  # the new recorder's file too
    # The planner planned around the lost robot, then with it again.
    story = [(e.kind, e.robot) for e in observer.mission_events]
    offline = story.index((MissionEvent.KIND_ROBOT_OFFLINE, 'MARC1'))
    assert (MissionEvent.KIND_ROBOT_BACK, 'MARC1') in story[offline:], story
    log = (tmp_path / 'logs' / 'agent_MARC1.log').read_text()
    assert log.count('authenticated fleet') == 2  # both agents logged to it


def test_a_killed_monitor_comes_back_on_its_web_port(tmp_path, ros_domain):
    port = free_port()
    with paper_fleet(tmp_path, ros_domain, '--web-port', str(port)) as (fleet, observer):
        under_way(observer, jobs=1)
        assert page_answers(port, 10)
        kill(fleet, 'monitor_node')
        assert page_answers(port, 30)
        out, err = finish(fleet)
    assert f'live mission page: http://127.0.0.1:{port}/' in out
    assert "node 'monitor' killed by SIGKILL; starting it again in 1 s" in err
    assert "node 'monitor' started again" in err
    assert len(list(tmp_path.glob('solar_panel-*.png'))) == 1  # drawn by the new monitor


def page_answers(port: int, timeout: float) -> bool:
    """Whether the live page answers on `port` within `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f'http://127.0.0.1:{port}/', timeout=2) as page:
                if page.status == 200:
                    return True
        except (urllib.error.URLError, OSError):
            pass
        time.sleep(0.2)
    return False


def test_a_killed_planner_resumes_its_mission_from_its_journal(tmp_path, ros_domain):
    with paper_fleet(tmp_path, ros_domain, '--web-port', '0') as (fleet, observer):
        under_way(observer)
        mission = observer.status.mission_id
        kill(fleet, 'planner_node')
        out, err = finish(fleet)
    check_each_job_done_once(observer)
    assert observer.status.mission_id == mission
    assert "node 'planner' killed by SIGKILL; starting it again in 1 s" in err
    assert "node 'planner' started again" in err
    assert f"resuming mission '{mission}'" in (tmp_path / 'logs' / 'planner.log').read_text()
    assert len(list((tmp_path / 'journal').glob(f'*/{mission}.journal'))) == 1


def test_without_respawn_a_killed_agent_ends_the_fleet(tmp_path, ros_domain):
    with paper_fleet(tmp_path, ros_domain, '--web-port', '0', '--no-respawn') as (
            fleet, observer):
        nodes = children(fleet.pid)
        under_way(observer, jobs=1)
        kill(fleet, "robot_name:='MARC1'")
        out, err = fleet.communicate(timeout=60)
    assert fleet.returncode == 1, out + err
    assert ("node 'agent_MARC1' killed by SIGKILL; not starting it again: respawning is off; "
            'the fleet stops') in err
    assert 'Traceback' not in out + err
    assert not still_running(nodes, 10.0)
