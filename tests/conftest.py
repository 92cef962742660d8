import json
import os
import statistics
import sys
from collections import defaultdict
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

# after the thread variables above (numba reads them when it is imported): with an empty numba cache the test
# workers compile each cached kernel once between them, not once each
from numba_compile_lock import install_for_xdist_worker  # noqa: E402

install_for_xdist_worker()


@pytest.fixture(autouse=True)
def _one_numba_thread_per_test_worker():
    """Under xdist, numba's parallel kernels use one thread (set at run time: numba may be loaded already)."""
    if os.environ.get("PYTEST_XDIST_WORKER") and "numba" in sys.modules:
        import numba
        numba.set_num_threads(1)
    yield


#: seconds each test file takes (setup, call and teardown of its tests; written by ``--write-file-durations``
#: from a run on a warm numba cache): only their order matters, and only for the order of the files
FILE_DURATIONS = Path(__file__).parent / "file_durations.json"


def pytest_addoption(parser):
    parser.addoption("--write-file-durations", action="store_true",
                     help=f"write the seconds each test file took to {FILE_DURATIONS.name} (for the xdist order)")


def pytest_collection_modifyitems(session, config, items):
    """Test files longest first, each file's own order kept (LPT scheduling).

    ``--dist loadfile`` hands a whole file to a worker that is nearly out of work, in the order collected
    (``--no-loadscope-reorder``: not by number of tests). The longest files first leave short ones to fill
    the gaps at the end, instead of one long file keeping one core busy while the other idles. A file not
    yet in the table counts as the median file."""
    try:
        seconds = json.loads(FILE_DURATIONS.read_text())
    except (OSError, ValueError):
        return
    default = statistics.median(seconds.values()) if seconds else 0.0
    first = {}
    for i, item in enumerate(items):
        first.setdefault(item.nodeid.split("::")[0], i)
    items.sort(key=lambda item: (-seconds.get(item.nodeid.split("::")[0], default),
                                 first[item.nodeid.split("::")[0]]))


_FILE_SECONDS = defaultdict(float)


def pytest_runtest_logreport(report):
    _FILE_SECONDS[report.nodeid.split("::")[0]] += report.duration


def pytest_sessionfinish(session):
    """``--write-file-durations``: the table of :func:`pytest_collection_modifyitems` (in the xdist controller,
    which receives every worker's reports, or in a run without xdist)."""
    if session.config.getoption("--write-file-durations") and not os.environ.get("PYTEST_XDIST_WORKER") \
            and _FILE_SECONDS:
        FILE_DURATIONS.write_text(json.dumps({k: round(v, 2) for k, v in sorted(_FILE_SECONDS.items())}, indent=1)
                                  + "\n")


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
