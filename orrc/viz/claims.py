"""The text's qualitative claims, checked where the chapter runs.

A chapter states things its numbers show ("the warm start needs fewer iterations"); a hidden
cell checks each of them with ``claim(condition, "the statement as the text makes it")``.

* In the book's build (``orrc.config.book_build()``) a false claim raises :class:`ClaimError`
  with the statement: the build fails, and the text never says what its numbers contradict.
* Anywhere else (a live notebook, a script) the reader may have changed a parameter, a
  horizon or a bound, to see what happens; the text was written for the chapter's values and
  need not hold for others. A false claim then shows one line, "For these parameters the text's
  statement no longer holds: ...", saying that this is expected after a change, and the
  notebook goes on. In a kernel the line is a cell output; elsewhere a :class:`ClaimWarning`.
"""
from __future__ import annotations

import warnings

__all__ = ["claim", "ClaimError", "ClaimWarning"]


class ClaimError(AssertionError):
    """A statement of the text that the chapter's own numbers contradict (the book's build).

    Examples
    --------
    >>> from orrc.viz import ClaimError
    >>> issubclass(ClaimError, AssertionError)
    True
    """


class ClaimWarning(UserWarning):
    """A statement of the text that does not hold for the parameters a reader chose.

    Examples
    --------
    >>> import warnings
    >>> import orrc.viz
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     orrc.viz.claim(False, "the cost decreases")
    >>> caught[0].category is orrc.viz.ClaimWarning
    True
    """


NOTE = ("For these parameters the text's statement no longer holds: \u201c{statement}\u201d. "
        "This is expected after changing a parameter: the text describes the values it was "
        "written with.")


def _kernel():
    try:
        from IPython import get_ipython
    except ImportError:  # pragma: no cover
        return None
    shell = get_ipython()
    return shell if shell is not None and hasattr(shell, "kernel") else None


def claim(condition, statement: str, why: str | None = None) -> None:
    """Check one qualitative statement of the text: ``condition`` is what the numbers must satisfy
    for ``statement`` (the claim as the text words it) to hold. Returns None (a cell that ends
    with a claim shows nothing when it holds).

    In the book's build a false claim raises :class:`ClaimError` (the build fails with
    ``statement``); elsewhere it shows a one-line note naming the statement and goes on (see
    the module docstring). ``why``: an optional sentence appended to the note (why the statement
    depends on the parameters, e.g. "a shorter horizon need not satisfy the threshold").

    Parameters
    ----------
    condition : what the numbers must satisfy (a bool, or numpy's).
    statement : the claim as the text words it.
    why : an optional sentence for the note.

    Returns
    -------
    None

    Raises
    ------
    ClaimError
        In the book's build, when ``condition`` is false.
    orrc.OrrcValueError
        When ``statement`` is not a non-empty string.

    Examples
    --------
    Outside the book's build a statement that no longer holds warns:

    >>> import warnings
    >>> import orrc.viz
    >>> orrc.viz.claim(2 > 1, "two is more than one")
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     orrc.viz.claim(1 > 2, "one is more than two")
    >>> [w.category.__name__ for w in caught]
    ['ClaimWarning']
    """
    from .. import config
    from .._validate import OrrcValueError

    if not isinstance(statement, str) or not statement.strip():
        raise OrrcValueError(f"statement must be the claim as the text makes it (a non-empty string); "
                             f"got {statement!r}")
    if why is not None and not isinstance(why, str):
        raise OrrcValueError(f"why must be a sentence (a string) or None; got {type(why).__name__}")
    try:
        holds = bool(condition)
    except (TypeError, ValueError) as exc:   # e.g. an array of several truth values
        raise OrrcValueError(f"condition must be one truth value (use all(...) or any(...) for an "
                             f"array); got {type(condition).__name__}: {exc}") from None
    if holds:
        return
    if config.book_build():
        raise ClaimError(statement)
    note = NOTE.format(statement=statement.strip()) + (f" {why.strip()}" if why else "")
    if _kernel() is not None:
        from IPython.display import display

        display({"text/plain": note, "text/markdown": "\u26a0\ufe0f " + note}, raw=True)
    else:
        warnings.warn(note, ClaimWarning, stacklevel=2)
