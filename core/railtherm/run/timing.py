"""How a run is timed and its memory measured: the peak-memory reader, the repeat rule, the compile watch.

:func:`railtherm.run.runner.execute_run` uses these; they hold the rules that make a timing honest
(no compilation in a timed solve; memory including native allocations) at the cost of about one solve
per run.
"""
from __future__ import annotations

import contextlib
import ctypes
import gc
import math
import threading

import psutil


class RSSPeak:
    """Peak resident set size of this process during a block, and its growth [bytes].

    ``peak`` is the process's absolute high-water mark during the block (interpreter, libraries and
    whatever the solver keeps between calls included: what a machine must hold to run it);
    ``growth`` is that peak minus the resident set at the start (what the block itself took).

    On Linux the kernel's high-water mark (``VmHWM``) is reset by writing ``5`` to
    ``/proc/self/clear_refs`` before the block and read after it; where that is not possible, a
    thread samples the RSS (psutil) every millisecond. The value counts everything the process
    allocates (numpy, numba, SuperLU, FiPy), unlike :mod:`tracemalloc`; it does not slow the code.
    Under a threaded executor (dask workers run several tasks in one process) it includes what the
    other threads allocate meanwhile. Memory the process already holds is not counted: freed heap
    memory is handed back to the OS first (``malloc_trim``), but pools that a library keeps to itself
    (numba, FiPy caches) are reused without growth.
    """

    def __init__(self):
        self.peak = math.nan
        self.growth = math.nan

    @staticmethod
    def native() -> bool:
        """True where the kernel's high-water mark can be reset and read (Linux): no sampling thread,
        so the memory can be measured in a timed solve without perturbing it."""
        try:
            with open("/proc/self/clear_refs", "w") as fh:
                fh.write("5")
            RSSPeak._status("VmHWM")
            return True
        except OSError:
            return False

    @staticmethod
    def _status(key: str) -> float:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return float(line.split()[1]) * 1024.0
        raise OSError(key)

    @staticmethod
    def _trim() -> None:
        """Return freed heap memory to the OS (glibc ``malloc_trim``), so that a solve reusing it counts."""
        try:
            ctypes.CDLL("libc.so.6").malloc_trim(0)
        except (OSError, AttributeError):  # pragma: no cover - not glibc
            pass

    def __enter__(self):
        self._sampler = None
        self._trim()
        try:
            with open("/proc/self/clear_refs", "w") as fh:
                fh.write("5")
            self._base = self._status("VmRSS")
            self._mode = "hwm"
        except OSError:
            proc = psutil.Process()
            self._base = float(proc.memory_info().rss)
            self._mode = "sample"
            self._max = self._base
            self._stop = threading.Event()

            def sample():
                while not self._stop.wait(0.001):
                    self._max = max(self._max, float(proc.memory_info().rss))
            self._sampler = threading.Thread(target=sample, daemon=True)
            self._sampler.start()
        return self

    def __exit__(self, *exc):
        if self._mode == "hwm":
            self.peak = max(self._status("VmHWM"), self._base)
        else:
            self._stop.set()
            self._sampler.join()
            self.peak = max(self._max, self._base)
        self.growth = self.peak - self._base
        return False


def freeze_process_objects() -> None:
    """Collect the garbage, then move every object the process holds to the garbage collector's permanent
    generation (:func:`gc.freeze`), after a warm-up.

    What the warm-up left (the plugins' modules, numba's compiled kernels and their type registries: about
    2e5 objects) is then never traversed again; a timed solve's full collections traverse only what solves
    create. Without it, the first solve after a warm-up paid a full collection of the imported libraries
    (0.08 s of a 0.2 s FiPy solve), an artefact of the harness's process and not of the method. Objects stay
    freed by reference counting as before; only a reference cycle among them would be kept.
    """
    gc.collect()
    gc.freeze()


#: seconds of timed solving after which a run stops repeating its solve (at most ``repeat`` solves)
TIMING_BUDGET = 0.5


def more_solves(times: list[float], repeat: int, adaptive: bool) -> bool:
    """Whether a run times one more solve, given its timed solves so far ``times`` [s].

    A verification study (``adaptive``) repeats a solve only while it is short: until about
    :data:`TIMING_BUDGET` seconds of timing are collected, at most ``repeat`` solves; a solve over
    0.5 s is timed once (the result's own solve). A sweep (not ``adaptive``) takes exactly ``repeat``.
    """
    if len(times) >= max(1, repeat):
        return False
    return sum(times) < TIMING_BUDGET if adaptive else True


@contextlib.contextmanager
def compile_watch():
    """Yield a list that holds, after the block, the numba compilations that happened inside it.

    A timed solve that compiled (a kernel the warm-up did not reach, e.g. another scheme at a finer
    level) is not a timing: :func:`_solve_timed` solves once more. Loading a kernel from numba's
    on-disk cache is not a compilation (milliseconds).
    """
    events: list = []
    try:
        from numba.core import event  # numba: ~0.8 s, only when a run is timed
    except ImportError:  # pragma: no cover - numba is a dependency; plugins need not use it
        yield events
        return
    with event.install_recorder("numba:compile") as rec:
        yield events
    events.extend(rec.buffer)
