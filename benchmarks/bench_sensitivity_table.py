"""The issue's sensitivity table: forward sensitivities against the plain run and against central differences
at equal accuracy (``python benchmarks/bench_sensitivity.py --table``; the cases and the rule below).

For each case a reference S_ref(t_end) of every position and velocity is computed once, by a run with all 16
sensitivities at ``REFERENCE_RTOL``. An error is then the largest relative sensitivity of the difference, max_ij
|S_ij - S_ref,ij| |p_j| / scale_i (scale_i: the state's largest magnitude over the reference run's rows), over
the same of S_ref, for each parameter j, and the largest over j: the error relative to the response's largest
amplification of a relative change of that parameter. Equal accuracy: each method's cheapest setting whose error
for the first Ns parameters is below ``accuracy``: the sensitivities' loosest rtol of ``SENSITIVITY_RTOLS``, with S
in IDA's error test (the default) and out of it (``SolverOptions(sensitivity_error_test=False)``), each reported;
central differences' loosest rtol of ``FD_RTOLS`` with any relative step h of ``FD_STEPS`` (p +- h |p|, |p| = 1
at 0). Then ``repeats`` rounds time, interleaved, whole ``simulate`` calls on the assembled model (sessions
opened, dy0/dp, the jumps and the output rows included; the libraries compiled in an untimed first call): the
plain run at the sensitivities' rtol, the run with Ns sensitivities, and the 2 Ns + 1 runs of central
differences (the base run and each parameter moved both ways, ``moved_parameter``). Medians; a shared machine:
ratios only.
"""

from __future__ import annotations

import statistics
import time
import warnings
from collections.abc import Callable

import numpy as np

import daeclear as dc
from daeclear.assembly.sensitivity import moved_parameter, parameter_value
from daeclear.results.sensitivity_growth import relative_growth

SLIDER_CRANK = ["clearance.clearance", "clearance.law.restitution", "rod.mass", "slider.mass", "rod.inertia",
                "clearance.material.young", "drive.speed", "B.s_i[0]", "clearance.bearing_radius",
                "clearance.material.poisson", "B.s_j[0]", "clearance.s_j[0]", "gravity[1]", "A.s_j[0]",
                "clearance.s_i[1]", "D.s_i[1]"]  # each moves the response (the crank's mass does not: it is driven)
CHAIN = [f"pin{k}.clearance" for k in range(2, 10)] + [f"link{k}.mass" for k in range(2, 10)]
#: case -> (model factory, t_end, its 16 sensitivity parameters in the order they are taken)
CASES: dict[str, tuple[Callable[[], dc.DAEModel], float, list[str]]] = {
    "fig415-2ms": (lambda: dc.assemble(dc.mechanisms.slider_crank("revolute")), 2e-3, SLIDER_CRANK),
    "fig415-2rev": (lambda: dc.assemble(dc.mechanisms.slider_crank("revolute")), 24e-3, SLIDER_CRANK),  # 5000 rpm
    "chain16": (lambda: dc.assemble(dc.mechanisms.chain(16, rpm=300.0)), 2e-3, CHAIN),
}
WIDTHS = (1, 2, 4, 8, 16)
REFERENCE_RTOL = 1e-10
SENSITIVITY_RTOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
FD_RTOLS = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
FD_STEPS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)


def final(model: dc.DAEModel, t_end: float, rtol: float, names: list[str] | None,
          times: int = 2, may_fail: bool = False, tested: bool = True) -> tuple[dc.Result, float]:
    """One whole simulate call and its wall time (a failed run: SystemExit, or returned with ``may_fail``);
    ``tested=False``: S out of IDA's error test (``SolverOptions(sensitivity_error_test=False)``)."""
    options = None if tested else dc.SolverOptions(sensitivity_error_test=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        start = time.perf_counter()
        result = dc.simulate(model, t_end, rtol=rtol, save=dc.SaveAt(times=np.linspace(0.0, t_end, times),
                                                                    steps=False), sensitivities=names,
                             on_failure="return", options=options)
        wall = time.perf_counter() - start
    if not result.success and not may_fail:
        raise SystemExit(f"bench_sensitivity --table: a run failed: {result.message}")
    return result, wall


def end_sensitivities(result: dc.Result, n: int) -> np.ndarray:
    """S(t_end) of the first ``n`` states (positions and velocities), (n, Ns)."""
    return np.stack([result.sensitivity(name)[-1] for name in result.state_names[:n]])


class Errors:
    """The errors of candidate S(t_end) against the reference, per number of parameters."""

    def __init__(self, model: dc.DAEModel, t_end: float, names: list[str]) -> None:
        self.n = 2 * model.n_q
        ref, _ = final(model, t_end, REFERENCE_RTOL, names, times=201)
        self.S = end_sensitivities(ref, self.n)
        self.scale = np.maximum(np.abs(ref.y[:, :self.n]).max(axis=0), 1e-12)
        self.p = np.array([abs(parameter_value(model, name)) or 1.0 for name in names])

    def of(self, S: np.ndarray, width: int) -> float:
        """The error of ``S`` (n, >= width) for the first ``width`` parameters (NaN anywhere: inf)."""
        diff, ref = S[:, :width] - self.S[:, :width], self.S[:, :width]
        if not np.all(np.isfinite(diff)):
            return float("inf")
        worst = 0.0
        for j in range(width):  # each parameter against its own response (their sizes differ by decades)
            size = relative_growth(ref[None, :, j:j + 1], self.scale, self.p[j:j + 1])[0]
            error = relative_growth(diff[None, :, j:j + 1], self.scale, self.p[j:j + 1])[0]
            worst = max(worst, error / size if size > 0 else (0.0 if error == 0 else float("inf")))
        return worst


def fd_derivatives(model: dc.DAEModel, t_end: float, names: list[str], rtol: float, h: float, n: int) -> np.ndarray:
    """Central differences of the first ``n`` states at t_end, (n, len(names))."""
    columns = []
    for name in names:
        p = parameter_value(model, name)
        step = h * (abs(p) or 1.0)
        runs = [final(moved_parameter(model, name, p + s * step), t_end, rtol, None, may_fail=True)[0] for s in (1, -1)]
        ends = [r.y[-1, :n] if r.success else np.full(n, np.nan) for r in runs]
        columns.append((ends[0] - ends[1]) / (2.0 * step))
    return np.stack(columns, axis=1)


def table(case: str, widths: list[int], accuracy: float, repeats: int) -> None:
    """The table of one case: per Ns the settings that reach ``accuracy``, the medians and the ratios."""
    make, t_end, names = CASES[case]
    model = make()
    errors = Errors(model, t_end, names)
    top = max(widths)
    sens_err: dict[tuple[float, bool], np.ndarray] = {}
    for rtol in SENSITIVITY_RTOLS:  # a run that fails at a loose rtol reaches nothing: error inf
        for tested in (True, False):
            result = final(model, t_end, rtol, names[:top], may_fail=True, tested=tested)[0]
            sens_err[rtol, tested] = (end_sensitivities(result, errors.n) if result.success
                                      else np.full((errors.n, top), np.nan))
    fd = {(rtol, h): fd_derivatives(model, t_end, names[:top], rtol, h, errors.n)
          for rtol in FD_RTOLS for h in FD_STEPS}
    print(f"\n{case}: t_end {t_end * 1e3:g} ms, accuracy {accuracy:g} (against S at rtol {REFERENCE_RTOL:g}), "
          f"{repeats} rounds, medians (shared machine: ratios only); S test: S in IDA's error test (the default) "
          "or out (SolverOptions(sensitivity_error_test=False)); / plain: against the plain run at the same rtol")
    print(f"{'Ns':>3} {'S test':>6} {'rtol':>7} {'error':>8} {'plain s':>9} {'sens s':>9} {'/ plain':>8} {'1+Ns/2':>7} "
          f"{'fd rtol':>8} {'fd h':>6} {'fd error':>9} {'fd s':>9} {'fd / sens':>10}")
    for width in widths:
        picks = {tested: next((r for r in SENSITIVITY_RTOLS if errors.of(sens_err[r, tested], width) <= accuracy),
                              None) for tested in (True, False)}
        fd_pick = next(((r, h) for r in FD_RTOLS for h in FD_STEPS if errors.of(fd[r, h], width) <= accuracy), None)
        chosen = names[:width]
        for tested, pick in picks.items():
            if pick is not None:
                final(model, t_end, pick, chosen, tested=tested)  # compiles this width's library: untimed
        walls: dict[tuple[str, object], list[float]] = {("fd", None): []}
        walls.update({key: [] for tested, pick in picks.items() for key in (("plain", pick), ("sens", tested))})
        for _ in range(repeats):  # interleaved: the plain run at each pick's rtol, each pick, central differences
            for tested, pick in picks.items():
                if pick is not None:
                    walls["plain", pick].append(final(model, t_end, pick, None)[1])
                    walls["sens", tested].append(final(model, t_end, pick, chosen, tested=tested)[1])
            if fd_pick is not None:
                start = time.perf_counter()
                final(model, t_end, fd_pick[0], None)
                fd_derivatives(model, t_end, chosen, fd_pick[0], fd_pick[1], errors.n)
                walls["fd", None].append(time.perf_counter() - start)
        for tested, pick in picks.items():
            label = "in" if tested else "out"
            if pick is None:
                print(f"{width:3d} {label:>6} sensitivities do not reach {accuracy:g} at rtol "
                      f"{SENSITIVITY_RTOLS[-1]:g}")
                continue
            plain, sens = statistics.median(walls["plain", pick]), statistics.median(walls["sens", tested])
            row = (f"{width:3d} {label:>6} {pick:7.0e} {errors.of(sens_err[pick, tested], width):8.1e} {plain:9.4f} "
                   f"{sens:9.4f} {sens / plain:8.1f} {1 + 0.5 * width:7.1f}")
            if fd_pick is None:
                print(f"{row} {'central differences do not reach it':>45}")
                continue
            fd_s = statistics.median(walls["fd", None])
            print(f"{row} {fd_pick[0]:8.0e} {fd_pick[1]:6.0e} {errors.of(fd[fd_pick], width):9.1e} {fd_s:9.4f} "
                  f"{fd_s / sens:10.2f}")
