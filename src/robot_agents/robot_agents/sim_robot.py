"""`sim_robot`: a simulated robot behind one agent run with the `action` driver.

It serves the robot's `<robot>/travel` (`fjsp_msgs/action/Travel`) and
`<robot>/execute_operation` (`fjsp_msgs/action/ExecuteOperation`) action servers, as a real
robot's bridge would (docs/robot-drivers.md). Each goal takes a duration drawn around its
nominal one (`simulation`: `spread`, `bias`, seeded by `seed` and the robot's name) and may fail
part way (`failure_rate`); its feedback says the share done and the duration it expects, which
it knows only as a real robot does, by running late. A cancelled goal stops at once where the
robot is. Given the places' coordinates (`places`, as `name=x,y[,z];...`), it moves between
them and publishes its pose (`<robot>/pose`, `geometry_msgs/PoseStamped` in frame `map`).

One process per robot, node `sim_<robot>` (`fjsp_common.fleet.sim_robot_node_name`).
"""

import sys
from dataclasses import dataclass

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future

from fjsp_common.fleet import sim_robot_node_name
from fjsp_common.parameters import ParameterSpec, table
from fjsp_common.running import ParameterError, declare, run_node
from fjsp_msgs.action import ExecuteOperation, Travel
from robot_agents.action_driver import DEFAULT_OPERATION_ACTION, DEFAULT_TRAVEL_ACTION, action_name
from robot_agents.agent_node import robot_name_from_parameters
from robot_agents.simulation import Noise, SimulatedRobot, parse_places

POSE_TOPIC = 'pose'
"""Published under the robot's name: `<robot>/pose`."""
POSE_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL,
                      history=HistoryPolicy.KEEP_LAST, depth=1)
"""The latest pose: a late joiner sees where the robot stands."""
FRAME = 'map'

PARAMETERS = table(
    ParameterSpec('robot_name', '', 'name of the robot it simulates, as the scenario lists it'),
    ParameterSpec('seed', 0, 'seed of the drawn durations and failures (with the robot name)',
                  low=0, high=2**31 - 1),
    ParameterSpec('spread', 0.0, 'actual durations are drawn within +-spread of the nominal '
                  'ones (a share: 0.3 is +-30 %)', low=0.0, high=1.0),
    ParameterSpec('bias', 0.0, 'share by which durations run long on average (negative: '
                  'short); legs never run short of their nominal time', low=-0.9, high=10.0),
    ParameterSpec('failure_rate', 0.0, 'chance that a leg or operation fails part way, '
                  'failing the robot', low=0.0, high=1.0),
    ParameterSpec('feedback_period', 0.05, 'seconds between feedbacks (and poses) of a goal',
                  low=0.005, high=1.0),
    ParameterSpec('places', '', "coordinates of the places, 'name=x,y[,z];...': the robot "
                  'moves between them and publishes its pose; empty: no pose'),
)


class SimRobot(Node):
    def __init__(self, robot: str):
        super().__init__(sim_robot_node_name(robot))
        value = {name: declare(self, spec) for name, spec in PARAMETERS.items()
                 if name != 'robot_name'}
        try:
            places = parse_places(value['places'])
        except ValueError as error:
            raise ParameterError(f"parameter 'places': {error}") from None
        self.robot = robot
        self.sim = SimulatedRobot(robot, Noise(value['spread'], value['bias'],
                                               value['failure_rate']), value['seed'], places)
        self.period = value['feedback_period']
        self.pose_pub = self.create_publisher(PoseStamped, f'{robot}/{POSE_TOPIC}', POSE_QOS)
        self.travelling = 0
        """The latest travel goal: an older one still running is preempted."""
        for kind, template, execute in (
                (Travel, DEFAULT_TRAVEL_ACTION, self.travel),
                (ExecuteOperation, DEFAULT_OPERATION_ACTION, self.operate)):
            ActionServer(self, kind, action_name(template, robot), execute,
                         goal_callback=lambda _: GoalResponse.ACCEPT,
                         cancel_callback=lambda _: CancelResponse.ACCEPT)
        self.get_logger().info(f"simulated robot '{robot}' ready (spread {value['spread']:g}, "
                               f"bias {value['bias']:g}, failure rate "
                               f"{value['failure_rate']:g}, seed {value['seed']})")

    def wall(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    async def travel(self, handle):
        goal = handle.request
        self.travelling += 1
        token = self.travelling
        self.sim.set_off(goal.origin, goal.destination)
        outcome = await self.run(handle, self.sim.draw(goal.nominal_duration, leg=True),
                                 f"leg to '{goal.destination}'", Travel.Feedback,
                                 lambda: token != self.travelling)
        if outcome.status == GoalStatus.STATUS_SUCCEEDED:
            self.sim.arrive(goal.destination)
            self.publish_pose()
        return Travel.Result(duration=outcome.duration, share=outcome.share,
                             message=outcome.message)

    async def operate(self, handle):
        goal = handle.request
        outcome = await self.run(handle, self.sim.draw(goal.nominal_duration, leg=False),
                                 f"operation '{goal.operation_name}' of job '{goal.job}'",
                                 ExecuteOperation.Feedback, lambda: False, moving=False)
        return ExecuteOperation.Result(duration=outcome.duration, message=outcome.message)

    async def run(self, handle, draw, what: str, feedback, preempted, moving: bool = True):
        """Run one goal to its end: done, failed, cancelled or preempted. Its feedback
        expects the nominal duration until it runs past it, as a robot would."""
        began = self.wall()
        ended: Future = Future()

        def check():
            if ended.done():
                return
            elapsed = self.wall() - began
            share = 1.0 if draw.duration <= 0 else min(1.0, elapsed / draw.duration)
            if draw.fails_at is not None and share >= draw.fails_at:
                share = draw.fails_at
                end = _Outcome(GoalStatus.STATUS_ABORTED, draw.duration * share, share,
                               f'simulated failure {share:.0%} into its {what}')
            elif handle.is_cancel_requested:
                end = _Outcome(GoalStatus.STATUS_CANCELED, elapsed, share, 'stopped')
            elif preempted():
                end = _Outcome(GoalStatus.STATUS_ABORTED, elapsed, share,
                               'preempted by a newer goal')
            elif share >= 1.0:
                end = _Outcome(GoalStatus.STATUS_SUCCEEDED, draw.duration, 1.0, '')
            else:
                end = None
            if moving:
                self.sim.move(share)
                self.publish_pose()
            if end is None:
                handle.publish_feedback(feedback(share=share, expected_duration=max(
                    handle.request.nominal_duration, elapsed)))
                return
            ended.set_result(end)

        timer = self.create_timer(self.period, check)
        check()
        try:
            outcome = await ended
        finally:
            self.destroy_timer(timer)
        {GoalStatus.STATUS_SUCCEEDED: handle.succeed, GoalStatus.STATUS_ABORTED: handle.abort,
         GoalStatus.STATUS_CANCELED: handle.canceled}[outcome.status]()
        return outcome

    def publish_pose(self) -> None:
        position = self.sim.position
        if position is None:
            return
        pose = PoseStamped()
        pose.header.stamp = self.get_clock().now().to_msg()
        pose.header.frame_id = FRAME
        pose.pose.position.x, pose.pose.position.y = position[0], position[1]
        pose.pose.position.z = position[2] if len(position) > 2 else 0.0
        pose.pose.orientation.w = 1.0
        self.pose_pub.publish(pose)


@dataclass(frozen=True)
class _Outcome:
    status: int
    duration: float
    """Seconds it took: the drawn duration when done, else until it ended."""
    share: float
    message: str


def main(args=None):
    sys.exit(run_node(lambda: SimRobot(robot_name_from_parameters()), 'sim_robot', args))
