"""The arguments of one step of ``PreviewRHC`` (Algorithm 1), checked: the state x, the preview
window w_{t:t+M-1} (its unseen rows padded with zeros), the cost parameters and the warm start.

:class:`_StepArguments` holds these checks for :class:`~orrc.controllers.preview.PreviewRHC`, which
inherits them; they read the controller's ``system``, ``M``, ``preview_w``, ``cost`` and ``_default_P``.
"""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_array
from ..solvers.plan import Plan


class _StepArguments:
    """The checks of one step's arguments of :class:`~orrc.controllers.preview.PreviewRHC`."""

    def _check_preview(self, x, w_preview, cost_params):
        n = self.system.n
        x = as_array("x", x, (n,))
        w_preview = as_array("w_preview", w_preview)
        if w_preview.ndim == 1 and n == 1:
            w_preview = w_preview[:, None]
        k = self.preview_w
        if w_preview.ndim != 2 or w_preview.shape[1] != n or w_preview.shape[0] < k:
            want = f"(M, n) = ({self.M}, {n}) (at least M rows)" if k == self.M else \
                f"(k, n) = ({k}, {n}) (at least preview_w = k rows)"
            raise OrrcValueError(f"w_preview must have shape {want}; got shape {w_preview.shape}")
        w_preview = self._pad(w_preview[:k])
        if cost_params is None:
            P = self._default_P
        else:
            P = self.cost.check_params(cost_params)
            if P.shape[0] < self.M:
                raise OrrcValueError(
                    f"cost_params must have at least M={self.M} rows; got shape {P.shape}")
            P = P[: self.M]
        return x, w_preview, P

    def _pad(self, W):
        """The M-row disturbance of the plan: the k seen rows, zeros for the unseen ones."""
        if len(W) == self.M:
            return W
        out = np.zeros((self.M, self.system.n))
        out[:len(W)] = W
        return out

    def _check_warm_start(self, warm_start):
        if warm_start is None:
            return None
        if not isinstance(warm_start, Plan):
            raise OrrcValueError(f"warm_start must be a Plan (the result of plan()) or None; got "
                                 f"{type(warm_start).__name__}")
        M, n, m = self.M, self.system.n, self.system.m
        U = as_array("warm_start.inputs", warm_start.inputs, (M, m))
        X = as_array("warm_start.states", warm_start.states, (M + 1, n))
        return U, X
