"""Controllers: Algorithm 1 (PreviewRHC) and the baselines."""
from .base import Controller, Decision, Observation
from .baselines import LQR, Clairvoyant, ZeroInput
from .gpc import GPC, DisturbanceAction
from .hinf import HInfinity
from .regret_optimal import RegretOptimal
from .preview import PreviewRHC

__all__ = ["Controller", "Decision", "Observation", "PreviewRHC", "LQR", "Clairvoyant", "ZeroInput", "HInfinity", "GPC", "DisturbanceAction",
           "RegretOptimal"]
