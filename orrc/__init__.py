"""orrc: online learning robust control (Muthirayan and Khargonekar, 2021).

The package behind the book: systems, costs, disturbances, the paper's
controllers, the closed-loop simulator and the metrics. Plotting lives in
``orrc.viz`` and is imported only by the book.
"""
from ._validate import NonFiniteWarning, OrrcValueError, SizeWarning
from .controllers import (GPC, LQR, Clairvoyant, Controller, Decision, DisturbanceAction, EstimateThenControl, HInfinity,
                          LambdaConfident, LiftedRHC, MinMaxRHC, Observation, PreviewRHC, RegretOptimal,
                          RobustPreviewRHC, ZeroInput)
from .costs import Cost, CostSequence, L1Cost, QuadraticCost, StageCost
from .disturbances import Ball, Box, Polytope
from .metrics import attenuation_ratio, attenuation_regret, dynamic_regret
from .simulate import Trajectory, simulate
from .sweep import SweepError, Table, sweep
from .solvers.plan import Plan, SolverError, SolverWarning
from .systems import LinearSystem, NonlinearSystem, System
from .parametric import LinearParametricSystem, ParametricSystem
from ._progress import progress, working
from . import config, disturbances, examples, forecasts
from . import certify, checks, estimation, theory, tradeoff

__version__ = "0.1.0"

__all__ = [
    "OrrcValueError", "SolverWarning", "SolverError", "SizeWarning", "NonFiniteWarning",
    "System", "LinearSystem", "NonlinearSystem", "ParametricSystem", "LinearParametricSystem",
    "StageCost", "QuadraticCost", "L1Cost", "Cost", "CostSequence",
    "Ball", "Box", "Polytope", "disturbances", "forecasts", "examples",
    "Controller", "Observation", "Decision", "PreviewRHC", "EstimateThenControl", "LiftedRHC", "MinMaxRHC", "LQR",
    "Clairvoyant", "ZeroInput", "HInfinity", "GPC", "DisturbanceAction", "RegretOptimal", "Plan",
    "LambdaConfident", "RobustPreviewRHC",
    "simulate", "Trajectory", "sweep", "Table", "SweepError",
    "attenuation_regret", "attenuation_ratio", "dynamic_regret", "progress",
    "working",
]
