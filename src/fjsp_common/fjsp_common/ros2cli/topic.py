"""`ros2 topic`: list, echo, info, hz and pub, with ros2cli's syntax and output.

`echo` subscribes with the reliability, durability and depth the publishers offer, as
ros2cli does, so a late reader still gets latched messages and kept event histories.
"""

import argparse
import math
import time

from rclpy.qos import (
    DurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)

from .graph import (
    LOOKUP_SPIN_TIME,
    CommandError,
    add_list_verb,
    add_spin_time,
    cli_node,
    described,
    find_types,
    print_listing,
    seconds_argument,
    spin_for,
    spin_until,
)
from .messages import fill, interface_class, parse_values, to_yaml

HZ_WINDOW = 10000
HZ_PERIOD = 1.0


class RateWindow:
    """The receiving rate of a topic over the last `size` intervals between messages, as
    `ros2 topic hz` computes it: a line at most once per HZ_PERIOD of message times."""

    def __init__(self, size: int = HZ_WINDOW):
        self.size = size
        self.intervals: list[float] = []
        self.last: float | None = None
        self.reported: float | None = None

    def add(self, now: float) -> None:
        if self.last is not None:
            self.intervals.append(now - self.last)
            del self.intervals[:-self.size]
        self.last = now

    def report(self, force: bool = False) -> str | None:
        """The line for the intervals so far, if a message came a period after the one of
        the last line (or `force`); as ros2cli, the first line comes a period after the first
        interval."""
        if not self.intervals:
            return None
        if not force and (self.reported is None or self.last < self.reported + HZ_PERIOD):
            if self.reported is None:
                self.reported = self.last
            return None
        self.reported = self.last
        return rate_line(self.intervals)


def rate_line(intervals: list[float]) -> str:
    """ros2cli's two lines: the mean rate, then min, max, standard deviation and window."""
    mean = sum(intervals) / len(intervals)
    deviation = math.sqrt(sum((x - mean) ** 2 for x in intervals) / len(intervals))
    rate = 1.0 / mean if mean > 0 else 0.0
    return (f'average rate: {rate:.3f}\n\tmin: {min(intervals):.3f}s max: {max(intervals):.3f}s '
            f'std dev: {deviation:.5f}s window: {len(intervals)}')


def main(argv) -> int:
    parser = argparse.ArgumentParser(prog='ros2 topic',
                                     description='Inspect and publish the topics of the graph.')
    verbs = parser.add_subparsers(dest='verb', required=True,
                                  metavar='{list,echo,info,hz,pub}')
    add_list_verb(verbs, 'topics', '--count-topics', '--include-hidden-topics')
    echo = verbs.add_parser('echo', help='print the messages of a topic')
    echo.add_argument('topic_name', help='e.g. /mission_status')
    echo.add_argument('message_type', nargs='?',
                      help='e.g. fjsp_msgs/msg/MissionStatus (default: as discovered)')
    echo.add_argument('--once', action='store_true', help='print one message and exit')
    echo.add_argument('--field', default='',
                      help='print only this field of each message (e.g. robots, stamp.sec)')
    info = verbs.add_parser('info', help="print a topic's type, publishers and subscribers")
    info.add_argument('topic_name', help='e.g. /plan')
    info.add_argument('-v', '--verbose', action='store_true',
                      help='each publisher and subscription with its node and QoS')
    hz = verbs.add_parser('hz', help='print the rate at which a topic is received')
    hz.add_argument('topic_name', help='e.g. /robot_states')
    hz.add_argument('-w', '--window', type=_positive_int, default=HZ_WINDOW, metavar='N',
                    help=f'intervals to average over (default {HZ_WINDOW})')
    hz.add_argument('--duration', type=_positive_float, metavar='S',
                    help='stop after S seconds (default: run until Ctrl-C)')
    pub = verbs.add_parser('pub', help='publish a message, at a rate or once')
    pub.add_argument('topic_name', help='e.g. /chatter')
    pub.add_argument('message_type', help='e.g. std_msgs/msg/String')
    pub.add_argument('values', nargs='?', default='{}',
                     help="the message's fields in YAML, e.g. \"{data: hello}\" (default: {})")
    pub.add_argument('-r', '--rate', type=_positive_float, default=1.0, metavar='N',
                     help='messages per second (default 1)')
    pub.add_argument('-p', '--print', type=int, default=1, metavar='N', dest='print_nth',
                     help='print only every N-th message (0: none; default 1)')
    times = pub.add_mutually_exclusive_group()
    times.add_argument('-1', '--once', action='store_true', help='publish one message and exit')
    times.add_argument('-t', '--times', type=_positive_int, default=0, metavar='N',
                       help='publish N messages and exit')
    pub.add_argument('-w', '--wait-matching-subscriptions', type=int, metavar='N',
                     help='subscriptions to wait for before publishing (default 1 with --once '
                          'or --times, else 0)')
    pub.add_argument('--keep-alive', type=seconds_argument, default=0.1, metavar='S',
                     help='seconds to stay after the last message, for it to be delivered')
    pub.add_argument('--qos-reliability', choices=('reliable', 'best_effort'),
                     default='reliable')
    pub.add_argument('--qos-durability', choices=('volatile', 'transient_local'),
                     default='volatile')
    pub.add_argument('--qos-depth', type=_positive_int, default=10, metavar='N')
    for verb in (echo, info, hz, pub):
        add_spin_time(verb, LOOKUP_SPIN_TIME)
    args = parser.parse_args(argv)
    if args.verb == 'pub':
        message = fill(interface_class(args.message_type, 'msg')(), parse_values(args.values))
    with cli_node() as node:
        if args.verb == 'list':
            return print_listing(node, args, node.get_topic_names_and_types)
        name = node.resolve_topic_name(args.topic_name)
        if args.verb == 'info':
            return _info(node, name, args)
        try:
            if args.verb == 'pub':
                return _pub(node, name, message, args)
            return {'echo': _echo, 'hz': _hz}[args.verb](node, name, args)
        except KeyboardInterrupt:
            # Ctrl-C is how echo, hz and pub end, whether they got going or not.
            return 0


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0:
        raise argparse.ArgumentTypeError(f'must be a whole number > 0, got {text!r}')
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 < value < math.inf:
        raise argparse.ArgumentTypeError(f'must be a number > 0, got {text!r}')
    return value


def _topic_type(node, name: str, seconds: float) -> str:
    return find_types(node, node.get_topic_names_and_types, name, 'topic', seconds)[0]


def _echo(node, name: str, args) -> int:
    type_name = args.message_type or _topic_type(node, name, args.spin_time)
    message_type = interface_class(type_name, 'msg')
    # The publishers' QoS decides how to subscribe (a latched message reaches only a
    # transient-local reader): wait for one to be discovered.
    spin_until(node, lambda: node.count_publishers(name) > 0, args.spin_time)
    offers = [e.qos_profile for e in node.get_publishers_info_by_topic(name)]
    qos = QoSProfile(depth=max([10] + [q.depth for q in offers]))
    if offers and all(q.reliability == ReliabilityPolicy.RELIABLE for q in offers):
        qos.reliability = ReliabilityPolicy.RELIABLE
    else:
        qos.reliability = ReliabilityPolicy.BEST_EFFORT
    if offers and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offers):
        qos.durability = DurabilityPolicy.TRANSIENT_LOCAL
    fields = [part for part in args.field.split('.') if part]
    _field(message_type(), fields, type_name, args.field)
    received = []

    def show(msg):
        print(to_yaml(_field(msg, fields, type_name, args.field)), end='')
        print('---', flush=True)
        received.append(msg)

    node.create_subscription(message_type, name, show, qos)
    spin_until(node, lambda: args.once and bool(received), math.inf)
    return 0


def _field(message, path: list[str], type_name: str, field: str):
    """The field `path` of `message` (the message itself for an empty path)."""
    value = message
    for part in path:
        if part not in getattr(value, 'get_fields_and_field_types', dict)():
            raise CommandError(f"{type_name} has no field '{field}'")
        value = getattr(value, part)
    return value


def _info(node, name: str, args) -> int:
    type_name = _topic_type(node, name, args.spin_time)
    described(node, lambda: (node.count_publishers(name), node.count_subscribers(name)),
              args.spin_time)
    types = node.get_topic_names_and_types()
    types = dict(types).get(name, [type_name])
    end = '\n\n' if args.verbose else '\n'
    print(f'Type: {types[0] if len(types) == 1 else types}', end=end)
    print(f'Publisher count: {node.count_publishers(name)}', end=end)
    if args.verbose:
        for endpoint in node.get_publishers_info_by_topic(name):
            print(endpoint, end=end)
    print(f'Subscription count: {node.count_subscribers(name)}', end=end)
    if args.verbose:
        for endpoint in node.get_subscriptions_info_by_topic(name):
            print(endpoint, end=end)
    return 0


def _hz(node, name: str, args) -> int:
    message_type = interface_class(_topic_type(node, name, args.spin_time), 'msg')
    window = RateWindow(args.window)
    node.create_subscription(message_type, name, lambda _: window.add(time.monotonic()),
                             qos_profile_sensor_data)
    started, shown = time.monotonic(), False
    while args.duration is None or time.monotonic() - started < args.duration:
        spin_for(node, min(0.1, _left(started, args.duration)))
        line = window.report()
        if line:
            print(line, flush=True)
            shown = True
    if not shown:
        line = window.report(force=True)
        if line is None:
            raise CommandError(f"fewer than two messages on '{name}' in {args.duration:g} s")
        print(line)
    return 0


def _left(started: float, duration: float | None) -> float:
    return math.inf if duration is None else max(0.0, started + duration - time.monotonic())


def _pub(node, name: str, message, args) -> int:
    qos = QoSProfile(depth=args.qos_depth,
                     reliability=ReliabilityPolicy[args.qos_reliability.upper()],
                     durability=DurabilityPolicy[args.qos_durability.upper()])
    publisher = node.create_publisher(type(message), name, qos)
    times = 1 if args.once else args.times
    wanted = args.wait_matching_subscriptions
    if wanted is None:
        wanted = 1 if times else 0
    if publisher.get_subscription_count() < wanted:
        print(f'Waiting for at least {wanted} matching subscription(s)...', flush=True)
        if not spin_until(node, lambda: publisher.get_subscription_count() >= wanted,
                          args.spin_time):
            raise CommandError(f"{publisher.get_subscription_count()} of {wanted} matching "
                               f"subscription(s) on '{name}' after {args.spin_time:g} s "
                               '(-w 0 publishes without waiting)')
    print('publisher: beginning loop', flush=True)
    count, started = 0, time.monotonic()
    while True:
        count += 1
        if args.print_nth and count % args.print_nth == 0:
            print(f'publishing #{count}: {message!r}\n', flush=True)
        publisher.publish(message)
        if times and count >= times:
            break
        time.sleep(max(0.0, started + count / args.rate - time.monotonic()))
    time.sleep(args.keep_alive)
    return 0
