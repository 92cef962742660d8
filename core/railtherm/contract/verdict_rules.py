"""The numbers of docs/verdicts.md's scorecard rule, read by the analysis that stores the verdicts and by the
report that applies the rule to metrics written without them (the report may not import the analysis).

``RISE_FRACTION``: a finer level's headline error this much (in units of the tolerance) above the smallest error
of the coarser levels makes a ladder non-monotone ("rises again under refinement").
``TIME_TIE``: qualifying levels whose best wall times are within this factor of the cheapest one cost the same
(timings of short solves move by tens of per cent between runs); of those the lowest level is the verdict, so
that two runs of one study quote the same level.
"""
from __future__ import annotations

RISE_FRACTION = 0.1
TIME_TIE = 1.5


def cheapest(candidates: list, time, level):
    """The verdict among the qualifying ``candidates``: the lowest ``level(c)`` among those whose ``time(c)`` [s]
    is within :data:`TIME_TIE` of the smallest (a time that is not finite counts as infinite)."""
    def t(c):
        v = time(c)
        return v if v == v and v != float("inf") else float("inf")
    best = min(t(c) for c in candidates)
    tied = [c for c in candidates if t(c) <= TIME_TIE * best] if best < float("inf") else list(candidates)
    return min(tied, key=level)
