"""What this process made of one DAE: :class:`CompiledDAE`, the compiled library object of a
:class:`~daeclear.engine.session_base.DAEFunctions`.

A ``DAEFunctions`` is a value (CasADi functions and sizes); what is made of it in a process (its
normalised form, its generated, compiled and loaded IDA library, the ODE form and library of the
non-IDA methods, the forward-sensitivity functions of each width) is kept by a ``CompiledDAE``, made
empty by whoever owns the functions (the assembly's ``Structure``, one per structure key, so the
models of one structure share it) and filled on first use.
:func:`~daeclear.engine.ida_session.open_session` takes either; given bare functions it makes its own,
used once.
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

from .build import BuildResult
from .codegen import NormalizedModel, OdeSpec, build_model_library, normalize_model
from .library import ModelLibrary, OdeLibrary, StaleLibrary
from .sensitivity_functions import SensitivityFunctions, augmented_functions, sensitivity_functions
from .session_base import DAEFunctions
from .sundials import SundialsMismatch

__all__ = ["CompiledDAE"]

log = logging.getLogger("daeclear")


class CompiledDAE:
    """The compiled library object of ``functions``: each part made at its first use, then kept.

    ``normalized()`` and ``library()`` make their parts themselves; ``ode_spec`` and ``ode_library``
    are set by the non-IDA methods (``daeclear.solvers.ode_model``, ``ode_evaluators``), which make
    them from the model. Not a value: one object per owner, whose parts its sessions share.
    """

    __slots__ = ("functions", "_normalized", "_loaded", "_sensitivity", "_stacked", "ode_spec", "ode_library")

    def __init__(self, functions: DAEFunctions) -> None:
        self.functions = functions
        self._normalized: NormalizedModel | None = None
        self._loaded: tuple[ModelLibrary, BuildResult] | None = None
        self._sensitivity: dict[tuple[int, tuple[int, ...]], SensitivityFunctions] = {}
        self._stacked: dict[tuple[int, bool, bool, tuple[int, ...]], CompiledDAE] = {}
        #: the index-1 equations as an ODE (numbers symbolic), made by the non-IDA methods
        self.ode_spec: OdeSpec | None = None
        #: the ODE library loaded for ``ode_spec`` and how it was built
        self.ode_library: tuple[OdeLibrary, BuildResult] | None = None

    def normalized(self) -> NormalizedModel:
        """The functions with column inputs, ``P`` last (:func:`~daeclear.engine.codegen.normalize_model`)."""
        if self._normalized is None:
            self._normalized = normalize_model(self.functions)
        return self._normalized

    def library(self) -> tuple[ModelLibrary, BuildResult]:
        """The IDA library, built (or found in the disk cache) and loaded at the first call; later calls
        report a cache hit that took no time. A damaged or stale library is built again, never run
        (SundialsMismatch if even the fresh build is stale); a failure is raised, and tried again next time."""
        if self._loaded is not None:
            return self._loaded
        clib, build = _load_library(self.functions, self.normalized())
        self._loaded = (clib, dataclasses.replace(build, cache_hit=True, compile_time=0.0, codegen_time=0.0))
        return clib, build

    def sensitivity(self, width: int, extras: tuple[int, ...]) -> SensitivityFunctions:
        """The forward-sensitivity functions for ``width`` parameters with the directional derivatives of
        the extras ``extras`` (:func:`~daeclear.engine.sensitivity_functions.sensitivity_functions`), made at
        the first call for that width and those extras, then kept."""
        key = (width, extras)
        if key not in self._sensitivity:
            self._sensitivity[key] = sensitivity_functions(self.functions, width, extras)
        return self._sensitivity[key]

    def stacked(self, width: int, coupled: bool, block: bool, derivatives: tuple[int, ...]) -> CompiledDAE:
        """The compiled object of the stacked DAE [y; S] for ``width`` parameters
        (:func:`~daeclear.engine.sensitivity_functions.augmented_functions` with these arguments), made at the
        first call for them, then kept with what its sessions load: a run with sensitivities opens it without
        building its functions and generating its source again (most of such a call's set-up)."""
        key = (width, coupled, block, derivatives)
        if key not in self._stacked:
            self._stacked[key] = CompiledDAE(augmented_functions(self.functions, width, coupled=coupled, block=block,
                                                                 derivatives=derivatives))
        return self._stacked[key]

    def __repr__(self) -> str:
        made = [name for name, part in (("normalized", self._normalized), ("library", self._loaded),
                                        ("ode_spec", self.ode_spec), ("ode_library", self.ode_library)) if part]
        return f"<CompiledDAE {self.functions.name!r}: {', '.join(made) or 'nothing made yet'}>"


def _file_id(path: Path) -> tuple[int, int] | None:
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_ino, st.st_mtime_ns


def _remove_if_unchanged(path: Path, seen: tuple[int, int] | None) -> None:
    """Delete a rejected cache entry, unless another process has replaced it meanwhile."""
    if seen is not None and _file_id(path) == seen:
        path.unlink(missing_ok=True)


def _load_library(funcs: DAEFunctions, model: NormalizedModel) -> tuple[ModelLibrary, BuildResult]:
    """Build (or find in the cache) and load the model's library; a damaged or stale one is built again,
    never run (SundialsMismatch if even the fresh build is stale)."""
    build = build_model_library(funcs, model=model)
    seen = _file_id(build.path)
    try:
        return ModelLibrary.load(build.path), build
    except (OSError, StaleLibrary) as exc:
        log.info("daeclear: rebuilding the compiled model %r: %s", model.name, exc)
        _remove_if_unchanged(build.path, seen)
    build = build_model_library(funcs, model=model)
    seen = _file_id(build.path)
    try:
        return ModelLibrary.load(build.path), build
    except StaleLibrary as exc:
        _remove_if_unchanged(build.path, seen)
        raise SundialsMismatch(f"{exc} (even freshly built: the SUNDIALS libraries the library loads are not "
                               "those of the scikit-sundae wheel)") from exc
