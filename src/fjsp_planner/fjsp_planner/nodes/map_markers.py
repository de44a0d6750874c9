"""The mission's map as standard messages, so that Foxglove's 3D panel (or RViz) shows the
fleet live and in replay: `geometry_msgs/PoseArray` of the robots and
`visualization_msgs/MarkerArray` of the places and the robots with their names.

Each MarkerArray is a whole picture: it opens with DELETEALL, so a viewer that seeks in a
recording, or a mission with other places, never keeps stale marks.
"""

import math

from geometry_msgs.msg import Point, Pose, PoseArray, Quaternion, Vector3
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from fjsp_common.vocabulary import RobotMode
from fjsp_planner.observe.facts import MapPlace
from fjsp_planner.observe.fleet_map import Position, RobotOnMap, spread

PLACE_COLOUR = ColorRGBA(r=0.55, g=0.55, b=0.6, a=0.8)
TEXT_COLOUR = ColorRGBA(r=0.1, g=0.1, b=0.1, a=1.0)
MODE_COLOURS = {
    RobotMode.IDLE: ColorRGBA(r=0.2, g=0.65, b=0.2, a=1.0),
    RobotMode.TRAVELLING: ColorRGBA(r=1.0, g=0.5, b=0.05, a=1.0),
    RobotMode.WAITING: ColorRGBA(r=0.6, g=0.6, b=0.6, a=1.0),
    RobotMode.WORKING: ColorRGBA(r=0.12, g=0.47, b=0.71, a=1.0),
    RobotMode.HOLDING: ColorRGBA(r=0.25, g=0.41, b=0.88, a=1.0),
    RobotMode.FAILED: ColorRGBA(r=0.85, g=0.1, b=0.1, a=1.0),
    RobotMode.OFFLINE: ColorRGBA(r=0.45, g=0.45, b=0.45, a=0.5),
}
NOWHERE = Pose(position=Point(x=math.nan, y=math.nan, z=math.nan),
               orientation=Quaternion(w=1.0))
"""The pose of a robot that is not on the map."""


def _pose(position: Position) -> Pose:
    half = position.heading / 2
    return Pose(position=Point(x=position.x, y=position.y, z=position.z),
                orientation=Quaternion(z=math.sin(half), w=math.cos(half)))


def pose_array(header: Header, robots: list[RobotOnMap]) -> PoseArray:
    """One pose per robot, in the plan's order; NaN coordinates for one not on the map."""
    return PoseArray(header=header, poses=[
        _pose(r.position) if r.position is not None else NOWHERE for r in robots])


def marker_array(header: Header, places: list[MapPlace], robots: list[RobotOnMap],
                 size: float) -> MarkerArray:
    """Every place (a disc and its name) and every robot on the map (a ball coloured by its
    mode, and its name; robots at one spot set apart round it)."""
    markers = [Marker(header=header, action=Marker.DELETEALL)]

    def mark(ns, index, kind, x, y, z, scale, colour, text=''):
        markers.append(Marker(
            header=header, ns=ns, id=index, type=kind, action=Marker.ADD,
            pose=Pose(position=Point(x=x, y=y, z=z), orientation=Quaternion(w=1.0)),
            scale=scale, color=colour, text=text))

    for index, place in enumerate(places):
        mark('places', index, Marker.CYLINDER, place.x, place.y, place.z,
             Vector3(x=2 * size, y=2 * size, z=size / 4), PLACE_COLOUR)
        mark('place_names', index, Marker.TEXT_VIEW_FACING, place.x, place.y,
             place.z - size, Vector3(z=size), TEXT_COLOUR, place.name)
    offsets = spread(robots)
    for index, robot in enumerate(robots):
        where = robot.position
        if where is None:
            continue
        dx, dy = offsets[robot.robot]
        x, y = where.x + 1.2 * size * dx, where.y + 1.2 * size * dy
        colour = MODE_COLOURS.get(robot.mode, PLACE_COLOUR)
        mark('robots', index, Marker.SPHERE, x, y, where.z + size / 2,
             Vector3(x=size, y=size, z=size), colour)
        mark('robot_names', index, Marker.TEXT_VIEW_FACING, x, y, where.z + 1.8 * size,
             Vector3(z=size), TEXT_COLOUR, robot.robot)
    return MarkerArray(markers=markers)
