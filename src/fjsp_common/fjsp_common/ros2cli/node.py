"""`ros2 node list` and `ros2 node info`, in ros2cli's output."""

import argparse
import sys

from rclpy.action.graph import (
    get_action_client_names_and_types_by_node,
    get_action_server_names_and_types_by_node,
)

from .graph import (
    LISTING_SPIN_TIME,
    LOOKUP_SPIN_TIME,
    add_spin_time,
    cli_node,
    described,
    discover,
    find_node,
    is_hidden,
    node_names,
    split_node_name,
)

SECTIONS = ('Subscribers', 'Publishers', 'Service Servers', 'Service Clients',
            'Action Servers', 'Action Clients')


def info_lines(name: str, sections: dict) -> list[str]:
    """`ros2 node info`'s lines: the node's name, then each section's `name: types`, one
    per line (an empty section leaves an empty line, as ros2cli prints it)."""
    lines = [name]
    for section in SECTIONS:
        lines.append(f'  {section}:')
        entries = [f'    {n}: {", ".join(types)}' for n, types in sections[section]]
        lines.append('\n'.join(entries))
    return lines


def node_sections(node, name: str, include_hidden: bool = False) -> dict:
    """What node `name` publishes, subscribes to, serves and calls: section -> sorted
    (name, types) pairs."""
    base, namespace = split_node_name(name)
    lookups = {
        'Subscribers': node.get_subscriber_names_and_types_by_node,
        'Publishers': node.get_publisher_names_and_types_by_node,
        'Service Servers': node.get_service_names_and_types_by_node,
        'Service Clients': node.get_client_names_and_types_by_node,
        'Action Servers': lambda b, n: get_action_server_names_and_types_by_node(node, b, n),
        'Action Clients': lambda b, n: get_action_client_names_and_types_by_node(node, b, n),
    }
    return {section: sorted((n, list(types)) for n, types in lookup(base, namespace)
                            if include_hidden or not is_hidden(n))
            for section, lookup in lookups.items()}


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 node', description='Inspect the nodes of the '
                                     'ROS graph.')
    verbs = parser.add_subparsers(dest='verb', required=True, metavar='{list,info}')
    listing = verbs.add_parser('list', help='print the nodes of the graph')
    listing.add_argument('-a', '--all', action='store_true', help='hidden nodes too')
    listing.add_argument('-c', '--count-nodes', action='store_true',
                         help='print only how many nodes there are')
    add_spin_time(listing, LISTING_SPIN_TIME)
    info = verbs.add_parser('info', help="print a node's topics, services and actions")
    info.add_argument('node_name', help='e.g. /planner')
    info.add_argument('--include-hidden', action='store_true',
                      help='hidden topics, services and actions too')
    add_spin_time(info, LOOKUP_SPIN_TIME)
    args = parser.parse_args(argv)
    with cli_node() as node:
        if args.verb == 'list':
            names = discover(node, lambda: node_names(node, include_hidden=args.all),
                             args.spin_time)
            if args.count_nodes:
                print(len(names))
                return 0
            if len(set(names)) < len(names):
                print('WARNING: Be aware that there are nodes in the graph that share an exact '
                      'name, which can have unintended side effects.', file=sys.stderr)
            for name in names:
                print(name)
            return 0
        name = find_node(node, args.node_name, args.spin_time)
        described(node, lambda: node_sections(node, name, include_hidden=True), args.spin_time)
        print('\n'.join(info_lines(name, node_sections(node, name, args.include_hidden))))
        return 0
