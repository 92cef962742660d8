"""tests/numba_compile_lock.py: a cached numba function whose compile lock another worker holds is compiled only
after that worker lets go of it (then numba finds the other worker's result in the disk cache, or compiles)."""
from __future__ import annotations

import fcntl
import importlib.util
import threading

import numba_compile_lock as L

KERNEL = '''import numba


@numba.njit(cache=True)
def twice(x):
    return 2 * x
'''


def test_a_compile_waits_for_the_lock_of_another_worker(tmp_path):
    L.install()
    path = tmp_path / "compile_lock_probe.py"
    path.write_text(KERNEL)
    spec = importlib.util.spec_from_file_location("compile_lock_probe", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    box = {}
    with open(L.lock_folder() / L.lock_name(mod.twice.py_func), "a") as held:   # the other worker compiles
        fcntl.flock(held, fcntl.LOCK_EX)
        th = threading.Thread(target=lambda: box.setdefault("value", mod.twice(21)), daemon=True)
        th.start()
        th.join(1.0)
        assert th.is_alive() and "value" not in box        # waiting for the lock, not compiling
        fcntl.flock(held, fcntl.LOCK_UN)
    th.join(60)
    assert box["value"] == 42
    assert mod.twice.stats.cache_misses or mod.twice.stats.cache_hits   # compiled (or loaded) once the lock was free
