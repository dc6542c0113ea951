"""What a chapter needs from the notebook it runs in, with or without the book's tools.

:func:`glue` hands a computed number to the book's prose: it is ``myst_nb.glue`` when
myst-nb is installed, writes the same output (:func:`_record`) in a build of the book whose
kernel has no myst-nb (the test build runs the chapters in the environment a download installs),
and is a plain store otherwise, so that a chapter downloaded as ``.ipynb`` runs wherever
``orrc`` is installed (``pip install`` of the project).
Every glued value is kept in :data:`glued`, by key.

The prose quotes a glued number with a MyST inline expression,
``{eval}`glued("l1-q19", ".0f")```: :data:`glued` called with a key and a format returns a
:class:`Quoted` value whose plain-text form is the formatted number (no quotes around it), so

* in JupyterLab (jupyterlab-myst) the expression is evaluated in the chapter's kernel when its
  Markdown cell runs (Run All), and the number appears in the text;
* in the HTML book the local Sphinx extension ``tools/sphinx_live.py`` reads the same
  expression as ``{glue:text}`l1-q19:.0f``` and pastes the value the executed notebook glued,
  formatted the same way (``format(value, ".0f")``).

Where no renderer evaluates the expressions (a notebook viewer without MyST, an untrusted
notebook), the values stay readable in the notebook itself: in a live kernel :func:`glue`
shows one folded line under the cell that computed them ("Numbers quoted in the text (3)",
unfolded ``l1-q19 = 23.39``, ...; as text where HTML is not shown).
"""
from __future__ import annotations

from ..config import book_build

__all__ = ["glue", "glued", "Quoted"]


class Quoted:
    """A glued value formatted for the prose: ``repr`` (what a notebook shows as ``text/plain``)
    is ``format(value, fmt)``, without quotes, as ``{glue:text}`key:fmt``` renders it.

    Parameters
    ----------
    key : the glued key.
    value : the glued value.
    fmt : a format specification (``".2f"``, ``".3g"``, ...).

    Examples
    --------
    >>> from orrc.viz.notebook import Quoted
    >>> Quoted("ratio", 0.123456, ".3f")
    0.123
    """

    __slots__ = ("key", "value", "fmt")

    def __init__(self, key: str, value, fmt: str = ""):
        self.key, self.value, self.fmt = key, value, fmt

    def __str__(self) -> str:
        return _formatted(self.value, self.fmt)

    __repr__ = __str__


def _formatted(value, fmt: str) -> str:
    """``format(value, fmt)`` after the conversion the book's ``{glue:text}`` applies: an integer
    presentation type (``d``, ``x``, ...) takes ``int(value)``, a float type (``f``, ``e``, ``g``,
    ``%``, ...) ``float(value)``, ``s`` ``str(value)``."""
    kind = fmt[-1:] if fmt else ""
    if kind in ("b", "c", "d", "o", "x", "X"):
        value = int(value)
    elif kind in ("e", "E", "f", "F", "g", "G", "n", "%"):
        value = float(value)
    elif kind == "s":
        value = str(value)
    return format(value, fmt)


class Glued(dict):
    """Every value glued in this session, by key (a dict); ``glued(key, fmt)`` quotes one of them
    formatted for the prose (:class:`Quoted`), the form ``{eval}`glued("key", "fmt")``` of the
    chapters' Markdown.

    Examples
    --------
    >>> import orrc.viz
    >>> orrc.viz.glue("threshold", 5.0)
    >>> orrc.viz.glued["threshold"], orrc.viz.glued("threshold", ".0f")
    (5.0, 5)
    """

    def __call__(self, key: str, fmt: str = "") -> Quoted:
        from .._validate import OrrcValueError

        if not isinstance(key, str) or key not in self:
            known = ", ".join(sorted(self)[:8]) + (", ..." if len(self) > 8 else "")
            raise OrrcValueError(f"key must be a key glued earlier in this notebook (run the cells above "
                                 f"first); got {key!r}; glued so far: {known or 'nothing'}")
        if not isinstance(fmt, str):
            raise OrrcValueError(f"fmt must be a format specification string such as '.2f'; got {fmt!r}")
        try:
            _formatted(self[key], fmt)
        except (TypeError, ValueError) as exc:
            raise OrrcValueError(f"fmt {fmt!r} does not format the value glued as {key!r} "
                                 f"({type(self[key]).__name__}): {exc}") from None
        return Quoted(key, self[key], fmt)


glued: Glued = Glued()   # every value glued in this session, by key (also without myst-nb)


def _live_shell():
    """The IPython shell of a live kernel (not the book's build), else None."""
    from .. import config

    try:
        from IPython import get_ipython
    except ImportError:  # pragma: no cover
        return None
    shell = get_ipython()
    if shell is None or not hasattr(shell, "kernel") or config.book_build():
        return None
    return shell


_shown: dict = {}   # execution count -> (display handle, {key: text}) of the fallback line


def _short(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value) if isinstance(value, (int, str)) else repr(value)


def _show_in_cell(shell, name: str, value) -> None:
    """The fallback: one folded line under the running cell listing the values it glued so far
    ("Numbers quoted in the text (3)", unfolded: ``l1-q19 = 23.39``, ...)."""
    import html

    from IPython.display import display

    count = shell.execution_count
    handle, values = _shown.get(count, (None, {}))
    values[name] = _short(value)
    listed = ", ".join(f"{k} = {v}" for k, v in values.items())
    rows = "".join(f"<li><code>{html.escape(k)}</code> = {html.escape(v)}</li>" for k, v in values.items())
    bundle = {"text/plain": f"Numbers quoted in the text: {listed}",
              "text/html": f"<details class=\"orrc-quoted\"><summary>Numbers quoted in the text "
                           f"({len(values)})</summary><ul>{rows}</ul></details>"}
    if handle is None:
        _shown.clear()
        _shown[count] = (display(bundle, raw=True, display_id=True), values)
    else:
        handle.update(bundle, raw=True)


def glue(name: str, value, display: bool = False) -> None:
    """Glue ``value`` under the key ``name`` for the book's prose (myst-nb's ``glue``; without
    myst-nb only stored in :data:`glued`). ``display=False`` (the book's default: the number
    appears where the prose quotes it, not where it is computed; in a live kernel one folded line
    under the cell still lists what it glued). Returns None, as myst-nb's ``glue`` (a cell that
    ends with a glue shows no ``Out``).

    Parameters
    ----------
    name : the key the prose quotes.
    value : the value (a number, usually).
    display : also show the value under the cell.

    Returns
    -------
    None

    Raises
    ------
    orrc.OrrcValueError
        When ``name`` is not a non-empty string.

    Examples
    --------
    A cell computes and glues; the prose quotes ``{eval}`glued("gamma-c", ".1f")```:

    >>> import orrc.viz
    >>> orrc.viz.glue("gamma-c", 572.8458)
    >>> orrc.viz.glued("gamma-c", ".1f")
    572.8
    """
    from .._validate import OrrcValueError

    if not isinstance(name, str) or not name:
        raise OrrcValueError(f"name must be a non-empty string (the glue key); got {name!r}")
    if hasattr(value, "item") and getattr(value, "shape", None) == ():   # a numpy scalar: plain Python,
        value = value.item()                                             # so the prose can format it
    glued[name] = value
    shell = _live_shell()
    if shell is not None and not display:
        _show_in_cell(shell, name, value)
    try:
        from IPython import get_ipython
    except ImportError:
        return
    try:
        from myst_nb import glue as myst_glue
    except ImportError:
        myst_glue = _record if book_build() else None
    if myst_glue is not None and get_ipython() is not None:  # glued through the notebook's outputs
        myst_glue(name, value, display=display)


#: the MIME prefix of a value glued but not displayed (myst-nb's ``GLUE_PREFIX``)
GLUE_PREFIX = "application/papermill.record/"


def _record(name: str, value, display: bool = False) -> None:
    """The output ``myst_nb.glue(name, value, display)`` writes, for a kernel without myst-nb: the
    value's display formats under :data:`GLUE_PREFIX` (none when ``display``) and the key in the
    output's ``scrapbook`` metadata, which the book's build reads."""
    from IPython.core.formatters import format_display_data
    from IPython.display import display as show

    bundle, metadata = format_display_data(value)
    prefix = "" if display else GLUE_PREFIX
    metadata["scrapbook"] = {"name": name, "mime_prefix": prefix}
    show({prefix + k: v for k, v in bundle.items()}, raw=True, metadata=metadata)
