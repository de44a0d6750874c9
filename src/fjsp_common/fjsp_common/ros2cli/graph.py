"""Joining the ROS graph for one command, as ros2cli does without its daemon.

A command makes one hidden node (`_ros2cli_<pid>`, left out of every listing), waits for
discovery, does its work and leaves. Discovery between fresh processes takes up to about 3 s
with Fast DDS on a loaded machine, and finds a fleet piecemeal (a node before its endpoints, one
node's endpoints seconds after another's), so every wait is bounded by the command's
`--spin-time`: a listing cannot know when the graph is complete and waits all of it, then as
long again at most while the graph still changes; a command about one node, topic, service or
action waits until that one is seen, then as a listing would for its details.
"""

import argparse
import os
import time
from collections.abc import Callable
from contextlib import contextmanager

import rclpy
from rclpy.signals import SignalHandlerOptions
from rclpy.topic_or_service_is_hidden import topic_or_service_is_hidden

LISTING_SPIN_TIME = 3.0
LOOKUP_SPIN_TIME = 5.0
SETTLE_SECONDS = 1.0
ANSWER_TIMEOUT = 10.0


class CommandError(Exception):
    """What stops a command: one line for the user that names what was wrong."""


def add_list_verb(verbs, things: str, count_option: str, hidden_option: str | None = None):
    """`<command> list` as ros2cli has it for topics, services and actions: -t for the
    types, -c for how many, -a for hidden ones too (where they can be hidden)."""
    listing = verbs.add_parser('list', help=f'print the {things} of the graph')
    listing.add_argument('-t', '--show-types', action='store_true',
                         help="also print each one's type")
    listing.add_argument('-c', count_option, dest='count', action='store_true',
                         help=f'print only how many {things} there are')
    if hidden_option:
        listing.add_argument('-a', hidden_option, dest='include_hidden', action='store_true',
                             help=f'hidden {things} too')
    else:
        listing.set_defaults(include_hidden=True)
    add_spin_time(listing, LISTING_SPIN_TIME)
    return listing


def print_listing(node, args, names_and_types: Callable[[], list]) -> int:
    """What a `list` verb prints: each name (with its types, `-t`), or how many (`-c`)."""
    entries = [(name, types) for name, types in discover(
        node, lambda: sorted(names_and_types()), args.spin_time)
        if args.include_hidden or not is_hidden(name)]
    if args.count:
        print(len(entries))
    for name, types in [] if args.count else entries:
        print(f"{name} [{', '.join(types)}]" if args.show_types else name)
    return 0


def add_spin_time(parser, default: float) -> None:
    what = ('seconds to wait for discovery' if default == LISTING_SPIN_TIME
            else 'seconds to wait at most for it to be discovered')
    parser.add_argument('--spin-time', type=seconds_argument, default=default, metavar='S',
                        help=f'{what} (default {default:g})')


def seconds_argument(text: str) -> float:
    """argparse's type for a number of seconds: finite and >= 0."""
    try:
        value = float(text)
    except ValueError:
        value = float('nan')
    if not 0 <= value < float('inf'):
        raise argparse.ArgumentTypeError(f'must be a number of seconds >= 0, got {text!r}')
    return value


@contextmanager
def cli_node():
    """A hidden node of this process in a context of its own. Ctrl-C stays a Python
    KeyboardInterrupt (rclpy's own handler would turn it into a shutdown mid-wait)."""
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(f'_ros2cli_{os.getpid()}', start_parameter_services=False)
    node.joined_at = time.monotonic()
    try:
        yield node
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def spin_until(node, holds: Callable[[], bool], seconds: float) -> bool:
    """Spin `node` until `holds()` or `seconds` passed; whether it holds."""
    deadline = time.monotonic() + seconds
    while not holds():
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        rclpy.spin_once(node, timeout_sec=min(0.1, left))
    return True


def spin_for(node, seconds: float) -> None:
    spin_until(node, lambda: False, seconds)


def settled(node, snapshot: Callable[[], object], at_least: float, at_most: float):
    """`snapshot()` (what the command lists or describes) once this process has been in the
    graph `at_least` seconds and it has not changed for SETTLE_SECONDS, or once it has been
    there `at_most` seconds: a loaded machine discovers a fleet piecemeal, a node before its
    endpoints."""
    start = node.joined_at
    last, since = snapshot(), time.monotonic()
    while True:
        now = time.monotonic()
        if now - start >= at_most or (now - start >= at_least and now - since >= SETTLE_SECONDS):
            return last
        rclpy.spin_once(node, timeout_sec=0.1)
        current = snapshot()
        if current != last:
            last, since = current, time.monotonic()


def discover(node, snapshot: Callable[[], object], seconds: float):
    """What a listing shows: `snapshot()` after `seconds` of discovery, and then as long
    again at most for the graph to stop changing."""
    return settled(node, snapshot, seconds, 2 * seconds)


def described(node, snapshot: Callable[[], object], seconds: float):
    """What a command about one node, topic or action shows, once that one was found:
    `snapshot()` settled as a listing's would be, within the command's `seconds`."""
    return settled(node, snapshot, min(LISTING_SPIN_TIME, seconds), seconds)


def answer(node, future, what: str, seconds: float = ANSWER_TIMEOUT):
    """The result of `future`, spinning `node` for it at most `seconds`."""
    rclpy.spin_until_future_complete(node, future, timeout_sec=seconds)
    if not future.done():
        future.cancel()
        raise CommandError(f'{what} did not answer within {seconds:g} s')
    if future.exception() is not None:
        raise CommandError(f'{what} failed: {future.exception()}')
    return future.result()


is_hidden = topic_or_service_is_hidden


def full_name(name: str, namespace: str) -> str:
    return namespace + ('' if namespace.endswith('/') else '/') + name


def absolute(name: str) -> str:
    return name if name.startswith('/') else '/' + name


def node_names(node, include_hidden: bool = False) -> list[str]:
    """Full names of the graph's nodes, sorted; a name twice if two nodes share it."""
    return sorted(full_name(name, namespace)
                  for name, namespace in node.get_node_names_and_namespaces()
                  if include_hidden or not is_hidden(name))


def find_node(node, name: str, seconds: float) -> str:
    """The full name of node `name` once discovered; CommandError if it is not within
    `seconds`."""
    wanted = absolute(name)
    if not spin_until(node, lambda: wanted in node_names(node, include_hidden=True), seconds):
        raise CommandError(f"node '{wanted}' not found (waited {seconds:g} s for discovery)")
    return wanted


def find_types(node, listing: Callable[[], list], name: str, what: str,
               seconds: float) -> list[str]:
    """The types of topic or service `name` (`what`) once `listing()` (name-types pairs) has
    it; CommandError if it does not within `seconds`."""
    found = {}

    def seen() -> bool:
        found.update(listing())
        return name in found

    if not spin_until(node, seen, seconds):
        raise CommandError(f"{what} '{name}' not found (waited {seconds:g} s for discovery)")
    return list(found[name])


def split_node_name(name: str) -> tuple[str, str]:
    """(name, namespace) of a full node name."""
    namespace, _, base = absolute(name).rpartition('/')
    return base, namespace or '/'
