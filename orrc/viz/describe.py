"""Text alternatives of figures: what a figure shows, in words, for readers who cannot see it.

A screen reader announces an image by its ``alt`` text. :func:`describe` writes that text from what
the figure itself knows, before it is rendered: the figure's title, and for each panel its title,
what is plotted against what (the axis labels), its scales, and the names of its series (legend
entries and labelled artists). An explorer's frame adds the parameter values of the frame
(:func:`frame_description`). Mathtext (``$\\gamma_c$``) is read as plain text (``γ_c``).
"""
from __future__ import annotations

import re

__all__ = ["describe", "frame_description", "plain"]

#: at most this many series are named per panel ("and 3 more" after them)
MAX_SERIES = 6

_GREEK = {name: chr(code) for name, code in (
    ("alpha", 0x3B1), ("beta", 0x3B2), ("gamma", 0x3B3), ("delta", 0x3B4), ("epsilon", 0x3B5), ("zeta", 0x3B6),
    ("eta", 0x3B7), ("theta", 0x3B8), ("kappa", 0x3BA), ("lambda", 0x3BB), ("mu", 0x3BC), ("nu", 0x3BD),
    ("xi", 0x3BE), ("pi", 0x3C0), ("rho", 0x3C1), ("sigma", 0x3C3), ("tau", 0x3C4), ("phi", 0x3C6),
    ("chi", 0x3C7), ("psi", 0x3C8), ("omega", 0x3C9), ("Gamma", 0x393), ("Delta", 0x394), ("Theta", 0x398),
    ("Lambda", 0x39B), ("Sigma", 0x3A3), ("Phi", 0x3A6), ("Psi", 0x3A8), ("Omega", 0x3A9))}
_SYMBOLS = {"infty": "∞", "leq": "≤", "le": "≤", "geq": "≥", "ge": "≥", "times": "×", "cdot": "·", "to": "→",
            "sum": "Σ", "Vert": "‖", "|": "‖", "ell": "ℓ", "approx": "≈", "propto": "∝", "sqrt": "√", "star": "*"}


#: accents kept as combining marks on the letter they stand over (ᾱ, γ̄, θ̂, x̃, α̲)
_ACCENTS = {"bar": "\u0304", "overline": "\u0304", "hat": "\u0302", "widehat": "\u0302", "tilde": "\u0303",
            "widetilde": "\u0303", "underline": "\u0332", "dot": "\u0307"}
_ACCENT = re.compile(r"\\(%s)\s*(?:\{([^{}]*)\}|(\\[A-Za-z]+|\S))" % "|".join(sorted(_ACCENTS, key=len, reverse=True)))
_STYLE = re.compile(r"\\(?:mathrm|mathit|mathbf|mathcal|mathsf|mathnormal|boldsymbol|text|textrm|operatorname"
                    r"|rm|it|bf|cal|sf)(?![A-Za-z])\s*")


def _command(name: str) -> str:
    plain_name = name[3:] if name.startswith("var") and name[3:] in _GREEK else name   # \varphi -> φ
    return _GREEK.get(plain_name, _SYMBOLS.get(name, name))


def plain(text: str) -> str:
    """``text`` with its mathtext spans read as plain text: ``$\\bar\\gamma_{c}$`` -> ``γ̄_c`` (an accent is
    kept as a combining mark on its letter), ``$c_s^{\\rm known}$`` -> ``c_s^known``, ``$\\varphi_t$`` ->
    ``φ_t``; line breaks become spaces.

    Parameters
    ----------
    text : a label, possibly with mathtext.

    Returns
    -------
    str
        the plain reading.

    Examples
    --------
    >>> from orrc.viz.describe import plain
    >>> plain("$\\\\gamma_c$ against $M$")
    'γ_c against M'
    """
    def accent(m):
        body = math(m.group(2) if m.group(2) is not None else m.group(3), top=False)
        return body + _ACCENTS[m.group(1)] if body else body

    def math(s, top=True):
        s = _ACCENT.sub(accent, s)
        s = _STYLE.sub("", s)
        s = re.sub(r"\\([A-Za-z]+|\|)", lambda g: _command(g.group(1)), s)
        if top:
            s = re.sub(r"[{}]", "", s).replace("\\,", " ").replace("\\;", " ").replace("\\", "")
        return s

    text = re.sub(r"\$(.+?)\$", lambda m: math(m.group(1)), str(text))
    return re.sub(r"\s+", " ", text).strip()


def _series(ax) -> list[str]:
    """The names a reader would find in the panel's legend: the legend's entries, else the labels
    of its labelled lines, collections and bars (matplotlib's private ``_...`` labels left out)."""
    leg = ax.get_legend()
    if leg is not None:
        names = [t.get_text() for t in leg.get_texts()]
    else:
        names = [a.get_label() for a in [*ax.lines, *ax.collections, *ax.containers]
                 if isinstance(a.get_label(), str)]
    seen = []
    for n in (plain(n) for n in names):
        if n and not n.startswith("_") and n not in seen:
            seen.append(n)
    return seen


def _panel(ax) -> str:
    """One panel in words: its title, what is plotted against what, its scales, its series."""
    title = plain(ax.get_title() or ax.get_title("left") or ax.get_title("right"))
    x, y = plain(ax.get_xlabel()), plain(ax.get_ylabel())
    if ax.images:
        what = "a colour map" + (f" over {y} and {x}" if x and y else "")
    elif y and x:
        what = f"{y} against {x}"
    elif y or x:
        what = y or f"{x} on the horizontal axis"
    elif ax.tables or not ax.axison:
        what = "a table" if ax.tables else "a diagram"
    else:
        what = "a plot"
    scales = [f"{axis} on a {scale} scale" for axis, scale in (("x", ax.get_xscale()), ("y", ax.get_yscale()))
              if scale != "linear" and (axis == "x" and x or axis == "y" and y)]
    text = f"{title}: {what}" if title else what
    if scales:
        text += f" ({', '.join(scales)})"
    names = _series(ax)
    if names:
        shown = ", ".join(names[:MAX_SERIES]) + (f" and {len(names) - MAX_SERIES} more" if len(names) > MAX_SERIES else "")
        text += f"; series: {shown}"
    return text


def describe(fig) -> str:
    """A short text alternative of a matplotlib figure, from its titles, axis labels, scales and
    series names (call it before the figure is rendered and closed). Colour bars and axes without
    anything drawn are left out; twin axes are described with their panel.

    Parameters
    ----------
    fig : a matplotlib figure, before it is rendered and closed.

    Returns
    -------
    str
        the text alternative.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz.describe import describe
    >>> describe(fig)
    'A run: t on the horizontal axis; series: cost.'
    """
    from .legibility import _figure_arg

    fig = _figure_arg("fig", fig)
    panels = []
    for ax in fig.axes:
        if not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        drawn = ax.lines or ax.collections or ax.patches or ax.images or ax.texts or ax.tables or ax.containers
        if not drawn and not (ax.get_title() or ax.get_ylabel()):
            continue
        panels.append(_panel(ax))
    sup = getattr(fig, "_suptitle", None)
    head = plain(sup.get_text()) if sup is not None else ""
    legends = [plain(t.get_text()) for leg in fig.legends for t in leg.get_texts()]
    parts = [f"{head}." if head else ""]
    if len(panels) == 1:
        parts.append(panels[0][0].upper() + panels[0][1:] + ".")
    elif panels:
        parts.append(f"{len(panels)} panels. " + " ".join(f"Panel {i}, {p}." for i, p in enumerate(panels, 1)))
    if legends:
        parts.append("Legend: " + ", ".join(n for n in legends if n) + ".")
    text = " ".join(p for p in parts if p)
    return text or "A figure without titles, labels or series."


def frame_description(kwargs: dict, fig) -> str:
    """The text alternative of one frame of an explorer: its parameter values, then :func:`describe`.

    Parameters
    ----------
    kwargs : the frame's parameter values.
    fig : the frame's figure.

    Returns
    -------
    str
        the parameter values, then :func:`describe`.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz.describe import frame_description
    >>> frame_description({"M": 5}, fig)
    'Frame with M = 5. A run: t on the horizontal axis; series: cost.'
    """
    values = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in kwargs.items())
    return f"Frame with {values}. {describe(fig)}"
