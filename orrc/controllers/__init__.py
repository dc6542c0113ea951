"""Controllers: Algorithm 1 (PreviewRHC) and the baselines."""
from .base import Controller, Decision, Observation
from .baselines import LQR, Clairvoyant, ZeroInput
from .hinf import HInfinity
from .preview import PreviewRHC

__all__ = ["Controller", "Decision", "Observation", "PreviewRHC", "LQR", "Clairvoyant", "ZeroInput", "HInfinity"]
