"""Work run beside the main search, each in a daemon thread of its own: a thread whose result
(or error) comes back to the caller, and a CP-SAT search followed through its handle."""

import threading
import time

from fjsp_planner.solving.cpsat import SearchHandle, solve_cpsat


class Beside:
    """`work()` in a daemon thread of its own; `result()` waits for it and returns its value
    or re-raises its error in the caller's thread."""

    def __init__(self, name, work):
        self._outcome = {}

        def run():
            try:
                self._outcome['value'] = work()
            except BaseException as error:  # re-raised in the caller's thread
                self._outcome['error'] = error

        self._thread = threading.Thread(target=run, name=name, daemon=True)
        self._thread.start()

    def done(self) -> bool:
        return not self._thread.is_alive()

    def result(self):
        self._thread.join()
        if 'error' in self._outcome:
            raise self._outcome['error']
        return self._outcome['value']


class CpsatBeside(Beside):
    """`solve_cpsat` in a thread of its own until `deadline`, followed by a `SearchHandle`;
    `relaxation` and `pairwise_travel` as `solve_cpsat` takes them."""

    def __init__(self, problem, deadline, workers, upper_bound, hint, log, relaxation=True,
                 pairwise_travel=False):
        self.handle = SearchHandle()
        self.started = time.monotonic()
        super().__init__('cpsat', lambda: solve_cpsat(
            problem, max(0.05, deadline - time.monotonic()), workers, hint=hint,
            upper_bound=upper_bound, log=log, handle=self.handle, relaxation=relaxation,
            pairwise_travel=pairwise_travel))
