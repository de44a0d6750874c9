"""YAML read within bounds: nesting, alias expansion and self-containing aliases are refused
with the limit and the place, before a recursive parser could crash the process; everything
within the bounds reads as PyYAML reads it."""

import pytest
import yaml

from fjsp_common.bounded_yaml import MAX_NESTING, MAX_YAML_VALUES
from fjsp_planner.model.extension import extend
from fjsp_planner.model.limits import load_yaml
from fjsp_planner.model.problem import ProblemError
from fjsp_planner.model.scenario import ScenarioError, load_scenario, scenario_from_text

from repo_paths import PAPER


def nested_block(levels: int) -> str:
    """`levels` mappings inside one another, one per line, each indented one more."""
    return ''.join(f"{' ' * i}k{i}:\n" for i in range(levels)) + f"{' ' * levels}end\n"


def problems(text: str) -> list[str]:
    with pytest.raises(ProblemError) as caught:
        load_yaml(text)
    return caught.value.problems


@pytest.mark.parametrize(('text', 'message'), [
    ('[' * 30000 + ']' * 30000, 'YAML nesting deeper than 64 levels at line 1, column 65'),
    ('a: ' + '{b: ' * 100 + '1' + '}' * 100,
     'YAML nesting deeper than 64 levels at line 1, column 256'),
    (nested_block(100), 'YAML nesting deeper than 64 levels at line 65, column 65'),
    ('- ' * 5000 + 'x', 'YAML nesting deeper than 64 levels at line 1, column 129'),
    ('deep: &deep ' + '[' * 40 + ']' * 40 + '\nuse: ' + '[' * 40 + '*deep' + ']' * 40,
     'YAML nesting deeper than 64 levels (through alias *deep) at line 2, column 46'),
    ('loop: &loop [1, *loop]', 'YAML alias *loop at line 1, column 17 is inside what it '
                               'names: a structure cannot contain itself'),
    ('a: &a [x, x, x, x, x, x, x, x, x, x]\n'
     + ''.join(f'{chr(98 + i)}: &{chr(98 + i)} [' + ', '.join([f'*{chr(97 + i)}'] * 10)
               + ']\n' for i in range(7)),
     f'YAML of more than {MAX_YAML_VALUES} values (aliases counted as what they name) at '
     'line 7'),
    ('a: [1, 2', 'YAML syntax error at line 2, column 1'),
], ids=['brackets 30000 deep', 'braces 100 deep', 'indentation 100 deep', 'dashes 5000 deep',
        'alias nested in nesting', 'alias inside itself', 'alias bomb', 'syntax error'])
def test_unbounded_yaml_is_refused_naming_the_limit_and_the_place(text, message):
    found = problems(text)
    assert any(message in p for p in found), found


def test_a_text_at_the_limits_reads_as_pyyaml_reads_it():
    deepest = '[' * MAX_NESTING + '1' + ']' * MAX_NESTING
    assert load_yaml(deepest) == yaml.safe_load(deepest)
    text = ('robot: &r {type: Arm, speed: 3}\nrobots: [*r, *r]\nnested: &n [[1, [2]]]\n'
            'more: [*n, *n]\nwhen: 2024-01-01\n')
    assert load_yaml(text) == yaml.safe_load(text)
    assert load_yaml('') is None


def test_a_text_larger_than_the_limit_is_refused_before_it_is_parsed():
    assert load_yaml('x' * 101) == 'x' * 101
    with pytest.raises(ProblemError, match='the YAML text has 101 bytes; at most 100 are '
                                           'read'):
        load_yaml('x' * 101, max_bytes=100)


def test_a_deeply_nested_scenario_file_is_refused_not_a_crash(tmp_path):
    """60 KB of brackets: the C loader overflowed the C stack and killed the process."""
    path = tmp_path / 'deep.yaml'
    path.write_text('[' * 30000 + ']' * 30000)
    with pytest.raises(ScenarioError, match='deep.yaml: YAML nesting deeper than 64 levels '
                                            'at line 1, column 65'):
        load_scenario(path)
    with pytest.raises(ScenarioError, match='YAML nesting deeper than 64 levels'):
        scenario_from_text('jobs: ' + '[' * 30000 + ']' * 30000)


def test_a_deeply_nested_fragment_is_refused_not_a_recursion_error():
    """4 KB, 2000 levels: the Python loader raised RecursionError, which killed the planner
    when sent with `mission add`."""
    problem = load_scenario(PAPER)
    with pytest.raises(ProblemError) as caught:
        extend(problem, 'jobs: ' + '[' * 2000 + ']' * 2000)
    assert caught.value.problems == [
        'fragment: YAML nesting deeper than 64 levels at line 1, column 70']
