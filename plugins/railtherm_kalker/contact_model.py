"""Model "kalker" as core registers it: one model for the normal and tangential stages.

Core's plugin host keys models by name alone, so the two stage models of this plugin, both named
``kalker`` (:class:`railtherm_kalker.normal_model.KalkerNormal` and
:class:`railtherm_kalker.tangential_model.KalkerTangential`), cannot both be registered. This coupled
model carries the name for both stages and delegates: a chain ``normal = "kalker"`` runs the normal
model, ``tangential = "kalker"`` the tangential one on the patch the plan hands it (the kalker normal
model's, or another normal model's, e.g. core's Hertz patch), and both together run in sequence.
Registering the two stage models directly is a one-line change in :mod:`railtherm_kalker.plugin` once
core keys models by (stage, name).
"""
from __future__ import annotations

from railtherm import Capabilities, CoupledModel, Refused

from .normal_model import KalkerNormal
from .tangential_model import KalkerTangential

__all__ = ["KalkerContact"]


class KalkerContact(CoupledModel):
    """Kalker's exact contact on the half-space, normal and tangential stages: the exact pressure of the
    scene's gap (:class:`railtherm_kalker.normal_model.KalkerNormal`) and the exact steady rolling
    tractions, slip and creep forces (:class:`railtherm_kalker.tangential_model.KalkerTangential`).

    References
    ----------
    .. [1] J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990.
       doi:10.1007/978-94-015-7889-9
    """

    name = "kalker"
    stages = ("normal", "tangential")
    description = ("Kalker's exact contact on the half-space: normal (any gap, Polonsky-Keer CG) and steady "
                   "rolling (semismooth Newton-GMRES), influence coefficients applied by FFT")
    capabilities = Capabilities(
        contacts=frozenset({"ellipse", "line", "gap"}), sources=frozenset({"computed"}),
        tangential=frozenset({"creepage", "full-sliding"}),
        provides=KalkerNormal.capabilities.provides | KalkerTangential.capabilities.provides)
    options = {**KalkerNormal.options, **KalkerTangential.options}

    def supports(self, scene, level):
        why = super().supports(scene, level)
        if why:
            return why
        # the tangential limits are checked when the tangential stage runs (a normal-only chain needs
        # no friction or creepage)
        return KalkerNormal().supports(scene, level)

    def compute(self, scene, level, options, stages, upstream):
        patch = upstream.patch
        if "normal" in stages:
            patch = KalkerNormal().compute_patch(scene, level, options)
        if "tangential" in stages:
            if patch is None:
                raise Refused(f"scene {scene.name!r}: model 'kalker' (tangential) needs a normal stage's patch")
            tang = KalkerTangential()
            why = tang.supports(scene, level)
            if why:
                raise Refused(why, kind="validity")
            normal_diag = patch.diagnostics if "normal" in stages else {}
            patch = tang.compute_tangential(scene, patch, level, options)
            if normal_diag:
                diag = {**{f"normal_{k}": v for k, v in normal_diag.items()}, **patch.diagnostics}
                diag["converged"] = bool(normal_diag.get("converged", True)) and bool(diag.get("converged", True))
                patch = patch.with_tangential(diagnostics=diag)
        return patch, None, None
