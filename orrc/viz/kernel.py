"""Where the plotting code runs: inside a Jupyter kernel or not.

The lowest module of :mod:`orrc.viz`: :mod:`orrc.viz.explore` and :mod:`orrc.viz.live` both ask it
(the one decides between the live widget and the static frames, the other whether to draw frames
ahead on the kernel's event loop), and importing :mod:`orrc.viz` asks it before registering the
figures' HTML form (:func:`orrc.viz.figures.install`).
"""
from __future__ import annotations

from .._progress import in_kernel   # one kernel check for the package (progress bars, status lines, widgets)

__all__ = ["in_kernel"]
