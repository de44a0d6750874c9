"""The `ros2` front end's parsing and formatting, checked against ros2cli's output by hand
(no ROS processes: message classes, parameter messages and files only)."""

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseWithCovariance, Twist
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
    ParameterValue,
)
from rclpy.parameter import get_parameter_value

from fjsp_common import ros2cli
from fjsp_common.ros2cli import action, interface, messages, node, param, topic
from fjsp_common.ros2cli.graph import CommandError

# --- types and messages ---------------------------------------------------------------------

@pytest.mark.parametrize('name, kind, error', [
    ('geometry_msgs', 'msg', "'geometry_msgs' is not a message type name"),  # no type
    ('geometry_msgs/srv/Twist', 'msg', 'is not a message type name'),  # wrong kind
    ('../msg/Path', 'msg', "'../msg/Path' is not a message type name"),
    ('os/msg/Path', 'msg', r"unknown message type 'os/msg/Path' \(no package 'os'\)"),
    ('geometry_msgs/msg/Twst', 'msg', "unknown message type 'geometry_msgs/msg/Twst'"),
    ('no_such_pkg/msg/Twist', 'msg', "unknown message type 'no_such_pkg/msg/Twist'"),
    ('rcl_interfaces/srv/Nope', 'srv', "unknown service type 'rcl_interfaces/srv/Nope'"),
])
def test_bad_type_names_are_named(name, kind, error):
    with pytest.raises(CommandError, match=error):
        messages.interface_class(name, kind)


def test_types_are_found_with_or_without_their_kind():
    assert messages.interface_class('geometry_msgs/msg/Twist', 'msg') is Twist
    assert messages.interface_class('geometry_msgs/Twist', 'msg') is Twist


@pytest.mark.parametrize('text, values', [
    ('{linear: {x: 1.5}}', {'linear': {'x': 1.5}}),
    ('', {}),  # nothing given: every field keeps its default
    ('{}', {}),
])
def test_values_are_a_yaml_mapping(text, values):
    assert messages.parse_values(text) == values


@pytest.mark.parametrize('text, error', [
    ('{linear: [1}', 'are not read: YAML syntax error'),
    ('{a: ' + '[' * 30000 + ']' * 30000 + '}', 'YAML nesting deeper than 64 levels'),
    ('[1, 2]', 'must be a YAML mapping'),
    ('3', 'must be a YAML mapping'),
])
def test_bad_values_are_refused(text, error):
    with pytest.raises(CommandError, match=error):
        messages.parse_values(text)


def test_fill_sets_nested_messages_and_sequences_of_them():
    array = messages.fill(DiagnosticArray(), {
        'header': {'frame_id': 'cell1', 'stamp': {'sec': 7}},
        'status': [{'level': 2, 'name': 'MARC1', 'values': [{'key': 'mode', 'value': 'failed'}]},
                   {'name': 'LSMS'}],
    })
    assert (array.header.frame_id, array.header.stamp.sec) == ('cell1', 7)
    assert [s.name for s in array.status] == ['MARC1', 'LSMS']
    assert array.status[0].level == DiagnosticStatus.ERROR  # a byte field from an integer
    assert (array.status[0].values[0].key, array.status[0].values[0].value) == ('mode', 'failed')
    assert array.status[1].level == DiagnosticStatus.OK


def test_fill_takes_whole_numbers_for_floats():
    twist = messages.fill(Twist(), {'linear': {'x': 2}})
    assert twist.linear.x == 2.0 and isinstance(twist.linear.x, float)


@pytest.mark.parametrize('values, error', [
    ({'linaer': {}}, "geometry_msgs/msg/Twist has no field 'linaer' "
                     r'\(fields: linear, angular\)'),
    ({'linear': {'w': 1.0}}, "has no field 'linear.w'"),
    ({'linear': 3}, "field 'linear' is a geometry_msgs/Vector3, which 3 is not"),
    ({'linear': {'x': 'fast'}}, "field 'linear.x' is a double, which 'fast' is not"),
    ({'linear': {'x': True}}, "field 'linear.x' is a double, which True is not"),
])
def test_fill_names_the_field_that_does_not_fit(values, error):
    with pytest.raises(CommandError, match=error):
        messages.fill(Twist(), values)


@pytest.mark.parametrize('values, error', [
    # rclpy's generated classes do not check ranges by default: a 300 would be sent as 44.
    ({'status': [{'level': 300}]}, r"field 'status\[0\].level' is a octet, which 300 is not "
                                   r'\(a whole number in \[0, 255\]\)'),
    ({'status': [{'level': -1}]}, r"'status\[0\].level'.*-1 is not"),
    ({'status': {'name': 'x'}}, "field 'status' is a .*give a list"),
    ({'status': [{'name': 5}]}, r"field 'status\[0\].name' is a string, which 5 is not"),
])
def test_fill_checks_ranges_and_shapes(values, error):
    with pytest.raises(CommandError, match=error):
        messages.fill(DiagnosticArray(), values)


def test_fill_checks_fixed_array_sizes():
    with pytest.raises(CommandError, match=r'holds exactly 36 values'):
        messages.fill(PoseWithCovariance(), {'covariance': [0.0] * 35})
    pose = messages.fill(PoseWithCovariance(), {'covariance': [1] * 36})
    assert list(pose.covariance) == [1.0] * 36


def test_messages_print_as_ros2cli_yaml():
    twist = messages.fill(Twist(), {'linear': {'x': 0.5}})
    assert messages.to_yaml(twist) == ('linear:\n  x: 0.5\n  y: 0.0\n  z: 0.0\n'
                                       'angular:\n  x: 0.0\n  y: 0.0\n  z: 0.0\n')
    assert messages.to_yaml(12) == '12\n'
    status = messages.fill(DiagnosticStatus(), {'level': 1, 'name': 'A'})
    assert messages.to_yaml(status).startswith('level: 1\nname: A\n')


# --- parameters -----------------------------------------------------------------------------

@pytest.mark.parametrize('text, line', [
    ('3.0', 'Double value is: 3.0'),
    ('3', 'Integer value is: 3'),
    ('true', 'Boolean value is: True'),
    ('cpsat', 'String value is: cpsat'),
    ('[1, 2]', 'Integer values are: [1, 2]'),
    ('[a, b]', "String values are: ['a', 'b']"),
])
def test_param_get_lines(text, line):
    assert param.get_line(get_parameter_value(text)) == line


def test_param_get_hides_the_type_on_request():
    assert param.get_line(get_parameter_value('2.5'), hide_type=True) == '2.5'
    assert param.get_line(ParameterValue()) == 'Parameter not set.'


def test_param_describe_lines():
    descriptor = ParameterDescriptor(
        name='delay_threshold', type=ParameterType.PARAMETER_DOUBLE,
        description='schedule units an operation may run late before a re-plan',
        floating_point_range=[FloatingPointRange(from_value=0.0, to_value=1e6)])
    assert param.describe_lines(descriptor) == [
        'Parameter name: delay_threshold',
        '  Type: double',
        '  Description: schedule units an operation may run late before a re-plan',
        '  Constraints:',
        '    Min value: 0.0',
        '    Max value: 1000000.0',
    ]
    read_only = ParameterDescriptor(name='workers', type=ParameterType.PARAMETER_INTEGER,
                                    read_only=True, additional_constraints='a power of 2',
                                    integer_range=[IntegerRange(from_value=1, to_value=64,
                                                                step=1)])
    assert param.describe_lines(read_only) == [
        'Parameter name: workers', '  Type: integer', '  Constraints:', '    Read only: true',
        '    Min value: 1', '    Max value: 64', '    Step: 1',
        '    Additional constraints: a power of 2']


def test_param_dump_nests_dotted_names_under_the_node():
    document = param.dump_document('/planner', {'time_limit': 10.0, 'qos.depth': 5,
                                                'qos.reliable': True, 'scenario': ''})
    assert document == {'/planner': {'ros__parameters': {
        'qos': {'depth': 5, 'reliable': True}, 'scenario': '', 'time_limit': 10.0}}}


PARAMS_FILE = """
/**:
  ros__parameters:
    heartbeat_timeout: 1.5
planner:
  ros__parameters:
    time_limit: 5.0
    search: {workers: 2}
agent_MARC1:
  ros__parameters:
    robot_type: MARC
"""


def test_param_load_takes_the_node_section_and_on_request_the_wildcard(tmp_path):
    path = tmp_path / 'params.yaml'
    path.write_text(PARAMS_FILE)

    def loaded(**options):
        return {p.name: param.python_value(p.value)
                for p in param.parameters_from_file(str(path), '/planner', **options)}

    assert loaded(use_wildcard=False) == {'time_limit': 5.0, 'search.workers': 2}
    assert loaded(use_wildcard=True) == {'heartbeat_timeout': 1.5, 'time_limit': 5.0,
                                         'search.workers': 2}


@pytest.mark.parametrize('text, error', [
    (PARAMS_FILE.replace('planner:', 'monitor:'),
     r"has no section for node '/planner' \(sections: /\*\*, monitor, agent_MARC1\)"),
    ('planner: 3\n', "section 'planner' needs a 'ros__parameters' mapping"),
    ('[1, 2]\n', "must map node names to 'ros__parameters'"),
    ('planner: {ros__parameters: [1}\n', 'is not read: YAML syntax error'),
    ('planner: {ros__parameters: {x: ' + '[' * 30000 + ']' * 30000 + '}}\n',
     'YAML nesting deeper than 64 levels'),
])
def test_param_load_names_what_is_wrong_with_the_file(tmp_path, text, error):
    path = tmp_path / 'params.yaml'
    path.write_text(text)
    with pytest.raises(CommandError, match=error):
        param.parameters_from_file(str(path), '/planner', use_wildcard=False)


def test_param_load_names_a_missing_file(tmp_path):
    with pytest.raises(CommandError, match="cannot read parameters file '.*nope.yaml'"):
        param.parameters_from_file(str(tmp_path / 'nope.yaml'), '/planner', False)


# --- nodes, actions, topics -----------------------------------------------------------------

def test_node_info_lines_leave_an_empty_line_for_an_empty_section():
    sections = {section: [] for section in node.SECTIONS}
    sections['Publishers'] = [('/plan', ['fjsp_msgs/msg/Plan']),
                              ('/rosout', ['rcl_interfaces/msg/Log'])]
    sections['Action Servers'] = [('/run_mission', ['fjsp_msgs/action/RunMission'])]
    assert '\n'.join(node.info_lines('/planner', sections)) == (
        '/planner\n'
        '  Subscribers:\n\n'
        '  Publishers:\n'
        '    /plan: fjsp_msgs/msg/Plan\n'
        '    /rosout: rcl_interfaces/msg/Log\n'
        '  Service Servers:\n\n'
        '  Service Clients:\n\n'
        '  Action Servers:\n'
        '    /run_mission: fjsp_msgs/action/RunMission\n'
        '  Action Clients:\n')


def test_action_info_lines():
    servers = [('/planner', ['fjsp_msgs/action/RunMission'])]
    assert action.info_lines('/run_mission', [], servers) == [
        'Action: /run_mission', 'Action clients: 0', 'Action servers: 1', '    /planner']
    assert action.info_lines('/run_mission', [], servers, show_types=True)[-1] == \
        '    /planner [fjsp_msgs/action/RunMission]'
    assert action.info_lines('/run_mission', [], servers, count=True) == [
        'Action: /run_mission', 'Action clients: 0', 'Action servers: 1']


def test_hz_reports_once_a_period_of_messages_over_its_window():
    window = topic.RateWindow(size=3)
    window.add(0.0)
    assert window.report() is None  # no interval yet
    for now in (0.1, 0.2, 0.4):
        window.add(now)
    assert window.report() is None  # as ros2cli: the first line a period later
    window.add(1.0)  # the window keeps the last 3 intervals: 0.1, 0.2, 0.6
    assert window.report() is None  # 0.6 s after the message of the first report
    window.add(1.5)  # intervals 0.2, 0.6, 0.5: mean 1.3/3 s, deviation sqrt(0.26/9) s
    assert window.report() == ('average rate: 2.308\n\tmin: 0.200s max: 0.600s '
                               'std dev: 0.16997s window: 3')
    assert window.report() is None  # no message since
    assert window.report(force=True).startswith('average rate: 2.308')


# --- interfaces -----------------------------------------------------------------------------

@pytest.fixture
def share(tmp_path):
    """Two packages' installed interface files: `cell` nests `geo` types."""
    (tmp_path / 'cell' / 'msg').mkdir(parents=True)
    (tmp_path / 'cell' / 'srv').mkdir()
    (tmp_path / 'geo' / 'msg').mkdir(parents=True)
    (tmp_path / 'geo' / 'msg' / 'Point.msg').write_text(
        '# A point.\n\nfloat64 x  # metres\nfloat64 y\n')
    (tmp_path / 'cell' / 'msg' / 'Robot.msg').write_text(
        '# One robot of the cell.\n'
        'string name        # as in the scenario\n'
        '                   # (letters and digits)\n'
        '\n'
        'uint8 MODE_IDLE=0  # waiting\n'
        'geo/Point[] path\n'
        'Tool tool\n')
    (tmp_path / 'cell' / 'msg' / 'Tool.msg').write_text('# A tool.\nstring<=8 kind\n')
    (tmp_path / 'cell' / 'srv' / 'Move.srv').write_text(
        'geo/Point goal\n---\nbool success  # reached\n')
    return lambda package: tmp_path / package


def test_interface_show_expands_nested_types_without_their_comments(share):
    assert interface.interface_lines('cell/msg/Robot', locate=share) == [
        '# One robot of the cell.',
        'string name        # as in the scenario',
        '                   # (letters and digits)',
        '',
        'uint8 MODE_IDLE=0  # waiting',
        'geo/Point[] path',
        '\tfloat64 x',
        '\tfloat64 y',
        'Tool tool',
        '\tstring<=8 kind',
    ]


def test_interface_show_of_a_service_and_without_comments(share):
    assert interface.interface_lines('cell/srv/Move', locate=share) == [
        'geo/Point goal', '\tfloat64 x', '\tfloat64 y', '---', 'bool success  # reached']
    assert interface.interface_lines('cell/msg/Robot', locate=share, comments=False)[:3] == [
        'string name', 'uint8 MODE_IDLE=0', 'geo/Point[] path']
    assert interface.interface_lines('cell/msg/Robot', locate=share,
                                     nested_comments=True)[6:9] == [
        '\t# A point.', '\t', '\tfloat64 x  # metres']


@pytest.mark.parametrize('name, error', [
    ('cell/msg/Nope', r"unknown interface 'cell/msg/Nope' \(no msg/Nope.msg in package 'cell'\)"),
    ('cell/Robot', "'cell/Robot' is not an interface type name"),
    ('cell/idl/Robot', "'cell/idl/Robot' is not an interface type name"),
])
def test_interface_show_names_a_bad_type(share, name, error):
    with pytest.raises(CommandError, match=error):
        interface.interface_lines(name, locate=share)


# --- the command line -----------------------------------------------------------------------

@pytest.mark.parametrize('argv, code, error', [
    (['bag', 'play'], 2, "'bag' is not provided by this front end"),
    (['interface', 'show', 'cell/Robot'], 1,
     "ros2 interface show: 'cell/Robot' is not an interface type name"),
    (['pkg', 'executables', 'no_such_package'], 1,
     "ros2 pkg executables: Package 'no_such_package' not found"),
    (['service', 'call', '/x', 'geometry_msgs/srv/Nope'], 1,
     "ros2 service call: unknown service type 'geometry_msgs/srv/Nope'"),
    (['topic', 'pub', '/x', 'geometry_msgs/msg/Twist', '{linear: 1}'], 1,
     "ros2 topic pub: field 'linear' is a geometry_msgs/Vector3, which 1 is not"),
    (['topic', 'hz', '/x', '--duration', '0'], 2, 'argument --duration: must be a number > 0'),
    (['param', 'get', '/planner'], 2, 'the following arguments are required: parameter_name'),
])
def test_errors_are_one_line_and_an_exit_code(capsys, argv, code, error):
    try:
        returned = ros2cli.main(argv)
    except SystemExit as exited:  # argparse's own exit on bad arguments
        returned = exited.code
    assert returned == code
    stderr = capsys.readouterr().err
    assert error in stderr and 'Traceback' not in stderr
    if code == 1:
        assert len(stderr.splitlines()) == 1
