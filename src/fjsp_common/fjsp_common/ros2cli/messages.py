"""Interface types by name, messages filled from YAML and printed as YAML, as ros2cli does
(its `rosidl_runtime_py` is not on PyPI). No graph: everything here is tested without ROS
processes.
"""

import importlib
import math
import re

import yaml
from ament_index_python.resources import has_resource
from rosidl_parser.definition import (
    CHARACTER_TYPES,
    FLOATING_POINT_TYPES,
    OCTET_TYPE,
    AbstractGenericString,
    AbstractNestedType,
    Array,
    BoundedSequence,
    NamespacedType,
)

from fjsp_common.bounded_yaml import YamlError, load_yaml

from .graph import CommandError

KINDS = {'msg': 'message', 'srv': 'service', 'action': 'action'}
# The classes a generated type of each kind has: a message has fields, a service a request
# and a response, an action a goal, a result and feedback.
_MEMBERS = {'msg': ('get_fields_and_field_types',), 'srv': ('Request', 'Response'),
            'action': ('Goal', 'Result', 'Feedback')}
_IDENTIFIER = re.compile(r'[A-Za-z][A-Za-z0-9_]*')


def split_type(type_name: str, kind: str) -> tuple[str, str]:
    """(package, name) of `package/kind/Name`, or of `package/Name` as ros2cli accepts it."""
    parts = type_name.split('/')
    if len(parts) == 2:
        parts.insert(1, kind)
    if len(parts) != 3 or parts[1] != kind or not all(_IDENTIFIER.fullmatch(p) for p in parts):
        raise CommandError(f"'{type_name}' is not a {KINDS[kind]} type name (expected "
                           f'<package>/{kind}/<Name>, e.g. {_EXAMPLES[kind]})')
    return parts[0], parts[2]


_EXAMPLES = {'msg': 'std_msgs/msg/String', 'srv': 'fjsp_msgs/srv/InjectFault',
             'action': 'fjsp_msgs/action/RunMission'}


def interface_class(type_name: str, kind: str):
    """The Python class of a message, service or action type named as ros2cli names it."""
    package, name = split_type(type_name, kind)
    # Only interface packages of the ament index are imported: a type name is user input.
    if not has_resource('packages', package):
        raise CommandError(f"unknown {KINDS[kind]} type '{type_name}' (no package "
                           f"'{package}')")
    try:
        found = getattr(importlib.import_module(f'{package}.{kind}'), name)
    except (ImportError, AttributeError):
        raise CommandError(f"unknown {KINDS[kind]} type '{type_name}' (is its package "
                           'built and sourced?)') from None
    if not all(hasattr(found, member) for member in _MEMBERS[kind]):
        raise CommandError(f"'{type_name}' is not a {KINDS[kind]} type")
    return found


def parse_values(text: str) -> dict:
    """The YAML mapping a user gave for a message, e.g. `{fault: 0, factor: 2.0}`."""
    try:
        values = load_yaml(text)
    except YamlError as error:
        raise CommandError(f'values {text[:200]!r} are not read: {error}') from None
    if values is None:
        return {}
    if not isinstance(values, dict):
        raise CommandError(f"values {text!r} must be a YAML mapping, e.g. '{{field: value}}'")
    return values


def fill(message, values: dict, path: str = ''):
    """Set the fields of `message` from `values` (mappings for nested messages, lists for
    arrays and sequences), each checked against its type as rosidl would with its field
    checks on (generated classes skip them by default); returns `message`."""
    fields = message.get_fields_and_field_types()
    slots = dict(zip(fields, message.SLOT_TYPES, strict=True))
    for name, value in values.items():
        if name not in fields:
            raise CommandError(f"{_type_name(message)} has no field '{path}{name}' (fields: "
                               f"{', '.join(fields) or 'none'})")
        setattr(message, name, _checked(slots[name], value, f'{path}{name}', fields[name]))
    return message


def _checked(slot, value, where: str, shown: str):
    """`value` as field `where` of type `slot` holds it; CommandError if it does not fit."""
    def unfit(why: str = '') -> CommandError:
        return CommandError(f"field '{where}' is a {shown}, which {value!r} is not{why}")

    if isinstance(slot, NamespacedType):
        if not isinstance(value, dict):
            raise unfit(' (give a mapping of its fields)')
        return fill(_class_of(slot)(), value, f'{where}.')
    if isinstance(slot, AbstractNestedType):
        if not isinstance(value, list):
            raise unfit(' (give a list)')
        if isinstance(slot, Array) and len(value) != slot.size:
            raise unfit(f' (it holds exactly {slot.size} values)')
        if isinstance(slot, BoundedSequence) and len(value) > slot.maximum_size:
            raise unfit(f' (it holds at most {slot.maximum_size} values)')
        element = getattr(slot.value_type, 'typename', None) or str(slot.value_type)
        return [_checked(slot.value_type, v, f'{where}[{i}]', element)
                for i, v in enumerate(value)]
    if isinstance(slot, AbstractGenericString):
        if not isinstance(value, str):
            raise unfit()
        if hasattr(slot, 'maximum_size') and len(value) > slot.maximum_size:
            raise unfit(f' (at most {slot.maximum_size} characters)')
        return value
    kind = slot.typename
    if kind == 'boolean':
        if not isinstance(value, bool):
            raise unfit()
        return value
    if kind in FLOATING_POINT_TYPES:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise unfit()
        return float(value)
    if kind in CHARACTER_TYPES:
        if not isinstance(value, str) or len(value) != 1:
            raise unfit()
        return value
    low, high = _integer_range(kind)
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise unfit(f' (a whole number in [{low}, {high}])')
    return bytes([value]) if kind == OCTET_TYPE else value


_INTEGER_BITS = {'int8': 8, 'int16': 16, 'int32': 32, 'int64': 64,
                 'short': 16, 'long': 32, 'long long': 64, 'octet': 8}


def _integer_range(kind: str) -> tuple[int, int]:
    bits = _INTEGER_BITS[kind.removeprefix('unsigned ').removeprefix('u')]
    if kind.startswith('u') or kind == OCTET_TYPE:
        return 0, 2 ** bits - 1
    return -2 ** (bits - 1), 2 ** (bits - 1) - 1


def _class_of(namespaced: NamespacedType):
    return getattr(importlib.import_module('.'.join(namespaced.namespaces)), namespaced.name)


def _type_name(message) -> str:
    module = type(message).__module__.split('.')
    return f'{module[0]}/{module[1]}/{type(message).__name__}'


def plain(value):
    """A message as dicts and lists in field order, as ros2cli prints it."""
    if hasattr(value, 'get_fields_and_field_types'):
        return {field: plain(getattr(value, field))
                for field in value.get_fields_and_field_types()}
    if isinstance(value, bytes):
        return value[0] if len(value) == 1 else list(value)
    if hasattr(value, 'tolist'):
        return value.tolist()
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    return value


def to_yaml(message) -> str:
    """`message` in ros2cli's YAML (block style, fields in order), ending with a newline."""
    data = plain(message)
    if not isinstance(data, dict | list):
        return f'{data}\n'
    return yaml.dump(data, sort_keys=False, allow_unicode=True, width=math.inf,
                     default_flow_style=False)
