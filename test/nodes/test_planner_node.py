"""The planner node built in-process (no fleet): it declares exactly the parameters of its
table, with the table's defaults, descriptions, ranges and read-only flags, and runs missions
with the settings they give."""

import pytest
import rclpy

from fjsp_common.auth import FLEET_KEY_FILE
from fjsp_planner.execution.mission.settings import PARAMETERS, Settings
from fjsp_planner.nodes.planner import PlannerNode
from fjsp_planner.testing import DomainClaim

ROS_OWN = {'use_sim_time', 'start_type_description_service'}
"""Parameters rclpy declares on every node."""


@pytest.fixture
def planner():
    claim = DomainClaim()
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=claim.domain)
    node = None
    try:
        node = PlannerNode(context=context)
        yield node
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown(context=context)
        claim.release()


def test_the_planner_declares_exactly_the_parameters_of_its_table(planner):
    declared = set(planner.list_parameters([], 0).names)
    assert declared - ROS_OWN == set(PARAMETERS) | {FLEET_KEY_FILE.name}
    for spec in (*PARAMETERS.values(), FLEET_KEY_FILE):
        descriptor = planner.describe_parameter(spec.name)
        assert planner.get_parameter(spec.name).value == spec.default, spec.name
        assert descriptor.description == spec.description, spec.name
        assert descriptor.read_only == spec.read_only, spec.name
        assert descriptor.additional_constraints == spec.constraints, spec.name
        ranges = [(r.from_value, r.to_value)
                  for r in (*descriptor.floating_point_range, *descriptor.integer_range)]
        assert ranges == ([] if spec.low is None else [(spec.low, spec.high)]), spec.name


def test_its_missions_run_with_the_settings_its_parameters_give(planner):
    assert planner.settings() == Settings()
    assert Settings().time_limit == PARAMETERS['time_limit'].default == 10.0
    assert Settings().heartbeat_timeout == PARAMETERS['heartbeat_timeout'].default == 1.0
