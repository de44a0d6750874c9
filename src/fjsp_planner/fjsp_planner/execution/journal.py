"""A mission's journal: what a restarted planner needs that the fleet does not hold.

The robots keep their task events for late joiners and report where they are, but the plan
revisions (which robots do which job, which jobs a revision continued) and the planner's own
verdicts (a job done, jobs added, the mission's end) die with the planner. The journal keeps
them: one file per mission, one JSON object per line, appended and flushed to disk before the
planner acts on what it records (a plan is on disk before any robot can follow it). A line cut
short by a crash is ignored, as is anything after it. A record that cannot be written leaves
the file as it was before it (`JournalError`).
"""

import json
import os
import tempfile
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from fjsp_planner.model.schedule import JobAssignment, Schedule

SUFFIX = '.journal'


class JournalError(ValueError):
    """A journal that cannot be used; the message names the file and the line."""


@dataclass(frozen=True)
class MissionRecord:
    mission_id: str
    scenario_yaml: str
    scenario_name: str
    panels: int
    shift: float
    origin: str
    """Identifies where the mission came from (the planner's `scenario` parameter, or a
    goal): a restarted planner does not start a mission of the same origin again."""
    settings: dict
    accepted: float
    queued: bool = False
    """Accepted into the queue behind a running mission: it waits until a StartRecord
    follows."""


@dataclass(frozen=True)
class PlanRecord:
    revision: int
    start: float
    """Wall seconds of schedule time 0."""
    schedule: Schedule | None
    """None for the revision that cancelled the mission."""
    continued: frozenset[str]
    reasons: tuple[str, ...]
    starts: dict[str, str | None] = field(default_factory=dict)
    """Where each robot started the mission (None: anywhere); empty in older journals."""
    incarnations: dict[str, int] = field(default_factory=dict)
    """The agent incarnation each robot's tasks were planned for: a restarted planner tells
    from it which agents restarted while it was down. Empty in older journals."""


@dataclass(frozen=True)
class DoneRecord:
    assignment: JobAssignment
    revision: int
    event_id: str = ''
    """The id of the job-done event that declared it ('' in older journals): a restarted
    planner publishes it again, as the event history of the process that sent it died with
    that process."""


@dataclass(frozen=True)
class JobsAddedRecord:
    fragment_yaml: str
    jobs: tuple[str, ...]


@dataclass(frozen=True)
class EndRecord:
    state: str
    reasons: tuple[str, ...]


@dataclass(frozen=True)
class StartRecord:
    """A queued mission's turn came: it started at wall seconds `at`."""

    at: float


Record = MissionRecord | PlanRecord | DoneRecord | JobsAddedRecord | EndRecord | StartRecord


def waits_in_queue(records: list[Record]) -> bool:
    """Whether the journaled mission of `records` was queued, and neither started nor ended."""
    return records[0].queued and not any(isinstance(r, StartRecord | EndRecord)
                                         for r in records)


class Journal:
    """Appends records to one mission's file; `write` returns once its record is on disk.

    A record that cannot be written whole (a full disk, a file size limit, a directory made
    read-only) is cut off again, so the file keeps every record before it and nothing of it,
    and `JournalError` says why: the caller decides what a mission without its journal
    does. Records are written with one system call each, not through a buffer that would
    try a failed write again when the next record comes."""

    def __init__(self, path: Path):
        self.path = Path(path)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        except OSError as error:
            raise JournalError(f'{self.path}: cannot open the journal: '
                               f'{error.strerror or error}') from None

    def write(self, record: Record) -> None:
        data = (json.dumps(_encode(record), separators=(',', ':')) + '\n').encode()
        try:
            size = os.fstat(self._fd).st_size
        except OSError as error:
            raise JournalError(self._failed(error)) from None
        try:
            written = 0
            while written < len(data):
                written += os.write(self._fd, data[written:])
            os.fsync(self._fd)
        except OSError as error:
            try:
                os.ftruncate(self._fd, size)
            except OSError:
                pass  # a line cut short is ignored when read
            raise JournalError(self._failed(error)) from None

    def _failed(self, error: OSError) -> str:
        return f'{self.path}: cannot write the journal: {error.strerror or error}'

    def close(self) -> None:
        """Close the file; what was written is on disk already."""
        if self._fd >= 0:
            fd, self._fd = self._fd, -1
            try:
                os.close(fd)
            except OSError:
                pass

    def discard(self) -> None:
        """Close and delete the file: the mission it was opened for does not run."""
        self.close()
        self.path.unlink(missing_ok=True)


def journal_directory(path) -> Path:
    """`path`, made if missing, as a directory journals can be created in; JournalError
    saying why it cannot be one."""
    path = Path(path).expanduser()
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise JournalError(f'{path}: is not a directory') from None
    except OSError as error:
        raise JournalError(f'{path}: cannot be made: {error.strerror or error}') from None
    try:
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as error:
        raise JournalError(f'{path}: cannot create files in it: {error.strerror or error}'
                           ) from None
    return path


def journal_path(directory: Path, mission_id: str) -> Path:
    return Path(directory) / f'{mission_id}{SUFFIX}'


def read_journal(path: Path) -> list[Record]:
    """Every complete record of `path`, in order; the first must be its MissionRecord."""
    records = []
    try:
        lines = Path(path).read_text(encoding='utf-8').split('\n')
    except (OSError, UnicodeDecodeError) as error:
        raise JournalError(f'{path}: cannot read the journal: {error}') from None
    for number, line in enumerate(lines, 1):
        if not line:
            continue
        try:
            records.append(_decode(json.loads(line)))
        except (ValueError, KeyError, TypeError) as error:
            if number >= len(lines) - 1:
                break  # the last line, cut short by a crash
            raise JournalError(f'{path}, line {number}: {error}') from None
    if not records or not isinstance(records[0], MissionRecord):
        raise JournalError(f'{path}: does not start with a mission record')
    return records


def unfinished(directory: Path) -> list[tuple[Path, list[Record]]]:
    """The journals of `directory` with no end record, oldest first."""
    return [(path, records) for path, records in journals(directory)
            if not isinstance(records[-1], EndRecord)]


def journals(directory: Path) -> list[tuple[Path, list[Record]]]:
    """Every readable journal of `directory`, oldest mission first."""
    found = []
    for path in sorted(Path(directory).glob(f'*{SUFFIX}')):
        try:
            records = read_journal(path)
        except JournalError:
            continue
        found.append((path, records))
    found.sort(key=lambda item: item[1][0].accepted)
    return found


# --- JSON --------------------------------------------------------------------------------

def _encode(record: Record) -> dict:
    if isinstance(record, MissionRecord):
        return {'type': 'mission', 'id': record.mission_id, 'scenario': record.scenario_yaml,
                'name': record.scenario_name, 'panels': record.panels, 'shift': record.shift,
                'origin': record.origin, 'settings': record.settings,
                'accepted': record.accepted, 'queued': record.queued}
    if isinstance(record, PlanRecord):
        return {'type': 'plan', 'revision': record.revision, 'start': record.start,
                'schedule': None if record.schedule is None else _schedule(record.schedule),
                'continued': sorted(record.continued), 'reasons': list(record.reasons),
                'starts': dict(record.starts), 'incarnations': dict(record.incarnations)}
    if isinstance(record, DoneRecord):
        return {'type': 'done', 'job': _assignment(record.assignment),
                'revision': record.revision, 'event_id': record.event_id}
    if isinstance(record, JobsAddedRecord):
        return {'type': 'jobs_added', 'fragment': record.fragment_yaml,
                'jobs': list(record.jobs)}
    if isinstance(record, StartRecord):
        return {'type': 'start', 'at': record.at}
    return {'type': 'end', 'state': record.state, 'reasons': list(record.reasons)}


def _decode(data: dict) -> Record:
    kind = data['type']
    if kind == 'mission':
        return MissionRecord(data['id'], data['scenario'], data['name'], int(data['panels']),
                             float(data['shift']), data['origin'], dict(data['settings']),
                             float(data['accepted']), bool(data.get('queued', False)))
    if kind == 'plan':
        schedule = data['schedule']
        return PlanRecord(int(data['revision']), float(data['start']),
                          None if schedule is None else _read_schedule(schedule),
                          frozenset(data['continued']), tuple(data['reasons']),
                          dict(data.get('starts', {})),
                          {robot: int(n) for robot, n in data.get('incarnations', {}).items()})
    if kind == 'done':
        return DoneRecord(_read_assignment(data['job']), int(data['revision']),
                          str(data.get('event_id', '')))
    if kind == 'jobs_added':
        return JobsAddedRecord(data['fragment'], tuple(data['jobs']))
    if kind == 'end':
        return EndRecord(data['state'], tuple(data['reasons']))
    if kind == 'start':
        return StartRecord(float(data['at']))
    raise ValueError(f'unknown record type {kind!r}')


def _assignment(a: JobAssignment) -> dict:
    return {'job': a.job, 'plan': a.plan, 'start': str(a.start), 'end': str(a.end),
            'robots': dict(a.robots)}


def _read_assignment(data: dict) -> JobAssignment:
    return JobAssignment(data['job'], int(data['plan']), Fraction(data['start']),
                         Fraction(data['end']),
                         {robot: int(q) for robot, q in data['robots'].items()})


def _schedule(schedule: Schedule) -> dict:
    return {'jobs': [_assignment(a) for a in schedule.jobs.values()],
            'sequences': {robot: list(jobs) for robot, jobs in schedule.sequences.items()}}


def _read_schedule(data: dict) -> Schedule:
    jobs = {a.job: a for a in map(_read_assignment, data['jobs'])}
    return Schedule(jobs, {robot: tuple(seq) for robot, seq in data['sequences'].items()})
