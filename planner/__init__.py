"""The reactive step generator (RSG) of the paper, as a library: pure NumPy, no simulator.

Build a :class:`PlannerConfig` (the paper's point mass by default), make a
:class:`ReactiveStepGenerator` from it, and call it every control tick with a
:class:`MeasuredState`; it returns a :class:`PlannerOutput` (ZMP, hdot, next step and
its time, the Lyapunov level). ``examples/`` shows it in a loop.
"""

from planner.exceptions import ParameterError, RsgError, StepQpError
from planner.lyapunov import LyapunovDesign
from planner.parameters import (
    CONTROLLERS,
    Constraints,
    GaitParameters,
    LipmModel,
    PlannerConfig,
    RsgParameters,
)
from planner.reference_model import ReferenceModel
from planner.step_generator import ReactiveStepGenerator
from planner.types import Foothold, MeasuredState, PlannerOutput, Push, StepEvent

__all__ = [
    "CONTROLLERS",
    "Constraints",
    "Foothold",
    "GaitParameters",
    "LipmModel",
    "LyapunovDesign",
    "MeasuredState",
    "ParameterError",
    "PlannerConfig",
    "PlannerOutput",
    "Push",
    "ReactiveStepGenerator",
    "ReferenceModel",
    "RsgError",
    "RsgParameters",
    "StepEvent",
    "StepQpError",
]
