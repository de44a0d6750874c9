"""The mission journal: records round-trip exactly, a line cut by a crash is ignored, and
unfinished missions are found."""

import errno
import os
from fractions import Fraction
from pathlib import Path

import pytest

from fjsp_planner.execution.journal import (
    DoneRecord,
    EndRecord,
    JobsAddedRecord,
    Journal,
    JournalError,
    MissionRecord,
    PlanRecord,
    StartRecord,
    journal_directory,
    journal_path,
    journals,
    read_journal,
    unfinished,
    waits_in_queue,
)
from fjsp_planner.model.schedule import JobAssignment, Schedule

ASSIGNMENT = JobAssignment('Ja', 0, Fraction(7, 3), Fraction(22, 3), {'MARC1': 0, 'LSMS': 0})
SCHEDULE = Schedule({'Ja': ASSIGNMENT}, {'MARC1': ('Ja',), 'LSMS': ('Ja',), 'MARC2': ()})


def mission(mission_id='m1', accepted=10.0, queued=False):
    return MissionRecord(mission_id, 'name: x\n', 'x', 2, -1.0, 'parameter:abc',
                         {'time_scale': 0.1}, accepted, queued)


def test_records_round_trip_exactly(tmp_path):
    path = journal_path(tmp_path, 'm1')
    journal = Journal(path)
    records = [mission(), PlanRecord(1, 12.5, SCHEDULE, frozenset({'Ja'}), ('r',),
                                     {'R1': 'dock', 'R2': None}, {'R1': 7, 'R2': 12}),
               DoneRecord(ASSIGNMENT, 1, 'planner/17/3'), JobsAddedRecord('jobs: []', ('A', 'B')),
               PlanRecord(2, 12.5, None, frozenset(), ('cancelled',)),
               EndRecord('cancelled', ('by test',))]
    for record in records:
        journal.write(record)
    journal.close()
    assert read_journal(path) == records


def test_a_line_cut_short_by_a_crash_is_ignored(tmp_path):
    path = journal_path(tmp_path, 'm1')
    journal = Journal(path)
    journal.write(mission())
    journal.write(DoneRecord(ASSIGNMENT, 1))
    journal.close()
    with path.open('a') as f:
        f.write('{"type": "done", "job": {"job": "J')
    assert len(read_journal(path)) == 2


def test_a_broken_line_inside_the_journal_is_an_error(tmp_path):
    path = journal_path(tmp_path, 'm1')
    path.write_text('{"type": "mission"\n{"type": "end", "state": "x", "reasons": []}\n\n')
    with pytest.raises(JournalError, match='line 1'):
        read_journal(path)


def test_unfinished_missions_oldest_first(tmp_path):
    for mission_id, accepted, ended in (('b', 2.0, False), ('a', 3.0, False), ('c', 1.0, True)):
        journal = Journal(journal_path(tmp_path, mission_id))
        journal.write(mission(mission_id, accepted))
        if ended:
            journal.write(EndRecord('complete', ()))
        journal.close()
    (tmp_path / 'junk.journal').write_text('not json\n\n')
    assert [records[0].mission_id for _, records in journals(tmp_path)] == ['c', 'b', 'a']
    assert [records[0].mission_id for _, records in unfinished(tmp_path)] == ['b', 'a']


def test_a_queued_mission_waits_until_its_start_is_journaled(tmp_path):
    path = journal_path(tmp_path, 'm2')
    journal = Journal(path)
    journal.write(mission('m2', queued=True))
    assert read_journal(path) == [mission('m2', queued=True)]
    assert waits_in_queue(read_journal(path))
    journal.write(StartRecord(42.5))
    journal.close()
    assert read_journal(path) == [mission('m2', queued=True), StartRecord(42.5)]
    assert not waits_in_queue(read_journal(path))
    assert not waits_in_queue([mission('m3', queued=True), EndRecord('cancelled', ('x',))])
    assert not waits_in_queue([mission('m4')])


def test_a_record_that_cannot_be_written_leaves_the_journal_as_it_was(tmp_path, monkeypatch):
    """A disk that fills halfway through a record: the record is cut off again, the error
    names the file and why, and the journal reads back as it was before."""
    path = journal_path(tmp_path, 'm1')
    journal = Journal(path)
    journal.write(mission())
    before = path.read_bytes()
    write = os.write

    def full_after_half(fd, data):
        write(fd, data[:len(data) // 2])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, 'write', full_after_half)
    with pytest.raises(JournalError, match=f'{path}: cannot write the journal: No space left '
                                           'on device'):
        journal.write(PlanRecord(1, 12.5, SCHEDULE, frozenset(), ()))
    monkeypatch.undo()
    assert path.read_bytes() == before
    journal.write(DoneRecord(ASSIGNMENT, 1))
    journal.close()
    assert read_journal(path) == [mission(), DoneRecord(ASSIGNMENT, 1)]


def test_a_full_device_is_a_journal_error_not_an_os_error():
    journal = Journal(Path('/dev/full'))
    with pytest.raises(JournalError, match='/dev/full: cannot write the journal: No space'):
        journal.write(mission())
    journal.close()


def test_a_journal_directory_that_cannot_be_one_is_named(tmp_path):
    file = tmp_path / 'file'
    file.write_text('')
    with pytest.raises(JournalError, match=f'{file}: is not a directory'):
        journal_directory(file)
    with pytest.raises(JournalError, match=f'{file / "sub"}: cannot be made: Not a directory'):
        journal_directory(file / 'sub')
    with pytest.raises(JournalError, match='/proc: cannot create files in it'):
        journal_directory('/proc')
    assert journal_directory(tmp_path / 'new' / 'dir').is_dir()
