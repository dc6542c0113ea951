"""Tables of the theory chapters: the constants of Section 5.1 and the margins of the paper's
inequalities, under typeset headers (:func:`orrc.viz.plots.table`), so that a chapter prints what the
reader needs instead of a long repr.
"""
from __future__ import annotations

import math

import numpy as np

from .._validate import OrrcValueError, as_int
from ._theory_common import _constants, _margins
from .style import _nonempty_dict

__all__ = ["Table", "table", "constants_table", "margins_table"]


def _math_html(text: str) -> str:
    """``text`` as HTML, each ``$...$`` span typeset by MathJax (Sphinx's inline-math markup)."""
    import html

    parts = str(text).split("$")
    if len(parts) % 2 == 0:  # an odd number of $: no math, show it as it is
        return html.escape(str(text))
    return "".join(html.escape(p) if i % 2 == 0 else
                   f'<span class="math notranslate nohighlight">\\({html.escape(p)}\\)</span>'
                   for i, p in enumerate(parts))


class Table:
    """A small table that displays as HTML in notebooks and in the book, as Markdown in
    ``_repr_markdown_`` and as plain text otherwise (a Markdown table of text/markdown would not be
    rendered by the book's CommonMark output renderer). Headers and cells may hold ``$...$`` math,
    typeset by MathJax in the HTML. Made by :func:`table`, which formats the numbers.

    Parameters
    ----------
    headers : list of str, the column headers.
    rows : list of lists of str, the cells, one list per row (as many cells as headers).

    Examples
    --------
    >>> from orrc.viz.plots import Table
    >>> Table(["$M$", "cost"], [["5", "2.1"], ["10", "1.9"]])
    M   cost
    5   2.1
    10  1.9
    """

    def __init__(self, headers, rows):
        self.headers, self.rows = headers, rows

    def _repr_html_(self):
        head = "".join(f"<th>{_math_html(h)}</th>" for h in self.headers)
        body = "".join("<tr>" + "".join(f"<td>{_math_html(c)}</td>" for c in r) + "</tr>" for r in self.rows)
        return (f'<div class="orrc-table-wrap" style="overflow-x:auto"><table class="table orrc-table">'
                f"<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>")

    def _repr_markdown_(self):
        lines = ["| " + " | ".join(self.headers) + " |", "|" + "|".join("---" for _ in self.headers) + "|"]
        return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in self.rows])

    def __repr__(self):
        plain = [[c.replace("$", "") for c in r] for r in [self.headers, *self.rows]]
        widths = [max(len(r[i]) for r in plain) for i in range(len(self.headers))]
        fmt = "  ".join(f"{{:<{w}}}" for w in widths)
        return "\n".join(fmt.format(*r) for r in plain)


def table(headers, rows, digits: int = 4) -> Table:
    """A :class:`Table` of numbers under typeset headers: what a chapter prints instead of a long
    repr (e.g. the columns R^p_T(1) of Eq. (2) per controller).

    Parameters
    ----------
    headers : the column headers; ``$...$`` in a header is math (e.g. ``"$R^p_T(1)$"``).
    rows : one sequence of cells per row, as many as headers; floats are printed with ``digits``
        significant digits, infinities as ∞ and −∞, NaN as a dash, anything else with ``str``.
    digits : the significant digits of a float, >= 1.

    Returns
    -------
    Table
        It displays as HTML in a notebook and in the book, as plain text otherwise.

    Examples
    --------
    >>> import math
    >>> from orrc.viz import plots
    >>> plots.table(["controller", "$R^p_T(1)$"], [["LQR", 12.3456], ["none", math.inf]],
    ...             digits=3)
    controller  R^p_T(1)
    LQR         12.3
    none        ∞
    """
    headers = [str(h) for h in headers]
    rows = [list(r) for r in rows]
    for i, r in enumerate(rows):
        if len(r) != len(headers):
            raise OrrcValueError(f"row {i} has {len(r)} cells; the table has {len(headers)} columns")
    digits = as_int("digits", digits, minimum=1)

    def fmt(v):
        if isinstance(v, (float, np.floating)):
            if np.isnan(v):
                return "—"
            if np.isinf(v):
                return "∞" if v > 0 else "−∞"
            return f"{v:.{digits}g}"
        return str(v)

    return Table(headers, [[fmt(v) for v in r] for r in rows])


def constants_table(constants, digits: int = 4):
    r"""The constants of Section 5.1 (Lemma 1's class and Theorem 1's level) under typeset headers:
    α_lo, ᾱ, γ̄, the horizon threshold ᾱ²/α_lo² + 1, the decay rate a_min, b and Theorem 1's γ_c (∞
    where no pair is below the threshold), and whether they are certified or estimated.

    Parameters
    ----------
    constants : dict label -> :class:`orrc.certify.Constants` (one row per label, the label
        first), or a list of them (one row each, no label column: the horizon M tells the rows
        apart).
    digits : the significant digits of the numbers, >= 1.

    Returns
    -------
    Table
        An :func:`orrc.viz.plots.table`, one row per entry of ``constants``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> from orrc.viz.theory_plots import constants_table
    >>> ex = orrc.examples.scalar_unstable()
    >>> t = constants_table({"scalar": certify.lq_constants(ex.system, ex.cost, M=8)})
    >>> t.headers[:3], len(t.rows), t.rows[0][-1]
    (['', '$M$', '$\\underline{\\alpha}$'], 1, 'certified (exact)')
    """
    from .._validate import OrrcValueError
    if isinstance(constants, (list, tuple)):
        if not constants:
            raise OrrcValueError("constants must list at least one orrc.certify.Constants; got an empty list")
        items = [(None, _constants(f"constants[{i}]", c)) for i, c in enumerate(constants)]
    else:
        items = [(label, _constants(f"constants[{label!r}]", c))
                 for label, c in _nonempty_dict("constants", constants, "Constants").items()]
    labelled = items[0][0] is not None
    rows = []
    for label, c in items:
        rows.append(([label] if labelled else []) + [
            c.M, c.alpha_lo, c.alpha_hi, c.gamma_bar, c.threshold, c.a if c.admissible else math.nan,
            c.b, c.gamma_c, "estimated (sampled)" if c.estimate else "certified (exact)"])
    head = ["$M$", r"$\underline{\alpha}$", r"$\overline{\alpha}$", r"$\overline{\gamma}$",
            r"threshold $\overline{\alpha}^2/\underline{\alpha}^2 + 1$", r"$a_{\min}$", "$b$", r"$\gamma_c$", "kind"]
    return table(([""] if labelled else []) + head, rows, digits=digits)


def margins_table(margins: dict, digits: int = 4):
    """The step-by-step margins (bound minus actual) of the paper's inequalities (Lemmas 1, 2, 4, 5
    and 6, Theorems 1 to 3) in one table: for each, how many steps, whether it holds at all of
    them (up to rounding), the smallest margin and the step where it occurs, and the median margin.

    Parameters
    ----------
    margins : dict label -> :class:`orrc.checks.Margins`, one row each.
    digits : the significant digits of the numbers, >= 1.

    Returns
    -------
    Table
        An :func:`orrc.viz.plots.table` with the columns inequality, steps, holds, smallest
        margin, at step, median margin.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> from orrc.viz.theory_plots import margins_table
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> m = checks.value_bound_margins(traj, 8, k.alpha_hi, k.gamma_bar)
    >>> t = margins_table({"value bound": m})
    >>> t.rows[0][:3]
    ['value bound', '50', 'yes']
    """
    margins = _nonempty_dict("margins", margins)
    rows = []
    for label, m in margins.items():
        m = _margins(f"margins[{label!r}]", m)
        i = int(np.argmin(m.margin))
        rows.append([label, len(m), "yes" if m.holds() else "NO", float(m.margin[i]), int(m.t[i]),
                     float(np.median(m.margin))])
    return table(["inequality", "steps", "holds", "smallest margin", "at step", "median margin"], rows,
                 digits=digits)
