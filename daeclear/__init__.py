"""daeclear: dynamics of planar mechanisms with clearance joints.

Scene --assemble--> DAEModel --simulate--> Result --> analysis | plot | io
"""

from __future__ import annotations

from . import analysis, loads, mechanisms, profiles
from .assemble import DAEModel, assemble
from .errors import (AssemblyError, DaeclearError, DaeclearWarning, Interrupted, OutputError, PhysicsWarning, SceneError,
                     SolveError)
from .result import ContactEvent, Result, load
from .contact import Material
from .loads import Expression, Force, Motor, RotationalSpringDamper, SpringDamper, Table, Torque
from .scene import Body, Driver, Revolute, RevoluteClearance, Scene, Translational, TranslationalClearance
from .solve import simulate
from .sweep import load_sweep, sweep  # the function `sweep` shadows the module: import names from daeclear.sweep

__version__ = "0.1.0"

__all__ = [
    "AssemblyError", "Body", "ContactEvent", "DAEModel", "DaeclearError", "DaeclearWarning", "Driver",
    "Interrupted", "Material", "OutputError", "PhysicsWarning", "Result", "Revolute", "RevoluteClearance", "Scene", "SceneError", "SolveError", "Translational",
    "TranslationalClearance", "analysis", "assemble", "load", "load_sweep", "mechanisms", "profiles", "simulate", "sweep",
    # applied loads (daeclear.loads)
    "Expression", "Force", "Motor", "RotationalSpringDamper", "SpringDamper", "Table", "Torque", "loads",
]
