"""The user's parameters file as the launcher reads it: refused with every reason, never a
traceback, whatever the file holds."""

from fjsp_planner.launcher.params import read_params_file


def test_a_deeply_nested_parameters_file_is_refused_with_the_limit(tmp_path):
    """2000 levels: the Python YAML loader raised RecursionError out of `fleet`."""
    path = tmp_path / 'deep.yaml'
    path.write_text('/**:\n  ros__parameters:\n    x: ' + '[' * 2000 + ']' * 2000 + '\n')
    assert read_params_file(path) == ({}, [
        f'{path}: YAML nesting deeper than 64 levels at line 3, column 69'])


def test_a_parameters_file_is_read_with_its_sections(tmp_path):
    path = tmp_path / 'params.yaml'
    path.write_text('/**:\n  ros__parameters:\n    time_scale: 0.1\n')
    assert read_params_file(path) == ({'/**': {'ros__parameters': {'time_scale': 0.1}}}, [])


def test_a_missing_parameters_file_is_named(tmp_path):
    path = tmp_path / 'none.yaml'
    assert read_params_file(path) == ({}, [f'{path}: no such file'])
