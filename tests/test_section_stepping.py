"""The pass windows of core's section-stepping driver (railtherm.solving.section_stepping): a pass heats
the block from ``k interval - before`` to ``k interval + after``; overlapping windows are stepped as one."""
from railtherm.solving.section_stepping import pass_windows


def test_windows_apart_stay_apart_and_overlapping_ones_merge():
    assert pass_windows(3, 1.0, 0.1, 0.2) == [(0, 0), (1, 1), (2, 2)]
    # the next pass opens 0.1 s before its arrival, the last one closes 0.95 s after it: every pair overlaps
    assert pass_windows(4, 1.0, 0.1, 0.95) == [(0, 3)]
    # touching windows (k + 1) interval - before == k interval + after merge (the stepper needs no gap)
    assert pass_windows(2, 1.0, 0.5, 0.5) == [(0, 1)]
    assert pass_windows(2, 1.0, 0.5, 0.5 - 1e-9) == [(0, 0), (1, 1)]
    assert pass_windows(1, 1.0, 5.0, 5.0) == [(0, 0)]
    assert pass_windows(0, 1.0, 0.1, 0.1) == []
