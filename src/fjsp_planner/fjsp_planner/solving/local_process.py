"""The local search (`local`) in a Python process of its own, so that a second run of it gets
a core beside the first: threads of one process share one core for Python code
(docs/solver.md, "Local search").

The child is this module run by the same interpreter with the parent's import path: it reads
the problem, the start, the deadline (`time.monotonic()`, one clock for every process of the
machine) and the seed as a pickle on its standard input, and writes the schedule it found and
when as a pickle on its standard output. Its schedule crosses a pipe, so the parent validates
it again; a child that fails, or overruns its deadline by more than `GRACE` seconds, is
killed and leaves a note instead of a schedule. A child whose parent has ended stops at its
next step.
"""

import os
import pickle
import subprocess
import sys
import tempfile
import time

from fjsp_planner.model.problem import Problem
from fjsp_planner.model.schedule import Schedule
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.local import local_search

SECOND_SEED = 1
"""Seed of the run in a process of its own (the first runs with 0)."""
MIN_SECONDS = 2.0
"""Seconds of search below which a second process would spend much of them starting."""
GRACE = 2.0
"""Seconds past the deadline the child may take to time, validate and send its schedule
(a few tenths at 1000 jobs)."""


def local_searches(problem: Problem, start: Schedule, deadline: float, runs: int,
                   stop=None) -> tuple[Schedule, float, tuple[str, ...]]:
    """The best schedule of `runs` (1 or 2) runs of `local_search` from `start` (the second
    in a process of its own, when `MIN_SECONDS` remain), when it was found
    (`time.monotonic()`), and notes on a second run that failed. With `stop`, both end when
    it holds."""
    second = (LocalSearchProcess(problem, start, deadline, SECOND_SEED)
              if runs >= 2 and deadline - time.monotonic() >= MIN_SECONDS else None)
    best, best_at = local_search(problem, start, deadline, stop=stop)
    if second is None:
        return best, best_at, ()
    if stop is not None and stop():
        second.stop()
        return best, best_at, ()
    found = second.result()
    if found is None:
        return best, best_at, (f'the local search in a second process {second.failure}',)
    return (*min((best, best_at), found, key=lambda run: run[0].makespan), ())


class LocalSearchProcess:
    """`local_search(problem, start, deadline, seed)` in a child process, started at once."""

    def __init__(self, problem: Problem, start: Schedule, deadline: float, seed: int):
        self._problem = problem
        self._deadline = deadline
        self.failure = None
        """Why the child gave no schedule, once `result` has found it."""
        path = os.pathsep.join(entry for entry in sys.path if entry)
        try:
            with tempfile.TemporaryFile() as request:
                pickle.dump((problem, start, deadline, seed), request)
                request.seek(0)
                self._child = subprocess.Popen(
                    [sys.executable, '-m', __name__], stdin=request,
                    stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                    env=dict(os.environ, PYTHONPATH=path))
        except Exception as error:  # no process to start, or a problem pickle refuses
            self._child, self.failure = None, f'could not start: {error}'

    def result(self) -> tuple[Schedule, float] | None:
        """The child's schedule and when it was found (`time.monotonic()`), once it ends
        after the deadline; None when it failed (see `failure`)."""
        if self._child is None:
            return None
        try:
            out, err = self._child.communicate(
                timeout=max(0.0, self._deadline - time.monotonic()) + GRACE)
        except subprocess.TimeoutExpired:
            self.stop()
            self.failure = f'gave no schedule within {GRACE:g} s of the limit'
            return None
        except OSError as error:
            self.stop()
            self.failure = f'could not be reached: {error}'
            return None
        if self._child.returncode != 0:
            last = err.decode(errors='replace').strip().splitlines()[-1:] or ['no message']
            self.failure = f'ended with exit code {self._child.returncode}: {last[0]}'
            return None
        try:
            schedule, found_at = pickle.loads(out)
        except Exception as error:  # whatever a damaged pickle raises
            self.failure = f'sent no readable schedule: {error}'
            return None
        if not isinstance(schedule, Schedule) or validate(self._problem, schedule):
            self.failure = 'sent a schedule that is not valid'
            return None
        return schedule, found_at

    def stop(self):
        """End the child now, its schedule unread (its pipes closed even if it had ended)."""
        if self._child is not None:
            if self._child.poll() is None:
                self._child.kill()
            self._child.communicate()


def _serve():
    parent = os.getppid()
    problem, start, deadline, seed = pickle.load(sys.stdin.buffer)
    # A parent killed meanwhile would leave the search running to its deadline.
    found = local_search(problem, start, deadline, seed=seed,
                         stop=lambda: os.getppid() != parent)
    sys.stdout.buffer.write(pickle.dumps(found))


if __name__ == '__main__':
    _serve()
