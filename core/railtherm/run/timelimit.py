"""Time limits of runs: :func:`_time_limit` raises :class:`RunTimeout` in the thread that runs a solve.

One :class:`Watchdog` thread per process (:data:`WATCHDOG`) runs actions at deadlines, for runs in
threads other than the main one (dask workers) and for executors that end a stuck worker. This module
imports nothing from railtherm: the runner and the executors both use it.
"""
from __future__ import annotations

import contextlib
import ctypes
import math
import signal
import threading
import time
from typing import Any

__all__ = ["RunTimeout", "Watchdog", "WATCHDOG", "_async_raise", "_time_limit"]


class RunTimeout(Exception):
    """A run exceeded its per-run time limit."""

    def __init__(self, message: str = "run exceeded the per-run time limit"):
        super().__init__(message)


def _async_raise(tid: int, exc: type | None) -> None:
    """Raise ``exc`` in thread ``tid`` at its next bytecode (None clears a pending one)."""
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(tid), ctypes.py_object(exc) if exc else None)


class Watchdog:
    """One daemon thread per process that runs actions at deadlines (time limits of runs in threads).

    A thread per run would cost more than a small run itself (starting a thread waits for it to
    run, which under a busy dask worker takes milliseconds). Actions run under the watchdog's lock,
    so :meth:`cancel` returning False means the action has completed.
    """

    def __init__(self):
        self._cond = threading.Condition()
        self._entries: dict[int, tuple[float, Any]] = {}
        self._count = 0
        self._thread: threading.Thread | None = None

    def add(self, seconds: float, action) -> int:
        """Run ``action()`` in ``seconds`` unless cancelled; returns a token for :meth:`cancel`."""
        with self._cond:
            self._count += 1
            self._entries[self._count] = (time.monotonic() + seconds, action)
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(target=self._loop, daemon=True, name="railtherm-watchdog")
                self._thread.start()
            self._cond.notify()
            return self._count

    def cancel(self, token: int) -> bool:
        """True if the action was cancelled before it ran."""
        with self._cond:
            return self._entries.pop(token, None) is not None

    def _loop(self):
        with self._cond:
            while True:
                now = time.monotonic()
                due = [k for k, (d, _) in self._entries.items() if d <= now]
                for k in due:
                    _, action = self._entries.pop(k)
                    try:
                        action()
                    except Exception:  # noqa: BLE001 - a failing action must not end the watchdog
                        pass
                nxt = min((d for d, _ in self._entries.values()), default=None)
                self._cond.wait(None if nxt is None else max(0.0, nxt - time.monotonic()))


WATCHDOG = Watchdog()


@contextlib.contextmanager
def _time_limit(seconds: float):
    """Raise :class:`RunTimeout` in the calling thread after ``seconds``.

    In the main thread of a POSIX process: SIGALRM (interrupts sleeps and waits). In another thread
    (dask workers run tasks in threads): the process's :data:`WATCHDOG` raises the exception
    asynchronously in the thread, which takes effect at its next Python bytecode; a run stuck inside
    one C call is ended by its executor (the processes and dask executors end the worker after a
    grace period).
    """
    if not (seconds and seconds > 0 and math.isfinite(seconds)):
        yield
        return
    if threading.current_thread() is threading.main_thread() and hasattr(signal, "SIGALRM"):
        def handler(signum, frame):
            raise RunTimeout(f"run exceeded the per-run time limit of {seconds:g} s")

        old = signal.signal(signal.SIGALRM, handler)
        signal.setitimer(signal.ITIMER_REAL, seconds)
        try:
            yield
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
        return
    tid = threading.get_ident()
    token = WATCHDOG.add(seconds, lambda: _async_raise(tid, RunTimeout))
    try:
        yield
    finally:
        if not WATCHDOG.cancel(token):
            _async_raise(tid, None)  # fired: clear the exception if it was not delivered yet
