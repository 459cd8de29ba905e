"""Old module paths (before the sub-packages) as thin aliases for one release.

``import daeclear.scene`` (or ``from daeclear.scene import Body``) still works: a finder at the front
of ``sys.meta_path`` answers for each old path (no module lives there any more) with a module that
re-exports the public names of the module's new place and whose docstring says where it moved. At
the front, so that an editable install of an older tree cannot answer first. Written by
tools/restructure.py.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import types

#: Old module path -> its new place.
OLD_PATHS: dict[str, str] = {
    "daeclear.accuracy": "daeclear.studies.accuracy",
    "daeclear.analysis": "daeclear.studies.analysis",
    "daeclear.animate": "daeclear.plot.animate",
    "daeclear.automaton": "daeclear.assembly.automaton",
    "daeclear.codegen": "daeclear.engine.codegen",
    "daeclear.ida_session": "daeclear.engine.ida_session",
    "daeclear.loads": "daeclear.model.loads",
    "daeclear.mechanisms": "daeclear.model.mechanisms",
    "daeclear.outputs": "daeclear.results.outputs",
    "daeclear.physics": "daeclear.solvers.physics",
    "daeclear.profiles": "daeclear.model.profiles",
    "daeclear.readings": "daeclear.model.readings",
    "daeclear.recorder": "daeclear.solvers.recorder",
    "daeclear.response_metrics": "daeclear.studies.response_metrics",
    "daeclear.result": "daeclear.results.result",
    "daeclear.scene": "daeclear.model.scene",
    "daeclear.stability": "daeclear.studies.stability",
    "daeclear.style": "daeclear.plot.style",
    "daeclear.sweep": "daeclear.studies.sweep",
}


class OldPathFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds and loads the alias modules of :data:`OLD_PATHS`."""

    def find_spec(self, fullname: str, path: object = None, target: object = None
                  ) -> importlib.machinery.ModuleSpec | None:
        return importlib.util.spec_from_loader(fullname, self) if fullname in OLD_PATHS else None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> None:
        return None  # a plain module

    def exec_module(self, module: types.ModuleType) -> None:
        new = importlib.import_module(OLD_PATHS[module.__name__])
        names = [name for name, value in vars(new).items()
                 if not name.startswith("_") and not isinstance(value, types.ModuleType)]
        module.__doc__ = f"Moved to {new.__name__}; this old path stays as a thin alias for one release."
        module.__dict__.update({name: getattr(new, name) for name in names})
        module.__dict__["__all__"] = names


if not any(isinstance(finder, OldPathFinder) for finder in sys.meta_path):
    sys.meta_path.insert(0, OldPathFinder())
