import os
import sys
from pathlib import Path

import pytest

from studies import ELASTIC, ellipse_scene

sys.path.insert(0, str(Path(__file__).parent))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
if os.environ.get("PYTEST_XDIST_WORKER"):
    # one test worker per core: each numerical library gets one thread, or N workers oversubscribe N cores.
    # NUMBA_NUM_THREADS only before numba is imported: numba re-reads it when it compiles and refuses a
    # change of its thread count ("Cannot set NUMBA_NUM_THREADS"); afterwards set_num_threads (below)
    for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS") + (() if "numba" in sys.modules else ("NUMBA_NUM_THREADS",)):
        os.environ.setdefault(_var, "1")


@pytest.fixture(autouse=True)
def _one_numba_thread_per_test_worker():
    """Under xdist, numba's parallel kernels use one thread (set at run time: numba may be loaded already)."""
    if os.environ.get("PYTEST_XDIST_WORKER") and "numba" in sys.modules:
        import numba
        numba.set_num_threads(1)
    yield




@pytest.fixture
def flat_host():
    """A plugin host with core and the fixture plugins only (no entry points)."""
    from fixture_plugins import FlatPlugin
    from railtherm.solving import plugins
    saved = plugins._HOST
    host = plugins.new_host([("flat", FlatPlugin())], autoload=False, strict=True)
    plugins.set_host(host)
    yield host
    plugins.set_host(saved)


STUDY = """
schema_version = 1
[study]
name = "tiny"
methods = {methods}
levels = [0, 1]
repeat = 1
timeout = {timeout}
{elastic}{scene}heat_partition = 0.5
outputs = ["max_surface_temperature", "surface_temperature", "heat_flux", "frictional_power"]
"""


@pytest.fixture
def write_study(tmp_path):
    def write(methods='["flat"]', speed="[30.0, 60.0]", timeout=60, extra=""):
        p = tmp_path / "study.toml"
        p.write_text(STUDY.format(methods=methods, timeout=timeout, elastic=ELASTIC, scene=ellipse_scene(speed=speed))
                     + extra)
        return p
    return write
