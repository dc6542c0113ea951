"""Controllers: Algorithm 1 (PreviewRHC), Algorithm 2 (EstimateThenControl), the baselines."""
from .base import Controller, Decision, Observation
from .baselines import LQR, Clairvoyant, ZeroInput
from .preview import PreviewRHC
from .lifted import LiftedRHC
from .estimate import EstimateThenControl, Excitation

__all__ = ["Controller", "Decision", "Observation", "PreviewRHC", "LQR", "Clairvoyant", "ZeroInput", "LiftedRHC",
           "EstimateThenControl", "Excitation"]
