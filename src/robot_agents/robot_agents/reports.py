"""An agent's reports kept on disk, for the agent process that comes after it.

The task events an agent publishes are the only record of the robot's work until the planner
declares the job done: other nodes learn them from the agent's event writer, which keeps its
history for late joiners. An agent killed while no planner runs takes that history with it,
and the planner that resumes the mission never learns that an operation was done, though
the robot's co-workers and successors went on from it. So an agent given a `reports_dir`
appends each report to a file of its robot before publishing it, and a new agent of the same
robot publishes again the reports of the latest mission it finds there.

One JSON object per line, flushed at once (a killed process loses nothing it wrote; a machine
crash may lose the last lines); a line cut short by a crash is skipped. The file is rewritten
with at most `keep` lines when it is opened.
"""

import json
import os
from pathlib import Path

FIELDS = {'sec': int, 'nanosec': int, 'event_id': str, 'mission_id': str, 'kind': int,
          'robot': str, 'job': str, 'revision': int, 'time': float, 'reason': str}
"""A report's fields and their types (a time may be written as an integer)."""


def _valid(report) -> bool:
    if not isinstance(report, dict):
        return False
    for name, kind in FIELDS.items():
        value = report.get(name)
        allowed = (int, float) if kind is float else kind
        if isinstance(value, bool) or not isinstance(value, allowed):
            return False
    return True


class ReportLog:
    """The reports of one robot in `directory`; `earlier` holds those of the latest mission
    earlier agents reported on, oldest first."""

    def __init__(self, directory: Path, robot: str, keep: int):
        self.path = Path(directory) / f'{robot}.reports'
        self.path.parent.mkdir(parents=True, exist_ok=True)
        reports = self._read()[-keep:]
        latest = reports[-1]['mission_id'] if reports else None
        self.earlier = [r for r in reports if r['mission_id'] == latest]
        with self.path.open('w', encoding='utf-8') as rewritten:
            rewritten.writelines(json.dumps(r, separators=(',', ':')) + '\n' for r in reports)
        self._file = self.path.open('a', encoding='utf-8')

    def _read(self) -> list[dict]:
        try:
            lines = self.path.read_text(encoding='utf-8').splitlines()
        except FileNotFoundError:
            return []
        except (OSError, UnicodeDecodeError):
            return []  # unreadable: nothing to hand on, and it is started afresh
        reports = []
        for line in lines:
            try:
                report = json.loads(line)
            except ValueError:
                continue
            if _valid(report):
                reports.append({name: report[name] for name in FIELDS})
        return reports

    def append(self, report: dict) -> None:
        self._file.write(json.dumps({name: report[name] for name in FIELDS},
                                    separators=(',', ':')) + '\n')
        self._file.flush()

    def close(self) -> None:
        if not self._file.closed:
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
