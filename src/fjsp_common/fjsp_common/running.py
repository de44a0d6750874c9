"""What every node process of the fleet does alike: declare its parameters the ROS way, refuse
a bad one with a one-line reason and exit code 2, and stop quietly on Ctrl-C, SIGTERM or an
external shutdown.

Parameters are declared from their definitions (`fjsp_common.parameters`) with a
`ParameterDescriptor` (description, range, read-only), so `ros2 param describe` documents them
and rclpy itself refuses an out-of-range or read-only `set`, at start-up (`-p`,
`--params-file`) and at run time alike.
"""

import re
import signal
import threading
from collections.abc import Callable

import rclpy
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node

from fjsp_common.parameters import ParameterSpec


class ParameterError(ValueError):
    """A node parameter with a value the node cannot run with."""


def declare(node: Node, spec: ParameterSpec):
    """Declare the parameter `spec` defines and return its value; ParameterError, naming it
    and why, for a value the node cannot run with."""
    descriptor = ParameterDescriptor(description=spec.description, read_only=spec.read_only,
                                     additional_constraints=spec.constraints)
    name, default, low, high = spec.name, spec.default, spec.low, spec.high
    if isinstance(default, float):
        descriptor.floating_point_range = [FloatingPointRange(
            from_value=float(low), to_value=float(high), step=0.0)]
    elif isinstance(default, int) and not isinstance(default, bool):
        descriptor.integer_range = [IntegerRange(from_value=low, to_value=high, step=0)]
    try:
        value = node.declare_parameter(name, default, descriptor).value
    except InvalidParameterTypeException as error:
        raise ParameterError(f"parameter '{name}' must be of type {_kind(default)}, like "
                             f'{default!r} ({spec.description}): {error}') from None
    except InvalidParameterValueException as error:
        # rclpy keeps the refused value only in its message.
        given = re.search(r'value \((.*)\) for parameter', str(error), re.DOTALL)
        why = (f'must be within [{_number(low)}, {_number(high)}]' if low is not None
               else 'was refused')
        raise ParameterError(f"parameter '{name}' {why} ({spec.description}), got "
                             f"{shorten(given.group(1), 80) if given else 'another value'}"
                             ) from None
    if spec.choices and value not in spec.choices:
        raise ParameterError(f"parameter '{name}' must be one of {', '.join(spec.choices)}, "
                             f'got {shorten(value, 80)!r}')
    return value


def _kind(default) -> str:
    return {bool: 'bool', int: 'integer', float: 'double', str: 'string'}.get(
        type(default), type(default).__name__)


def _number(value) -> str:
    return f'{value:g}' if isinstance(value, float) else str(value)


def shorten(text: str, limit: int = 200) -> str:
    """`text` cut to `limit` characters for a log line: a forged 1 MB name must not flood it."""
    return text if len(text) <= limit else f'{text[:limit]}... ({len(text)} characters)'


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def run_node(make_node: Callable[[], Node], logger: str, args=None,
             done: Callable[[Node], bool] = lambda node: False) -> int:
    """Build the node, spin it until Ctrl-C, SIGTERM or `done(node)`, clean up; the process's
    exit code.

    rclpy's own signal handling is off: it shuts the context down under running callbacks
    (an RCLError "context is not valid" when one publishes). While the node is being built, a
    signal interrupts that work at once (a huge scenario stops loading); once it spins, a
    signal only asks the spin loop to stop, between callbacks — raising it from the handler
    could land in a finaliser, where Python swallows it and the node would spin on.
    """
    rclpy.init(args=args, signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    stop = threading.Event()
    for sig in STOP_SIGNALS:
        signal.signal(sig, _interrupt)
    node = executor = None
    code = 0
    try:
        node = make_node()
        for sig in STOP_SIGNALS:
            signal.signal(sig, lambda signum, frame: stop.set())
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stop.is_set() and not done(node) and rclpy.ok():
            executor.spin_once(timeout_sec=SPIN_CHECK)
    except ParameterError as error:
        rclpy.logging.get_logger(logger).error(str(error))
        code = 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        # A second Ctrl-C (or the launcher's SIGINT after a terminal's) must not break the
        # clean-up into a traceback.
        for sig in STOP_SIGNALS:
            signal.signal(sig, signal.SIG_IGN)
        # Left to its finaliser, the executor would destroy its guard conditions at exit,
        # after rclpy: "Exception ignored in Executor.__del__ ... InvalidHandle".
        if executor is not None:
            executor.shutdown()
        if node is not None:
            try:
                node.destroy_node()
            except (KeyboardInterrupt, ExternalShutdownException):
                pass
        rclpy.try_shutdown()
    return code


SPIN_CHECK = 0.1
"""Seconds a spinning node may take to notice a stop request when nothing else wakes it."""


def _interrupt(signum, frame):
    raise KeyboardInterrupt
