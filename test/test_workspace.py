"""Where pictures and recordings go by default, and file names made from mission ids."""

import pytest

from fjsp_planner import workspace


def test_out_is_beside_the_install_space(monkeypatch, tmp_path):
    prefix = tmp_path / 'ws' / 'install' / 'fjsp_planner'
    prefix.mkdir(parents=True)
    (prefix.parent / '.colcon_install_layout').write_text('isolated\n')
    monkeypatch.setattr('ament_index_python.packages.get_package_prefix', lambda _: str(prefix))
    assert workspace.default_out_dir() == tmp_path / 'ws' / 'out'


def test_elsewhere_it_is_under_the_home_ros_directory(monkeypatch, tmp_path):
    monkeypatch.setattr('ament_index_python.packages.get_package_prefix',
                        lambda _: str(tmp_path / 'opt' / 'ros'))
    monkeypatch.delenv('ROS_HOME', raising=False)
    monkeypatch.setenv('HOME', str(tmp_path))
    assert workspace.default_out_dir() == tmp_path / '.ros' / 'fjsp' / 'out'


@pytest.mark.parametrize('mission, name', [
    ('solar_panel-20261201T033247-4d87', 'solar_panel-20261201T033247-4d87'),
    ('../../etc/passwd', '_.._etc_passwd'),  # cannot leave the output directory
    ('', 'unnamed'),
    ('a' * 500, 'a' * 120),
])
def test_mission_ids_become_safe_file_names(mission, name):
    assert workspace.safe_file_name(mission) == name
