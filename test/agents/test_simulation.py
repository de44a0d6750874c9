"""The simulated robot behind `sim_robot`: drawn durations, failures and moves (no ROS)."""

import pytest

from robot_agents.simulation import Noise, SimulatedRobot, format_places, parse_places


@pytest.mark.parametrize(('noise', 'low', 'high'), [
    (Noise(), 1.0, 1.0),
    (Noise(spread=0.3), 0.7, 1.3),
    (Noise(spread=0.3, bias=0.5), 1.2, 1.8),
])
def test_simulated_durations_lie_in_their_band_and_legs_never_run_short(noise, low, high):
    sim = SimulatedRobot('R1', noise, seed=7)
    operations = [sim.draw(10.0, leg=False).duration / 10 for _ in range(400)]
    legs = [sim.draw(10.0, leg=True).duration / 10 for _ in range(400)]
    assert low - 1e-9 <= min(operations) and max(operations) <= high + 1e-9
    assert max(1.0, low) - 1e-9 <= min(legs) and max(legs) <= max(1.0, high) + 1e-9
    if noise.spread:
        assert max(operations) - min(operations) > noise.spread   # spread across the band


def test_simulated_draws_repeat_with_their_seed_and_robot():
    def draws(robot, seed):
        sim = SimulatedRobot(robot, Noise(spread=0.3, failure_rate=0.2), seed)
        return [sim.draw(5.0, leg=False) for _ in range(50)]

    assert draws('R1', 3) == draws('R1', 3)
    assert draws('R1', 3) != draws('R2', 3) and draws('R1', 3) != draws('R1', 4)
    failing = [d for d in draws('R1', 3) if d.fails_at is not None]
    assert 3 <= len(failing) <= 20 and all(0 <= d.fails_at < 1 for d in failing)


def test_a_simulated_robot_moves_between_places_with_coordinates():
    sim = SimulatedRobot('R1', Noise(), 0, parse_places('dock=0,0;site=6,8'))
    sim.set_off('dock', 'site')
    sim.move(0.5)
    assert sim.position == (3.0, 4.0)
    sim.set_off('site', 'dock')                      # turned back where it stood
    sim.move(0.5)
    assert sim.position == (1.5, 2.0)
    sim.arrive('dock')
    assert sim.position == (0.0, 0.0)


@pytest.mark.parametrize('text', ['dock=0', 'dock=0,0,0,0', '=1,2', 'dock=a,b', 'dock=nan,0'])
def test_bad_places_are_named(text):
    with pytest.raises(ValueError, match=f'place {text!r} is not name=x,y or name=x,y,z'):
        parse_places(text)


def test_places_read_back_as_written():
    places = {'dock': (0.0, 0.5), 'a b': (1.0, 2.0, 3.25)}
    assert parse_places(format_places(places)) == places
