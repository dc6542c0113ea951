"""Controllers: Algorithm 1 (PreviewRHC), Algorithm 3 (MinMaxRHC) and the baselines."""
from .base import Controller, Decision, Observation
from .baselines import LQR, Clairvoyant, ZeroInput
from .minmax import MinMaxRHC
from .preview import PreviewRHC

__all__ = ["Controller", "Decision", "Observation", "PreviewRHC", "MinMaxRHC", "LQR", "Clairvoyant", "ZeroInput"]
