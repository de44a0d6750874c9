"""`ros2 service list`, `type` and `call`, in ros2cli's syntax and output."""

import argparse

from .graph import (
    LISTING_SPIN_TIME,
    LOOKUP_SPIN_TIME,
    CommandError,
    add_spin_time,
    answer,
    cli_node,
    discover,
    find_types,
    is_hidden,
)
from .messages import fill, interface_class, parse_values


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 service',
                                     description='Inspect and call the services of the graph.')
    verbs = parser.add_subparsers(dest='verb', required=True, metavar='{list,type,call}')
    listing = verbs.add_parser('list', help='print the services of the graph')
    listing.add_argument('-t', '--show-types', action='store_true',
                         help="also print each service's type")
    listing.add_argument('-a', '--include-hidden-services', action='store_true',
                         help='hidden services too')
    add_spin_time(listing, LISTING_SPIN_TIME)
    kind = verbs.add_parser('type', help="print a service's type")
    kind.add_argument('service_name', help='e.g. /cancel_mission')
    add_spin_time(kind, LOOKUP_SPIN_TIME)
    call = verbs.add_parser('call', help='call a service and print its response')
    call.add_argument('service_name', help='e.g. /MARC1/inject_fault')
    call.add_argument('service_type', help='e.g. fjsp_msgs/srv/InjectFault')
    call.add_argument('values', nargs='?', default='{}',
                      help="the request's fields in YAML, e.g. '{fault: 0}' (default: {})")
    call.add_argument('--timeout', type=float, default=30.0, metavar='S',
                      help='seconds to wait for the response (default 30)')
    add_spin_time(call, LOOKUP_SPIN_TIME)
    args = parser.parse_args(argv)
    if args.verb == 'call':
        # Everything the user typed is checked before joining the graph.
        service_type = interface_class(args.service_type, 'srv')
        request = fill(service_type.Request(), parse_values(args.values))
    with cli_node() as node:
        if args.verb == 'list':
            for name, types in discover(
                    node, lambda: sorted(node.get_service_names_and_types()), args.spin_time):
                if args.include_hidden_services or not is_hidden(name):
                    print(f"{name} [{', '.join(types)}]" if args.show_types else name)
            return 0
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
