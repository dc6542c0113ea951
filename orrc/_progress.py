"""Progress bars for the long computations of the book: seen in a live notebook, never in the HTML.

``for M in orrc.progress(Ms, desc="horizons"): ...`` is the loop over ``Ms`` with a progress bar
(``tqdm.auto``: a widget in a Jupyter kernel, text in a terminal) that appears only once the loop
has run for ``delay`` seconds (2 by default), so a quick loop shows nothing.

A single long call (no loop to count, e.g. the regret-optimal controller's convex program) says
what it is doing instead: ``with working("solving the regret-optimal SDP"): ...`` shows one status
line while it runs, and at the end either removes it (it took less than ``delay``) or leaves
"... done in 6.7 s". No bar or status line at all:

* in the book's build (``orrc.config.book_build()``, ``ORRC_BOOK_BUILD=1``): the executed chapters
  keep no progress output and no stray standard error;
* outside a kernel when standard error is not a terminal (tests, scripts piped to a file).
"""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager

__all__ = ["progress", "watched", "working"]


def in_kernel() -> bool:
    """True inside a Jupyter kernel (an IPython shell with a kernel), where a live widget or a status
    line can be shown. Asks only an IPython already imported: ``import orrc`` stays light.

    Returns
    -------
    bool
        whether this code runs in a Jupyter kernel.

    Examples
    --------
    >>> from orrc.viz.kernel import in_kernel
    >>> in_kernel()       # a doctest runs outside any kernel
    False
    """
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and hasattr(shell, "kernel")


def watched() -> bool:
    """A reader is watching: a Jupyter kernel or a terminal, and not the book's build."""
    from . import config

    if config.book_build():
        return False
    return in_kernel() or bool(getattr(sys.stderr, "isatty", lambda: False)())


def progress(iterable, desc: str | None = None, total: int | None = None, delay: float = 2.0):
    """``iterable`` with a progress bar while a reader is watching (:func:`watched`), else ``iterable``
    itself. ``desc``: the bar's label; ``total``: the number of items (default ``len(iterable)`` when
    it has one); ``delay``: seconds before the bar appears (a loop that ends sooner shows none).

    Parameters
    ----------
    iterable : what to loop over.
    desc : the bar's label.
    total : the number of items (default ``len(iterable)`` when it has one).
    delay : seconds before the bar appears.

    Returns
    -------
    iterable
        ``iterable`` itself, or a ``tqdm`` bar over it that yields the same items.

    Raises
    ------
    orrc.OrrcValueError
        When ``iterable`` cannot be looped over, or ``desc``, ``total`` or ``delay`` is malformed.

    Examples
    --------
    Outside a live kernel or a terminal (here) the loop runs without a bar:

    >>> import orrc
    >>> [M * M for M in orrc.progress(range(4), desc="horizons")]
    [0, 1, 4, 9]
    """
    from ._validate import OrrcValueError, as_float, as_int

    if not hasattr(iterable, "__iter__"):
        raise OrrcValueError(f"iterable must be something to loop over (a list, a range, ...); got "
                             f"{type(iterable).__name__}")
    if desc is not None and not isinstance(desc, str):
        raise OrrcValueError(f"desc must be a string (the bar's label) or None; got {type(desc).__name__}")
    total = None if total is None else as_int("total", total, minimum=0)
    delay = as_float("delay", delay, minimum=0.0)
    if not watched():
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, delay=delay, leave=False)


@contextmanager
def working(message: str, delay: float = 2.0):
    """A status line "⏳ ``message`` …" while the block runs, where a reader watches in a live kernel
    (:func:`watched`, a kernel only: a terminal gets nothing). At the end the line is emptied when the
    block took less than ``delay`` seconds, else it says "``message``: done in 6.7 s".

    Parameters
    ----------
    message : what the call is doing (a non-empty string).
    delay : seconds below which the line is removed at the end.

    Yields
    ------
    None
        the block runs inside the context.

    Raises
    ------
    orrc.OrrcValueError
        When ``message`` is not a non-empty string or ``delay`` is negative.

    Examples
    --------
    >>> import orrc
    >>> with orrc.working("building the controllers"):
    ...     ex = orrc.examples.double_integrator()
    >>> ex.system.n
    2
    """
    from ._validate import OrrcValueError, as_float

    if not isinstance(message, str) or not message:
        raise OrrcValueError(f"message must be a non-empty string (what the call is doing); got {message!r}")
    delay = as_float("delay", delay, minimum=0.0)
    if not (watched() and in_kernel()):
        yield
        return
    from IPython.display import display

    handle = display({"text/plain": f"\u23f3 {message} \u2026"}, raw=True, display_id=True)
    t0 = time.perf_counter()
    try:
        yield
    finally:
        seconds = time.perf_counter() - t0
        handle.update({"text/plain": f"{message}: done in {seconds:.1f} s" if seconds >= delay else ""}, raw=True)
