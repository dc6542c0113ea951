"""Lemma 6 tested on one problem: :func:`lemma6_case` and its result :class:`Lemma6Case`.

For one linear-quadratic problem (n = 1 or 2, a box W) the exact value V_{W,M} of the min-max
plan (:class:`~orrc.MinMaxRHC`, vertex method), its increment's worst vertex of W at every state
of a grid (refined locally at the worst one), and the ratio r of :mod:`orrc.certify.lemma6` over
the tight and the certified pairs (ᾱ_W, γ̄_W). The search over random problems is
:mod:`orrc.certify.lemma6`; the independent recheck of a worst point
``orrc.certify._lemma6_recheck``.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .._validate import PY_CALL_OPS, OrrcValueError, _describe, as_float, as_int, check_size
from .._problem import check_problem
from ..controllers.minmax import MinMaxRHC
from ..costs import QuadraticCost
from ..disturbances import Box
from ..solvers.scenario_tree import tree_nodes
from ..systems import LinearSystem
from .minmax import minmax_constants

#: relative tolerance of "r > 1" (the exact method's values are certified to 1e-9 relative)
RTOL = 1e-6
#: operations charged per exact min-max solve on top of its arithmetic: the Python and QP-setup overhead
#: of one ``MinMaxRHC.plan`` (about 3 ms measured on a small problem, 750 numpy calls' worth)
SOLVE_OPS = 750 * PY_CALL_OPS


def _solve_ops(n, M, policy="open-loop"):
    """Operations of one exact solve: the vertex tables' products and ten rounds (open-loop), or the
    conic solve on the scenario tree of 2^n-vertex W (feedback), plus the overhead."""
    if policy == "feedback":
        return 2e4 * float(tree_nodes(2 ** n, M)) * (n + 2) + 3 * SOLVE_OPS
    N = 2.0 ** (n * (M - 1))
    return 20 * N * (M * n) ** 2 + SOLVE_OPS


@dataclass(repr=False)
class Lemma6Case:
    """Lemma 6 tested on one problem (:func:`lemma6_case`).

    ``ratio``: r of :mod:`orrc.certify.lemma6` over the tight pairs (<= 1: the inequality held at every
    point tried); ``ratio_certified``: the same for the certified pair; ``x``, ``w``, ``alpha_hi_W``,
    ``gamma_bar_W``: where the largest r was found (state, vertex of W, pair); ``above_threshold``:
    whether that pair satisfies Theorem 3's M > ᾱ_W²/α_lo² + 1; ``any_above``: whether some tight
    pair does; ``points``: states tried (grid and refinement); ``solves``: min-max problems solved.
    """

    system: LinearSystem
    cost: QuadraticCost
    M: int
    W: Box
    ratio: float
    ratio_certified: float
    x: np.ndarray
    w: np.ndarray
    alpha_hi_W: float
    gamma_bar_W: float
    above_threshold: bool
    any_above: bool
    points: int
    solves: int
    info: dict = field(default_factory=dict)

    def holds(self, rtol: float = RTOL) -> bool:
        """r <= 1 (+ rtol): Lemma 6's inequality held at every state, vertex and pair tried."""
        return bool(self.ratio <= 1.0 + rtol)

    def __repr__(self):
        return (f"Lemma6Case(n={self.system.n}, M={self.M}, ratio={self.ratio:.4g}, "
                f"ratio_certified={self.ratio_certified:.4g}, points={self.points}, solves={self.solves})")


class _Problem:
    """V_{W,M}, κ_{W,M} and the increment's worst vertex for one LQ problem (counts the solves)."""

    def __init__(self, system, cost, M, W, policy="open-loop"):
        self.system, self.cost, self.M, self.W = system, cost, M, W
        self.rhc = MinMaxRHC(system, cost, M, W, method="exact", policy=policy)
        self.verts = W.vertices()
        self.w2 = W.max_norm_sq
        self.alpha_lo = float(cost.alpha_lo)
        self.solves = 0

    def value(self, x):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = self.rhc.plan(np.asarray(x, float))
        self.solves += 1
        if not (p.success and p.certified and np.isfinite(p.value)):
            raise OrrcValueError(f"the exact min-max solve failed at x={np.asarray(x).tolist()} ({p.status}): "
                                 "the problem is too badly scaled for the search")
        return float(p.value), p.inputs[0]

    def increment(self, x):
        """(V(x), max_w V(x⁺) - V(x), the worst vertex w)."""
        x = np.asarray(x, float)
        V, u = self.value(x)
        base = self.system.A @ x + self.system.B @ u
        nxt = [self.value(base + w)[0] for w in self.verts]
        k = int(np.argmax(nxt))
        return V, nxt[k] - V, self.verts[k]


def _gammas(M, alpha_lo, ah, gb):
    """Γ_{W,V}, Γ^γ_{W,V} of Lemma 6 for arrays of pairs."""
    ah, gb = np.asarray(ah, float), np.asarray(gb, float)
    return ah ** 2 / ((M - 1) * alpha_lo) - alpha_lo, gb * (ah / ((M - 1) * alpha_lo) + 1.0)


def _ratios(M, alpha_lo, w2, sig, inc, ah, gb):
    """r for every (pair, state): shape (pairs, states)."""
    G, Gg = _gammas(M, alpha_lo, ah, gb)
    return (np.asarray(inc)[None, :] - G[:, None] * np.asarray(sig)[None, :]) / (Gg[:, None] * w2)


def _grid(n, n_x, n_angles, span, wbar):
    """0, then n_x radii in [1e-3, span] w̄ (log-spaced) in n_angles directions (n = 1: ±1)."""
    radii = wbar * np.geomspace(1e-3, span, n_x)
    if n == 1:
        dirs = np.array([[1.0], [-1.0]])
    else:
        th = 2 * np.pi * np.arange(n_angles) / n_angles
        dirs = np.column_stack([np.cos(th), np.sin(th)])
    return np.vstack([np.zeros(n), (dirs[:, None, :] * radii[None, :, None]).reshape(-1, n)])


def _check_lq(system, cost, M, W):
    check_problem(system, cost, linear=True, quadratic=True, who="lemma6_case")
    if system.n not in (1, 2):
        raise OrrcValueError(f"the Lemma 6 search is exact for n = 1 or 2 states; got a system with n={system.n}")
    if not isinstance(W, Box):
        raise OrrcValueError(f"W must be an orrc.Box (the increment's worst case is at a vertex); got {_describe(W)}")
    if W.n != system.n:
        raise OrrcValueError(f"W must have the system's dimension n={system.n}; got a box of dimension {W.n}")
    if not W.max_norm_sq > 0:
        raise OrrcValueError(f"W must contain a non-zero disturbance (max‖w‖² > 0); got {W!r}")
    if not cost.alpha_lo > 0:
        raise OrrcValueError(f"the cost needs alpha_lo = λ_min(Q) > 0 for Lemma 6; got alpha_lo={cost.alpha_lo}")
    return as_int("M", M, minimum=2, maximum=12)


def lemma6_case(system, cost, M, W, n_x: int = 30, n_angles: int = 12, n_pairs: int = 60,
                x_span: float = 1e3, refine: bool = True, policy: str = "open-loop") -> Lemma6Case:
    """Lemma 6's inequality V_{W,M}(x⁺) - V_{W,M}(x) <= Γ_{W,V} σ(x) + Γ^γ_{W,V} max‖w‖² tested on one
    problem (see :mod:`orrc.certify.lemma6`): the largest ratio r over the grid of states, the vertices
    of W and the tight and certified pairs (ᾱ_W, γ̄_W).

    Parameters
    ----------
    system : an :class:`~orrc.LinearSystem` with n = 1 or 2 states.
    cost : a :class:`~orrc.QuadraticCost` (σ = ‖x‖², α_lo = λ_min(Q) > 0).
    M : the horizon, 2 <= M <= 12.
    W : an :class:`~orrc.Box` of dimension n with max‖w‖² > 0.
    n_x : radii of the grid per direction (>= 3); n_angles : directions for n = 2 (>= 4).
    n_pairs : points of the tight curve (>= 5); x_span : the largest radius, in units of w̄ (> 1).
    refine : refine the worst grid point by a local search.
    policy : "open-loop" (Algorithm 3 as written, V_{W,M}) or "feedback" (feedback min-max,
        V^fb_{W,M}, the controller Lemma 6 is proved for; its r is at most 1 up to the solver's accuracy).

    Returns
    -------
    Lemma6Case
        The largest ratio r (tight and certified pairs), where it was found, and the counts.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2)
    >>> case = certify.lemma6_case(ex.system, ex.cost, 3, orrc.Box(-0.3, 0.3), n_x=4,
    ...                            n_pairs=5, refine=False, policy="feedback")
    >>> case.holds(), case.points
    (True, 9)

    Each state costs 1 + 2^n exact min-max solves of 2^{n(M-1)} vertex sequences; the total is
    estimated and checked first (``orrc.config``'s limits).
    """
    M = _check_lq(system, cost, M, W)
    if policy not in ("open-loop", "feedback"):
        raise OrrcValueError(f"policy must be 'open-loop' or 'feedback'; got {_describe(policy)}")
    n_x = as_int("n_x", n_x, minimum=3, maximum=10_000)
    n_angles = as_int("n_angles", n_angles, minimum=4, maximum=10_000)
    n_pairs = as_int("n_pairs", n_pairs, minimum=5, maximum=100_000)
    x_span = as_float("x_span", x_span, minimum=1.0, strict_min=True, maximum=1e8)
    if not isinstance(refine, bool):
        raise OrrcValueError(f"refine must be True or False; got {_describe(refine)}")
    n = system.n
    states = 1 + n_x * (2 if n == 1 else n_angles) + (40 if refine else 0)
    N = 2.0 ** (n * (M - 1))
    check_size(f"lemma6_case at M={M}, n={n}, n_x={n_x}, n_angles={n_angles}: {states} states × {1 + 2 ** n} "
               f"exact {policy} min-max solves of {int(N)} vertex sequences",
               ops=states * (1 + 2 ** n) * _solve_ops(n, M, policy),
               nbytes=8.0 * (N * M * (n + 2) * 4 + n_pairs * states * 3), hint="lower n_x, n_angles or M")
    prob = _Problem(system, cost, M, W, policy)
    w2, a_lo = prob.w2, prob.alpha_lo
    xs = _grid(n, n_x, n_angles, x_span, math.sqrt(w2))
    rows = [prob.increment(x) for x in xs]
    V = np.array([r[0] for r in rows])
    inc = np.array([r[1] for r in rows])
    sig = np.einsum("ij,ij->i", xs, xs)
    cert = minmax_constants(system, cost, M, W, n_samples=1, policy=policy)
    P0 = float(cert.info["alpha_hi_inf"])
    gamma0 = V[0] / w2
    gbs = gamma0 * (1.0 + np.geomspace(1e-4, 1e4, n_pairs))
    nz = sig > 0
    ahs = np.array([max(P0, a_lo, float(np.max((V[nz] - g * w2) / sig[nz]))) for g in gbs])
    R = _ratios(M, a_lo, w2, sig, inc, ahs, gbs)
    k, i = np.unravel_index(int(np.argmax(R)), R.shape)
    best = [float(R[k, i]), xs[i], rows[i][2], k]
    points = len(xs)
    if refine:
        found = _refine(prob, xs, i, lambda x, inc_x: float(_ratios(M, a_lo, w2, [x @ x], [inc_x],
                                                                         ahs[k:k + 1], gbs[k:k + 1])[0, 0]))
        points += found[3]
        if found[0] > best[0]:
            best = [found[0], found[1], found[2], k]
    r_cert = float(np.max(_ratios(M, a_lo, w2, sig, inc, [cert.alpha_hi_W], [cert.gamma_bar_W])))
    k = best[3]
    above = ahs < a_lo * math.sqrt(M - 1)
    return Lemma6Case(system, cost, M, W, best[0], r_cert, np.asarray(best[1]), np.asarray(best[2]),
                      float(ahs[k]), float(gbs[k]), bool(above[k]), bool(above.any()), points, prob.solves,
                      {"x": xs, "V": V, "increment": inc, "pairs": np.column_stack([gbs, ahs]), "ratios": R,
                       "certified": (cert.alpha_hi_W, cert.gamma_bar_W), "P0": P0, "policy": policy})


def _refine(prob, xs, i, ratio_of):
    """Local search for a larger ratio around grid point i: (r, x, w, evaluations)."""
    from scipy import optimize

    best = [-math.inf, xs[i], None, 0]

    def neg(z):
        x = np.atleast_1d(np.asarray(z, float))
        _, inc, w = prob.increment(x)
        r = ratio_of(x, inc)
        best[3] += 1
        if r > best[0]:
            best[:3] = [r, x.copy(), w]
        return -r

    x0 = xs[i]
    d = np.linalg.norm(xs - x0, axis=1)
    step = float(np.min(d[d > 0]))
    if prob.system.n == 1:
        optimize.minimize_scalar(neg, bounds=(x0[0] - step, x0[0] + step), method="bounded",
                                 options={"xatol": 1e-6 * max(step, 1e-12), "maxiter": 40})
    else:
        simplex = np.array([x0, x0 + [step, 0.0], x0 + [0.0, step]])
        optimize.minimize(neg, x0, method="Nelder-Mead", options={"initial_simplex": simplex, "maxfev": 40,
                                                                  "xatol": 1e-6 * step, "fatol": 1e-9})
    return best
