"""Forecasts of the disturbance: the preview of Eq. (2) when it is not exact.

The paper's controllers see the disturbances w_{t:t+M-1} exactly (Algorithms 1 and 2) or not at
all (Algorithm 3). Between the two, a controller receives at step t a *forecast*
ŵ_{t:t+M-1|t}, and the truth w_t is revealed one step later, with x_{t+1}. A forecast model
issues the forecasts; :func:`orrc.simulate` with ``forecast=`` hands the controller the model's
window instead of the true one, and nothing else (its ``Observation.w_preview`` is the forecast,
``Observation.w_past`` the revealed w_{t-1}).

A model sees what it would see in practice, and, when it is a model *of an error* (an exact
forecast plus noise, a bias, a delay, an adversarial error), the true window it perturbs: that is
how a forecast error of a known size is made for an experiment. The controller never sees the
truth. Models compose by ``+``: the errors add, ``Noisy(0.1) + Bias(0.05)`` is the truth plus
noise plus a bias.

* :class:`Exact`: ŵ_{t+j|t} = w_{t+j} (Algorithm 1's preview);
* :class:`Zero`: ŵ_{t+j|t} = 0 (no preview: what Algorithm 3 plans around);
* :class:`Noisy`: w_{t+j} + ê_{t,j}, ê_{t,j} ~ N(0, (s_f(1 + g_f j))² I), noise growing with the
  lead j;
* :class:`Bias`: w_{t+j} + b;
* :class:`Delay`: w_{t+j-d}, a forecast d steps late (zeros before the start);
* :class:`AR`: a least-squares autoregressive model fitted online on w_{0:t-1}, run forward (it
  never reads the truth);
* :class:`AdversarialError`: w_{t+j} + ê_{t,j} with ‖ê_{t,j}‖ = r_E, pointed against w_{t+j}.

Used by the robust-preview and λ-confident controllers (:mod:`orrc.controllers.forecast`).
"""
from __future__ import annotations

import numpy as np

from ._validate import OrrcValueError, as_array, as_float, as_int

__all__ = ["Forecast", "Exact", "Zero", "Noisy", "Bias", "Delay", "AR", "AdversarialError", "forecast_errors"]


class Forecast:
    """A forecast model: at step t it issues ŵ_{t:t+M-1|t} (the preview of Eq. (2), possibly wrong).

    Subclasses implement :meth:`window`; :meth:`reset` starts a run (a model with a random
    error draws the same errors in every run with the same seed).

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import Bias
    >>> truth = np.ones((3, 1))
    >>> (Bias(0.5) + Bias(0.25)).window(0, np.zeros((0, 1)), truth).ravel()
    array([1.75, 1.75, 1.75])
    """

    name = "forecast"

    def reset(self, n: int) -> None:
        """Start a run with n-dimensional disturbances (the default keeps no state)."""

    def window(self, t: int, past: np.ndarray, truth: np.ndarray) -> np.ndarray:
        """ŵ_{t:t+M-1|t}.

        Parameters
        ----------
        t : int
            The step.
        past : ndarray, shape (t, n)
            The revealed disturbances w_0..w_{t-1} (read-only).
        truth : ndarray, shape (M, n)
            The true window w_t..w_{t+M-1} (read-only); only models of an error read it.

        Returns
        -------
        ndarray, shape (M, n)
            The forecast.
        """
        raise NotImplementedError

    def __add__(self, other: "Forecast") -> "Forecast":
        if not isinstance(other, Forecast):
            return NotImplemented
        return _ErrorSum(self, other)

    def __repr__(self):
        return self.name


class _ErrorSum(Forecast):
    """ŵ = w + Σ_i (ŵ_i − w): the errors of several models added."""

    def __init__(self, *models: Forecast):
        self.models = [p for m in models for p in (m.models if isinstance(m, _ErrorSum) else [m])]
        self.name = " + ".join(m.name for m in self.models)

    def reset(self, n: int) -> None:
        for m in self.models:
            m.reset(n)

    def window(self, t, past, truth):
        out = np.array(truth, dtype=float)
        for m in self.models:
            out += m.window(t, past, truth) - truth
        return out


class Exact(Forecast):
    """The exact preview, ŵ_{t+j|t} = w_{t+j}: Algorithm 1's information pattern.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import Exact
    >>> Exact().window(0, np.zeros((0, 2)), np.arange(4.0).reshape(2, 2))
    array([[0., 1.],
           [2., 3.]])
    """

    name = "exact"

    def window(self, t, past, truth):
        return np.array(truth, dtype=float)


class Zero(Forecast):
    """No information: ŵ_{t+j|t} = 0, the nominal disturbance of a controller without preview.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import Zero
    >>> Zero().window(0, np.zeros((0, 1)), np.ones((2, 1))).ravel()
    array([0., 0.])
    """

    name = "zero"

    def window(self, t, past, truth):
        return np.zeros(np.shape(truth))


class Noisy(Forecast):
    """Gaussian noise growing with the lead: ŵ_{t+j|t} = w_{t+j} + ê_{t,j}, ê_{t,j} ~ N(0, s_j² I),
    s_j = s_f (1 + g_f j).

    The error of lead j at step t is drawn from a generator seeded by (seed, t), so it is the same
    whatever the horizon M (a longer horizon adds leads, it does not redraw the first ones).

    Parameters
    ----------
    scale : float
        s_f >= 0, the standard deviation at lead 0.
    growth : float, default 0
        g_f >= 0, how fast s_j grows with the lead j.
    seed : int, default 0
        The seed of the errors.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import Noisy
    >>> f = Noisy(0.1, growth=1.0, seed=3)
    >>> a = f.window(5, np.zeros((5, 1)), np.zeros((2, 1)))
    >>> b = f.window(5, np.zeros((5, 1)), np.zeros((4, 1)))
    >>> bool(np.array_equal(a, b[:2]))
    True
    """

    def __init__(self, scale: float, growth: float = 0.0, seed: int = 0):
        self.scale = as_float("scale", scale, minimum=0.0)
        self.growth = as_float("growth", growth, minimum=0.0)
        self.seed = as_int("seed", seed, minimum=0)
        self.name = f"noisy(s_f={self.scale:g}, g_f={self.growth:g})"

    def window(self, t, past, truth):
        M, n = truth.shape
        e = np.random.default_rng([self.seed, t]).standard_normal((M, n))
        return truth + (self.scale * (1.0 + self.growth * np.arange(M)))[:, None] * e


class Bias(Forecast):
    """A constant error: ŵ_{t+j|t} = w_{t+j} + b.

    Parameters
    ----------
    b : float or array_like, shape (n,)
        The bias.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import Bias
    >>> Bias([0.1, -0.1]).window(0, np.zeros((0, 2)), np.zeros((1, 2)))
    array([[ 0.1, -0.1]])
    """

    def __init__(self, b):
        self.b = np.atleast_1d(as_array("b", b))
        if self.b.ndim != 1:
            raise OrrcValueError(f"b must be a number or a vector of length n; got shape {self.b.shape}")
        self.name = f"bias({np.array2string(self.b, precision=3)})"

    def window(self, t, past, truth):
        if self.b.size not in (1, truth.shape[1]):
            raise OrrcValueError(f"b must be a number or a vector of length n={truth.shape[1]}; got {self.b.size} entries")
        return truth + self.b


class Delay(Forecast):
    """A late forecast: ŵ_{t+j|t} = w_{t+j-d} (the revealed past where t+j-d < t, zero before w_0).

    Parameters
    ----------
    d : int
        The delay in steps, d >= 0 (0 is the exact preview).

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import Delay
    >>> past, truth = np.array([[1.0], [2.0]]), np.array([[3.0], [4.0]])
    >>> Delay(1).window(2, past, truth).ravel()
    array([2., 3.])
    """

    def __init__(self, d: int):
        self.d = as_int("d", d, minimum=0)
        self.name = f"delay({self.d})"

    def window(self, t, past, truth):
        M, n = truth.shape
        out = np.zeros((M, n))
        for j in range(M):
            k = t + j - self.d
            if k >= t:
                out[j] = truth[k - t]
            elif k >= 0:
                out[j] = past[k]
        return out


class AR(Forecast):
    """A forecaster that learns: the autoregressive model w_k ≈ Σ_{i=1}^p Φ_i w_{k-i} fitted by
    (ridge-regularised) least squares on the revealed w_{0:t-1}, run forward over the window.

    It never reads the true window. Before it has ``min_samples`` equations it forecasts zero (what
    a controller without preview assumes).

    Parameters
    ----------
    order : int, default 2
        p >= 1.
    ridge : float, default 1e-8
        The ridge weight, relative to the data's scale (keeps the fit defined on few samples).
    min_samples : int, optional
        Equations needed before forecasting; default 2 p n.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import AR
    >>> past = np.array([[0.5 ** k] for k in range(10)])   # w_k = 0.5 w_{k-1}
    >>> np.round(AR(order=1).window(10, past, np.zeros((2, 1))).ravel(), 6)
    array([0.000977, 0.000488])
    """

    def __init__(self, order: int = 2, ridge: float = 1e-8, min_samples: int | None = None):
        self.order = as_int("order", order, minimum=1)
        self.ridge = as_float("ridge", ridge, minimum=0.0)
        self.min_samples = None if min_samples is None else as_int("min_samples", min_samples, minimum=1)
        self.name = f"AR({self.order})"

    def coefficients(self, past: np.ndarray) -> np.ndarray | None:
        """[Φ_1 ... Φ_p] (n, p n) fitted on ``past`` (k, n); None with too few samples."""
        k, n = past.shape
        p = self.order
        need = 2 * p * n if self.min_samples is None else self.min_samples
        if k - p < need:
            return None
        Y = past[p:]                                                  # w_k, k = p..t-1
        Z = np.hstack([past[p - i:k - i] for i in range(1, p + 1)])   # [w_{k-1} ... w_{k-p}]
        G = Z.T @ Z
        G[np.diag_indices_from(G)] += self.ridge * max(np.trace(G) / len(G), 1e-300)
        return np.linalg.solve(G, Z.T @ Y).T

    def window(self, t, past, truth):
        M, n = truth.shape
        Phi = self.coefficients(np.asarray(past, dtype=float))
        if Phi is None:
            return np.zeros((M, n))
        p = self.order
        hist = [past[t - i] for i in range(1, p + 1)]                 # w_{t-1}, ..., w_{t-p}
        out = np.empty((M, n))
        for j in range(M):
            out[j] = Phi @ np.concatenate(hist)
            hist = [out[j]] + hist[:-1]
        return out


class AdversarialError(Forecast):
    """An error at the edge of a set, pointed against the truth: ŵ_{t+j|t} = w_{t+j} + ê_{t,j},
    ê_{t,j} = −r_E sign(w_{t+j}) (``norm="inf"``: the box ‖ê‖_∞ <= r_E) or −r_E w_{t+j}/‖w_{t+j}‖
    (``norm="2"``: the ball ‖ê‖ <= r_E).

    It is the largest error of the set that undoes the preview's information (it shrinks, or
    flips, every previewed disturbance); it is not the worst case for a particular controller.

    Parameters
    ----------
    radius : float
        r_E >= 0.
    norm : {"inf", "2"}, default "inf"

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.forecasts import AdversarialError
    >>> AdversarialError(0.3).window(0, np.zeros((0, 2)), np.array([[1.0, -0.2]]))
    array([[0.7, 0.1]])
    """

    def __init__(self, radius: float, norm: str = "inf"):
        self.radius = as_float("radius", radius, minimum=0.0)
        if norm not in ("inf", "2"):
            raise OrrcValueError(f'norm must be "inf" (a box) or "2" (a ball); got {norm!r}')
        self.norm = norm
        self.name = f"adversarial(r_E={self.radius:g}, {norm})"

    def window(self, t, past, truth):
        if self.norm == "inf":
            return truth - self.radius * np.sign(truth)
        size = np.linalg.norm(truth, axis=1, keepdims=True)
        return truth - self.radius * np.divide(truth, size, out=np.zeros_like(truth), where=size > 0)


def forecast_errors(traj) -> np.ndarray:
    """ŵ_{t+j|t} − w_{t+j} of a run with a forecast (:func:`orrc.simulate` with ``forecast=``).

    Parameters
    ----------
    traj : Trajectory
        A run whose ``forecasts`` were recorded.

    Returns
    -------
    ndarray, shape (T, M_w, n)
        The error of lead j at step t.

    Examples
    --------
    >>> import orrc
    >>> from orrc.forecasts import Bias, forecast_errors
    >>> ex = orrc.examples.double_integrator()
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=3)
    >>> w = orrc.disturbances.uniform_ball(L=13, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(ex.system, rhc, ex.x0, w, T=10, forecast=Bias(0.2))
    >>> float(abs(forecast_errors(traj) - 0.2).max()) < 1e-12
    True
    """
    if getattr(traj, "forecasts", None) is None:
        raise OrrcValueError("traj has no forecasts: it was not simulated with forecast=...")
    T, Mw = traj.forecasts.shape[:2]
    truth = np.lib.stride_tricks.sliding_window_view(traj.w_all, Mw, axis=0)[:T].transpose(0, 2, 1)
    return traj.forecasts - truth
