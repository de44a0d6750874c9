"""Missions as a service that cannot be confused, over real processes: every client is heard
whatever other clients did."""

import time

from fjsp_planner.missions import MissionClient

from repo_paths import PAPER

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')

SLOW = 0.1
"""Wall seconds per schedule unit: one panel takes about 3 s."""


def idle_fleet(fjsp_fleet, key=False, **planner):
    """An idle planner (no scenario: it waits for goals) and the paper's four agents."""
    fleet = fjsp_fleet(PAPER, time_scale=SLOW, key=key, planner=planner)
    fleet.start_planner(scenario='')
    for robot in ROBOTS:
        fleet.start_agent(robot)
    fleet.wait_for(lambda o: len(o.robots) == 4 and o.status is not None, 30,
                   'the four agents and the idle planner')
    return fleet


def client_of(fleet) -> MissionClient:
    return MissionClient(domain_id=fleet.domain, key_file=fleet.key_file)


# --- item E: clients do not lock each other out -------------------------------------------

def test_an_old_client_is_heard_after_a_newer_one_used_the_planner(fjsp_fleet):
    """Found in the field: every client signed as 'mission_client', and replay protection
    orders a sender's messages by process start, so once a newer client had spoken, a
    long-lived older one was refused ('the goal is not signed with the fleet key')."""
    fleet = idle_fleet(fjsp_fleet, key=True)
    with client_of(fleet) as old:
        old.status()
        time.sleep(0.01)
        with client_of(fleet) as new:
            for client in (new, old, new):
                mission = client.submit(PAPER)
                client.cancel(mission.mission_id, reason='next client')
                assert mission.result(timeout=30).state == 'cancelled'
            last = old.run(PAPER, timeout=90)
    assert last.complete, last
    assert fleet.observer.status.ignored_unauthenticated == 0


