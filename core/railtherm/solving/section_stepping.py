"""The time-stepping driver of a pass history at a fixed section, shared by the methods that step a block.

A block around the section (a method's own discretisation: :mod:`railtherm_fdm.history`'s 2-D and 3-D
finite volumes, :mod:`railtherm_fipy.history`'s FiPy cells) supplies a stepper; this driver runs the
passes in windows while a source is over the block (explicit or implicit steps, chosen by cost), the
cooling between them on a ladder of growing steps (explicit or implicit per rung, by cost), the residual
rise of each pass from a source-free side run, and the superposition of one pass's response under a
constant schedule. A block has ``x`` (positions along the rail [m], the section at index ``i0``), ``z``,
``capacity`` (one entry per unknown), ``dt_stab`` (explicit stability limit [s]), ``node_shape`` and
``stepper(x_edges, y_edges, flux, speed, factor, t0)``; the stepper ``explicit``, ``adi`` (source-free
implicit steps), ``implicit_steps``, ``fresh`` and the costs ``heating_cost`` (an implicit heating step in
explicit node updates), ``implicit_cost`` (an implicit cooling step in explicit steps).
"""
from __future__ import annotations

import math
import time as _time
from types import SimpleNamespace

import numpy as np

from ..contract.transient import TransientHistory
from ..physics.pass_history import pass_peaks_and_residual, pass_time_above
from ..references.transient import shifted_sum

__all__ = ["heating_scheme", "cooling_ladder", "schedule_factor", "section_history", "superposed_history",
           "histories_at_section", "theta_steps", "ImplicitSectionStepper", "pass_windows"]


def schedule_factor(tr):
    """The heat-input factor f(t) [1] of the scene's schedule (vectorised); 1 without one."""
    if tr.schedule_time is None:
        return lambda t: np.ones(np.shape(t))
    st, sf = np.asarray(tr.schedule_time, float), np.asarray(tr.schedule_factor, float)
    return lambda t: np.interp(t, st, sf)


def cooling_ladder(span: float, first: float, per_doubling: int) -> list[tuple[float, int]]:
    """(step [s], count) covering ``span``: ``per_doubling`` steps of ``first``, then as many of 2 first,
    4 first, ... (dt/t about 1/(2 per_doubling): few distinct steps, each factorised once), the last rung
    shortened (a whole number of equal steps) to end exactly at span."""
    rungs, total, dt = [], 0.0, first
    while total < span * (1.0 - 1e-12):
        left = span - total
        if per_doubling * dt >= left:
            m = max(1, int(math.ceil(left / dt - 1e-9)))
            rungs.append((left / m, m))
            break
        rungs.append((dt, per_doubling))
        total += per_doubling * dt
        dt *= 2.0
    return rungs


def heating_scheme(requested: str, dt_stab: float, dt_source: float,
                   implicit_cost: float) -> tuple[str, float, str]:
    """The scheme while a source is over the block, its step [s] and the reason.

    "auto": the explicit scheme at ``min(0.9 dt_stab, dt_source)`` when its steps cost at most the implicit
    scheme's at the source's step ``dt_source`` = h/V (one Crank-Nicolson LU solve counted as
    ``implicit_cost`` explicit node updates per node), else the
    implicit one; "explicit" / "implicit" as asked (the explicit step never beyond the stability limit)."""
    dt_exp = min(0.9 * dt_stab, dt_source)
    per_exp, per_imp = 1.0 / dt_exp, implicit_cost / dt_source
    costs = (f"explicit at min(0.9 dt_stab, h/V) = {dt_exp:.3g} s: {per_exp:.3g} node updates per node and second "
             f"of heating; implicit Crank-Nicolson at h/V = {dt_source:.3g} s: {per_imp:.3g} (one solve = "
             f"{implicit_cost:g} updates per node)")
    if requested == "explicit" or (requested == "auto" and per_exp <= per_imp):
        return "explicit", dt_exp, ("asked: " if requested == "explicit" else "cheaper: ") + costs
    return "implicit", dt_source, ("asked: " if requested == "implicit" else "cheaper: ") + costs


def theta_steps(T, t0: float, dt: float, m: int, power, step, sample, width: int, theta: float = 0.5,
                start: int = 0):
    """``m`` theta-scheme steps of ``dt`` [s] from time ``t0`` [s], the first ``start`` backward Euler: the
    loop of every stepper's ``implicit_steps``, the discretisation its own.

    ``power(t)``: the nodal heat input at time t; ``step(T, dt, theta, p_old, p_new)``: the new state;
    ``sample(T)``: the ``width`` values recorded after each step. Returns (T, time reached [s], the recorded
    rows (m, width), their times [s])."""
    out = np.empty((m, width))
    t = t0
    p_old = power(t)
    for i in range(m):
        t1 = t + dt
        p_new = power(t1)
        T = step(T, dt, 1.0 if i < start else theta, p_old, p_new)
        p_old = p_new
        t = t1
        out[i] = sample(T)
    return T, t, out, t - dt * np.arange(m - 1, -1, -1)


class ImplicitSectionStepper:
    """Crank-Nicolson steps (the first ``start`` backward Euler) of a linear section ``C dT/dt + K T = p`` with the
    interface of :func:`section_history` and no explicit steps: one sparse LU per (step size, theta), shared by
    the steppers :meth:`fresh` makes. A method's section gives ``block`` (its ``capacity`` size, ``rows`` and
    ``weights`` of the sampled points), :meth:`_factor` (the LU of ``C/dt + theta K``), :meth:`_rhs` (the right
    side of one step), :meth:`_load` (the nodal heat input at the end of each step) and
    :attr:`cooling_implicit` (what its steps are, for the record)."""

    implicit_cost = 0.0                                 # every cooling rung implicit
    cooling_implicit = ""

    def __init__(self, block, x_edges, flux, speed, factor, t0):
        self.b = block
        self.args = (x_edges, flux, speed)
        self.xe = np.asarray(x_edges, dtype=float)
        self.speed = float(speed)
        self.factor = factor
        self.T = np.zeros(block.capacity.size)
        self.t = t0
        self.times, self.rows = [], []
        self.explicit_steps = 0
        self.adi_steps = 0
        self.implicit = self
        self.cache = {}
        self.solves = 0

    def fresh(self, t0: float):
        """A stepper of the same block and source from t0 [s], state zero (shares the factorisations)."""
        out = type(self)(self.b, *self.args, self.factor, t0)
        out.cache = self.cache
        return out

    def explicit(self, dt, m, arrivals, heated=True):
        raise NotImplementedError(f"{type(self).__name__} steps its section implicitly only")

    def adi(self, dt: float, m: int, start: int = 0):
        """m source-free Crank-Nicolson steps of dt, the first ``start`` backward Euler."""
        self.implicit_steps(dt, m, (), 0.5, start)
        self.adi_steps += m

    def implicit_steps(self, dt: float, m: int, arrivals=(), theta: float = 0.5, start: int = 0):
        """m theta-scheme steps of dt [s] (the first ``start`` backward Euler); heat of the passes arriving at
        ``arrivals`` [s]."""
        b = self.b

        def step(T, dt, th, p_old, p_new):
            key = (float(dt), th)
            if key not in self.cache:
                self.cache[key] = self._factor(dt, th)
            self.solves += 1
            return self.cache[key].solve(self._rhs(T, dt, th, p_old, p_new))
        self.T, self.t, out, times = theta_steps(self.T, self.t, dt, m, self._load(dt, arrivals), step,
                                                 lambda T: np.sum(T[b.rows] * b.weights, axis=1), b.rows.shape[0],
                                                 theta, start)
        self.times.append(times)
        self.rows.append(out)


def pass_windows(count: int, interval: float, before: float, after: float) -> list[tuple[int, int]]:
    """(first pass, last pass) of each stepping window: pass k heats the block from ``k interval - before``
    to ``k interval + after`` [s]; windows that overlap are merged into one."""
    windows, k = [], 0
    while k < count:
        last = k
        while last + 1 < count and (last + 1) * interval - before <= last * interval + after:
            last += 1
        windows.append((k, last))
        k = last + 1
    return windows


def _residuals(time, rise, count: int, interval: float, lead: float, ahead: dict) -> np.ndarray:
    """Residual surface rise [K] of each pass (:func:`section_history`): from the source-free side run where
    the next pass opens a window of its own (``ahead``: pass -> rise), else the last step before the next
    pass's source reaches the section node's dual cell (``lead`` [s] = h/(2V) before its arrival); the last
    pass's at the end of the history."""
    before = np.searchsorted(time, interval * np.arange(1, count + 1) - lead, side="right") - 1
    residual = rise[np.clip(before, 0, time.size - 1), 0]
    for k, value in ahead.items():
        residual[k] = value
    residual[-1] = rise[-1, 0]
    return residual


# one driver for the pass windows (explicit or implicit, by cost) and the cooling between them (explicit or
# implicit per rung of the step ladder, by cost): the phases share the stepper and the cost model
def section_history(block, x_edges, flux, speed: float, tr, interval: float, level: int,
                    requested: str = "auto", y_edges=None):
    """Rise history [K] of the section at the block's output depths: (time (nt,), rise (nt, ndepth),
    residual (count,), diag).

    The residual rise of pass k is the surface rise at (k + 1) interval without pass k + 1: where pass k + 1
    opens a window of its own, a copy of the block at the window's start cooled on source-free (the cooling
    ladder) to that time. The history itself cannot give it: its section node stands for a dual cell the
    next source starts heating half a cell before its leading edge arrives, and the explicit scheme spreads
    that heat a node a step, a numerical forerunner (the exact one is e^(-V d / kappa) at distance d) that
    grows with refinement like h^(-1/2). Where the windows of k and k + 1 overlap (passes a few contact
    durations apart): the rise at the last step ending before pass k + 1 reaches the node's dual cell
    ((k + 1) interval - h/(2V)). After the last pass: at count * interval. The time axis: every step, from 0
    to count * interval."""
    t_start = _time.perf_counter()
    a2 = float(x_edges[-1] - x_edges[0])
    V = float(speed)
    h = float(block.x[block.i0 + 1] - block.x[block.i0])
    W = float(block.x[-1])
    count = int(tr.count)
    n = block.capacity.size
    st = block.stepper(x_edges, y_edges, flux, V, schedule_factor(tr), 0.0)
    heat_scheme, dt_heat, heat_reason = heating_scheme(requested, block.dt_stab, h / V, st.heating_cost)
    n_before = int(math.ceil((W / V) / dt_heat))
    n_after = int(math.ceil(((W + a2) / V) / dt_heat))
    windows = pass_windows(count, interval, n_before * dt_heat, n_after * dt_heat)
    st.t = -n_before * dt_heat
    per_doubling = 2 ** (int(level) + 1)
    rungs_explicit = rungs_implicit = 0
    ahead = {}                                          # pass k -> its residual from the source-free side run

    def cool(span, stepper=st):
        nonlocal rungs_explicit, rungs_implicit
        for i, (dt, m) in enumerate(cooling_ladder(span, dt_heat, per_doubling)):
            m_exp = int(math.ceil(m * dt / (0.9 * block.dt_stab)))
            if m_exp <= st.implicit_cost * m:
                stepper.explicit(m * dt / m_exp, m_exp, (), heated=False)
                rungs_explicit += stepper is st
            else:
                stepper.adi(dt, m, start=2 if rungs_implicit == 0 else 0)
                rungs_implicit += stepper is st
    for first, last in windows:
        w0 = first * interval - n_before * dt_heat
        if st.t < w0 - 1e-15:
            cool(w0 - st.t)
        st.t = w0
        if first > 0:
            # the residual of the pass before: the block cooled on without this pass's source to its arrival
            side = st.fresh(w0)
            side.T = st.T.copy()
            cool(first * interval - w0, side)
            ahead[first - 1] = float(side.rows[-1][-1, 0])
        m = int(round((last * interval + n_after * dt_heat - w0) / dt_heat))
        arrivals = interval * np.arange(first, last + 1)
        if heat_scheme == "explicit":
            st.explicit(dt_heat, m, arrivals)
        else:
            st.implicit_steps(dt_heat, m, arrivals)
    if st.t < count * interval:
        cool(count * interval - st.t)
    time = np.concatenate(st.times)
    rise = np.concatenate(st.rows)
    keep = time > 0
    time = np.concatenate([[0.0], time[keep]])
    rise = np.concatenate([np.zeros((1, rise.shape[1])), rise[keep]])
    residual = _residuals(time, rise, count, interval, 0.5 * h / V, ahead)
    diag = {"nodes": n, "node_shape": block.node_shape, "cell_x": h,
            "first_depth_cell": float(block.z[1]), "block_half_length": W, "block_depth": float(block.z[-1]),
            "stability_limit": block.dt_stab, "heating_scheme": heat_scheme, "heating_step": dt_heat,
            "heating_reason": heat_reason,
            "cooling_rungs_explicit": rungs_explicit, "cooling_rungs_implicit": rungs_implicit,
            "cooling_reason": (f"no source: a ladder of {per_doubling} steps of {dt_heat:.3g} s, 2x, 4x ...; each rung "
                               "explicit at the stability limit when that takes at most "
                               f"{st.implicit_cost:g} steps per rung step, else implicit {st.cooling_implicit}"),
            "explicit_steps": st.explicit_steps, "adi_steps": st.adi_steps, "residual_side_runs": len(ahead),
            "implicit_factorisations": len(st.implicit.cache),
            "implicit_solves": st.implicit.solves, "wall_time_solver": _time.perf_counter() - t_start}
    return time, rise, residual, diag


def superposed_history(block, x_edges, flux, speed: float, tr, interval: float, level: int,
                       requested: str = "auto", y_edges=None):
    """As :func:`section_history` for a schedule constant over the whole history (factor f): the block is
    linear, so one pass stepped to ``count * interval`` (its response R(theta) on fdm's own axis) serves
    every pass, ``f sum_k R(t - k interval)`` (:func:`railtherm.references.transient.shifted_sum`; R linearly
    interpolated between its samples for the earlier passes, on the cooling ladder where dt/t <= 1/8). The
    time axis: in every pass the one-pass axis's times within the interval, every step while the source
    heats the section (1.25 contact durations D), then at most 64 samples per D."""
    count = int(tr.count)
    one = SimpleNamespace(count=1, schedule_time=None, schedule_factor=None, depths=tr.depths,
                          threshold=tr.threshold)
    t1, r1, _, diag = section_history(block, x_edges, flux, speed, one, count * interval, level, requested, y_edges)
    f = 1.0 if tr.schedule_time is None else float(tr.schedule_factor[0])
    offsets = t1[t1 < interval * (1.0 - 1e-12)]
    duration = float(x_edges[-1] - x_edges[0]) / float(speed)
    # every step while the source heats the section (the peaks), then about 64 samples per contact duration
    late = np.nonzero(offsets > 1.25 * duration)[0]
    if late.size > 1:
        every = max(1, int(duration / 64.0 / float(np.median(np.diff(offsets[late[:64]]))) if late.size > 64 else 1))
        keep = np.ones(offsets.size, dtype=bool)
        dense = late[np.diff(offsets, prepend=0.0)[late] < duration / 64.0]
        keep[dense] = False
        keep[dense[::every]] = True
        offsets = offsets[keep]
    time = np.concatenate([k * interval + offsets for k in range(count)] + [[count * interval]])

    def curve(theta):
        return np.stack([np.interp(theta, t1, r1[:, j], left=0.0) for j in range(r1.shape[1])], axis=1)
    rise = f * shifted_sum(time, count, interval, curve)
    h = float(block.x[block.i0 + 1] - block.x[block.i0])
    before = curve(interval * np.arange(1, count + 1) - 0.5 * h / float(speed))[:, 0]
    residual = f * np.cumsum(before)
    residual[-1] = f * curve(interval * np.arange(1, count + 1))[:, 0].sum()
    diag.update({"superposition": True, "superposition_reason": "the schedule is constant: one pass's response, "
                 "stepped to the end of the history, summed over the passes"})
    return time, rise, residual, diag


def histories_at_section(transient, convection, x_edges, y_edges, fluxes, speeds, bodies, bulk, level: int,
                         requested: str, make_block, method: str, neglects: str):
    """The :class:`~railtherm.contract.transient.TransientHistory` of both bodies on the union of their time
    axes, and diagnostics: each heated body's history by :func:`superposed_history` (a constant schedule,
    several passes) or :func:`section_history` on the block ``make_block(speed [m/s], material, convection
    [W/(m^2 K)], duration [s], depths [m])``.

    Parameters
    ----------
    transient : railtherm.input.transient.Transient
        The scene's passes (``count``, ``interval`` [s], resolved), schedule, ``depths`` [m] and
        ``threshold`` [degC].
    convection : float or None
        Heat transfer coefficient of the surface [W/(m^2 K)]; None: 0.
    x_edges, y_edges : array_like or None
        Cell edges of the source grid [m] (``y_edges`` None for a line contact).
    fluxes : sequence of array_like or None
        Each body's flux [W/m^2] on the source grid (None or zeros: the body stays at its bulk temperature).
    speeds : (float, float)
        Each body's surface speed through the contact [m/s].
    bodies : (Material, Material)
        Wheel and rail, handed to ``make_block``.
    bulk : (float, float)
        Bulk temperatures [degC].
    level : int
        Resolution level [1].
    requested : str
        Heating scheme: "auto", "explicit" or "implicit".
    make_block : callable
        The method's block (see above).
    method, neglects : str
        What the block is and what it neglects (diagnostics).
    """
    tr = transient
    count, interval = int(tr.count), float(tr.interval)
    z = np.asarray(tr.depths, dtype=float)
    runs, diag = [], {"transient_passes": count, "transient_interval": interval, "transient_method": method,
                      "transient_neglects": neglects}
    for i, (m, v, q) in enumerate(zip(bodies, speeds, fluxes)):
        if q is None or not np.any(np.asarray(q) != 0):
            runs.append(None)
            continue
        block = make_block(v, m, float(convection or 0.0), count * interval, z)
        constant = tr.schedule_factor is None or len(set(tr.schedule_factor)) == 1
        run = superposed_history if constant and count > 1 else section_history
        t, r, res, d = run(block, x_edges, q, v, tr, interval, level, requested, y_edges)
        runs.append((t, r, res))
        diag.update({f"{('wheel', 'rail')[i]}_history_{k}": val for k, val in d.items()})
    axes = [r[0] for r in runs if r is not None]
    time = np.unique(np.concatenate(axes)) if axes else np.linspace(0.0, count * interval, 21)
    rise = np.stack([np.zeros((time.size, z.size)) if r is None else
                     np.stack([np.interp(time, r[0], r[1][:, j]) for j in range(z.size)], axis=1) for r in runs])
    peak = np.empty((2, count, z.size))
    residual = np.empty((2, count))
    above = np.empty((2, count, z.size))
    for i in range(2):
        p, _ = pass_peaks_and_residual(time, rise[i], count, interval)
        peak[i] = p + bulk[i]
        residual[i] = 0.0 if runs[i] is None else runs[i][2]
        above[i] = pass_time_above(time, rise[i], count, interval, tr.threshold - bulk[i])
    temperature = rise + np.asarray(bulk, dtype=float)[:, None, None]
    diag["transient_time_samples"] = int(time.size)
    return TransientHistory(time=time, z=z, temperature=temperature, peak=peak, residual=residual,
                            time_above=above), diag
