"""daeclear: dynamics of planar mechanisms with clearance joints.

Scene --assemble--> DAEModel --simulate--> Result --> analysis | plot | io
"""

from __future__ import annotations

# Old module paths, thin aliases for one release (daeclear.old_paths): those `import daeclear` loaded
# before the move are imported first, so that `daeclear.<old>.<name>` keeps working after
# `import daeclear` and the names bound below win over the aliases (the function `sweep` over the
# module `daeclear.sweep`).
from . import old_paths  # noqa: F401  (installs the finder of the old paths)
# the names below are served by the old-path finder (mypy cannot see them)
from . import (  # type: ignore[attr-defined]  # noqa: F401
    accuracy, analysis, automaton, codegen, ida_session, loads, mechanisms, outputs, physics, profiles,
    recorder, result, scene, sweep)

from .studies import analysis  # noqa: F811  (the module of the new path wins over its alias)
from .model import loads, mechanisms, profiles  # noqa: F811
from .assembly.assemble import DAEModel, assemble
from .assembly import placement as _placement  # noqa: F401  (registers Scene.assembled)
from .errors import (AssemblyError, DaeclearError, DaeclearWarning, Interrupted, OutputError, PhysicsWarning,
                     SceneError, SolveError)
from .results.result import ContactEvent, Result, load
from .contact import Material
from .model.loads import Expression, Force, Motor, RotationalSpringDamper, SpringDamper, Table, Torque
from .model.scene import Body, Driver, Revolute, RevoluteClearance, Scene, Translational, TranslationalClearance
from .solver_options import SolverOptions
from .solvers.ida import simulate
# the function `sweep` shadows the module: import names from daeclear.studies.sweep
from .studies.sweep import load_sweep, sweep  # noqa: F811

__version__ = "0.1.0"

__all__ = [
    "AssemblyError", "Body", "ContactEvent", "DAEModel", "DaeclearError", "DaeclearWarning", "Driver",
    "Interrupted", "Material", "OutputError", "PhysicsWarning", "Result", "Revolute", "RevoluteClearance", "Scene",
    "SceneError", "SolveError", "SolverOptions", "Translational", "TranslationalClearance", "analysis", "assemble",
    "load", "load_sweep", "mechanisms", "profiles", "simulate", "sweep",
    # applied loads (daeclear.loads)
    "Expression", "Force", "Motor", "RotationalSpringDamper", "SpringDamper", "Table", "Torque", "loads",
]
