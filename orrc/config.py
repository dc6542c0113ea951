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
"""
from __future__ import annotations

import contextlib
import os
from dataclasses import fields, replace

from . import _validate


def quick() -> bool:
    """True when the environment variable ORRC_QUICK is set to 1/true/yes."""
    return os.environ.get("ORRC_QUICK", "").strip().lower() in ("1", "true", "yes")


def size(full: int, quick_size: int) -> int:
    """``full`` normally, ``quick_size`` under ORRC_QUICK=1."""
    return quick_size if quick() else full


def book_build() -> bool:
    """True when the book's build executes this code: the environment variable ORRC_BOOK_BUILD is
    1/true/yes. Every build of the book sets it (the full book, the quick build of ``make test``,
    the solution-free edition); a live notebook does not have it. :func:`orrc.viz.explore` renders
    its static frames only in a build (or outside a kernel, where there is no live widget), and
    progress bars (:func:`orrc.progress`) stay silent in a build."""
    return os.environ.get("ORRC_BOOK_BUILD", "").strip().lower() in ("1", "true", "yes")


Limits = _validate.Limits          # the record and the limits in force live where check_size reads them
get_limits = _validate.get_limits


def set_limits(**changes) -> Limits:
    """Change some limits for the rest of the session (keywords: the fields of :class:`Limits`);
    returns the previous limits, so ``set_limits(**vars(previous))`` restores them."""
    _validate.check_options("limit", changes, [f.name for f in fields(Limits)])
    new = replace(get_limits(), **{k: _validate.limit_value(k, v) for k, v in changes.items()})
    if new.warn_bytes > new.max_bytes or new.warn_ops > new.max_ops:  # a warning threshold above its limit
        new = replace(new, warn_bytes=min(new.warn_bytes, new.max_bytes), warn_ops=min(new.warn_ops, new.max_ops))
    return _validate.use_limits(new)


@contextlib.contextmanager
def limits(**changes):
    """``with orrc.config.limits(max_ops=1e12): ...`` -- other limits inside the block only.

    Yields the limits in force inside the block. ``math.inf`` switches a limit off.
    """
    previous = set_limits(**changes)
    try:
        yield get_limits()
    finally:
        _validate.use_limits(previous)


__all__ = ["quick", "size", "book_build", "Limits", "get_limits", "set_limits", "limits"]
