"""A stand-in for ros2cli, which is not on PyPI: `ros2_ws/bin/ros2` runs `main`.

The verbs users reach for, with ros2cli's (Jazzy) syntax and output, on rclpy's graph and
service APIs:

- `run`: `ros2 run` and `ros2 pkg executables`, through the ament index;
- `node`: `node list`, `node info`;
- `param`: `param list/get/set/describe/dump/load`, through the parameter services;
- `service`: `service list/type/call`;
- `action`: `action list/info/send_goal`;
- `topic`: `topic list/echo/info/hz/pub`;
- `interface`: `interface show`, from the installed .msg/.srv/.action files;
- `graph` (how a command joins the graph and waits for discovery) and `messages` (types by
  name, messages filled from YAML and printed as YAML) serve them all.

Where ros2cli prints a failure and still exits 0 (a refused `param set`, a rejected goal),
this one exits 1: scripts and tests can rely on the exit code. Every error is one line on
stderr naming what was wrong; Ctrl-C ends a streaming verb (`echo`, `hz`, `pub`) with exit
code 0 and anything else with 130, never with a traceback.
"""

import os
import sys

USAGE = """usage: ros2 <command> [<verb>] ...

  run <package> <executable> [args] [--ros-args ...]
  pkg executables [package]
  node list | info <node>
  param list [node] | get <node> <name> | set <node> <name> <value>
        | describe <node> <name>... | dump <node> | load <node> <file>
  service list [-t] | type <service> | call <service> <type> [values]
  action list [-t] | info <action> | send_goal <action> <type> [values] [--feedback]
  topic list [-t] | echo <topic> [type] [--once] | info <topic> [--verbose]
        | hz <topic> [--duration S] | pub <topic> <type> [values] [--once] [-r rate]
  interface show <type>

`ros2 <command> -h` (or `ros2 <command> <verb> -h`) for the options. A minimal front end:
use a full ROS 2 install for the other commands."""

COMMANDS = ('run', 'pkg', 'node', 'param', 'service', 'action', 'topic', 'interface')


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ('-h', '--help'):
        print(USAGE)
        return 0 if argv else 2
    command, rest = argv[0], argv[1:]
    if command not in COMMANDS:
        print(f"ros2: '{command}' is not provided by this front end (only "
              f"{', '.join(COMMANDS)}; use a full ROS 2 install for the rest)", file=sys.stderr)
        return 2
    if 'AMENT_PREFIX_PATH' not in os.environ:
        print('ros2: AMENT_PREFIX_PATH is not set; source ros2_ws/env.sh first', file=sys.stderr)
        return 1
    from rclpy.exceptions import NameValidationException

    from .graph import CommandError

    verb = f' {rest[0]}' if rest and not rest[0].startswith('-') and command != 'run' else ''
    try:
        return _command(command)(rest)
    except CommandError as error:
        print(f'ros2 {command}{verb}: {error}', file=sys.stderr)
        return 1
    except NameValidationException as error:
        print(f'ros2 {command}{verb}: {str(error).splitlines()[0]}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # The reader went away (`| head`): nothing more to say, and nothing to say it to.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


def _command(name: str):
    if name in ('run', 'pkg'):
        from . import run
        return run.run if name == 'run' else run.pkg
    from importlib import import_module
    return import_module(f'.{name}', __name__).main
