"""What computes a result's channels from its stored states: the model's output function, in one
vectorised call in the run's backend (bit for bit what the run would compute); a loaded result's
model is rebuilt from its file's scene description (:func:`evaluator_from_parameters`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from numpy.typing import NDArray

from ..assembly.assemble import DAEModel, assemble
from ..engine.ida_session import open_session
from ..core.errors import SceneError
from ..model.scenefile import scene_from_description

__all__ = ["ModelEvaluator", "evaluator_from_parameters", "rebuildable"]


class ModelEvaluator:
    """A model's channels and derivatives at stored rows, each call in a session of ``backend`` opened
    for it alone (the run's library, loaded once per process)."""

    def __init__(self, model: DAEModel, backend: str) -> None:
        self.model, self.backend = model, backend

    def _session(self) -> Any:
        return open_session(self.model.compiled, backend=self.backend, rtol=1e-6, atol=1.0,
                            parameters=self.model.parameter_values)

    def channels(self, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> Mapping[str, NDArray]:
        """Every channel at the rows (the model's output function, as the run evaluates it)."""
        session = self._session()
        try:
            return self.model.channels(t, y, yp, switch, session)
        finally:
            session.close()

    def consistent(self, t: NDArray, y: NDArray, switch: NDArray) -> tuple[NDArray, NDArray]:
        """(y, yp) at the rows by the run's own consistency pass: multipliers and accelerations from q
        and v with each row's switch vector (q and v kept; rows made consistent before come back equal)."""
        model, session = self.model, self._session()
        try:
            if session.set_layout(model.layout(project=model.formulation == "ggl")):
                y_out, yp_out, _ = session.report(t, y, switch, channels=False)
                return y_out, yp_out
            return model.consistent_state(t, y, model.term_forces_rows(t, y, switch, session), session)
        finally:
            session.close()


def rebuildable(parameters: Mapping[str, Any]) -> bool:
    """Whether a result's model can be rebuilt from its parameters alone (the scene from its
    description: not when an element holds a value that is not plain data, e.g. a Python callable)."""
    try:
        scene_from_description(parameters["scene"])
    except (SceneError, KeyError, TypeError, ValueError):
        return False
    return all(key in parameters for key in ("formulation", "alpha", "beta", "track_work"))


def evaluator_from_parameters(parameters: Mapping[str, Any]) -> ModelEvaluator:
    """The channels of a result file's states: its model rebuilt from the file's parameters (scene
    description, formulation, the GGL/Baumgarte numbers, track_work) in the run's backend."""
    scene = scene_from_description(parameters["scene"])
    formulation = str(parameters["formulation"])
    baumgarte = ({"alpha": float(parameters["alpha"]), "beta": float(parameters["beta"])}
                 if formulation == "index1" else {})
    model = assemble(scene, formulation, track_work=bool(parameters["track_work"]), **baumgarte)
    return ModelEvaluator(model, str(parameters.get("simulate", {}).get("backend", "auto")))
