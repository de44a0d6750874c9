"""An agent's reports kept on disk for the agent process after it (no ROS)."""

import json

from robot_agents.reports import ReportLog


def report(mission, number, job='Ja', kind=2, **changes):
    return {'sec': 1000 + number, 'nanosec': 5, 'event_id': f'MARC1/1/{number}',
            'mission_id': mission, 'kind': kind, 'robot': 'MARC1', 'job': job, 'revision': 1,
            'time': 2.5 * number, 'reason': '', **changes}


def test_a_new_agent_gets_the_latest_missions_reports_in_order(tmp_path):
    first = ReportLog(tmp_path, 'MARC1', keep=100)
    assert first.earlier == []
    reports = [report('m1', 1), report('m1', 2), report('m2', 3), report('m2', 4, job='Jb')]
    for r in reports:
        first.append(r)
    # Killed: no close. The next agent of the robot reads what was written.
    second = ReportLog(tmp_path, 'MARC1', keep=100)
    assert second.earlier == reports[2:]
    assert ReportLog(tmp_path, 'MARC2', keep=100).earlier == []


def test_damaged_lines_are_skipped_and_the_file_is_kept_short(tmp_path):
    log = ReportLog(tmp_path, 'MARC1', keep=3)
    for number in range(1, 6):
        log.append(report('m1', number))
    log.close()
    with (tmp_path / 'MARC1.reports').open('a') as file:
        file.write(json.dumps(report('m1', 6, kind='two')) + '\n')   # wrong type
        file.write(json.dumps(report('m1', 7, revision=True)) + '\n')  # a bool is no number
        file.write('{"sec": 1, "nanosec"')                             # cut short by a kill
    again = ReportLog(tmp_path, 'MARC1', keep=3)
    assert [r['event_id'] for r in again.earlier] == ['MARC1/1/3', 'MARC1/1/4', 'MARC1/1/5']
    assert len((tmp_path / 'MARC1.reports').read_text().splitlines()) == 3


def test_an_unreadable_file_is_started_afresh(tmp_path):
    (tmp_path / 'MARC1.reports').write_bytes(b'\xff\xfe not text')
    log = ReportLog(tmp_path, 'MARC1', keep=10)
    assert log.earlier == []
    log.append(report('m1', 1))
    log.close()
    assert ReportLog(tmp_path, 'MARC1', keep=10).earlier == [report('m1', 1)]
