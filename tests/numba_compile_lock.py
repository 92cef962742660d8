"""One compilation per numba function for all test workers: the others wait for it and load it from the disk cache.

With an empty numba cache (a fresh checkout or venv) the test workers of ``pytest -n auto`` meet the same
``cache=True`` kernels at about the same time (the green transient kernels, the moving-source reference), and each
compiles them: seconds of CPU per kernel and worker for a result the first worker writes to the shared disk cache
anyway. :func:`install` wraps ``numba.core.dispatcher.Dispatcher.compile`` so that a worker compiles a cached
function only while holding an exclusive file lock named after the function; a worker that finds it held waits,
then takes numba's own path, which loads the other worker's result from the disk cache (numba checks the cache
before compiling, :meth:`Dispatcher.compile`). With a warm cache the lock is taken once per function and
process (tens of microseconds). Nothing the tests check changes: numba compiles or loads the same code.

Deadlock-free: numba's process-wide compiler lock is taken first (one thread per process compiles), and a lock
held while another is awaited belongs to a caller waiting for its callee's lock; a cycle of waits would need a
cycle of calls.
"""
from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

from numba.core import dispatcher
from numba.core.caching import NullCache
from numba.core.compiler_lock import global_compiler_lock

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no flock, numba as it is
    fcntl = None


def lock_folder() -> Path:
    """The folder of the lock files [path]: one per user and numba cache location (``NUMBA_CACHE_DIR``, or
    beside the sources), so that concurrent test sessions sharing a cache share its locks too."""
    where = hashlib.sha1(os.environ.get("NUMBA_CACHE_DIR", "").encode()).hexdigest()[:12]
    d = Path(tempfile.gettempdir()) / f"railtherm-numba-compile-locks-{os.getuid()}-{where}"
    d.mkdir(exist_ok=True)
    return d


def lock_name(func) -> str:
    """The lock file's name for the Python function ``func`` of a numba dispatcher (its source file and name:
    the key of numba's disk cache beside the sources)."""
    return hashlib.sha1(f"{func.__code__.co_filename}:{func.__qualname__}".encode()).hexdigest()


def install() -> None:
    """Wrap numba's ``Dispatcher.compile`` with the per-function file lock in :func:`lock_folder`."""
    original = dispatcher.Dispatcher.compile
    if fcntl is None or getattr(original, "_railtherm_locked", False):
        return
    try:
        folder = lock_folder()
    except OSError:                                   # no temporary folder to lock in: numba as it is
        return

    def compile(self, sig):
        if isinstance(self._cache, NullCache):       # not cached on disk: nothing to share
            return original(self, sig)
        with global_compiler_lock:
            try:
                fh = open(folder / lock_name(self.py_func), "a")
            except OSError:                           # no lock file (e.g. a read-only temporary folder): compile
                return original(self, sig)
            with fh:
                fcntl.flock(fh, fcntl.LOCK_EX)
                try:
                    return original(self, sig)
                finally:
                    fcntl.flock(fh, fcntl.LOCK_UN)

    compile._railtherm_locked = True
    dispatcher.Dispatcher.compile = compile


def install_for_xdist_worker() -> bool:
    """Install the lock in a pytest-xdist worker process (True), nowhere else (False)."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return False
    install()
    return True
