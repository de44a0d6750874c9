"""A private rclpy node that listens to a fleet's topics from a thread of its own: how the
launcher and the test harness hear the fleet without touching the default context a user's
code may use."""

import itertools
import os
import threading
from contextlib import contextmanager

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

from fjsp_common.contract import screened_subscription


class Listener:
    """A node in a private rclpy context on one domain, spun on a thread of its own: its owner
    (the launcher, a test) keeps its main thread, and the default context a user's code may
    use is never touched. Callbacks added with `subscribe` run under `lock`, which
    `wait_for` waits on."""

    _numbers = itertools.count()

    def __init__(self, domain: int | None = None, name: str = 'fleet_listener',
                 discovery_range: str | None = None):
        self.context = rclpy.Context()
        with environment(ROS_AUTOMATIC_DISCOVERY_RANGE=discovery_range):
            rclpy.init(context=self.context, domain_id=domain)
        try:
            self.node = rclpy.create_node(f'{name}_{os.getpid()}_{next(self._numbers)}',
                                          context=self.context, enable_rosout=False,
                                          start_parameter_services=False)
        except BaseException:
            rclpy.try_shutdown(context=self.context)
            raise
        self.lock = threading.Condition()
        self._stopping = threading.Event()
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self._spin, name=name, daemon=True)
        self.thread.start()

    def _spin(self) -> None:
        try:
            while self.context.ok() and not self._stopping.is_set():
                self.executor.spin_once(timeout_sec=0.1)
        except ExternalShutdownException:
            pass
        except Exception:  # noqa: BLE001  the context went down between the check and the spin
            if self.context.ok():
                raise

    def subscribe(self, msg_type, topic: str, qos, callback, verifier=None):
        """Every message waiting is taken in a row; with a keyed `verifier`, those that cannot
        carry a signature are dropped from their bytes (`screened_subscription`)."""
        def locked(msg):
            with self.lock:
                callback(msg)
                self.lock.notify_all()
        return screened_subscription(self.node, msg_type, topic, qos, locked, verifier)

    def wait_for(self, predicate, timeout: float) -> bool:
        """Wait until `predicate()` holds (checked under the lock at every message); whether
        it does."""
        with self.lock:
            return self.lock.wait_for(predicate, timeout=timeout)

    def close(self) -> None:
        # The spinning thread stops before anything it waits on is destroyed: destroying the
        # node under a wait can leave that thread blocked in rclpy holding the interpreter,
        # and the join below, hence the caller, waiting for ever.
        self._stopping.set()
        self.executor.wake()
        self.thread.join(timeout=2.0)
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


@contextmanager
def environment(**values):
    """Set environment variables (None: leave as is) for the duration of a `with` block."""
    values = {k: v for k, v in values.items() if v is not None}
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
