"""Physics checks of a finished run: results no real mechanism could produce are warned of.

A run can succeed and still be meaningless (penetration beyond the clearance, constraint drift, a
contact crossed in one fixed step, a start inside the wall or flying across the play). Each finding
is a record (:func:`record`; keys and limits: docs/reliability.md, section 4) in ``Result.warnings``
and the HDF5 file, also issued as a :class:`daeclear.PhysicsWarning`.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..core.errors import AssemblyError, PhysicsWarning

if TYPE_CHECKING:
    from .dae_model import DAEModel, ExtrasEvaluator

KINDS: tuple[str, ...] = ("penetration", "initial_penetration", "initial_velocity", "constraint_drift",
                          "contact_within_one_step", "missed_contact")

# Limits as fractions of the clearance (translational joints: of the smaller of clearance and corner
# radius; docs/reliability.md). Beyond PENETRATION_FRACTION no contact law (small deformations) holds.
PENETRATION_FRACTION = 1.0
# A run starting deeper than this starts inside the wall (warned).
INITIAL_PENETRATION_FRACTION = 1e-2
# A declared start deeper than this is refused before the run unless allow_penetration=True.
START_PENETRATION_FRACTION = 0.1
# A given y0 may be a computed state in contact (runs reach 20-40 %): refused only beyond ten times
# what the check calls non-physical, a state no run reaches (e.g. y0=zeros).
GIVEN_PENETRATION_FRACTION = 10.0
# A driven mechanism's clearance joint whose sides move apart at t = 0 faster than this fraction of
# the fastest body (and INITIAL_VELOCITY_FLOOR) has velocities inconsistent with the joint.
INITIAL_VELOCITY_FRACTION = 1e-2
INITIAL_VELOCITY_FLOOR = 1e-3  # m/s
# Constraint drift (largest |Phi| of a run) above this fraction of the smallest clearance.
DRIFT_FRACTION = 1e-3
# Gaps closer to zero than this (m) have no reliable sign (an event point, round-off).
GAP_ROUNDING = 1e-12


def checked_channel(name: str) -> bool:
    """Whether :func:`check_run` reads a channel: every ``<pair>.penetration`` and ``constraints.position``
    (the model compiles these alone as its ``checks`` function, so a run is checked without its other channels)."""
    return name.endswith(".penetration") or name == "constraints.position"


def record(kind: str, quantity: str, value: float, limit: float, unit: str, where: str, t: float,
           message: str) -> dict[str, Any]:
    """One warning record (see the module docstring)."""
    return {"kind": kind, "quantity": quantity, "value": float(value), "limit": float(limit), "unit": unit,
            "where": where, "t": float(t), "message": message}


def issue(records: Sequence[dict[str, Any]], stacklevel: int = 3) -> None:
    """Issue every record as a PhysicsWarning (the records stay in the Result)."""
    for rec in records:
        warnings.warn(rec["message"], PhysicsWarning, stacklevel=stacklevel)


def joint_pairs(model: DAEModel, joint: str) -> list[str]:
    """The contact pairs (gap names) of one clearance joint: the joint itself or ``<joint>.<corner>``."""
    return [g for g in model.gap_names if g == joint or g.startswith(joint + ".")]


def check_run(model: DAEModel, t: NDArray[np.float64], y: NDArray[np.float64], channels: dict[str, NDArray[np.float64]],
              y0: NDArray[np.float64] | None, stats: dict[str, Any], session: ExtrasEvaluator | None = None, *,
              from_state: bool = False) -> list[dict[str, Any]]:
    """Every check on a run's output (times ``t``, states ``y``, channels): penetrations, the start
    (``y0``: the declared state at t = 0, None after the chapter's start) and drift; ``session``
    evaluates the constraints; ``from_state``: the run started from a given ``y0`` (contacts at the
    start are no error). Sets ``stats["max_constraint_drift"]``; returns the records (not issued)."""
    out: list[dict[str, Any]] = []
    declared = not from_state  # a restart from a run's state may start in contact
    for name, clearance, corner in model.clearance_joints:
        out += _penetration(model, name, clearance, corner, t, channels, declared)
    if y0 is not None and declared and model.driver_names:
        out += _initial_velocity(model, y0, session)
    out += _drift(model, t, y, channels, stats, session)
    return out


def _worst_drift_row(drift: NDArray[np.float64]) -> int:
    """The row of the largest (finite) constraint drift, the first of equal ones (np.nanargmax, faster)."""
    return int(np.where(np.isnan(drift), -np.inf, drift).argmax())


def key_rows(t: NDArray[np.float64], channels: dict[str, NDArray[np.float64]]) -> NDArray[np.intp]:
    """The rows :func:`check_run` reads: the first, and the worst of every ``<pair>.penetration`` and of
    ``constraints.position`` (the earliest of equal ones); check_run on them finds what it finds on the
    whole output, so a run is checked chunk by chunk (:class:`daeclear.solvers.recorder.Recorder`)."""
    if t.size == 0:
        return np.zeros(0, dtype=np.intp)
    rows = {0}
    for name, values in channels.items():
        if name.endswith(".penetration") and values.size:
            rows.add(int(np.where(np.isfinite(values), values, -np.inf).argmax()))
    drift = channels.get("constraints.position")
    if drift is not None and drift.size and np.isfinite(drift).any():
        rows.add(_worst_drift_row(drift))
    return np.array(sorted(rows), dtype=np.intp)


def _penetration(model: DAEModel, joint: str, clearance: float, corner: float, t: NDArray[np.float64],
                 channels: dict[str, NDArray[np.float64]], declared: bool) -> list[dict[str, Any]]:
    """Worst penetration of the joint over the run, and at t = 0 (``declared``: the start is the scene's)."""
    limit = PENETRATION_FRACTION * (min(clearance, corner) if corner > 0 else clearance)
    basis = "the corner radius" if 0 < corner < clearance else "the clearance"
    out: list[dict[str, Any]] = []
    worst: tuple[float, float, str] | None = None
    start: tuple[float, str] | None = None
    for pair in joint_pairs(model, joint):
        values = channels.get(f"{pair}.penetration")
        if values is None or values.size == 0:
            continue
        finite = np.where(np.isfinite(values), values, -np.inf)
        i = int(np.argmax(finite))
        if worst is None or finite[i] > worst[0]:
            worst = (float(values[i]), float(t[i]), pair)
        if t[0] == 0.0 and (start is None or values[0] > start[0]):
            start = (float(values[0]), pair)
    if declared and start is not None and start[0] > INITIAL_PENETRATION_FRACTION * clearance:
        value, pair = start
        out.append(record(
            "initial_penetration", "penetration", value, INITIAL_PENETRATION_FRACTION * clearance, "m", pair, 0.0,
            f"'{pair}' starts {value:.3g} m inside the wall at t=0 ({value / clearance:.1%} of the clearance "
            f"{clearance:.3g} m): the first contact force is an artefact of the declared positions. Declare "
            "positions with the journal inside its play, or use start='ideal' (clearance joints centred)."))
    if worst is not None and worst[0] > limit:
        value, when, pair = worst
        out.append(record(
            "penetration", "penetration", value, limit, "m", pair, when,
            f"'{pair}' penetrates {value:.3g} m at t={when:.6g} s, more than {basis} ({limit:.3g} m): the contact "
            "deforms by more than the joint's geometry allows, beyond what its contact law describes, and the "
            "result is not physical. Check the contact stiffness, the friction coefficient and the speed (a load "
            "the joint cannot carry), or a tighter rtol."))
    return out


def check_start_penetration(model: DAEModel, y0: NDArray[np.float64], yp0: NDArray[np.float64],
                            session: ExtrasEvaluator | None = None, *, given: bool = False) -> None:
    """Refuse (AssemblyError naming the pair, the depth and the clearance) a start with a contact pair
    deeper in its wall than START_PENETRATION_FRACTION of the clearance: a declaration error whose first contact
    force would be an artificial impact. ``given``: the state is simulate()'s ``y0``
    (GIVEN_PENETRATION_FRACTION)."""
    if not model.clearance_joints:
        return
    channels = model.channels(np.zeros(1), np.asarray(y0)[None, :], np.asarray(yp0)[None, :], session=session)
    for joint, clearance, corner in model.clearance_joints:
        fraction = GIVEN_PENETRATION_FRACTION if given else START_PENETRATION_FRACTION
        limit = fraction * (min(clearance, corner) if corner > 0 else clearance)
        basis = "the corner radius" if 0 < corner < clearance else "the clearance"
        for pair in joint_pairs(model, joint):
            depth = float(channels.get(f"{pair}.penetration", np.zeros(1))[0])
            if depth > limit:
                if given:
                    raise AssemblyError(
                        f"simulate: y0 puts clearance joint '{joint}' in deep penetration: '{pair}' is {depth:.3g} m "
                        f"inside the wall, {depth / clearance:.0%} of the clearance {clearance:.3g} m (a given state "
                        f"may penetrate at most {GIVEN_PENETRATION_FRACTION:g} times {basis}, {limit:.3g} m, "
                        "deeper than any run reaches); give a state from a run of this model (a row of result.y), "
                        "or pass allow_penetration=True to start there anyway.")
                raise AssemblyError(
                    f"scene '{model.scene_name}': clearance joint '{joint}' starts in deep penetration: '{pair}' "
                    f"is {depth:.3g} m inside the wall at t=0, {depth / clearance:.0%} of the clearance "
                    f"{clearance:.3g} m (a declared start may penetrate at most {START_PENETRATION_FRACTION:.0%} "
                    f"of {basis}, {limit:.3g} m); its first contact force would be an artefact of the declared "
                    "positions. Declare the positions with the journal (slider) inside its play, use start='ideal' "
                    "(clearance joints centred), or pass allow_penetration=True to start there anyway.")


def _initial_velocity(model: DAEModel, y0: NDArray[np.float64], session: ExtrasEvaluator | None = None
                      ) -> list[dict[str, Any]]:
    """Speed at which each clearance joint's two sides move apart at t = 0, for driven mechanisms only
    (without a driver a relative velocity is the experiment's initial condition)."""
    if not model.clearance_joints:
        return []
    n = model.n_q
    q, v = np.asarray(y0[:n], dtype=float), np.asarray(y0[n:2 * n], dtype=float)
    _, _, rates = model.constraints(q, v, 0.0, session, ideal=True)
    names = list(model.start_constraint_names)
    fastest = max((math.hypot(v[3 * k], v[3 * k + 1]) for k in range(n // 3)), default=0.0)
    limit = max(INITIAL_VELOCITY_FRACTION * fastest, INITIAL_VELOCITY_FLOOR)
    out: list[dict[str, Any]] = []
    for joint, clearance, _ in model.clearance_joints:
        if f"{joint}.x" in names:  # revolute: the journal centre's velocity relative to the bearing's
            i, j = names.index(f"{joint}.x"), names.index(f"{joint}.y")
            speed = math.hypot(rates[i], rates[j])
        elif f"{joint}.lateral" in names:  # translational: the slider centre across the guide
            speed = abs(float(rates[names.index(f"{joint}.lateral")]))
        else:
            continue
        if speed > limit:
            out.append(record(
                "initial_velocity", "relative speed", speed, limit, "m/s", joint, 0.0,
                f"'{joint}' starts with its two sides moving apart at {speed:.3g} m/s at t=0 (the fastest "
                f"body moves at {fastest:.3g} m/s): the declared velocities are inconsistent with the joint, "
                f"and the journal crosses its {clearance:.3g} m play into an artificial first impact. Declare "
                "velocities of an assembled mechanism, or use start='ideal'."))
    return out


def _drift(model: DAEModel, t: NDArray[np.float64], y: NDArray[np.float64], channels: dict[str, NDArray[np.float64]],
           stats: dict[str, Any], session: ExtrasEvaluator | None = None) -> list[dict[str, Any]]:
    """Largest constraint violation of the run, against DRIFT_FRACTION of the smallest clearance."""
    drift = channels.get("constraints.position")
    if drift is None or drift.size == 0:
        return []
    i = _worst_drift_row(drift) if np.isfinite(drift).any() else 0
    worst = float(drift[i])
    stats["max_constraint_drift"] = worst
    clearance = min((c for _, c, _ in model.clearance_joints), default=math.inf)
    if not worst > DRIFT_FRACTION * clearance:
        return []
    where = "constraints"
    if y.shape[0] > i and model.n_constraints:
        n = model.n_q
        phi = model.constraints(y[i, :n], y[i, n:2 * n], float(t[i]), session)[0]
        where = model.constraint_names[int(np.argmax(np.abs(phi)))]
    return [record(
        "constraint_drift", "constraint violation |Phi|", worst, DRIFT_FRACTION * clearance, "m", where, float(t[i]),
        f"simulate: the constraints drifted by {worst:.2e} m ('{where}' at t={float(t[i]):.6g} s), "
        f"{worst / clearance:.1%} of the smallest clearance ({clearance:.2e} m) "
        f"(formulation={model.formulation!r}); contact times and forces are uncertain by that much. "
        + ("Use formulation='ggl' (drift-free, the default) or a smaller rtol." if model.formulation != "ggl"
           else "Use a smaller rtol."))]


def check_fixed_steps(model: DAEModel, events: Sequence[Any], step: float,
                      missed: Sequence[tuple[float, float, str]]) -> list[dict[str, Any]]:
    """Fixed-step runs: whole contacts shorter than one step, and ``missed`` (t_start, t_end, pair) steps
    over which a gap changed sign without an event."""
    out: list[dict[str, Any]] = []
    onset: dict[str, float] = {}
    short: dict[str, list[tuple[float, float]]] = {}
    for event in events:
        if event.kind == "onset":
            onset[event.pair] = event.t
        elif event.pair in onset:
            duration = event.t - onset.pop(event.pair)
            if duration < step:
                short.setdefault(event.pair, []).append((duration, event.t - duration))
    for pair, found in short.items():
        duration, when = min(found)
        out.append(record(
            "contact_within_one_step", "contact duration", duration, step, "s", pair, when,
            f"'{pair}': {len(found)} contact(s) lasted less than one step ({step:.3g} s), the shortest "
            f"{duration:.3g} s from t={when:.6g} s: the fixed-step scheme crossed the whole contact in one "
            "step and did not resolve its force. Use a step below the contact duration, or method='ida'."))
    by_pair: dict[str, list[tuple[float, float]]] = {}
    for t0, t1, pair in missed:
        by_pair.setdefault(pair, []).append((t0, t1))
    for pair, spans in by_pair.items():
        t0, t1 = spans[0]
        out.append(record(
            "missed_contact", "gap sign changes without an event", len(spans), 0, "", pair, t0,
            f"'{pair}': the gap changed sign within {len(spans)} step(s) without a contact event, first from "
            f"t={t0:.6g} s to t={t1:.6g} s: the fixed-step scheme stepped through a contact. Use a smaller "
            "step, or method='ida'."))
    return out


def sign_changes(model: DAEModel, T: NDArray[np.float64], X: NDArray[np.float64]) -> list[tuple[float, float, str]]:
    """(t_start, t_end, pair) of consecutive points of one segment (no event between them) over which
    a gap changed sign, both ends clear of round-off; ``X`` holds (q, v) rows."""
    roots = model.functions.roots
    if roots is None or T.size < 2:
        return []
    N, n_states = T.size, model.n_states
    Y = np.zeros((N, n_states))
    Y[:, :X.shape[1]] = X
    G = np.array(roots.map(N)(T.reshape(1, -1), Y.T, np.zeros((n_states, N)), model.parameter_values)).reshape(-1, N).T
    sure = np.abs(G) > GAP_ROUNDING
    flips = (np.sign(G[1:]) != np.sign(G[:-1])) & sure[1:] & sure[:-1]
    return [(float(T[k]), float(T[k + 1]), model.gap_names[g]) for k, g in zip(*np.nonzero(flips))]
