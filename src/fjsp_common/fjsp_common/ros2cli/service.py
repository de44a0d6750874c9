"""`ros2 service list`, `type` and `call`, in ros2cli's syntax and output."""

import argparse

from .graph import (
    LOOKUP_SPIN_TIME,
    CommandError,
    add_list_verb,
    add_spin_time,
    answer,
    cli_node,
    find_types,
    print_listing,
    seconds_argument,
)
from .messages import fill, interface_class, parse_values


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 service',
                                     description='Inspect and call the services of the graph.')
    verbs = parser.add_subparsers(dest='verb', required=True, metavar='{list,type,call}')
    add_list_verb(verbs, 'services', '--count-services', '--include-hidden-services')
    kind = verbs.add_parser('type', help="print a service's type")
    kind.add_argument('service_name', help='e.g. /cancel_mission')
    add_spin_time(kind, LOOKUP_SPIN_TIME)
    call = verbs.add_parser('call', help='call a service and print its response')
    call.add_argument('service_name', help='e.g. /MARC1/inject_fault')
    call.add_argument('service_type', help='e.g. fjsp_msgs/srv/InjectFault')
    call.add_argument('values', nargs='?', default='{}',
                      help="the request's fields in YAML, e.g. '{fault: 0}' (default: {})")
    call.add_argument('--timeout', type=seconds_argument, default=30.0, metavar='S',
                      help='seconds to wait for the response (default 30)')
    add_spin_time(call, LOOKUP_SPIN_TIME)
    args = parser.parse_args(argv)
    if args.verb == 'call':
        # Everything the user typed is checked before joining the graph.
        service_type = interface_class(args.service_type, 'srv')
        request = fill(service_type.Request(), parse_values(args.values))
    with cli_node() as node:
        if args.verb == 'list':
            return print_listing(node, args, node.get_service_names_and_types)
        name = node.resolve_service_name(args.service_name)
        if args.verb == 'type':
            for service_type_name in find_types(node, node.get_service_names_and_types, name,
                                                'service', args.spin_time):
                print(service_type_name)
            return 0
        client = node.create_client(service_type, name)
        if not client.service_is_ready():
            print('waiting for service to become available...')
            if not client.wait_for_service(timeout_sec=args.spin_time):
                raise CommandError(f"service '{name}' not available (waited "
                                   f'{args.spin_time:g} s for discovery)')
        print(f'requester: making request: {request!r}\n')
        response = answer(node, client.call_async(request), f"service '{name}'", args.timeout)
        print(f'response:\n{response!r}\n')
        return 0
