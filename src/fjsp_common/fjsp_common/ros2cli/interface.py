"""`ros2 interface show`: the text of a .msg, .srv or .action file as installed, each nested
message type expanded under its field, indented by a tab, as ros2cli prints it."""

import argparse
from pathlib import Path

from rosidl_adapter.parser import (
    ACTION_REQUEST_RESPONSE_SEPARATOR,
    SERVICE_REQUEST_RESPONSE_SEPARATOR,
    InvalidResourceName,
    Type,
)

from .graph import CommandError
from .messages import KINDS

SEPARATORS = {SERVICE_REQUEST_RESPONSE_SEPARATOR, ACTION_REQUEST_RESPONSE_SEPARATOR}


def share_directory(package: str) -> Path:
    from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

    try:
        return Path(get_package_share_directory(package))
    except (PackageNotFoundError, LookupError, ValueError):
        raise CommandError(f"package '{package}' not found") from None


def interface_lines(type_name: str, *, comments: bool = True, nested_comments: bool = False,
                    locate=share_directory, depth: int = 0) -> list[str]:
    """The lines `ros2 interface show` prints for `type_name` (`package/kind/Name`): the file
    as written (without comments or blank lines unless `comments`), each field of a message
    type followed by that type's lines one tab further in (with comments only if
    `nested_comments`)."""
    parts = type_name.split('/')
    if len(parts) != 3 or parts[1] not in KINDS or not all(parts):
        raise CommandError(f"'{type_name}' is not an interface type name (expected "
                           '<package>/<msg|srv|action>/<Name>, e.g. fjsp_msgs/msg/Plan)')
    package, kind, name = parts
    path = locate(package) / kind / f'{name}.{kind}'
    try:
        text = path.read_text()
    except OSError:
        raise CommandError(f"unknown interface '{type_name}' (no {kind}/{name}.{kind} in "
                           f"package '{package}')") from None
    lines = []
    for raw in text.splitlines():
        raw = raw.rstrip()
        shown, nested = _line(package, raw, comments)
        if shown is not None:
            lines.append('\t' * depth + shown)
        if nested:
            lines.extend(interface_lines(nested, comments=nested_comments,
                                         nested_comments=nested_comments, locate=locate,
                                         depth=depth + 1))
    return lines


def _line(package: str, raw: str, comments: bool) -> tuple[str | None, str | None]:
    """(the line as shown, or None when left out; the message type it nests, if any)."""
    if raw in SEPARATORS:
        return raw, None
    # As rosidl reads the file: a comment runs from the first '#' to the end of the line.
    definition = raw.split('#', 1)[0].rstrip()
    if not comments:
        if not definition:
            return None, None
        raw = definition
    if not definition:
        return raw, None
    try:
        field_type = Type(definition.split()[0], context_package_name=package)
    except InvalidResourceName as error:
        raise CommandError(f'{package}: cannot read line {raw!r}: {error}') from None
    if field_type.is_primitive_type():
        return raw, None
    return raw, f'{field_type.pkg_name}/msg/{field_type.type}'


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 interface',
                                     description='Show the definition of an interface type.')
    verbs = parser.add_subparsers(dest='verb', required=True, metavar='{show}')
    show = verbs.add_parser('show', help='print the definition of a msg, srv or action type')
    show.add_argument('type', help='e.g. fjsp_msgs/msg/Plan, fjsp_msgs/action/RunMission')
    group = show.add_mutually_exclusive_group()
    group.add_argument('--all-comments', action='store_true',
                       help='show the comments of nested types too')
    group.add_argument('--no-comments', action='store_true',
                       help='show no comments or blank lines')
    args = parser.parse_args(argv)
    for line in interface_lines(args.type, comments=not args.no_comments,
                                nested_comments=args.all_comments):
        print(line)
    return 0
