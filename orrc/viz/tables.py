"""Tables of the theory chapters: the constants of Section 5.1 and the margins of the paper's
inequalities, under typeset headers (:func:`orrc.viz.plots.table`), so that a chapter prints what the
reader needs instead of a long repr.
"""
from __future__ import annotations

import math

import numpy as np

from ._theory_common import _constants, _margins
from .plots import _nonempty_dict

__all__ = ["constants_table", "margins_table"]


def constants_table(constants, digits: int = 4):
    """The constants of Section 5.1 under typeset headers: α_lo, ᾱ, γ̄, the horizon threshold
    ᾱ²/α_lo² + 1, the decay rate a_min, b and Theorem 1's γ_c (∞ where no pair is below the
    threshold), and whether the numbers are certified or estimated. ``constants``: a dict label ->
    :class:`orrc.certify.Constants` (one row per label, the label first), or a list of them
    (one row each, no label column: the horizon M tells the rows apart). An
    :func:`orrc.viz.plots.table`."""
    from .._validate import OrrcValueError
    from .plots import table

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
    """Step-by-step margins (bound minus actual) of the paper's inequalities, one row per
    label of ``margins`` (label -> :class:`orrc.checks.Margins`): how many steps, whether the
    inequality holds at all of them (up to rounding), the smallest margin and the step where
    it occurs, and the median margin. An :func:`orrc.viz.plots.table`."""
    from .plots import table

    margins = _nonempty_dict("margins", margins)
    rows = []
    for label, m in margins.items():
        m = _margins(f"margins[{label!r}]", m)
        i = int(np.argmin(m.margin))
        rows.append([label, len(m), "yes" if m.holds() else "NO", float(m.margin[i]), int(m.t[i]),
                     float(np.median(m.margin))])
    return table(["inequality", "steps", "holds", "smallest margin", "at step", "median margin"], rows,
                 digits=digits)
