"""Inject off-nominal events into a running mission: make a robot fail, recover, or run slower.

Each robot agent serves `<robot>/inject_fault` (`fjsp_msgs/srv/InjectFault`). From a test
script:

    from fjsp_planner.faults import FaultError, inject_fault

    inject_fault('MARC1', 'fail')          # abort what it does, stop where it is
    inject_fault('LSMS', 'delay', 2.0)     # its current (or next) operation takes twice as long
    inject_fault('MARC1', 'recover')       # back in service where it stopped

and from a shell:

    ros2 run fjsp_planner inject_fault MARC1 delay --factor 2 [--timeout 5]

`inject_fault` returns the agent's answer, or raises `FaultError` with a message saying what
went wrong (bad arguments, nobody answering, or the agent's refusal). ROS is imported only
when a call is made, so arguments can be checked without a built workspace.
"""

import argparse
import itertools
import math
import os
import sys
import time
import uuid
from contextlib import contextmanager

from fjsp_common.vocabulary import MAX_DELAY_FACTOR, MIN_DELAY_FACTOR

FAULTS = ('fail', 'recover', 'delay')
RESEND = 1.0
"""Seconds without an answer after which a fault request is sent again."""
# The agent refuses beyond these, also for the product of several delays on one operation:
# refused here before anything is sent.
BOUNDS = f'within [{MIN_DELAY_FACTOR:g}, {MAX_DELAY_FACTOR:g}]'


class FaultError(ValueError):
    """A fault that was not injected: bad arguments, no agent answering, or refused."""


def check_fault(fault: str, factor: float | None) -> float:
    """The factor to send for `fault` (0 when it takes none); FaultError if they do not fit."""
    if fault not in FAULTS:
        raise FaultError(f'unknown fault {fault!r}: expected one of {", ".join(FAULTS)}')
    if fault != 'delay':
        if factor is not None:
            raise FaultError(f"fault '{fault}' takes no factor (got {factor!r}); only "
                             "'delay' does")
        return 0.0
    if factor is None:
        raise FaultError(f"fault 'delay' needs a factor {BOUNDS} (e.g. 2 to double "
                         'durations)')
    try:
        factor = float(factor)
    except (TypeError, ValueError):
        raise FaultError(f"fault 'delay': factor must be a number, got {factor!r}") from None
    if not (math.isfinite(factor) and factor > 0):
        raise FaultError(f"fault 'delay': factor must be a finite number > 0, got {factor:g}")
    if not MIN_DELAY_FACTOR <= factor <= MAX_DELAY_FACTOR:
        raise FaultError(f"fault 'delay': factor must be {BOUNDS}, got {factor:g}")
    return factor


def inject_fault(robot: str, fault: str, factor: float | None = None, *, node=None,
                 timeout: float = 5.0, key_file=None) -> str:
    """Inject `fault` ('fail', 'recover' or 'delay' with `factor`) into `robot`'s agent.

    Returns the agent's message. Waits up to `timeout` seconds for the agent's service to
    appear and as long again for its answer. The call is made by a short-lived node of its
    own, spun here by an executor of its own:

    - without `node`, in a private rclpy context, so it works whether or not the caller has
      called `rclpy.init`, and never touches the caller's context. Its process joins the
      DDS domain afresh and first waits for discovery, up to about 3 s with Fast DDS on
      localhost;
    - with `node` (any rclpy node that has been running a while), in that node's context
      and namespace: the context has discovered the fleet already, so the answer comes in
      milliseconds; pass one when the fault must land at a precise moment. `node` itself is
      neither spun nor added to an executor, so this works however the caller spins it (an
      executor on another thread, by hand in this thread, not at all) and even from inside
      one of its callbacks.

    Both honour ROS_DOMAIN_ID and the other ROS environment variables. In a fleet with a
    key, the request is signed with the key in `key_file` (default: the file named by
    $FJSP_FLEET_KEY_FILE).
    """
    factor = check_fault(fault, factor)
    if not (isinstance(timeout, int | float) and math.isfinite(timeout) and timeout > 0):
        raise FaultError(f'timeout must be a number of seconds > 0, got {timeout!r}')
    if node is not None:
        with _helper_node(node.context, node.get_namespace()) as helper:
            return _call(helper, robot, fault, factor, timeout, key_file)
    with _own_node(args=[]) as own:
        return _call(own, robot, fault, factor, timeout, key_file)


@contextmanager
def _own_node(args):
    """A node in a private context, whatever the caller did with rclpy's default one."""
    import rclpy

    context = rclpy.Context()
    try:
        rclpy.init(args=args, context=context)
    except RuntimeError as error:  # rclpy's RCLError, e.g. for a bad ROS_DOMAIN_ID
        raise FaultError(f'could not start ROS: {error}') from None
    try:
        node = rclpy.create_node(f'inject_fault_{os.getpid()}', context=context)
        try:
            yield node
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


_helpers = itertools.count()


@contextmanager
def _helper_node(context, namespace=None):
    """A node of this call only. Borrowing the caller's node instead would mean spinning it:
    adding it to an executor of ours takes it away from the caller's executor (rclpy keeps
    one executor per node), and waiting for the caller's executor to take the answer hangs
    until the timeout when that executor is not spinning at the moment."""
    import rclpy

    node = rclpy.create_node(f'inject_fault_{os.getpid()}_{next(_helpers)}', context=context,
                             namespace=namespace, enable_rosout=False,
                             start_parameter_services=False)
    try:
        yield node
    finally:
        node.destroy_node()


def _call(node, robot, fault, factor, timeout, key_file) -> str:
    from rclpy.exceptions import InvalidServiceNameException

    from fjsp_common.auth import FleetKeyError, client_signer
    from fjsp_common.contract import INJECT_FAULT_SERVICE
    from fjsp_msgs.srv import InjectFault

    try:
        client = node.create_client(InjectFault, f'{robot}/{INJECT_FAULT_SERVICE}')
    except InvalidServiceNameException:
        raise FaultError(f'{robot!r} is not a robot name (letters, digits and underscores, '
                         'not starting with a digit)') from None
    try:
        name = node.resolve_service_name(client.srv_name)
        if not client.wait_for_service(timeout_sec=timeout):
            raise FaultError(f"no agent serves '{name}' (waited {timeout:g} s): is the robot's "
                             'agent running, with the same ROS_DOMAIN_ID?')
        request = InjectFault.Request(
            fault=getattr(InjectFault.Request, f'FAULT_{fault.upper()}'), factor=factor)
        try:
            signer = client_signer(key_file, f'inject_fault/{node.get_name()}')
        except FleetKeyError as error:
            raise FaultError(str(error)) from None
        request.request_id = f'{node.get_name()}/{uuid.uuid4().hex}'
        response = _answer(node, client, request, signer, name, timeout)
        if response is None:
            raise FaultError(f"'{name}' did not answer within {timeout:g} s")
    finally:
        node.destroy_client(client)
    if not response.success:
        raise FaultError(response.message)
    return response.message


def _answer(node, client, request, signer, name, timeout):
    """The agent's answer, or None after `timeout`. A fresh client's first answer can be lost
    (the agent may answer before it has discovered where to), so the request is resent every
    RESEND seconds; its id makes the agent answer a resent request without applying it again.
    """
    deadline = time.monotonic() + timeout
    while True:
        signer.sign(request, name)
        future = client.call_async(request)
        left = deadline - time.monotonic()
        if _wait(node, future, min(RESEND, max(left, 0.0))):
            return future.result()
        client.remove_pending_request(future)
        if time.monotonic() >= deadline:
            return None


def _wait(node, future, timeout) -> bool:
    """Spin our own `node` until the answer comes or `timeout` passes; whether it came."""
    from rclpy.executors import SingleThreadedExecutor

    executor = SingleThreadedExecutor(context=node.context)
    try:
        executor.add_node(node)
        executor.spin_until_future_complete(future, timeout_sec=timeout)
    finally:
        executor.shutdown()
    return future.done()


def main(argv=None) -> int:
    """`inject_fault ROBOT fail|recover|delay [--factor F] [--timeout S] [--ros-args ...]`:
    exit 0 when the agent accepted, 1 when it refused or nobody answered, 2 for bad
    arguments."""
    from rclpy.utilities import remove_ros_args

    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(
        prog='inject_fault',
        description="Make a robot agent fail, recover, or run slower (its "
                    "'<robot>/inject_fault' service).")
    parser.add_argument('robot', help='robot name, e.g. MARC1')
    parser.add_argument('fault', choices=FAULTS)
    parser.add_argument('--factor', type=float,
                        help="delay only: multiply the current (or next) operation's "
                             f'duration by F ({BOUNDS})')
    parser.add_argument('--key-file', metavar='FILE',
                        help='fleet key to sign the request with (default: '
                             '$FJSP_FLEET_KEY_FILE; none: unsigned)')
    parser.add_argument('--timeout', type=float, default=5.0, metavar='S',
                        help='seconds to wait for the agent to appear, and then to answer '
                             '(default 5)')
    try:
        own_args = remove_ros_args(['inject_fault', *argv])[1:]
    except RuntimeError as error:  # rclpy's RCLInvalidROSArgsError
        parser.error(f'bad ROS arguments: {error}')
    args = parser.parse_args(own_args)
    if not (math.isfinite(args.timeout) and args.timeout > 0):
        parser.error(f'--timeout must be a number of seconds > 0, got {args.timeout:g}')
    try:
        factor = check_fault(args.fault, args.factor)
    except FaultError as error:
        parser.error(str(error))
    try:
        # rclpy reads the --ros-args part (remappings, log level, ...) itself.
        with _own_node(['inject_fault', *argv]) as node:
            print(_call(node, args.robot, args.fault, factor, args.timeout, args.key_file))
    except FaultError as error:
        print(f'inject_fault: {error}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == '__main__':
    sys.exit(main())
