"""Places on a map: coordinates in a scenario, the distances they imply (exact where they are
whole millionths, else to the nearest millionth), explicit distances overriding them, panels,
fragments, and every kind of bad `locations` named."""

import dataclasses
from fractions import Fraction

import pytest
import yaml

from fjsp_planner.model.extension import extend
from fjsp_planner.model.places import euclidean_distances
from fjsp_planner.model.problem import ProblemError
from fjsp_planner.model.scenario import (
    load_scenario,
    parse_scenario,
    problem_mapping,
    repeat_panels,
)

from repo_paths import SCENARIOS


def scenario(**changes) -> dict:
    """A rover starting at the dock, two jobs; `changes` replace whole sections."""
    data = {
        'operation_types': {0: 'grip', 1: 'drive'},
        'locomote': 'drive',
        'robot_types': {'Rover': {'grip': 1, 'drive': 1}},
        'robots': [{'name': 'R1', 'type': 'Rover', 'start_location': 'dock'}],
        'jobs': [{'name': 'Pick', 'location': 'site', 'plans': [['grip']]},
                 {'name': 'Drop', 'location': 'shed', 'plans': [['grip']]}],
        'locations': {'dock': [0, 0], 'site': [3, 4], 'shed': [1, 1]},
    }
    data.update(changes)
    return data


@pytest.mark.parametrize(('a', 'b', 'distance'), [
    ((0, 0), (3, 4), Fraction(5)),                           # 3-4-5: exact
    ((Fraction('0.3'), 0), (0, Fraction('0.4')), Fraction(1, 2)),   # exact, in decimals
    ((0, 0, 0), (2, 3, 6), Fraction(7)),                     # 3-D, exact
    ((0, 0), (1, 1), Fraction('1.414214')),                  # sqrt 2 = 1.41421356: up
    ((0, 0, 0), (3, 2, 1), Fraction('3.741657')),            # sqrt 14 = 3.74165738: down
    ((-1, -1), (-1, -1), Fraction(0)),
])
def test_distance_from_coordinates(a, b, distance):
    found = euclidean_distances({'a': tuple(map(Fraction, a)), 'b': tuple(map(Fraction, b))})
    assert found == {('a', 'b'): distance, ('b', 'a'): distance}


def test_coordinates_give_every_distance_and_pairs_override_them():
    problem = parse_scenario(scenario(distances={'pairs': [['dock', 'shed', 2]]}))
    assert problem.distance('site', 'dock') == 5
    assert problem.distance('shed', 'site') == Fraction('3.605551')    # sqrt 13 = 3.6055513
    assert problem.distance('dock', 'shed') == problem.distance('shed', 'dock') == 2
    assert problem.coordinates['site'] == (3, 4)
    assert problem.travel('R1', 'dock', 'site') == 5


def test_a_place_without_coordinates_needs_only_its_distances():
    data = scenario(locations={'dock': [0, 0], 'site': [3, 4]},
                    distances={'pairs': [['shed', 'dock', 2], ['shed', 'site', 4]]})
    problem = parse_scenario(data)
    assert problem.distance('shed', 'site') == 4
    assert 'shed' not in problem.coordinates


def test_without_travel_a_place_needs_no_coordinates():
    data = scenario(locations={'dock': [0, 0], 'site': [3, 4]})
    del data['locomote']
    data['operation_types'] = {0: 'grip'}
    data['robot_types'] = {'Rover': {'grip': 1}}
    assert parse_scenario(data).coordinates == {'dock': (0, 0), 'site': (3, 4)}


# (why the locations are wrong, the `locations` section, what the message must say)
INVALID = [
    ('a place no job or start uses', {'dock': [0, 0], 'site': [3, 4], 'shed': [1, 1],
                                      'sight': [5, 5]},
     "location 'sight' in locations: no job is there and no robot starts there; did you mean "
     "'site'?"),
    ('one number', {'dock': [0], 'site': [3, 4], 'shed': [1, 1]},
     "location 'dock': coordinates must be [x, y] or [x, y, z], got [0]"),
    ('a mapping', {'dock': {'x': 0, 'y': 0}, 'site': [3, 4], 'shed': [1, 1]},
     "location 'dock': coordinates must be [x, y] or [x, y, z], got {'x': 0, 'y': 0}"),
    ('not a number', {'dock': [0, 'north'], 'site': [3, 4], 'shed': [1, 1]},
     "location 'dock' y: expected a finite number, got 'north'"),
    ('beyond the map', {'dock': [0, -2000000], 'site': [3, 4], 'shed': [1, 1]},
     "location 'dock' y: -2000000 is outside [-1e+06, 1e+06]"),
    ('a third', {'dock': [0, '1/3'], 'site': [3, 4], 'shed': [1, 1]},
     "location 'dock' y: '1/3' is not a whole number of millionths (coordinates take at most "
     '6 decimal places)'),
    ('2-D and 3-D mixed', {'dock': [0, 0], 'site': [3, 4, 0], 'shed': [1, 1]},
     "locations: 'dock' has 2 coordinates (x, y) but 'site' has 3 (x, y, z); give every "
     'location the same number'),
    ('too far apart', {'dock': [-1e6, -1e6], 'site': [1e6, 1e6], 'shed': [1, 1]},
     "locations 'dock' and 'site' are 2.82843e+06 apart by their coordinates, more than the "
     'limit of 1e+06 for a distance (3 pairs are)'),
    ('a place left out', {'dock': [0, 0], 'site': [3, 4]},
     "location 'shed' (job 'Drop') has no coordinates and no distance to any other "
     'location'),
    ('not a mapping', [['dock', 0, 0]],
     "'locations' must be a mapping of location -> [x, y] or [x, y, z]"),
]


@pytest.mark.parametrize('why, locations, expected', INVALID, ids=[r[0] for r in INVALID])
def test_bad_locations_are_named(why, locations, expected):
    with pytest.raises(ProblemError) as caught:
        parse_scenario(scenario(locations=locations))
    assert expected in caught.value.problems, caught.value.problems


def test_a_place_left_out_is_reported_once_not_per_pair():
    with pytest.raises(ProblemError) as caught:
        parse_scenario(scenario(locations={'dock': [0, 0], 'site': [3, 4]}))
    assert caught.value.problems == [
        "location 'shed' (job 'Drop') has no coordinates and no distance to any other "
        'location']


def test_unreadable_coordinates_are_reported_once():
    with pytest.raises(ProblemError) as caught:
        parse_scenario(scenario(locations={'dock': [0, 'north'], 'site': [3, 4],
                                           'shed': [1, 1]}))
    assert caught.value.problems == ["location 'dock' y: expected a finite number, got 'north'"]


def test_panels_are_drawn_side_by_side_and_keep_the_panel_distances():
    problem = parse_scenario(scenario())
    two = repeat_panels(problem, 2, shift=10)
    # The panel is 3 wide, so the copy moves 3 + 10 along x; the unused dock of panel 2
    # (the rover starts in panel 1) is not on the map.
    assert two.coordinates == {'dock_p1': (0, 0), 'site_p1': (3, 4), 'shed_p1': (1, 1),
                               'site_p2': (16, 4), 'shed_p2': (14, 1)}
    assert two.distance('site_p1', 'site_p2') == 10
    assert two.distance('dock_p1', 'site_p2') == 5 + 10
    again = parse_scenario(problem_mapping(two))
    assert (again.coordinates, again.distances) == (two.coordinates, two.distances)


def test_a_fragment_places_its_new_location_on_the_map():
    problem = parse_scenario(scenario())
    text = yaml.safe_dump({'jobs': [{'name': 'Park', 'location': 'bay', 'plans': [['grip']]}],
                           'locations': {'bay': [0, 4]}})
    extended, added = extend(problem, text)
    assert added == ('Park',)
    assert extended.coordinates['bay'] == (0, 4)
    assert extended.distance('bay', 'site') == 3
    assert extended.distance('bay', 'shed') == Fraction('3.162278')     # sqrt 10 = 3.1622776


def test_a_fragment_cannot_move_a_place():
    problem = parse_scenario(scenario())
    text = yaml.safe_dump({'jobs': [{'name': 'Park', 'location': 'site', 'plans': [['grip']]}],
                           'locations': {'site': [9, 9]}})
    with pytest.raises(ProblemError) as caught:
        extend(problem, text)
    assert "fragment: location 'site' is on the map already" in caught.value.problems


def test_the_yard_is_a_map_with_a_road_round_the_pond():
    problem = load_scenario(SCENARIOS / 'yard.yaml')
    assert len(problem.coordinates['depot']) == 3
    assert problem.distance('depot', 'gate') == 50                      # 30-40-50
    assert problem.distance('depot', 'mount') == 75                     # given: not 60
    assert problem.distance('mount', 'mast_head') == 12
    assert problem.distance('pad', 'mast_head') == Fraction('51.419841')   # sqrt 2644


def test_a_problem_refuses_coordinates_of_two_dimensions():
    problem = parse_scenario(scenario())
    with pytest.raises(ProblemError) as caught:
        dataclasses.replace(problem, coordinates={'dock': (0, 0), 'site': (3, 4, 0)})
    assert caught.value.problems == [
        'coordinates must all be (x, y) or all be (x, y, z); found 2 and 3 numbers']
