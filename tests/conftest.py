import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def random_lq(rng, n=3, m=2, spectral_radius=1.2):
    """A random (A, B, Q, R) with A scaled to the given spectral radius."""
    A = rng.standard_normal((n, n))
    A *= spectral_radius / max(abs(np.linalg.eigvals(A)))
    B = rng.standard_normal((n, m))
    G = rng.standard_normal((n, n))
    Q = G @ G.T / n + 0.1 * np.eye(n)
    H = rng.standard_normal((m, m))
    R = H @ H.T / m + 0.1 * np.eye(m)
    return A, B, Q, R
