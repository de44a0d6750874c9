"""Where the robots are on the mission's map, from the fleet's messages alone.

The plan carries the places the scenario gives coordinates (`PlanFact.places`). Each robot's
state says where it is (`location`) and, on a leg, where to and how far along
(`destination`, `progress`): the robot is drawn on the straight line between the two places,
that far along. The line is a drawing of the schedule's leg, not the robot's real path,
whose length the scenario's distance gives. A leg from nowhere (a robot that may start
anywhere goes to its first job without travelling) puts the robot at its destination.
A robot whose place has no coordinates, or that no plan has placed yet, is not on the map.

The monitor publishes these positions for Foxglove and other tools (`nodes/map_markers.py`)
and sends them to the live page (`view`).
"""

import math
from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass

from fjsp_common.vocabulary import RobotMode
from fjsp_planner.observe.facts import MapPlace, RobotStateFact
from fjsp_planner.observe.history import FleetHistory, MissionHistory, Outcome


@dataclass(frozen=True)
class Position:
    x: float
    y: float
    z: float
    heading: float
    """Radians from the x axis in the x-y plane: towards the destination on a leg, else 0."""


@dataclass(frozen=True)
class RobotOnMap:
    robot: str
    mode: RobotMode | None
    """None: it has not reported."""
    position: Position | None
    """None: not on the map."""
    job: str = ''
    location: str = ''
    destination: str = ''


def places(mission: MissionHistory) -> dict[str, MapPlace]:
    """The mission's map, as its latest plan gives it."""
    last = mission.last_plan
    return {p.name: p for p in last.places} if last is not None else {}


def position(where: Mapping[str, MapPlace], location: str, destination: str,
             progress: float) -> Position | None:
    """A robot at `location`, or `progress` of the way from there to `destination`."""
    to = where.get(destination) if destination else None
    start = where.get(location)
    if destination and to is None:
        return None
    if to is None:
        return Position(start.x, start.y, start.z, 0.0) if start is not None else None
    if start is None:
        if location:     # a leg from a place that is not on the map
            return None
        return Position(to.x, to.y, to.z, 0.0)
    f = min(max(progress, 0.0), 1.0) if math.isfinite(progress) else 0.0
    heading = math.atan2(to.y - start.y, to.x - start.x) if (to.x, to.y) != (
        start.x, start.y) else 0.0
    return Position(start.x + f * (to.x - start.x), start.y + f * (to.y - start.y),
                    start.z + f * (to.z - start.z), heading)


def robots_on_map(fleet: FleetHistory, mission: MissionHistory, wall: float
                  ) -> list[RobotOnMap]:
    """Every robot of the mission, in the plan's order, with where it is on the map."""
    where = places(mission)
    silent = fleet.silent(mission, wall) if not mission.ended else {}
    robots = []
    for name in mission.robot_names():
        state = _state(fleet, mission, name)
        if state is None:
            robots.append(RobotOnMap(name, None, None))
            continue
        mode = RobotMode.OFFLINE if name in silent else state.mode
        robots.append(RobotOnMap(
            name, mode, position(where, state.location, state.destination, state.progress),
            state.current_job, state.location, state.destination))
    return robots


def _state(fleet: FleetHistory, mission: MissionHistory, robot: str) -> RobotStateFact | None:
    """The robot's latest state in `mission` (its last one there once it moved on)."""
    state = fleet.robots.get(robot)
    if state is None or state.mission_id not in ('', mission.mission_id):
        return mission.last_state(robot)
    return state


def spread(robots: list[RobotOnMap]) -> dict[str, tuple[float, float]]:
    """Unit offsets in x-y that set apart robots drawn at one spot, from east over north to
    west (the place's name goes below it), so that each stays visible ((0, 0) for a robot
    alone at its spot)."""
    spots = defaultdict(list)
    for r in robots:
        if r.position is not None:
            spots[round(r.position.x, 6), round(r.position.y, 6), round(r.position.z, 6)
                  ].append(r.robot)
    offsets = {}
    for names in spots.values():
        for k, name in enumerate(names):
            angle = math.pi * k / (len(names) - 1) if len(names) > 1 else None
            offsets[name] = (math.cos(angle), math.sin(angle)) if angle is not None \
                else (0.0, 0.0)
    return offsets


def size(where: Mapping[str, MapPlace]) -> float:
    """A mark's size that reads well on this map: 1/40 of its extent (1 for a single place)."""
    if not where:
        return 1.0
    extent = max(max(getattr(p, axis) for p in where.values())
                 - min(getattr(p, axis) for p in where.values()) for axis in 'xyz')
    return extent / 40 if extent > 0 else 1.0


def view(fleet: FleetHistory, mission: MissionHistory, wall: float) -> dict | None:
    """The live page's map: places with their jobs, robots where they are (None: no map)."""
    where = places(mission)
    if not where:
        return None
    jobs: dict[str, list[str]] = {name: [] for name in where}
    # Every revision: later ones leave out the jobs done before them.
    for revision in sorted(mission.plans):
        for task in mission.plans[revision].tasks:
            if task.location in jobs and task.job not in jobs[task.location]:
                jobs[task.location].append(task.job)
    done = {job for job, a in mission.latest_attempts().items() if a.outcome == Outcome.DONE}
    robots = robots_on_map(fleet, mission, wall)
    offsets = spread(robots)
    return {
        'three_d': any(p.z != 0 for p in where.values()),
        'places': [{'name': p.name, 'x': p.x, 'y': p.y, 'z': p.z, 'jobs': jobs[p.name],
                    'done': [j for j in jobs[p.name] if j in done]} for p in where.values()],
        'robots': [{'robot': r.robot, 'mode': str(r.mode) if r.mode else 'no report',
                    'job': r.job, 'location': r.location, 'destination': r.destination,
                    **({'x': r.position.x, 'y': r.position.y, 'z': r.position.z,
                        'spread': list(offsets[r.robot])} if r.position is not None else {})}
                   for r in robots],
    }
