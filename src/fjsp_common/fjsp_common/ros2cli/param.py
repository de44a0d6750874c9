"""`ros2 param`: list, get, set, describe, dump and load a node's parameters through its
parameter services, with ros2cli's syntax and output."""

import argparse
import sys

import yaml
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rclpy.parameter import PARAMETER_SEPARATOR_STRING, get_parameter_value
from rclpy.parameter_client import AsyncParameterClient

from fjsp_common.bounded_yaml import MAX_YAML_BYTES, YamlError, load_yaml

from .graph import (
    LOOKUP_SPIN_TIME,
    CommandError,
    add_spin_time,
    answer,
    cli_node,
    discover,
    find_node,
    node_names,
)

# ParameterType -> (the field holding the value, `param get`'s label, `describe`'s type name)
KINDS = {
    ParameterType.PARAMETER_BOOL: ('bool_value', 'Boolean value is:', 'boolean'),
    ParameterType.PARAMETER_INTEGER: ('integer_value', 'Integer value is:', 'integer'),
    ParameterType.PARAMETER_DOUBLE: ('double_value', 'Double value is:', 'double'),
    ParameterType.PARAMETER_STRING: ('string_value', 'String value is:', 'string'),
    ParameterType.PARAMETER_BYTE_ARRAY: ('byte_array_value', 'Byte values are:', 'byte array'),
    ParameterType.PARAMETER_BOOL_ARRAY: ('bool_array_value', 'Boolean values are:',
                                         'boolean array'),
    ParameterType.PARAMETER_INTEGER_ARRAY: ('integer_array_value', 'Integer values are:',
                                            'integer array'),
    ParameterType.PARAMETER_DOUBLE_ARRAY: ('double_array_value', 'Double values are:',
                                           'double array'),
    ParameterType.PARAMETER_STRING_ARRAY: ('string_array_value', 'String values are:',
                                           'string array'),
}


def python_value(value: ParameterValue):
    """The value a ParameterValue holds (lists for arrays); None when not set."""
    if value.type not in KINDS:
        return None
    held = getattr(value, KINDS[value.type][0])
    return held if isinstance(held, bool | int | float | str) else list(held)


def type_name(parameter_type: int) -> str:
    return KINDS[parameter_type][2] if parameter_type in KINDS else 'not set'


def get_line(value: ParameterValue, hide_type: bool = False) -> str:
    """`ros2 param get`'s line: `Double value is: 2.0`, or the bare value."""
    if value.type not in KINDS:
        return 'Parameter not set.'
    shown = python_value(value)
    return str(shown) if hide_type else f'{KINDS[value.type][1]} {shown}'


def describe_lines(descriptor) -> list[str]:
    """`ros2 param describe`'s lines for one parameter."""
    lines = [f'Parameter name: {descriptor.name}', f'  Type: {type_name(descriptor.type)}']
    if descriptor.description:
        lines.append(f'  Description: {descriptor.description}')
    lines.append('  Constraints:')
    if descriptor.read_only:
        lines.append('    Read only: true')
    ranges = list(descriptor.floating_point_range) + list(descriptor.integer_range)
    if ranges:
        lines += [f'    Min value: {ranges[0].from_value}', f'    Max value: {ranges[0].to_value}']
        if ranges[0].step:
            lines.append(f'    Step: {ranges[0].step}')
    if descriptor.additional_constraints:
        lines.append(f'    Additional constraints: {descriptor.additional_constraints}')
    return lines


def dump_document(node: str, values: dict) -> dict:
    """`ros2 param dump`'s document: the node's parameters under `ros__parameters`, a dotted
    name (`qos.depth`) nested as YAML mappings, as a parameters file has them."""
    parameters = {}
    for name, value in sorted(values.items()):
        *parents, last = name.split(PARAMETER_SEPARATOR_STRING)
        into = parameters
        for parent in parents:
            into = into.setdefault(parent, {})
        into[last] = value
    return {node: {'ros__parameters': parameters}}


def parameters_from_file(path: str, node: str, use_wildcard: bool) -> list[Parameter]:
    """The parameters a parameters file gives `node` (its section, keyed with or without the
    leading slash; with `use_wildcard` the `/**` section first), in file order."""
    try:
        with open(path, encoding='utf-8') as stream:
            document = load_yaml(stream.read(MAX_YAML_BYTES + 1))
    except OSError as error:
        raise CommandError(f"cannot read parameters file '{path}': {error.strerror}") from None
    except (YamlError, UnicodeDecodeError) as error:
        raise CommandError(f"parameters file '{path}' is not read: {error}") from None
    if not isinstance(document, dict):
        raise CommandError(f"parameters file '{path}' must map node names to "
                           "'ros__parameters'")
    keys = [k for k in (['/**'] if use_wildcard else []) + [node, node.lstrip('/')]
            if k in document]
    if not keys:
        raise CommandError(f"parameters file '{path}' has no section for node '{node}' "
                           f"(sections: {', '.join(map(str, document)) or 'none'})")
    merged = {}
    for key in keys:
        section = document[key]
        if not isinstance(section, dict) or not isinstance(section.get('ros__parameters'),
                                                           dict):
            raise CommandError(f"parameters file '{path}': section '{key}' needs a "
                               "'ros__parameters' mapping")
        merged.update(_flattened(section['ros__parameters']))
    return [Parameter(name=name, value=value) for name, value in merged.items()]


def _flattened(values: dict, prefix: str = '') -> dict:
    flat = {}
    for name, value in values.items():
        if isinstance(value, dict):
            flat.update(_flattened(value, f'{prefix}{name}{PARAMETER_SEPARATOR_STRING}'))
        else:
            flat[f'{prefix}{name}'] = get_parameter_value(str(value))
    return flat


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 param',
                                     description="Inspect and change nodes' parameters.")
    verbs = parser.add_subparsers(dest='verb', required=True,
                                  metavar='{list,get,set,describe,dump,load}')
    listing = verbs.add_parser('list', help='the parameters of one node or of every node')
    listing.add_argument('node_name', nargs='?', help='e.g. /planner (default: every node)')
    listing.add_argument('--param-type', action='store_true', help="print each one's type")
    get = verbs.add_parser('get', help="print a parameter's value")
    get.add_argument('node_name')
    get.add_argument('parameter_name')
    get.add_argument('--hide-type', action='store_true', help='print only the value')
    setting = verbs.add_parser('set', help='set a parameter (the value is read as YAML)')
    setting.add_argument('node_name')
    setting.add_argument('parameter_name')
    setting.add_argument('value', help='e.g. 3.0, true, "[1, 2]", text')
    describe = verbs.add_parser('describe', help="print parameters' types, descriptions and "
                                'constraints')
    describe.add_argument('node_name')
    describe.add_argument('parameter_names', nargs='+')
    dump = verbs.add_parser('dump', help="print a node's parameters as a parameters file")
    dump.add_argument('node_name')
    load = verbs.add_parser('load', help='set parameters from a parameters file')
    load.add_argument('node_name')
    load.add_argument('parameter_file')
    load.add_argument('--use-wildcard', action='store_true',
                      help="also load the file's '/**' section")
    for verb in (listing, get, setting, describe, dump, load):
        add_spin_time(verb, LOOKUP_SPIN_TIME)
    args = parser.parse_args(argv)
    with cli_node() as node:
        if args.verb == 'list':
            return _list(node, args)
        client, name = _client(node, args.node_name, args.spin_time)
        return VERBS[args.verb](node, client, name, args)


def _client(node, node_name: str, seconds: float) -> tuple[AsyncParameterClient, str]:
    name = find_node(node, node_name, seconds)
    client = AsyncParameterClient(node, name)
    if not client.wait_for_services(timeout_sec=max(seconds, 1.0)):
        raise CommandError(f"node '{name}' offers no parameter services")
    return client, name


def _list(node, args) -> int:
    if args.node_name:
        targets = [find_node(node, args.node_name, args.spin_time)]
    else:
        targets = sorted(set(discover(node, lambda: node_names(node), args.spin_time)))
    for name in targets:
        client = AsyncParameterClient(node, name)
        if not client.wait_for_services(timeout_sec=1.0):
            if args.node_name:
                raise CommandError(f"node '{name}' offers no parameter services")
            continue
        names = sorted(answer(node, client.list_parameters(), f'{name}/list_parameters')
                       .result.names)
        types = {}
        if args.param_type and names:
            descriptors = answer(node, client.describe_parameters(names),
                                 f'{name}/describe_parameters').descriptors
            types = {d.name: type_name(d.type) for d in descriptors}
        if not args.node_name:
            print(f'{name}:')
        for parameter in names:
            print(f'  {parameter} (type: {types.get(parameter, "not set")})'
                  if args.param_type else f'  {parameter}')
    return 0


def _get(node, client, name, args) -> int:
    values = answer(node, client.get_parameters([args.parameter_name]),
                    f'{name}/get_parameters').values
    if not values:
        raise CommandError(f"node '{name}' has no parameter '{args.parameter_name}'")
    print(get_line(values[0], args.hide_type))
    return 0


def _set(node, client, name, args) -> int:
    parameter = Parameter(name=args.parameter_name, value=get_parameter_value(args.value))
    result = answer(node, client.set_parameters([parameter]),
                    f'{name}/set_parameters').results[0]
    if not result.successful:
        print('Setting parameter failed' + (f': {result.reason}' if result.reason else ''),
              file=sys.stderr)
        return 1
    print('Set parameter successful' + (f': {result.reason}' if result.reason else ''))
    return 0


def _describe(node, client, name, args) -> int:
    descriptors = answer(node, client.describe_parameters(args.parameter_names),
                         f'{name}/describe_parameters').descriptors
    if len(descriptors) != len(args.parameter_names):
        known = set(answer(node, client.list_parameters(), f'{name}/list_parameters')
                    .result.names)
        missing = [p for p in args.parameter_names if p not in known]
        raise CommandError(f"node '{name}' has no parameter "
                           + ', '.join(f"'{p}'" for p in missing or args.parameter_names))
    for descriptor in descriptors:
        print('\n'.join(describe_lines(descriptor)))
    return 0


def _dump(node, client, name, args) -> int:
    names = sorted(answer(node, client.list_parameters(), f'{name}/list_parameters')
                   .result.names)
    values = answer(node, client.get_parameters(names), f'{name}/get_parameters').values
    document = dump_document(name, {n: python_value(v) for n, v in zip(names, values,
                                                                       strict=True)})
    print(yaml.dump(document, default_flow_style=False))
    return 0


def _load(node, client, name, args) -> int:
    parameters = parameters_from_file(args.parameter_file, name, args.use_wildcard)
    results = answer(node, client.set_parameters(parameters), f'{name}/set_parameters').results
    failed = 0
    for parameter, result in zip(parameters, results, strict=True):
        reason = f': {result.reason}' if result.reason else ''
        if result.successful:
            print(f'Set parameter {parameter.name} successful{reason}')
        else:
            failed += 1
            print(f'Set parameter {parameter.name} failed{reason}', file=sys.stderr)
    return 1 if failed else 0


VERBS = {'get': _get, 'set': _set, 'describe': _describe, 'dump': _dump, 'load': _load}
