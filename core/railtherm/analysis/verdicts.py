"""The verdict rules of ``metrics.nc`` (contract: ``docs/verdicts.md``): which errors are scored at all
(noise floors, quantities zero by symmetry), whether an error against another method is independent
(no shared stage model), a run's status from its errors, the converged verdict of a method's refinement
ladder (the scorecard), and whether a reference method is converged itself.

Everything here works on numbers already computed (errors, levels, wall times); it solves nothing.
"""
from __future__ import annotations

import math

import numpy as np

from ..contract.verdict_rules import RISE_FRACTION, cheapest
from ..output.store import RESULT_STATUSES
from .analytic import _identical_elastic
from .rises import RISES

#: a reference whose magnitude (the max-norm of its rise for temperatures) is below this is noise, and
#: the metric is not scored: forces 1e-3 µN, powers 1e-9 W, temperature rises 1e-6 K, pressures 1e-3 Pa,
#: lengths 1e-12 m (far below anything a contact of a rail vehicle produces, far above round-off of
#: the quantities' sums)
NOISE_FLOOR = {"creep_force_x": (1e-9, "N"), "frictional_power": (1e-9, "W"), "max_pressure": (1e-3, "Pa"),
               "pressure_l2": (1e-3, "Pa"), "semi_axis_a": (1e-12, "m")}
NOISE_FLOOR.update({q: (1e-6, "K") for q in ("max_surface_temperature", "mean_contact_temperature",
                                              "surface_temperature_l2", "steady_wheel_temperature",
                                              "steady_mean_contact_temperature", "peak_temperature")})
#: the stage that produces each scored quantity (a quantity of two chains that run the same models up to and
#: including this stage is the same computation, not an independent check)
STAGE_OF = {"semi_axis_a": "normal", "max_pressure": "normal", "pressure_l2": "normal",
            "creep_force_x": "tangential", "frictional_power": "heat_source"}
STAGE_ORDER = ("normal", "tangential", "heat_source", "temperature")
#: a reference method is converged on a quantity when its own finest-level error estimate is below this
#: fraction of the tolerance
REFERENCE_FRACTION = 0.25
#: statuses of a run that produced a result
RESULTS = RESULT_STATUSES


def label(metric: str, cooling_depth: float = math.nan) -> str:
    """A metric's name in words; the cooling rate with the depths it is scored at ("cooling rate, z ≥ 26 µm").

    Parameters
    ----------
    metric : str
    cooling_depth : float
        Shallowest scored depth of the cooling rate [m] (NaN: not known).
    """
    text = metric.replace("_", " ")
    if metric == "cooling_rate" and math.isfinite(cooling_depth):
        text += f", z ≥ {cooling_depth * 1e6:.3g} µm"
    elif metric == "cooling_rate_all_depths":
        text = "cooling rate, all depths"
    return text


# -- what is scored ------------------------------------------------------------------------------
def _symmetric_in_y(contact_shape: str, gap_coefficients) -> bool:
    """Whether a contact of shape ``contact_shape`` (with the gap's ``gap_coefficients`` {(i, j): c}, or None) is
    symmetric in y: a Hertz ellipse or line, or a gap with even powers of y only."""
    if contact_shape in ("ellipse", "line"):
        return True
    return contact_shape == "gap" and all(j % 2 == 0 for (_, j) in (gap_coefficients or {}))


def zero_by_symmetry(creepage, contact_shape: str, gap_coefficients, wheel, rail, *, wheelset=None,
                     heat_source=None) -> dict[str, str]:
    """The metrics that are zero by symmetry on a scene, and why: {metric: reason} (empty when none is).

    The creep force Fx vanishes without longitudinal creepage on a contact symmetric in y between
    quasi-identical bodies: mirroring y maps the creepages (ξ, η, φ) to (ξ, −η, −φ) and keeps Fx, and
    reversing every creepage reverses every traction, so Fx(0, η, φ) = Fx(0, −η, −φ) = −Fx(0, η, φ) = 0
    for any friction law that depends on the slip's magnitude or the temperature only.

    Parameters
    ----------
    creepage : Creepage or None
        The scene's creepages (``scene.creepage``; None in full sliding).
    contact_shape : str
        "ellipse", "line" or "gap".
    gap_coefficients : dict or None
        The gap's coefficients {(i, j): c} of a contact of shape "gap".
    wheel, rail : Material
        The bodies (their elastic constants are compared).
    wheelset : Wheelset or None
        The scene's wheelset (its equilibrium sets the creepages: no symmetry is assumed).
    heat_source : GivenHeatSource or None
        The scene's given heat source (no creep force is computed).
    """
    if creepage is None or wheelset is not None or heat_source is not None or creepage.longitudinal != 0:
        return {}
    if not (_symmetric_in_y(contact_shape, gap_coefficients) and _identical_elastic(wheel, rail)):
        return {}
    return {"creep_force_x": "zero by symmetry (no longitudinal creepage on a contact symmetric in y)"}


def unscored(metric: str, reference, bulk=0.0, zero: dict | None = None) -> str:
    """Why ``metric`` is not scored against ``reference`` ("" when it is): zero by symmetry, a reference
    that is zero, or one below its :data:`NOISE_FLOOR`.

    Parameters
    ----------
    metric : str
    reference : array_like
        The reference values [units of the quantity].
    bulk : float or array_like
        Bulk temperature subtracted from a temperature [degC] (0 for other quantities).
    zero : dict, optional
        The scene's metrics that are zero by symmetry, and why (:func:`zero_by_symmetry`).
    """
    why = (zero or {}).get(metric, "")
    if why:
        return why
    r = np.asarray(reference, float) - np.asarray(bulk, float)
    r = r[np.isfinite(r)]
    if r.size == 0:
        return ""
    scale = float(np.max(np.abs(r)))
    floor, unit = NOISE_FLOOR.get(metric, (0.0, ""))
    if scale == 0.0:
        return "the reference is zero"
    if scale < floor:
        what = "its rise" if metric in RISES or metric == "surface_temperature_l2" else "it"
        return f"the reference is below the noise floor ({what} {scale:.2g} {unit} < {floor:g} {unit})"
    return ""


def shares_stage(metric: str, stages: str, ref_stages: str) -> str:
    """The stage model two chains share for ``metric`` ("" when the quantity is computed independently).

    Chains that run the same models for every stage up to and including the one that produces the
    quantity (:data:`STAGE_OF`; temperatures and the thermal trace: the temperature stage) compute the
    same number; an error between them is not a check.
    """
    own, ref = _stage_map(stages), _stage_map(ref_stages)
    if not own or not ref:
        return ""
    last = STAGE_OF.get(metric, "temperature")
    upto = STAGE_ORDER[: STAGE_ORDER.index(last) + 1]
    used = [s for s in upto if s in own or s in ref]
    if used and all(own.get(s) == ref.get(s) for s in used) and last in own:
        return f"{last}:{own[last]}"
    return ""


def _stage_map(text: str) -> dict:
    return dict(part.split(":", 1) for part in str(text).split() if ":" in part)


# -- a run's status --------------------------------------------------------------------------------
def independent(tag: str) -> bool:
    """Whether an error taken against ``tag`` verifies a run (an exact reference or another method)."""
    return tag.startswith("analytic:") or tag.startswith("method:")


def run_status(errs: dict, energy: float, energy_ref: str, tol: float, headline: str, labels: dict | None = None,
               why: str = "", notes: dict | None = None) -> tuple[str, str]:
    """(status, message) of a run that produced a result.

    ``ok``: the headline has a finite error against an independent reference within ``tol`` and no error
    (against anything) nor the energy balance exceeds it; ``inaccurate``: some error exceeds ``tol`` or is
    infinite (a non-finite value where the reference is finite), named in the message; ``unverified``
    otherwise (the headline is not checked independently; the message names what was).

    Parameters
    ----------
    errs : dict
        metric -> (relative error [1], reference tag); NaN errors are not scored.
    energy, energy_ref : float, str
        Energy balance [1] and how it was obtained.
    tol : float
        Tolerance [1].
    headline : str
        The scene's headline quantity.
    labels : dict, optional
        metric -> its name in words (the cooling rate with its depth range).
    why : str
        Why nothing independent was compared, when nothing was.
    notes : dict, optional
        metric -> why it fails (an infinite error) or is not scored.
    """
    labels, notes = labels or {}, notes or {}
    name = lambda k: labels.get(k, k)  # noqa: E731
    scored = {k: (v, t) for k, (v, t) in errs.items() if not math.isnan(v)}
    bad = {k: v for k, (v, t) in scored.items() if v > tol}
    if math.isfinite(energy) and abs(energy) > tol:
        bad["energy_balance"] = abs(energy)
    if bad:
        worst = max(bad, key=bad.get)
        against = errs[worst][1] if worst in errs else energy_ref
        if math.isinf(bad[worst]):
            return "inaccurate", (f"{name(worst)} fails against {against}: "
                                  + notes.get(worst, "not finite where its reference is"))
        return "inaccurate", (f"relative error {bad[worst]:.3g} in {name(worst)} (against {against}) exceeds "
                              f"the tolerance {tol:g}")
    indep = {k: (v, t) for k, (v, t) in scored.items() if independent(t)}
    checked = "; ".join(f"{name(k)} against {t} ({v:.3g})" for k, (v, t) in sorted(indep.items()))
    if headline in indep:
        also = "; ".join(f"{name(k)} against {t} ({v:.3g})" for k, (v, t) in sorted(indep.items()) if k != headline)
        return "ok", (f"headline {name(headline)} within {tol:g} of {indep[headline][1]} ({indep[headline][0]:.3g})"
                      + (f"; also checked: {also}" if also else ""))
    if not headline:
        head = "no headline quantity"
    elif headline in scored:
        head = f"headline {name(headline)} compared only with its own finest level"
    else:
        head = f"headline {name(headline)} not checked against an independent reference"
    if indep:
        return "unverified", f"{head}; checked: {checked}"
    others = sorted(k for k in scored if k != headline)
    if others:
        return "unverified", (f"{head}; no independent reference: only self-convergence (errors against its own "
                              "finest level) of " + ", ".join(name(k) for k in others))
    if scored:
        return "unverified", f"{head} (self-convergence); no independent reference"
    return "unverified", f"{head}: nothing independent to compare with" + (f" ({why})" if why else "")


# -- the converged verdict of a ladder ---------------------------------------------------------------
def ladder_verdict(runs: list[dict], tol: float) -> dict:
    """The scorecard verdict of one method on one scene from its refinement ladder.

    A level qualifies when its headline error (against an independent reference) and that of every finer
    level that ran are finite and within ``tol``: a failed run ran (its headline is not within tolerance),
    except one stopped by the time limit (no result, like a budget refusal); refused runs did not run. Of the
    qualifying levels the cheapest ``ok`` one is the verdict, else the cheapest qualifying one with its status;
    levels within :data:`railtherm.contract.verdict_rules.TIME_TIE` of the smallest wall time cost the same, and
    the lowest of them is taken.

    Parameters
    ----------
    runs : list of dict
        One per level: ``level``, ``status``, ``reason_kind``, ``headline_error`` [1], ``wall_time`` [s].
    tol : float
        Tolerance [1].

    Returns
    -------
    dict
        ``level`` (−1 when none qualifies), ``error`` [1], ``time`` [s], ``status`` ("" when none qualifies),
        ``monotone`` (False when the error rises again under refinement) and ``message`` in words.
    """
    ran = sorted((r for r in runs if r["status"] in RESULTS or (r["status"] == "failed" and r.get("reason_kind")
                                                                   != "timeout")), key=lambda r: r["level"])
    within = [r["status"] in RESULTS and math.isfinite(r["headline_error"]) and r["headline_error"] <= tol
              for r in ran]
    qual = [r for i, r in enumerate(ran) if all(within[i:])]
    errors = [(r["level"], r["headline_error"]) for r in ran if math.isfinite(r.get("headline_error", math.nan))]
    monotone = not any(e - min(x for _, x in errors[:i]) > RISE_FRACTION * tol
                       for i, (_, e) in enumerate(errors) if i > 0)
    words = []
    if not monotone:
        words.append("non-monotone: the headline error rises again under refinement ("
                     + " → ".join(f"{100 * e:.2g} %" for _, e in errors) + f" at levels "
                     + ", ".join(str(lv) for lv, _ in errors) + ")")
    if not qual:
        if ran:
            last = ran[-1]
            state = (f"{100 * last['headline_error']:.2g} % off" if math.isfinite(last["headline_error"])
                     else "failed" if last["status"] == "failed" else "not checked independently")
            words.insert(0, f"no level qualifies: the finest level that ran (level {last['level']}) is {state}")
        return {"level": -1, "error": math.nan, "time": math.nan, "status": "", "monotone": monotone,
                "message": "; ".join(words)}
    ok = [r for r in qual if r["status"] == "ok"]
    pick = cheapest(ok or qual, time=lambda r: r["wall_time"], level=lambda r: r["level"])
    return {"level": int(pick["level"]), "error": float(pick["headline_error"]), "time": float(pick["wall_time"]),
            "status": pick["status"], "monotone": monotone, "message": "; ".join(words)}


def reference_convergence(richardson: float, finest_step: float) -> float:
    """A reference method's own error estimate on a quantity at its finest level [1]: the Richardson
    estimate when its ladder gives one, else the finest step |Q_K − Q_{K−1}| / |Q_K| (NaN: one level only)."""
    return richardson if math.isfinite(richardson) else finest_step


def reference_note(method: str, estimate: float, tol: float, metric: str) -> str:
    """"reference not converged (...)" when ``estimate`` is not below :data:`REFERENCE_FRACTION` × ``tol``
    ("" when it is)."""
    limit = REFERENCE_FRACTION * tol
    if math.isfinite(estimate) and estimate < limit:
        return ""
    size = f"{100 * estimate:.2g} %" if math.isfinite(estimate) else "unknown (fewer than two levels)"
    return (f"reference not converged: {method}'s own finest-level error in {label(metric)} is {size}, not below "
            f"{100 * limit:.2g} % (a quarter of the tolerance)")
