"""Joint wear from a run: what Archard's law needs, read from a Result (issue 33).

:func:`wear_history` turns a run of a revolute clearance joint into the arrays of
:class:`daeclear.contact.wear.WearHistoryArrays`: the normal force, the contact direction in the
bearing's and in the journal's frame, the sliding speed of the contacting material points and the
penetration, at every output time. :func:`daeclear.contact.wear.wear_increment` spreads them over
the worn profile.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..assembly.dae_model import DAEModel
from ..contact.wear import WearHistoryArrays
from ..errors import SceneError
from ..results.result import Result


def _rotate(angle: NDArray[np.float64], point: NDArray[np.float64]) -> NDArray[np.float64]:
    """``A(angle) point`` for each angle: (n, 2)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * point[0] - s * point[1], s * point[0] + c * point[1]], axis=1)


def _cross(omega: NDArray[np.float64], r: NDArray[np.float64]) -> NDArray[np.float64]:
    """``omega x r`` in the plane: (n, 2)."""
    return np.stack([-omega * r[:, 1], omega * r[:, 0]], axis=1)


def wear_history(result: Result, model: DAEModel, joint: str) -> WearHistoryArrays:
    """The contact history of revolute clearance joint ``joint`` in a run of ``model``.

    Contact direction ``n = e / |e|`` (4.4), contact points ``Q_i = P_i + R_i n`` and ``Q_j = P_j + R_j n``
    (4.6), sliding speed the tangential component of ``v_Qj - v_Qi`` with each body's spin (4.9):
    computed here in numpy from the bodies' states, apart from the generated model.
    """
    elements = result.parameters.get("scene", {}).get("elements", {})
    element = elements.get(joint)
    if element is None or element.get("kind") != "RevoluteClearance":
        names = [name for name, e in elements.items() if e.get("kind") == "RevoluteClearance"]
        raise SceneError(f"wear_history: joint={joint!r}, must be a revolute clearance joint of the run "
                         f"({', '.join(names) or 'none'}).")
    bearing, journal = element["body_i"], element["body_j"]
    s_i, s_j = model.parameter(f"{joint}.s_i"), model.parameter(f"{joint}.s_j")
    r_i = float(model.parameter(f"{joint}.bearing_radius")[0])
    r_j = float(model.parameter(f"{joint}.journal_radius")[0])
    clearance = float(model.parameter(f"{joint}.clearance")[0])

    def body(name: str) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        if name == "ground":
            zero = np.zeros(result.t.size)
            return np.zeros((result.t.size, 2)), zero, np.zeros((result.t.size, 2)), zero
        return (np.stack([result[f"{name}.x"], result[f"{name}.y"]], axis=1), np.asarray(result[f"{name}.phi"]),
                np.stack([result[f"{name}.vx"], result[f"{name}.vy"]], axis=1), np.asarray(result[f"{name}.omega"]))

    (x_i, phi_i, v_i, w_i), (x_j, phi_j, v_j, w_j) = body(bearing), body(journal)
    arm_i, arm_j = _rotate(phi_i, s_i), _rotate(phi_j, s_j)
    e = (x_j + arm_j) - (x_i + arm_i)
    distance = np.hypot(e[:, 0], e[:, 1])
    n = e / np.maximum(distance, 1e-300)[:, None]
    tangent = np.stack([-n[:, 1], n[:, 0]], axis=1)
    v_qi = v_i + _cross(w_i, arm_i + r_i * n)
    v_qj = v_j + _cross(w_j, arm_j + r_j * n)
    slip = np.sum((v_qj - v_qi) * tangent, axis=1)
    direction = np.arctan2(n[:, 1], n[:, 0])
    return WearHistoryArrays(
        t=np.asarray(result.t, dtype=float), force=np.asarray(result[f"{joint}.normal_force"], dtype=float),
        angle_bearing=np.unwrap(direction - phi_i), angle_journal=np.unwrap(direction - phi_j),
        slip_speed=slip, penetration=np.clip(distance - clearance, 0.0, None))
