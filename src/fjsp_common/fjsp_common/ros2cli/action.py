"""`ros2 action list`, `info` and `send_goal`, in ros2cli's syntax and output."""

import argparse

from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.action.graph import (
    get_action_client_names_and_types_by_node,
    get_action_names_and_types,
    get_action_server_names_and_types_by_node,
)

from .graph import (
    LOOKUP_SPIN_TIME,
    CommandError,
    add_list_verb,
    add_spin_time,
    answer,
    cli_node,
    described,
    full_name,
    print_listing,
    spin_until,
)
from .messages import fill, interface_class, parse_values, to_yaml

STATUS_NAMES = {GoalStatus.STATUS_ACCEPTED: 'ACCEPTED', GoalStatus.STATUS_EXECUTING: 'EXECUTING',
                GoalStatus.STATUS_CANCELING: 'CANCELING', GoalStatus.STATUS_SUCCEEDED: 'SUCCEEDED',
                GoalStatus.STATUS_CANCELED: 'CANCELED', GoalStatus.STATUS_ABORTED: 'ABORTED'}
CANCEL_TIMEOUT = 5.0


def action_users(node, action: str) -> tuple[list, list]:
    """(clients, servers) of `action`: sorted (node full name, types) pairs."""
    clients, servers = [], []
    for name, namespace in node.get_node_names_and_namespaces():
        for found, into in ((get_action_client_names_and_types_by_node, clients),
                            (get_action_server_names_and_types_by_node, servers)):
            for action_name, types in found(node, name, namespace):
                if action_name == action:
                    into.append((full_name(name, namespace), list(types)))
    return sorted(clients), sorted(servers)


def info_lines(action: str, clients: list, servers: list, show_types: bool = False,
               count: bool = False) -> list[str]:
    """`ros2 action info`'s lines."""
    lines = [f'Action: {action}']
    for title, users in (('Action clients', clients), ('Action servers', servers)):
        lines.append(f'{title}: {len(users)}')
        if not count:
            lines += [f"    {name} [{', '.join(types)}]" if show_types else f'    {name}'
                      for name, types in users]
    return lines


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 action',
                                     description='Inspect and use the actions of the graph.')
    verbs = parser.add_subparsers(dest='verb', required=True, metavar='{list,info,send_goal}')
    add_list_verb(verbs, 'actions', '--count-actions')
    info = verbs.add_parser('info', help="print an action's clients and servers")
    info.add_argument('action_name', help='e.g. /run_mission')
    info.add_argument('-t', '--show-types', action='store_true', help='also print their types')
    info.add_argument('-c', '--count', action='store_true',
                      help='print only how many clients and servers there are')
    add_spin_time(info, LOOKUP_SPIN_TIME)
    goal = verbs.add_parser('send_goal', help='send a goal and wait for its result')
    goal.add_argument('action_name', help='e.g. /run_mission')
    goal.add_argument('action_type', help='e.g. fjsp_msgs/action/RunMission')
    goal.add_argument('goal', nargs='?', default='{}',
                      help="the goal's fields in YAML, e.g. \"{scenario_path: a.yaml}\"")
    goal.add_argument('-f', '--feedback', action='store_true', help='print its feedback')
    add_spin_time(goal, LOOKUP_SPIN_TIME)
    args = parser.parse_args(argv)
    if args.verb == 'send_goal':
        action_type = interface_class(args.action_type, 'action')
        request = fill(action_type.Goal(), parse_values(args.goal))
    with cli_node() as node:
        if args.verb == 'list':
            return print_listing(node, args, lambda: get_action_names_and_types(node))
        name = node.resolve_topic_name(args.action_name)
        if args.verb == 'info':
            users = [[], []]

            def seen() -> bool:
                users[:] = action_users(node, name)
                return any(users)

            if not spin_until(node, seen, args.spin_time):
                raise CommandError(f"action '{name}' not found: no client or server of it "
                                   f'(waited {args.spin_time:g} s for discovery)')
            users = described(node, lambda: action_users(node, name), args.spin_time)
            print('\n'.join(info_lines(args.action_name, *users, args.show_types, args.count)))
            return 0
        return _send_goal(node, name, action_type, request, args)


def _send_goal(node, name: str, action_type, goal, args) -> int:
    client = ActionClient(node, action_type, name)
    print('Waiting for an action server to become available...')
    if not client.wait_for_server(timeout_sec=args.spin_time):
        raise CommandError(f"action server '{name}' not available (waited "
                           f'{args.spin_time:g} s for discovery)')
    print(f'Sending goal:\n     {to_yaml(goal)}')

    def feedback(message):
        print(f'Feedback:\n    {to_yaml(message.feedback)}', flush=True)

    handle = answer(node, client.send_goal_async(goal, feedback if args.feedback else None),
                    f"action server '{name}'")
    if not handle.accepted:
        print('Goal was rejected.')
        return 1
    print(f'Goal accepted with ID: {bytes(handle.goal_id.uuid).hex()}\n', flush=True)
    result = handle.get_result_async()
    try:
        while not result.done():
            spin_until(node, result.done, 1.0)
    except KeyboardInterrupt:
        # As ros2cli does: a goal still running when the user stops waiting is cancelled.
        print('Canceling goal...')
        answer(node, handle.cancel_goal_async(), f"action server '{name}'", CANCEL_TIMEOUT)
        print('Goal canceled.')
        return 130
    outcome = result.result()
    print(f'Result:\n    {to_yaml(outcome.result)}')
    print(f'Goal finished with status: {STATUS_NAMES.get(outcome.status, "UNKNOWN")}')
    return 0 if outcome.status == GoalStatus.STATUS_SUCCEEDED else 1
