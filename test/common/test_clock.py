"""One mission's clock, checked by hand: schedule units from wall seconds and back."""

from types import SimpleNamespace

import pytest

from fjsp_common.clock import ScheduleClock, seconds


def test_schedule_time_counts_units_of_time_scale_seconds_from_the_mission_start():
    clock = ScheduleClock(mission_start=1000.0, time_scale=0.5)
    assert clock.units(1000.0) == 0
    assert clock.units(1004.0) == 8
    assert clock.units(999.0) == -2  # before the mission start
    assert clock.wall(8) == 1004.0


def test_a_stamp_reads_as_wall_seconds():
    assert seconds(SimpleNamespace(sec=1700000000, nanosec=250_000_000)) == \
        pytest.approx(1700000000.25)
