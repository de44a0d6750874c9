"""ROS parameters files as the launcher reads and writes them: a user's file is checked and
searched for what it sets; each node gets a file of its own with the launcher's values, passed
after the user's so that they win."""

import re
from pathlib import Path

import yaml

from fjsp_planner.model.limits import load_yaml, read_input_file
from fjsp_planner.model.problem import ProblemError


def read_params_file(path: Path) -> tuple[dict, list[str]]:
    """The parameters file's sections, and what makes it unusable (empty if nothing)."""
    try:
        data = load_yaml(read_input_file(path, 'parameters'))
    except ProblemError as error:
        return {}, [p if p.startswith(f'{path}:') else f'{path}: {p}' for p in error.problems]
    if not isinstance(data, dict) or not list(_sections(data)):
        return {}, [f'{path}: not a ROS parameters file (expected sections like '
                    "'/**: {ros__parameters: {...}}' or '<node name>: {ros__parameters: ...}')"]
    return data, []


def _sections(data: dict, namespace=()):
    """(node name pattern tokens, parameters) of each `ros__parameters` section."""
    for key, value in data.items():
        if key == 'ros__parameters' and isinstance(value, dict):
            yield namespace, value
        elif isinstance(value, dict):
            yield from _sections(value, namespace + tuple(t for t in str(key).split('/') if t))


def sets_parameter(params: dict, node: str, name: str) -> bool:
    """Whether a parameters file (as read) gives node `/<node>` a value for `name`; `*` and
    `**` match one and any number of name tokens, as rcl matches them."""
    for tokens, values in _sections(params):
        pattern = ''.join('(?:/[^/]+)*' if t == '**' else '/[^/]+' if t == '*'
                          else '/' + re.escape(t) for t in tokens)
        if name in values and re.fullmatch(pattern, f'/{node}'):
            return True
    return False


def ros_string(text: str) -> str:
    """`text` as a `-p name:=value` value: rcl reads values as YAML, so it is quoted (a robot
    named `on` or `1e3` stays a string)."""
    return "'" + text.replace("'", "''") + "'"


def write_node_params(path: Path, node: str, params: dict) -> None:
    """A parameters file giving `params` to node `/<node>` alone. Passed after the user's
    file, it wins over it: rclpy applies a node's own section after the `/**` one, and of two
    files the later one (`-p` values count as `/**`, so they would lose to a user's
    node section)."""
    values = {k: str(v) if isinstance(v, Path) else v for k, v in params.items()}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump({f'/{node}': {'ros__parameters': values}},
                                   sort_keys=False))
