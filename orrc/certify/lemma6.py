"""A search for counterexamples to Lemma 6 (Appendix D) on small linear-quadratic problems.

Lemma 6 of the paper states that along the closed loop of Algorithm 3 (min-max RHC, no
disturbance preview), for every state x and every w ∈ W,

    V_{W,M}(x⁺) - V_{W,M}(x) <= Γ_{W,V} σ(x) + Γ^γ_{W,V} w̄²,      x⁺ = f(x, κ_{W,M}(x), w),
    Γ_{W,V} = ᾱ_W²/((M-1)α_lo) - α_lo,   Γ^γ_{W,V} = γ̄_W (ᾱ_W/((M-1)α_lo) + 1),   w̄² = max_{w∈W} ‖w‖²,

for every pair (ᾱ_W, γ̄_W) of the class V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W w̄². Its proof has a gap (the
saddle-point step J(M^{t+1}, W*) <= J(M̃, W*), and one switching index for every W at once), so the
statement is open. This module tests it where everything is exact: x⁺ = A x + B u + w,
c = xᵀQx + uᵀRu (σ = ‖x‖², α_lo = λ_min(Q)), W a box, n = 1 or 2.

* V_{W,M} is computed exactly by the vertex method of :class:`~orrc.MinMaxRHC` (``method="exact"``,
  certified bounds).
* V_{W,M} is convex (a minimum over U of a maximum of convex quadratics in (x, U)), x⁺ is affine in
  w, so the increment is convex in w and its largest value over W is at a vertex of W: the 2^n
  vertices are checked.
* x runs over a grid (0, then radii log-spaced from 10⁻³ w̄ to ``x_span`` w̄ in ``n_angles``
  directions; V is homogeneous, V(sx; sW) = s²V(x; W), so the grid covers all scales), then a local
  refinement (bounded scalar search for n = 1, Nelder-Mead for n = 2) at the worst grid point.
* the pairs: the *tight* curve ᾱ_W(γ̄_W) = max(λ_max(P_0), α_lo, max_x (V(x) - γ̄_W w̄²)/σ(x)) over the
  grid (P_0 the nominal M-step Riccati matrix, a lower bound on every admissible ᾱ_W) at
  ``n_pairs`` values of γ̄_W, and the *certified* pair of :func:`orrc.certify.minmax_constants`.
  Both sides of the inequality grow with ᾱ_W and γ̄_W, so the tight pairs are the hardest test.

The result is the ratio

    r = max_{x, w, pair} (V_{W,M}(x⁺) - V_{W,M}(x) - Γ_{W,V} σ(x)) / (Γ^γ_{W,V} w̄²),

the factor by which Γ^γ_{W,V} would have to grow for the inequality to hold: r <= 1 means Lemma 6
holds on the points tried, r > 1 is a counterexample (re-checked by :func:`lemma6_recheck` with an
independent solver). :func:`lemma6_case` treats one problem; :func:`lemma6_search` draws
``n_problems`` random problems (seeded) and runs them with :func:`orrc.sweep` (any of its
backends; a progress bar in a live session).

This module holds the search over problems; the single case is computed in
``orrc.certify._lemma6_case`` and rechecked in ``orrc.certify._lemma6_recheck`` (all three
public names are importable from here and from :mod:`orrc.certify`).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .._validate import OrrcValueError, SizeWarning, _describe, as_float, as_int, check_size
from ..costs import QuadraticCost
from ..disturbances import Box, _rng
from ..sweep import sweep
from ..systems import LinearSystem
from ._lemma6_case import RTOL, SOLVE_OPS, Lemma6Case, _solve_ops, lemma6_case
from ._lemma6_recheck import lemma6_recheck

__all__ = ["Lemma6Case", "Lemma6Search", "lemma6_case", "lemma6_search", "lemma6_recheck", "lemma6_problem"]


def lemma6_problem(n: int, M, seed):
    """A random problem of the search for counterexamples to the inequality of Lemma 6 (Appendix D):
    x⁺ = A x + B u + w, c = xᵀQx + uᵀRu, w in a box W.

    A has spectral radius uniform in [0.2, 3] (a random sign for n = 1), B log-uniform in [0.2, 2] in
    magnitude (one input), Q = diag(log-uniform [0.1, 10]), R log-uniform in [10⁻³, 10³], W a box with
    lo_i in [-1, 0], hi_i in [0, 1] (for n = 1, one box in five lies on one side of 0).

    Parameters
    ----------
    n : int
        The state dimension, 1 or 2.
    M : int
        The horizon of the case the problem is drawn for; the draw does not depend on it.
    seed : int, numpy.random.Generator or None
        The seed of the draw (or a generator to draw from).

    Returns
    -------
    tuple of (LinearSystem, QuadraticCost, Box)
        The system, the cost and W.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.certify import lemma6_problem
    >>> system, cost, W = lemma6_problem(1, 3, seed=0)
    >>> bool(0.2 <= abs(system.A[0, 0]) <= 3 and 0.2 <= abs(system.B[0, 0]) <= 2)
    True
    >>> bool(np.all(W.lo < W.hi))
    True
    """
    n = as_int("n", n, minimum=1, maximum=2)
    rng = _rng(seed)
    rho = rng.uniform(0.2, 3.0)
    if n == 1:
        A = np.array([[rng.choice([-1.0, 1.0]) * rho]])
    else:
        A = rng.standard_normal((2, 2))
        A *= rho / max(np.abs(np.linalg.eigvals(A)).max(), 1e-12)
    B = rng.standard_normal((n, 1))
    B *= math.exp(rng.uniform(math.log(0.2), math.log(2.0))) / np.linalg.norm(B)
    Q = np.diag(np.exp(rng.uniform(math.log(0.1), math.log(10.0), n)))
    R = np.array([[math.exp(rng.uniform(math.log(1e-3), math.log(1e3)))]])
    lo, hi = -rng.uniform(0.0, 1.0, n), rng.uniform(0.0, 1.0, n)
    if n == 1 and rng.random() < 0.2:
        lo, hi = 0.3 * hi, hi + rng.uniform(0.1, 1.0, 1)
    hi = np.maximum(hi, lo + 0.05)
    return LinearSystem(A, B), QuadraticCost(Q, R), Box(lo, hi)


def _search_run(problem, seed, n, Ms, n_x, n_angles, n_pairs, x_span, policy="open-loop"):
    rng = _rng(seed)
    M = int(rng.choice(Ms))
    system, cost, W = lemma6_problem(n, M, rng)
    c = lemma6_case(system, cost, M, W, n_x=n_x, n_angles=n_angles, n_pairs=n_pairs, x_span=x_span, policy=policy)
    return {"M": M, "ratio": c.ratio, "ratio_certified": c.ratio_certified, "above_threshold": c.above_threshold,
            "any_above": c.any_above, "points": c.points, "solves": c.solves, "case": c}


@dataclass(repr=False)
class Lemma6Search:
    """The result of :func:`lemma6_search`, a search for counterexamples to the inequality of Lemma 6
    (Appendix D) over random problems.

    Attributes
    ----------
    n : int
        The state dimension of the problems.
    cases : list of Lemma6Case
        One :class:`Lemma6Case` per problem, in draw order.
    table : orrc.sweep.Table
        The table of the runs.
    ratio : float
        The largest r over all problems (r > 1: a counterexample).
    worst : Lemma6Case
        The case of that ratio.
    ratio_above : float
        The largest r among the problems whose worst pair is above Theorem 3's horizon threshold, nan
        if none.
    points, solves : int
        The states tried and the exact min-max solves, in total.
    counterexamples : list of Lemma6Case
        The cases with r > 1.

    Examples
    --------
    The summary of a small search (:func:`lemma6_search`), read from its cases:

    >>> import math
    >>> from orrc import certify
    >>> search = certify.lemma6_search(n=1, n_problems=2, M=2, n_x=3, n_angles=4, n_pairs=5,
    ...                                backend="serial")
    >>> search.worst is max(search.cases, key=lambda case: case.ratio)
    True
    >>> search.points == sum(case.points for case in search.cases)
    True
    >>> math.isnan(search.ratio_above)       # no problem is above Theorem 3's threshold
    True
    """

    n: int
    cases: list
    table: object

    @property
    def ratio(self) -> float:
        return max(c.ratio for c in self.cases)

    @property
    def worst(self) -> Lemma6Case:
        return max(self.cases, key=lambda c: c.ratio)

    @property
    def ratio_above(self) -> float:
        rs = [c.ratio for c in self.cases if c.above_threshold]
        return max(rs) if rs else math.nan

    @property
    def points(self) -> int:
        return sum(c.points for c in self.cases)

    @property
    def solves(self) -> int:
        return sum(c.solves for c in self.cases)

    @property
    def counterexamples(self) -> list:
        return [c for c in self.cases if not c.holds()]

    def __repr__(self):
        return (f"Lemma6Search(n={self.n}, problems={len(self.cases)}, ratio={self.ratio:.4g}, "
                f"counterexamples={len(self.counterexamples)}, points={self.points}, solves={self.solves})")


def lemma6_search(n: int = 1, n_problems: int = 8, M=(2, 3, 4, 6), n_x: int = 20, n_angles: int = 8,
                  n_pairs: int = 40, x_span: float = 1e3, seed: int = 0, backend: str | None = None,
                  client=None, policy: str = "open-loop") -> Lemma6Search:
    """Lemma 6 tested on ``n_problems`` random LQ problems with n states (:func:`lemma6_problem`,
    the horizon drawn from ``M``), each by :func:`lemma6_case`; the largest ratio r over all.

    Parameters
    ----------
    n : 1 or 2 states; n_problems : problems drawn (>= 1).
    M : the horizons to draw from (integers 2..12).
    n_x, n_angles, n_pairs, x_span : the grid of each problem, as in :func:`lemma6_case`.
    seed : the seed of the draws (problem i gets the i-th seed of ``numpy.random.SeedSequence(seed)``,
        whatever the backend).
    backend, client : :func:`orrc.sweep`'s backends ("auto", "serial", "processes", "dask").
    policy : "open-loop" (Algorithm 3 as written) or "feedback" (feedback min-max RHC).

    The size (problems × states × solves × vertex sequences) is estimated and checked first.

    Returns
    -------
    Lemma6Search
        The cases and their summary: the largest ratio r, the worst case, the counterexamples.

    Examples
    --------
    Two problems at M = 2 on a coarse grid (a real search uses the defaults):

    >>> from orrc import certify
    >>> search = certify.lemma6_search(n=1, n_problems=2, M=2, n_x=3, n_angles=4, n_pairs=5,
    ...                                backend="serial")
    >>> len(search.cases), search.points, search.solves
    (2, 76, 228)
    >>> bool(search.ratio == search.worst.ratio <= 1), search.counterexamples
    (True, [])
    """
    n = as_int("n", n, minimum=1, maximum=2)
    if policy not in ("open-loop", "feedback"):
        raise OrrcValueError(f"policy must be 'open-loop' or 'feedback'; got {_describe(policy)}")
    n_problems = as_int("n_problems", n_problems, minimum=1, maximum=100_000)
    Ms = np.atleast_1d(np.asarray(M, dtype=object))
    if Ms.ndim != 1 or Ms.size == 0:
        raise OrrcValueError(f"M must be a horizon or a list of horizons (integers 2..12); got {_describe(M)}")
    Ms = [as_int("M", m, minimum=2, maximum=12) for m in Ms]
    n_x = as_int("n_x", n_x, minimum=3, maximum=10_000)
    n_angles = as_int("n_angles", n_angles, minimum=4, maximum=10_000)
    n_pairs = as_int("n_pairs", n_pairs, minimum=5, maximum=100_000)
    x_span = as_float("x_span", x_span, minimum=1.0, strict_min=True, maximum=1e8)
    states = 41 + n_x * (2 if n == 1 else n_angles)
    N = 2.0 ** (n * (max(Ms) - 1))
    check_size(f"lemma6_search with n_problems={n_problems}, n={n}, M up to {max(Ms)}, n_x={n_x}: about "
               f"{n_problems * states * (1 + 2 ** n)} exact min-max solves of up to {int(N)} vertex sequences",
               ops=n_problems * states * (1 + 2 ** n) * _solve_ops(n, max(Ms), policy),
               nbytes=8.0 * n_problems * states * (n_pairs + 8), hint="lower n_problems, n_x or the horizons M")
    def run(problem, seed):
        return _search_run(problem, seed, n, Ms, n_x, n_angles, n_pairs, x_span, policy)

    with warnings.catch_warnings():   # the size was checked (and warned about) above, with the search's words
        warnings.simplefilter("ignore", SizeWarning)
        table = sweep(run, {"problem": list(range(n_problems))}, seeds=1, seed=seed, backend=backend,
                      client=client, ops_per_call=states * (1 + 2 ** n) * _solve_ops(n, max(Ms), policy))
    return Lemma6Search(n, [row["case"] for row in table], table)
