"""daeclear: dynamics of planar mechanisms with clearance joints.

Scene --assemble--> DAEModel --simulate--> Result --> analysis | plot | io

This module is the face above every stage (docs/architecture.md): it only gathers their public names.

The public names are imported when first used (PEP 562): ``import daeclear`` and ``daeclear --help``
load no numerical library (CasADi, scipy, h5py, matplotlib); ``daeclear.simulate`` loads what a run
needs. ``python -X importtime -c "import daeclear"`` measures it.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what the lazy names are, for type checkers and readers
    from .studies import analysis
    from .model import loads, mechanisms, profiles
    from .assembly.assemble import DAEModel, assemble
    from .assembly.placement import place
    from .core.errors import (AssemblyError, DaeclearError, DaeclearWarning, DiskFull, Interrupted, OutputError,
                              PhysicsWarning, SceneError, SolveError)
    from .core.events import ContactEvent
    from .results.result import Result, load
    from .contact import Material
    from .model.loads import Expression, Force, Motor, RotationalSpringDamper, SpringDamper, Table, Torque
    from .model.scene import (Body, Driver, Revolute, RevoluteClearance, Scene, Translational,
                              TranslationalClearance)
    from .plot.animate import animate
    from .solvers.save_at import SaveAt
    from .solvers.solver_options import SolverOptions
    from .solvers.dispatch import simulate
    from .studies.sweep import load_sweep, sweep

__version__ = "0.1.0"

__all__ = [
    "AssemblyError", "Body", "ContactEvent", "DAEModel", "DaeclearError", "DaeclearWarning", "DiskFull", "Driver",
    "Interrupted", "Material", "OutputError", "PhysicsWarning", "Result", "Revolute", "RevoluteClearance", "SaveAt",
    "Scene", "SceneError", "SolveError", "SolverOptions", "Translational", "TranslationalClearance", "analysis",
    "animate", "assemble", "load", "load_sweep", "mechanisms", "place", "profiles", "simulate", "sweep",
    # gradients of a response (daeclear.studies.gradient; docs/sensitivities.md)
    "EventTime", "Final", "Integral", "Peak", "gradient",
    # applied loads (daeclear.loads)
    "Expression", "Force", "Motor", "RotationalSpringDamper", "SpringDamper", "Table", "Torque", "loads",
]


_loading: list[str] = []  # non-empty while _load_all runs


def _load_all() -> dict[str, Any]:
    """Every public name, imported at once on the first use of one."""
    from .studies import analysis  # noqa: F401
    from .model import loads, mechanisms, profiles  # noqa: F401
    from .assembly.assemble import DAEModel, assemble  # noqa: F401
    from .assembly.placement import place  # noqa: F401
    from .core.errors import (AssemblyError, DaeclearError, DaeclearWarning, DiskFull, Interrupted,  # noqa: F401
                              OutputError, PhysicsWarning, SceneError, SolveError)
    from .core.events import ContactEvent  # noqa: F401
    from .results.result import Result, load  # noqa: F401
    from .contact import Material  # noqa: F401
    from .model.loads import (Expression, Force, Motor, RotationalSpringDamper, SpringDamper, Table,  # noqa: F401
                              Torque)
    from .model.scene import (Body, Driver, Revolute, RevoluteClearance, Scene, Translational,  # noqa: F401
                              TranslationalClearance)
    from .plot.animate import animate  # noqa: F401
    from .solvers.save_at import SaveAt  # noqa: F401
    from .solvers.solver_options import SolverOptions  # noqa: F401
    from .solvers.dispatch import simulate  # noqa: F401
    from .studies.sweep import load_sweep, sweep  # noqa: F401
    from .studies.gradient import gradient  # noqa: F401
    from .results.objectives import EventTime, Final, Integral, Peak  # noqa: F401
    names = locals()
    public = {name: names[name] for name in __all__}
    globals().update(public)  # bound once: later uses do not come here
    return public


def __getattr__(name: str) -> Any:
    """A public name: the first use imports them all. Another name is a sub-package or module
    (``daeclear.plot``), imported alone (the package's own ``from .. import contact`` comes here too)."""
    if name in __all__ and not _loading:
        _loading.append(name)
        try:
            return _load_all()[name]
        finally:
            _loading.clear()
    if name.startswith("_") or importlib.util.find_spec(f"{__name__}.{name}") is None:
        raise AttributeError(f"module 'daeclear' has no attribute {name!r}")
    return importlib.import_module(f"{__name__}.{name}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
