"""The replay command on recordings made without ROS: what it prints and writes, and its
answers to bad input (exit 1 with a one-line reason, exit 2 for bad arguments)."""

import pytest

from fjsp_planner.observe.replay import main

from mission_facts import MISSION, faulty_mission, record


def test_replay_prints_the_summary_and_story_and_draws_the_chart(tmp_path, capsys):
    path = tmp_path / 'fleet.mcap'
    record(path, faulty_mission())
    assert main([str(path), '--out', str(tmp_path / 'charts')]) == 0
    out = capsys.readouterr().out
    assert f'recording {path}: {len(faulty_mission())} messages' in out
    assert 'complete: 3/3 jobs done (planner: 3/3); 2 revisions, 1 aborted attempt, 1 voided' \
        in out
    assert "t=       5  job J2 aborted: robot 'C' failed" in out
    assert (tmp_path / 'charts' / f'{MISSION}.replay.png').is_file()
    assert (tmp_path / 'charts' / f'{MISSION}.replay.json').is_file()


def test_replay_of_one_mission_by_id(tmp_path, capsys):
    path = tmp_path / 'fleet.mcap'
    record(path, faulty_mission())
    assert main([str(path), '--mission', 'other', '--no-chart']) == 1
    assert "holds no mission 'other'" in capsys.readouterr().err
    assert main([str(path), '--mission', MISSION, '--no-chart']) == 0
    assert not list(tmp_path.glob('*.png'))


def test_an_unreadable_file_is_one_line_and_exit_1(tmp_path, capsys):
    assert main([str(tmp_path / 'missing.mcap')]) == 1
    err = capsys.readouterr().err
    assert err.startswith('replay: cannot open recording') and err.count('\n') == 1


@pytest.mark.parametrize('argv', [[], ['x.mcap', '--heartbeat-timeout', '0'],
                                  ['x.mcap', '--heartbeat-timeout', 'soon']])
def test_bad_arguments_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    assert 'usage: replay' in capsys.readouterr().err
