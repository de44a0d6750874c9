"""The fleet's topic table: every topic once, each read and written with the QoS its
readers and writers need."""

from rclpy.qos import DurabilityPolicy

from fjsp_common.contract import MAX_FLEET, ROBOT_STATES, TOPICS


def test_every_topic_of_a_mission_is_in_the_table_once():
    assert [t.name for t in TOPICS] == ['plan', 'robot_states', 'task_events',
                                        'mission_events', 'mission_status', 'job_states',
                                        '/diagnostics', 'robot_poses', 'fleet_map']
    assert [t.type.__name__ for t in TOPICS] == ['Plan', 'RobotState', 'TaskEvent',
                                                 'MissionEvent', 'MissionStatus', 'JobStates',
                                                 'DiagnosticArray', 'PoseArray', 'MarkerArray']


def test_a_late_joiner_gets_the_latest_state_of_every_robot():
    # Each agent's writer keeps its latest state; a reader keeps one per robot.
    assert ROBOT_STATES.writer_qos.depth == 1
    assert ROBOT_STATES.qos.depth >= MAX_FLEET
    for qos in (ROBOT_STATES.qos, ROBOT_STATES.writer_qos):
        assert qos.durability == DurabilityPolicy.TRANSIENT_LOCAL
