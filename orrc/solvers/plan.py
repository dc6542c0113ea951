"""The result of one receding-horizon solve."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Plan:
    """An M-step plan: ``inputs`` (M, m), ``states`` (M+1, n) and its value V_M.

    ``value`` is the optimal cost Σ_{j<M} c_j(x̃_j, ũ_j) (+ terminal cost, if any) of
    the problem that was solved. ``success`` and ``status`` report the solver's
    outcome; when ``success`` is False, ``fallback`` says what the inputs are.
    """

    inputs: np.ndarray
    states: np.ndarray
    value: float
    success: bool = True
    status: str = "optimal"
    iterations: int = 0
    solve_time: float = 0.0
    fallback: str | None = None
    extra: dict = field(default_factory=dict)
