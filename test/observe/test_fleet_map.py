"""Robots on the mission's map (no ROS): a robot at its place, or along its leg as far as its
progress says; off the map when its place has none; the page's map with the jobs of each
place; the map read back from a recording."""

import math

import pytest

from fjsp_common.vocabulary import RobotMode
from fjsp_planner.observe import fleet_map
from fjsp_planner.observe.facts import MapPlace
from fjsp_planner.observe.fleet_map import Position
from fjsp_planner.observe.history import FleetHistory
from fjsp_planner.observe.recording import replay

from mission_facts import MISSION, at, plan, record, state, task, work

PLACES = (MapPlace('at_J1', 0.0, 0.0, 0.0), MapPlace('at_J2', 4.0, 8.0, 0.0),
          MapPlace('mast', 4.0, 8.0, 6.0))
WHERE = {p.name: p for p in PLACES}


def test_a_robot_at_a_place_is_at_its_coordinates():
    assert fleet_map.position(WHERE, 'at_J2', '', 0.0) == Position(4, 8, 0, 0)


def test_a_robot_on_a_leg_is_as_far_along_as_its_progress():
    where = fleet_map.position(WHERE, 'at_J1', 'at_J2', 0.25)
    assert (where.x, where.y, where.z) == (1, 2, 0)
    assert where.heading == pytest.approx(math.atan2(8, 4))
    up = fleet_map.position(WHERE, 'at_J2', 'mast', 0.5)
    assert (up.x, up.y, up.z, up.heading) == (4, 8, 3, 0)


@pytest.mark.parametrize(('progress', 'x'), [(-1.0, 0.0), (2.0, 4.0), (math.nan, 0.0)])
def test_progress_outside_the_leg_stays_on_it(progress, x):
    assert fleet_map.position(WHERE, 'at_J1', 'at_J2', progress).x == x


def test_a_first_leg_from_nowhere_is_at_its_end():
    # A robot that may start anywhere goes to its first job without travelling.
    assert fleet_map.position(WHERE, '', 'at_J2', 0.0) == Position(4, 8, 0, 0)


@pytest.mark.parametrize(('location', 'destination'), [
    ('depot', ''),           # a place the scenario gives distances only
    ('at_J1', 'depot'),      # a leg to such a place
    ('depot', 'at_J1'),      # a leg from one
    ('', ''),                # no plan has placed it yet
])
def test_a_robot_whose_place_is_not_on_the_map_is_not_drawn(location, destination):
    assert fleet_map.position(WHERE, location, destination, 0.5) is None


def mission_with_a_map():
    """A travels from J1's place to J2's; B works at J2; C has not reported."""
    facts = [plan(1, 0, [task('A', 'J1', 0, 2), task('A', 'J2', 4, 6, co_workers=['B']),
                         task('B', 'J2', 4, 6, co_workers=['A'])], places=PLACES)]
    facts += work(['A'], 'J1', 1, 0, 2)
    facts += [state('A', 3.0, mode=RobotMode.TRAVELLING, location='at_J1',
                    destination='at_J2', progress=0.5),
              state('B', 3.0, mode=RobotMode.WAITING, job='J2', location='at_J2')]
    fleet = FleetHistory()
    for fact in facts:
        fleet.add(fact)
    return fleet, facts


def test_every_robot_of_the_mission_is_listed_in_the_plans_order():
    fleet, _ = mission_with_a_map()
    robots = fleet_map.robots_on_map(fleet, fleet.missions[MISSION], at(3.5))
    assert [(r.robot, r.mode) for r in robots] == [
        ('A', RobotMode.TRAVELLING), ('B', RobotMode.WAITING), ('C', None)]
    assert (robots[0].position.x, robots[0].position.y) == (2, 4)
    assert (robots[1].position.x, robots[1].position.y) == (4, 8)
    assert robots[2].position is None
    # Silent past the heartbeat timeout: offline, where it was last.
    later = fleet_map.robots_on_map(fleet, fleet.missions[MISSION], at(10))
    assert later[0].mode == RobotMode.OFFLINE and later[0].position == robots[0].position


def test_the_pages_map_names_each_places_jobs_and_sets_robots_at_one_spot_apart():
    fleet, _ = mission_with_a_map()
    fleet.add(state('A', 3.4, mode=RobotMode.WAITING, job='J2', location='at_J2'))
    view = fleet_map.view(fleet, fleet.missions[MISSION], at(3.5))
    assert view['three_d'] is True
    assert {p['name']: (p['jobs'], p['done']) for p in view['places']} == {
        'at_J1': (['J1'], ['J1']), 'at_J2': (['J2'], []), 'mast': ([], [])}
    a, b, c = view['robots']
    assert (a['x'], a['y'], b['x'], b['y']) == (4, 8, 4, 8)
    assert a['spread'] == [1.0, 0.0] and b['spread'] == pytest.approx([-1.0, 0.0])
    assert c == {'robot': 'C', 'mode': 'no report', 'job': '', 'location': '',
                 'destination': ''}


def test_a_mission_without_a_map_has_no_map():
    fleet = FleetHistory()
    fleet.add(plan(1, 0, [task('A', 'J1', 0, 2)]))
    assert fleet_map.view(fleet, fleet.missions[MISSION], at(1)) is None


def test_the_map_is_read_back_from_a_recording(tmp_path):
    _, facts = mission_with_a_map()
    record(tmp_path / 'map.mcap', facts)
    fleet, _ = replay(tmp_path / 'map.mcap')
    assert fleet_map.places(fleet.missions[MISSION]) == WHERE
