"""Controllers: Algorithm 1 (PreviewRHC), Algorithm 2 (EstimateThenControl), Algorithm 3 (MinMaxRHC), the
baselines, and the escalation
policy on solver failure (:mod:`orrc.controllers.failures`, shared by every receding-horizon controller)."""
from .base import Controller, Decision, Observation
from .baselines import LQR, Clairvoyant, ZeroInput
from .failures import FailureLadder
from .gpc import GPC, DisturbanceAction
from .hinf import HInfinity
from .minmax import MinMaxRHC
from .regret_optimal import RegretOptimal
from .preview import PreviewRHC
from .lifted import LiftedRHC
from .estimate import EstimateThenControl, Excitation
from .forecast import LambdaConfident, RobustPreviewRHC

__all__ = ["Controller", "Decision", "Observation", "PreviewRHC", "MinMaxRHC", "LQR", "Clairvoyant", "ZeroInput",
           "FailureLadder", "HInfinity", "GPC", "DisturbanceAction", "RegretOptimal", "LiftedRHC", "EstimateThenControl",
           "Excitation", "LambdaConfident", "RobustPreviewRHC"]
