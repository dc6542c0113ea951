"""Excitation signals for the estimation phase of Algorithm 2 (its "control for estimation").

Each returns an (N, m) array of inputs with |u_{k,i}| <= ``amplitude`` (the bounded excitation
of Assumption (iv) of Section 5.2) and takes a ``seed`` (an int or a ``numpy.random.Generator``):

* :func:`gaussian` -- i.i.d. N(0, std²) clipped to ±amplitude;
* :func:`prbs` -- a pseudo-random binary sequence ±amplitude: a maximum-length shift-register
  sequence (``scipy.signal.max_len_seq``) from a seeded initial state, each input its own shift;
  ``hold`` repeats each bit (more low-frequency content);
* :func:`multisine` -- a sum of sinusoids with random phases, scaled so its peak is the amplitude.

Persistent excitation (the rank condition of the estimators) needs enough distinct values: a
PRBS or Gaussian input excites every order; a multisine with k frequencies excites order 2k.
"""
from __future__ import annotations

import math

import numpy as np

from .._validate import OrrcValueError, as_float, as_int, as_seed, check_size

__all__ = ["gaussian", "prbs", "multisine"]

KINDS = ("gaussian", "prbs", "multisine")


def _rng(seed):
    return as_seed("seed", seed)


def _dims(N, m, amplitude, terms: int = 1):
    """N, m and the amplitude checked, and the (N, m) signal's size estimated before it is built
    (``terms``: the work per entry, e.g. the number of sinusoids of a multisine)."""
    N, m = as_int("N", N, minimum=1), as_int("m", m, minimum=1)
    amplitude = as_float("amplitude", amplitude, minimum=0.0, strict_min=True)
    check_size(f"an excitation signal of N={N} steps and m={m} inputs", nbytes=4 * 8.0 * N * m + 8.0 * N * terms,
               ops=20.0 * N * m * terms, hint="lower N")
    return N, m, amplitude


def gaussian(N: int, m: int, amplitude: float = 1.0, std: float | None = None, seed=None) -> np.ndarray:
    """u_k ~ N(0, std² I) i.i.d., clipped to [-amplitude, amplitude] (default std = amplitude/2).

    Parameters
    ----------
    N : the number of steps.
    m : the number of inputs.
    amplitude : the clipping bound.
    std : the standard deviation (default amplitude / 2).
    seed : a seed.

    Returns
    -------
    numpy.ndarray
        (N, m), row k is u_k, with max |u| <= amplitude.

    Raises
    ------
    orrc.OrrcValueError
        When N or m is not an integer >= 1, or a size is out of range.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc import estimation
    >>> u = estimation.gaussian(100, 1, amplitude=1.0, seed=0)
    >>> u.shape, bool(np.abs(u).max() <= 1.0)
    ((100, 1), True)
    """
    N, m, amplitude = _dims(N, m, amplitude)
    std = amplitude / 2 if std is None else as_float("std", std, minimum=0.0, strict_min=True)
    return np.clip(std * _rng(seed).standard_normal((N, m)), -amplitude, amplitude)


def prbs(N: int, m: int, amplitude: float = 1.0, hold: int = 1, seed=None) -> np.ndarray:
    """A pseudo-random binary sequence u_{k,i} = ±amplitude (maximum-length, period 2^b - 1).

    The register length b is the smallest with 2^b - 1 >= ceil(N/hold) (at least 5); the
    initial register state comes from ``seed`` (never all zeros) and input i starts at a random
    shift of the sequence. Each bit is held for ``hold`` steps.

    Parameters
    ----------
    N : the number of steps.
    m : the number of inputs.
    amplitude : the level ±amplitude.
    hold : steps each bit is held.
    seed : a seed.

    Returns
    -------
    numpy.ndarray
        (N, m), row k is u_k, with max |u| <= amplitude.

    Raises
    ------
    orrc.OrrcValueError
        When N or m is not an integer >= 1, or a size is out of range.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc import estimation
    >>> u = estimation.prbs(8, 1, amplitude=2.0, seed=0)
    >>> sorted(set(u.ravel().tolist()))
    [-2.0, 2.0]
    """
    N, hold = as_int("N", N, minimum=1), as_int("hold", hold, minimum=1)
    bits_needed = math.ceil(N / hold)
    nbits = max(5, math.ceil(math.log2(bits_needed + 1)))
    if nbits > 32:
        raise OrrcValueError(f"N={N} is too long for a PRBS of at most 32 register bits")
    N, m, amplitude = _dims(N, m, amplitude)
    from scipy.signal import max_len_seq

    rng = _rng(seed)
    state = rng.integers(0, 2, nbits)
    if not state.any():
        state[0] = 1
    period = 2 ** nbits - 1
    seq, _ = max_len_seq(nbits, state=state, length=period)
    out = np.empty((N, m))
    for i in range(m):
        shift = int(rng.integers(0, period))
        bits = np.roll(seq, -shift)
        reps = np.resize(bits, bits_needed)
        out[:, i] = np.repeat(reps, hold)[:N]
    return amplitude * (2.0 * out - 1.0)


def multisine(N: int, m: int, amplitude: float = 1.0, n_freqs: int = 8, seed=None) -> np.ndarray:
    """u_{k,i} = s Σ_j sin(2π f_j k + φ_{ij}): ``n_freqs`` frequencies f_j = j/(2 n_freqs + 1)
    (j = 1..n_freqs, spread over (0, 1/2)), random phases φ (seeded), s such that max |u| = amplitude.

    Parameters
    ----------
    N : the number of steps.
    m : the number of inputs.
    amplitude : the peak max |u|.
    n_freqs : the number of frequencies.
    seed : a seed for the phases.

    Returns
    -------
    numpy.ndarray
        (N, m), row k is u_k, with max |u| <= amplitude.

    Raises
    ------
    orrc.OrrcValueError
        When N or m is not an integer >= 1, or a size is out of range.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc import estimation
    >>> u = estimation.multisine(50, 2, amplitude=0.5, seed=0)
    >>> u.shape, round(float(np.abs(u).max()), 6)
    ((50, 2), 0.5)
    """
    n_freqs = as_int("n_freqs", n_freqs, minimum=1)
    N, m, amplitude = _dims(N, m, amplitude, terms=n_freqs)
    rng = _rng(seed)
    f = np.arange(1, n_freqs + 1) / (2 * n_freqs + 1)
    k = np.arange(N)[:, None]
    out = np.empty((N, m))
    for i in range(m):
        phi = rng.uniform(0, 2 * np.pi, n_freqs)
        s = np.sin(2 * np.pi * f[None, :] * k + phi[None, :]).sum(axis=1)
        peak = np.abs(s).max()
        out[:, i] = s / peak if peak > 0 else s
    return amplitude * out


def make(kind: str, N: int, m: int, amplitude: float = 1.0, seed=None) -> np.ndarray:
    """An excitation of a named ``kind`` (one of :data:`KINDS`) with the given amplitude."""
    if kind not in KINDS:
        raise OrrcValueError(f"unknown excitation kind {kind!r}; allowed: {list(KINDS)}")
    return {"gaussian": gaussian, "prbs": prbs, "multisine": multisine}[kind](N, m, amplitude=amplitude, seed=seed)
