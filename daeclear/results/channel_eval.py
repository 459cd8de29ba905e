"""What computes a result's channels from its stored states: the model's output function, in one
vectorised call in the run's backend (bit for bit what the run would compute); a loaded result's
model is rebuilt from its file's scene description (:func:`evaluator_from_parameters`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..assembly.assemble import DAEModel, assemble
from ..assembly.dae_model import EXTRA_OUTPUTS
from ..engine.ida_session import open_session
from ..core.errors import SceneError
from ..core.values import readonly
from ..model.scenefile import scene_from_description

if TYPE_CHECKING:
    from .result import Result

__all__ = ["ModelEvaluator", "RunChannels", "evaluator_from_parameters", "rebuildable"]


class ModelEvaluator:
    """A model's channels and derivatives at stored rows, each call in a session of ``backend`` opened
    for it alone (the run's library, loaded once per process)."""

    def __init__(self, model: DAEModel, backend: str) -> None:
        self.model, self.backend = model, backend

    def _session(self) -> Any:
        return open_session(self.model.compiled, backend=self.backend, rtol=1e-6, atol=1.0,
                            parameters=self.model.parameter_values)

    def channels(self, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray,
                 names: Sequence[str] | None = None) -> Mapping[str, NDArray]:
        """Every channel at the rows (the model's output function, as the run evaluates it); ``names``:
        those alone kept (one call all the same; ``yp`` may be one row, the same for every row)."""
        session = self._session()
        try:
            if names is None:
                return self.model.channels(t, y, yp, switch, session)
            values = self.model.evaluate(EXTRA_OUTPUTS, [t.reshape(-1, 1), y, yp, switch], t.size, session)
            column = self.model.channel_names.index
            return {name: np.ascontiguousarray(values[:, column(name)]) for name in names}
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


class RunChannels:
    """Some channels (``names``) of runs of the models of one structure, read from each run's stored
    rows in one call of the output function (a study reading a few channels of many runs).

    A run kept in memory stores IDA's own states; reading any channel first makes every row consistent
    (multipliers and yp: the run's consistency pass, about twice the output function's cost) and then
    computes every channel. Channels that read neither yp nor the multipliers the pass recomputes (by
    the sparsity of the output function: kinematics, gaps, contact forces) are the same numbers from
    the stored rows: here they are computed from them, bit for bit ``result[name]``; others go through
    the pass as before.
    """

    def __init__(self, model: DAEModel, names: Sequence[str]) -> None:
        missing = [name for name in names if name not in model.channel_names]
        if missing:
            raise SceneError(f"RunChannels: names={missing!r}, must be channels of the model "
                             f"({len(model.channel_names)}: model.channel_names).")
        self.names = tuple(names)
        self.outputs = model.outputs  # the structure's output function (every model of it shares it)
        rows = [model.channel_names.index(name) for name in names]
        self._y = np.array(self.outputs.jac_sparsity(0, 1), dtype=bool)[rows]  # which states each one reads
        self._reads_yp = bool(np.array(self.outputs.jac_sparsity(0, 2), dtype=bool)[rows].any())

    def __call__(self, result: Result, model: DAEModel, backend: str = "auto") -> dict[str, NDArray]:
        """The channels of ``result``, a run of ``model`` in ``backend`` (the run's: its parameters'
        ``simulate.backend``)."""
        if model.outputs is not self.outputs:
            raise SceneError(f"RunChannels: model '{model.scene_name}' is of another structure than the one the "
                             "channels were chosen for; make a RunChannels for it.")
        source = result.channel_source
        if source is None or source.computed or not source.t.size:  # computed already, or given as arrays
            return {name: np.asarray(result[name]) for name in self.names}
        y = source.y if self._y[:, source.recomputed].any() else source.stored_y
        yp = source.yp if self._reads_yp else np.zeros(model.n_states)
        values = ModelEvaluator(model, backend).channels(source.t, y, yp, source.switch, self.names)
        return {name: readonly(values[name]) for name in self.names}


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
