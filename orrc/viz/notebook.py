"""What a chapter needs from the notebook it runs in, with or without the book's tools.

:func:`glue` hands a computed number to the book's prose (``{glue:text}`key``` in the
Markdown): it is ``myst_nb.glue`` when myst-nb is installed (the book's build), and a
plain store otherwise, so that a chapter downloaded as ``.ipynb`` runs wherever ``orrc``
is installed (``pip install`` of the project) and the glued values stay readable in
:data:`glued`.
"""
from __future__ import annotations

__all__ = ["glue"]

glued: dict = {}   # every value glued in this session, by key (also without myst-nb)


def glue(name: str, value, display: bool = False):
    """Glue ``value`` under the key ``name`` for the book's prose (myst-nb's ``glue``; without
    myst-nb only stored in :data:`glued`). ``display=False`` (the book's default: the number
    appears where the prose quotes it, not where it is computed). Returns ``value``."""
    from .._validate import OrrcValueError

    if not isinstance(name, str) or not name:
        raise OrrcValueError(f"name must be a non-empty string (the glue key); got {name!r}")
    if hasattr(value, "item") and getattr(value, "shape", None) == ():   # a numpy scalar: plain Python,
        value = value.item()                                             # so the prose can format it
    glued[name] = value
    try:
        from IPython import get_ipython
        from myst_nb import glue as myst_glue
    except ImportError:
        return value
    if get_ipython() is not None:  # myst-nb glues through the notebook's outputs
        myst_glue(name, value, display=display)
    return value
