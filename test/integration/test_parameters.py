"""ROS-standard parameters over real processes: a parameters file
(config/params/paper_demo.yaml, passed as `--ros-args --params-file`) reaches every node, the
launcher's own options win over it, and a set through a node's parameter service that its
descriptor forbids (out of range, read-only) is refused with a reason."""

import time

import pytest
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.parameter import Parameter, parameter_value_to_python

from fjsp_planner.testing import FleetHarness

from repo_paths import REPO

SCENARIO = REPO / 'config' / 'scenarios' / 'solar_panel.yaml'
PARAMS = REPO / 'config' / 'params' / 'paper_demo.yaml'


@pytest.fixture(scope='module')
def fleet(tmp_path_factory):
    with FleetHarness(SCENARIO, out=tmp_path_factory.mktemp('params'), params_file=PARAMS,
                      time_scale=0.03) as fleet:
        fleet.start(monitor=True)
        fleet.check_mission_complete(timeout=60)
        yield fleet


def call(fleet, srv_type, service, request, timeout=20.0):
    node = fleet.observer.node
    client = node.create_client(srv_type, service)
    try:
        assert client.wait_for_service(timeout_sec=timeout), f'no {service} after {timeout} s'
        future = client.call_async(request)
        deadline = time.monotonic() + timeout
        while not future.done():
            assert time.monotonic() < deadline, f'{service} did not answer in {timeout} s'
            time.sleep(0.05)
        return future.result()
    finally:
        node.destroy_client(client)


def get(fleet, node, *names):
    answer = call(fleet, GetParameters, f'/{node}/get_parameters',
                  GetParameters.Request(names=list(names)))
    return [parameter_value_to_python(v) for v in answer.values]


def set_one(fleet, node, name, value):
    parameter = Parameter(name, value=value).to_parameter_msg()
    answer = call(fleet, SetParameters, f'/{node}/set_parameters',
                  SetParameters.Request(parameters=[parameter]))
    return answer.results[0]


def test_the_params_file_reaches_every_node(fleet):
    # /** keys reach planner and monitor; node-name keys one node; --time-scale wins.
    assert get(fleet, 'planner', 'robot_wait_timeout', 'heartbeat_timeout', 'time_scale') == \
        [10.0, 1.5, 0.03]
    assert get(fleet, 'monitor', 'heartbeat_timeout') == [1.5]
    assert get(fleet, 'agent_MARC1', 'robot_type') == ['MARC']
    assert get(fleet, 'agent_LSMS', 'robot_type') == ['LSMS']
    # The generic agents, pinned by the file, played the paper's types.
    assert {r: s.robot_type for r, s in fleet.observer.robots.items()} == {
        'Assembler': 'Assembler', 'LSMS': 'LSMS', 'MARC1': 'MARC', 'MARC2': 'MARC'}


def test_an_out_of_range_set_is_refused_with_a_reason(fleet):
    result = set_one(fleet, 'planner', 'time_limit', 0.0)
    assert not result.successful
    assert 'time_limit out of range Min: 0.01, Max: 3600.0' in result.reason, result.reason
    assert get(fleet, 'planner', 'time_limit') == [5.0]
    # Within the range the same parameter is taken: the refusal was the range's.
    assert set_one(fleet, 'planner', 'time_limit', 7.5).successful
    assert get(fleet, 'planner', 'time_limit') == [7.5]


def test_a_read_only_set_is_refused_with_a_reason(fleet):
    result = set_one(fleet, 'agent_MARC1', 'tick_period', 0.02)
    assert not result.successful
    assert 'Trying to set a read-only parameter: tick_period' in result.reason, result.reason
    assert get(fleet, 'agent_MARC1', 'tick_period') == [0.01]
