"""Run-size switch and computation limits.

* ``ORRC_QUICK=1`` in the environment shrinks long runs (:func:`quick`, :func:`size`): the same
  chapter source runs at full size in the book and at a reduced size for a quick check of every
  chapter (``make test`` sets it), never a copy.
* ``ORRC_BOOK_BUILD=1``, set when the HTML book is built, says that a chapter is executed for the
  HTML book, not in a live notebook (:func:`book_build`).
* Limits on the size of one computation (:class:`Limits`): before a computation whose memory or
  time grows fast (the exact LQ law at a long horizon, the vertices of a box in many
  dimensions, a worst-case attenuation over a long T, ...) ``orrc`` estimates it and refuses
  it above ``max_bytes`` / ``max_ops`` with an ``orrc.OrrcValueError`` that states the
  estimate and the limit, or warns (``orrc.SizeWarning``) above ``warn_bytes`` / ``warn_ops``.
  Defaults: refuse above 4 GiB or 1e11 operations (about 100 s), warn above 1 GiB or 1e10
  operations (about 10 s). Change them for the session with :func:`set_limits`, for a block
  with ``with orrc.config.limits(max_ops=1e12): ...``, or before start-up with the
  environment variables ``ORRC_MAX_BYTES``, ``ORRC_MAX_OPS``, ``ORRC_WARN_BYTES``,
  ``ORRC_WARN_OPS`` (numbers; ``inf`` switches a limit off). The mechanism is
  ``orrc._validate.check_size``.

.. rubric:: Errors and limits across the package

**Bad input** raises ``orrc.OrrcValueError`` (a ``ValueError``) naming the argument, what was given
and what is allowed: wrong types and shapes, NaN or inf, complex arrays (never silently made real),
empty dimensions (n = 0, m = 0, a 0×0 Q), values out of range, seeds that are not seeds, a controller
built for other dimensions (or, for ``Clairvoyant``, another T) than the simulated system (refused
before the first step). Nothing is reinterpreted: a truth value is ``True`` or ``False``, a count is an
integer (a horizon of 1.5 is refused, not truncated), lists of experiments must have equal lengths,
a warm start must come from a plan of the same horizon. Data are checked once, where they enter:
every row of a ``CostSequence`` (Q_t positive semidefinite, R_t positive definite), a
``NonlinearSystem``'s ``f`` and a ``Cost``'s function are evaluated once at construction (a
``math.sin`` applied to a CasADi symbol traces to NaN and is refused), σ must be finite and ≥ 0.

**Finite input, non-finite result.** No public function returns inf or NaN for finite input
without saying so:

.. list-table::
   :header-rows: 1
   :widths: 50 50

   * - where
     - what happens
   * - the paper's formulas (``orrc.theory``), ``Constants.bound``, the metrics, ``energy``,
       ``QuadraticCost.value``, a plan on the LQ path, the Riccati recursions
     - ``OrrcValueError`` listing the arguments (e.g. ``horizon_threshold(alpha_lo=1e-200,
       alpha_hi=1.0)`` overflows); the formulas take ratios first, so ``alpha_lo = alpha_hi =
       1e-200`` answers (threshold 2)
   * - ``EDMDModel.predict``, ``prediction_error`` on an unstable lifted model over a long horizon
     - one ``orrc.NonFiniteWarning`` naming the first step that overflowed
   * - ``orrc.simulate``: the state or the input becomes inf or NaN (the loop diverged)
     - ``FloatingPointError`` naming the step
   * - ``orrc.simulate``: the state stays finite but c_t, σ or V_M overflows, or a controller
       reports V_M = NaN
     - one ``orrc.NonFiniteWarning`` naming the quantities and the first step; a non-finite V_M is
       marked invalid (``Trajectory.value_valid``), and the metrics and checks refuse the trajectory
   * - ``worst_case_attenuation_limit`` of an unstable loop, ``Constants.gamma_c`` when no pair is
       admissible
     - ``inf`` by design, with a ``reason`` saying why

**Size limits.** The computations estimated before they run, and refused above the limits of
:class:`Limits`:

.. list-table::
   :header-rows: 1
   :widths: 40 60

   * - computation
     - what grows
   * - the exact LQ law at a long horizon (``PreviewRHC``, ``orrc.solvers.lq``)
     - the (n + Mn)² value matrix: about 116 TiB for ``PreviewRHC(M=10**6)`` on the double
       integrator, 1.6e11 operations for M = 2000
   * - the CasADi transcription, the Riccati recursions (``alpha_hi_floor``,
       ``smallest_certified_M``)
     - variables and operations linear in M, Riccati steps
   * - ``Box.vertices()``, the exact min-max method, the finite-horizon game
       (``MinMaxRHC(method="game")``), ``HInfinity`` with a long preview
     - 2^n vertices, 2^(nM) scenarios, game equations in n(M + 1)
   * - ``worst_case_attenuation``, ``worst_case_regret``, the condensed operators
     - (Tn)² matrices and their eigenvalues: 7.5 GiB at T = 5000 with n = 4
   * - ``lemma2_coefficients``, ``sampled_constants``, the disturbance generators and excitation
       signals, ``GPC``'s memory H, ``best_fixed_policy``, EDMD predictions
     - samples, grids and dictionaries
   * - ``orrc.sweep`` (the grid, before any seed is drawn), ``simulate``, ``explore``
     - runs, steps and frames

The estimates are rough (within a small factor, at a nominal 1e9 operations per second); they exist
to stop a many-terabyte allocation or an hour-long loop before it starts.

**Solver failures** of a receding-horizon controller follow one escalation policy (warm start, cold
start, IPOPT, then the shifted previous plan), stop with ``orrc.SolverError`` after ``max_failures``
consecutive failed steps, and issue one ``orrc.SolverWarning`` per run of ``orrc.simulate``; the
policy is described in ``orrc.controllers.failures``.
"""
from __future__ import annotations

import contextlib
import os
from dataclasses import fields, replace

from . import _validate


def quick() -> bool:
    """True when the environment variable ORRC_QUICK is set to 1/true/yes.

    Returns
    -------
    bool
        whether the run sizes are the test sizes.

    Examples
    --------
    >>> import orrc
    >>> orrc.config.quick() in (True, False)
    True
    """
    return os.environ.get("ORRC_QUICK", "").strip().lower() in ("1", "true", "yes")


def size(full: int, quick_size: int) -> int:
    """``full`` normally, ``quick_size`` under ORRC_QUICK=1.

    Parameters
    ----------
    full : the size a reader runs (the book's value).
    quick_size : the size under ``ORRC_QUICK=1``.

    Returns
    -------
    int
        ``quick_size`` when :func:`quick`, else ``full``.

    Examples
    --------
    In a chapter, a hidden cell after the visible ``T = 200`` rebinds it for the test run:

    >>> import orrc
    >>> T = 200
    >>> T = orrc.config.size(T, 40)
    >>> T == (40 if orrc.config.quick() else 200)
    True
    """
    return quick_size if quick() else full


def book_build() -> bool:
    """True when the book's build executes this code: the environment variable ORRC_BOOK_BUILD is
    1/true/yes. Every build of the book sets it (the full book, the quick build of ``make test``,
    the solution-free edition); a live notebook does not have it. :func:`orrc.viz.explore` renders
    its static frames only in a build (or outside a kernel, where there is no live widget), and
    progress bars (:func:`orrc.progress`) stay silent in a build.

    Returns
    -------
    bool
        whether this code runs in a build of the book.

    Examples
    --------
    >>> import orrc
    >>> orrc.config.book_build() in (True, False)
    True
    """
    return os.environ.get("ORRC_BOOK_BUILD", "").strip().lower() in ("1", "true", "yes")


Limits = _validate.Limits          # the record and the limits in force live where check_size reads them
get_limits = _validate.get_limits


def set_limits(**changes) -> Limits:
    """Change some limits for the rest of the session (keywords: the fields of :class:`Limits`);
    returns the previous limits, so ``set_limits(**vars(previous))`` restores them.

    Parameters
    ----------
    **changes : new values of ``max_bytes``, ``max_ops``, ``warn_bytes``, ``warn_ops`` (positive
        numbers; ``math.inf`` switches a limit off).

    Returns
    -------
    Limits
        the limits in force before the call.

    Raises
    ------
    orrc.OrrcValueError
        When a name is not a limit or a value is not a positive number.

    Examples
    --------
    >>> import orrc
    >>> previous = orrc.config.set_limits(max_ops=1e12)
    >>> orrc.config.get_limits().max_ops
    1000000000000.0
    >>> _ = orrc.config.set_limits(**vars(previous))    # restore
    """
    _validate.check_options("limit", changes, [f.name for f in fields(Limits)])
    new = replace(get_limits(), **{k: _validate.limit_value(k, v) for k, v in changes.items()})
    if new.warn_bytes > new.max_bytes or new.warn_ops > new.max_ops:  # a warning threshold above its limit
        new = replace(new, warn_bytes=min(new.warn_bytes, new.max_bytes), warn_ops=min(new.warn_ops, new.max_ops))
    return _validate.use_limits(new)


@contextlib.contextmanager
def limits(**changes):
    """``with orrc.config.limits(max_ops=1e12): ...`` -- other limits inside the block only.

    Yields the limits in force inside the block. ``math.inf`` switches a limit off.

    Parameters
    ----------
    **changes : as for :func:`set_limits`.

    Yields
    ------
    Limits
        the limits in force inside the block.

    Raises
    ------
    orrc.OrrcValueError
        When a name is not a limit or a value is not a positive number.

    Examples
    --------
    >>> import orrc
    >>> with orrc.config.limits(max_ops=1e12) as inside:
    ...     print(inside.max_ops)
    1000000000000.0
    """
    previous = set_limits(**changes)
    try:
        yield get_limits()
    finally:
        _validate.use_limits(previous)


__all__ = ["quick", "size", "book_build", "Limits", "get_limits", "set_limits", "limits"]
