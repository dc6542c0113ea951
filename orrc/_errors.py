"""The error and the warnings of bad or large input: :class:`OrrcValueError`, :class:`SizeWarning`,
:class:`NonFiniteWarning`. Re-exported by ``orrc._validate`` (and :mod:`orrc`).
"""
from __future__ import annotations


class OrrcValueError(ValueError):
    """Bad input to an ``orrc`` function (a ``ValueError`` subclass).

    Raised for input of the wrong type, shape or range, non-finite or complex input, empty
    dimensions, and computations too large for the limits of ``orrc.config`` (the message
    then states the estimate and the limit).

    Examples
    --------
    >>> import orrc
    >>> try:
    ...     orrc.LinearSystem([[1.0, 0.1], [0.0, 1.0]], [[0.0], [0.1], [1.0]])
    ... except orrc.OrrcValueError as err:
    ...     print(err)
    B must have shape (2, m) with m >= 1 to match A of shape (2, 2); got shape (3, 1)
    """


class SizeWarning(UserWarning):
    """A computation is large (above ``orrc.config`` 's warning thresholds) but allowed.

    Examples
    --------
    A computation above the warning threshold runs, and says how large it is:

    >>> import warnings
    >>> import orrc
    >>> with (orrc.config.limits(warn_bytes=1e3),
    ...       warnings.catch_warnings(record=True) as caught):
    ...     warnings.simplefilter("always")
    ...     vertices = orrc.Box(-1.0, 1.0, n=8).vertices()
    >>> vertices.shape, [w.category.__name__ for w in caught]
    ((256, 8), ['SizeWarning'])
    """


class NonFiniteWarning(RuntimeWarning):
    """A result overflowed (inf or NaN) although the input was finite; the message says where.

    Examples
    --------
    An unstable loop whose state stays finite while its stage costs overflow:

    >>> import warnings
    >>> import numpy as np
    >>> import orrc
    >>> ex = orrc.examples.scalar_unstable(A=1e100)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     traj = orrc.simulate(ex.system, orrc.ZeroInput(1, ex.cost), [1.0],
    ...                          np.zeros((3, 1)), T=3)
    >>> [w.category.__name__ for w in caught]
    ['NonFiniteWarning']
    """
