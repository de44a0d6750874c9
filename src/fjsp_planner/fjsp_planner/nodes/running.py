"""What every node process of the network does alike: refuse a bad parameter with a one-line
reason and exit code 2, and stop quietly on Ctrl-C or an external shutdown."""

from collections.abc import Callable

import rclpy
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


class ParameterError(ValueError):
    """A node parameter with a value the node cannot run with."""


def declared(node: Node, name: str, default):
    """The value of parameter `name`, declared with `default` (which also fixes its type)."""
    try:
        return node.declare_parameter(name, default).value
    except InvalidParameterTypeException as e:
        raise ParameterError(f"parameter '{name}' must be a {type(default).__name__} "
                             f'like {default!r}: {e}') from None


def run_node(make_node: Callable[[], Node], logger: str, args=None,
             spin: Callable[[Node], None] = rclpy.spin) -> int:
    """Build the node, spin it until shutdown, clean up; the process's exit code."""
    rclpy.init(args=args)
    node = None
    code = 0
    try:
        node = make_node()
        spin(node)
    except ParameterError as e:
        rclpy.logging.get_logger(logger).error(str(e))
        code = 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return code
