"""Where the plotting code runs: inside a Jupyter kernel or not.

The lowest module of :mod:`orrc.viz`: :mod:`orrc.viz.explore` and :mod:`orrc.viz.live` both ask it
(the one decides between the live widget and the static frames, the other whether to draw frames
ahead on the kernel's event loop), and importing :mod:`orrc.viz` asks it before registering the
figures' HTML form (:func:`orrc.viz.figures.install`).
"""
from __future__ import annotations

__all__ = ["in_kernel"]


def in_kernel() -> bool:
    """True inside a Jupyter kernel (an IPython shell with a kernel), where a live widget can be shown."""
    try:
        from IPython import get_ipython
    except ImportError:  # pragma: no cover - IPython comes with the book's dependencies
        return False
    ip = get_ipython()
    return ip is not None and hasattr(ip, "kernel")
