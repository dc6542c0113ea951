"""The book's benchmarks page: the directive ``orrc-benchmarks`` renders the results file of ``make bench``.

``benchmarks/run.py`` writes ``benchmarks/results.json`` (every row of its table with the seconds read
from its orrc and peer cells, the machine, the library and peer versions, the load average). The
directive reads that file when the book is built and renders, in this order: where and when it was
measured, the versions, one figure per benchmark (orrc's time beside the peer's, case by case, on a
log scale: the figures of the chapters, wide and narrow, with a text alternative written from the
figure), and the whole table, folded in a dropdown. The file is read at every build, so the page always shows the results
committed with the sources; a missing or malformed file fails the build.

Usage, in a MyST page::

    ```{orrc-benchmarks}
    ```

with an optional argument, the results file relative to the book's root (default
``benchmarks/results.json``).
"""
from __future__ import annotations

import json
import os
import textwrap
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from docutils.statemachine import StringList
from sphinx.util.nodes import nested_parse_with_titles

DEFAULT = "benchmarks/results.json"

#: the section title of each benchmark module's rows, in the order of ``benchmarks/run.py``
TITLES = {
    "peers": "The pendulum's closed loop against the tools a user would pick",
    "regret": "The regret-optimal controller at the literature's scale",
    "pendulum": "One receding-horizon step on the nonlinear pendulum",
    "closed_loop": "Nonlinear receding-horizon control in closed loop",
    "lq": "The exact linear-quadratic closed loop",
    "comparison": "The comparison chapter's table",
    "minmax": "The min-max problem of Algorithm 3",
    "widgets": "The explorers in a live kernel",
    "scaling": "How a closed-loop step grows with the horizon and the state dimension",
    "scaling_lq": "The exact linear-quadratic path as the state dimension grows",
    "structure": "A structure-exploiting QP solver inside SQP",
}

#: the modules drawn as time per step against a size (log-log, one line per tool, its fitted exponent)
SCALING = {"scaling", "scaling_lq"}
_TOOL_LABELS = {"orrc": "orrc", "bare": "bare CasADi loop", "bare_own": "bare loop, orrc's Hessian",
                "acados": "acados SQP", "acados_rti": "acados RTI", "dompc": "do-mpc", "numpy": "numpy Riccati loop"}
_TOOL_STYLE = {"orrc": ("#1f6fb4", "o", "-"), "bare": ("#555555", "s", "--"), "bare_own": ("#999999", "s", ":"),
               "acados": ("#d9822b", "^", "-"),
               "acados_rti": ("#d9822b", "v", ":"), "dompc": ("#2e8b57", "D", "-."), "numpy": ("#d9822b", "^", "-")}


class BenchmarksError(ValueError):
    """The results file is missing or not what ``benchmarks/run.py`` writes."""


def load(path: Path) -> dict:
    """The results file, checked for the keys the page reads."""
    if not path.is_file():
        raise BenchmarksError(f"no results file at {path}: run `make bench` (it writes benchmarks/results.json)")
    doc = json.loads(path.read_text(encoding="utf-8"))
    for key in ("date", "command", "machine", "versions", "rows"):
        if key not in doc:
            raise BenchmarksError(f"{path} has no {key!r}: it is not a results file of benchmarks/run.py")
    return doc


def _cell(text) -> str:
    """A table cell's text as reStructuredText (literal markup characters escaped, one line)."""
    s = " ".join(str(text if text is not None else "").split()) or "—"
    for ch in "\\*`|_":
        s = s.replace(ch, "\\" + ch)
    # escaped characters are left alone by the smart-quotes pass ("--quick" stays two hyphens)
    return s.replace("--", "\\-\\-").replace("...", "\\.\\.\\.")


def _list_table(head: list[str], rows: list[list[str]], widths: list[int] | None = None) -> list[str]:
    out = [".. list-table::", "   :header-rows: 1", "   :class: orrc-fit"]   # as wide as the column (CSS)
    if widths:
        out.append("   :widths: " + " ".join(map(str, widths)))
    out.append("")
    for row in [head, *rows]:
        out.append("   * - " + _cell(row[0]))
        out += ["     - " + _cell(c) for c in row[1:]]
    return out + [""]


def groups(doc: dict) -> list[tuple[str, list[dict]]]:
    """The rows by benchmark module, in the order they were run."""
    order: dict[str, list[dict]] = {}
    for row in doc["rows"]:
        order.setdefault(row.get("module", "?"), []).append(row)
    return list(order.items())


def figure(module: str, rows: list[dict], width: float = 7.4):
    """orrc's time and the peer's (median seconds) for every row of one benchmark that states a time,
    as horizontal bars on a log scale, each pair labelled above its bars (so the labels fit a phone's
    width as well as a laptop's); None when no row states a time."""
    from matplotlib.figure import Figure

    if module in SCALING:
        return scaling_figure(module, rows, width)
    timed = [r for r in rows if r.get("orrc_seconds")]
    if not timed:
        return None
    labels = [_short(r, width=int(12 * width)) for r in timed]
    if len(set(labels)) < len(labels):   # the same case in two rows (e.g. first moves, per move): say which
        labels = [_short(r, width=int(12 * width), distinct=_distinct(r["benchmark"], [t["benchmark"] for t in timed]))
                  for r in timed]
    fig = Figure(figsize=(width, 0.62 * len(timed) + 1.5))
    ax = fig.add_subplot()
    y = [1.4 * i for i in range(len(timed))]
    h = 0.38
    ax.barh([v - h / 2 for v in y], [r["orrc_seconds"] for r in timed], height=h, label="orrc", color="#1f6fb4")
    peer = [(v, r["peer_seconds"]) for v, r in zip(y, timed) if r.get("peer_seconds")]
    if peer:
        ax.barh([v + h / 2 for v, _ in peer], [s for _, s in peer], height=h, label="peer or reference",
                color="#d9822b")
    ax.set_xscale("log")
    lo = min([r["orrc_seconds"] for r in timed] + [s for _, s in peer])
    for v, label in zip(y, labels):   # the case's name above its pair of bars
        ax.text(lo / 1.5, v - h - 0.05, label, fontsize=9, va="bottom", ha="left")
    ax.set_yticks([])
    ax.set_ylim(y[-1] + 0.8, -1.2)
    ax.set_xlim(left=lo / 2)
    ax.set_xlabel("median time (s), log scale")
    ax.set_title(textwrap.fill(TITLES.get(module, module), int(6.5 * width)))
    fig.set_layout_engine("constrained")
    fig.legend(loc="outside lower center", ncols=2, fontsize=9)
    return fig


def scaling_series(rows: list[dict]) -> dict:
    """{grid: (size name, {tool: [(size, CPU seconds per step)]}, {tool: growth exponent})} from the rows of
    ``benchmarks/scaling.py`` or ``benchmarks/scaling_lq.py`` (their ``data``); a grid of one size (a single
    point, e.g. the quadrotor's) is left to the table."""
    out: dict = {}
    sizes: dict = {}
    for r in rows:
        d = r.get("data") or {}
        if "grid" in d and "size" in d:
            sizes.setdefault(d["grid"], set()).add(d["size"])
    for r in rows:
        d = r.get("data") or {}
        if "grid" not in d or ("size" in d and len(sizes[d["grid"]]) < 2):
            continue
        name = d.get("size_name") or ("n" if (d["grid"] == "lq" or "n grows" in d["grid"]) else "M")
        _, series, slopes = out.setdefault(d["grid"], (name, {}, {}))
        if "exponents" in d:
            slopes.update(d["exponents"])
        elif "t_orrc" in d:
            if d["size"] not in [s for s, _ in series.get("orrc", [])]:
                series.setdefault("orrc", []).append((d["size"], d["t_orrc"]))
            series.setdefault(d.get("tool", "numpy"), []).append((d["size"], d["t_peer"]))
    return out


def scaling_figure(module: str, rows: list[dict], width: float = 7.4):
    """CPU time per closed-loop step against the size of each grid, log-log, a line per tool with its fitted
    growth exponent in the legend; None when no row states a time."""
    from matplotlib.figure import Figure

    grids = scaling_series(rows)
    if not grids:
        return None
    narrow = width < 5
    cols = 1 if narrow else len(grids)
    fig = Figure(figsize=(width, (3.6 if narrow else 4.2) * (len(grids) if narrow else 1) + 0.8))
    axes = fig.subplots(len(grids) if narrow else 1, cols, squeeze=False).ravel()
    for ax, (grid, (name, series, slopes)) in zip(axes, grids.items()):
        for tool, pts in series.items():
            pts = sorted(pts)
            color, marker, line = _TOOL_STYLE.get(tool, ("#000000", "x", "-"))
            slope = f", exponent {slopes[tool]:.2f}" if tool in slopes else ""
            ax.loglog([p for p, _ in pts], [t for _, t in pts], marker=marker, linestyle=line, color=color,
                      label=f"{_TOOL_LABELS.get(tool, tool)}{slope}")
        ax.set_xlabel(f"{name} (log scale)")
        ax.set_ylabel("CPU time per step (s), log scale")
        ax.set_title(textwrap.fill("exact LQ path, n grows" if grid == "lq" else grid, 40), fontsize=10)
        ax.legend(fontsize=8)
    fig.suptitle(textwrap.fill(TITLES.get(module, module), int(6.5 * width)))
    fig.set_layout_engine("constrained")
    return fig


def figure_html(module: str, rows: list[dict]) -> str | None:
    """Both renderings of :func:`figure` (a laptop's and a phone's width) in one ``div.orrc-figure``, with
    the text alternative written from the figure; None when the benchmark states no time."""
    from orrc.viz.describe import describe
    from orrc.viz.figures import NARROW_IN, WIDE_IN, picture_html, render

    wide = figure(module, rows, WIDE_IN)
    if wide is None:
        return None
    alt = describe(wide)
    return picture_html(render(wide, close=False)[0], render(figure(module, rows, NARROW_IN), close=False)[0],
                        alt=alt)


def _short(row: dict, width: int = 34, distinct: str = "") -> str:
    """A bar's label: the row's case (and what tells apart rows of the same case), shortened to fit."""
    case = row["case"].split(";")[0].replace("orrc.simulate vs ", "vs ").strip()
    if distinct:   # "preview_rhc #1 (M: 5, gamma: 3)" of "first moves ..." -> "preview_rhc #1: first moves"
        case = f"{case.split(' (')[0]}: {' '.join(distinct.split()[:2])}"
    return case if len(case) <= width else case[: width - 1] + "…"


def _distinct(benchmark: str, all_benchmarks: list[str]) -> str:
    """What sets ``benchmark`` apart from the others of its module: the text after their common prefix."""
    prefix = os.path.commonprefix(sorted(set(all_benchmarks)))
    return benchmark[len(prefix):].strip(" ,()") or benchmark


def missed(rows: list[dict]) -> list[str]:
    """reStructuredText lines: a bullet per row whose target was missed, with its measured ratio, the target
    and what the row measured beside it (its correctness check: the solvers each tool's steps took, the
    iterations); nothing when every target was met."""
    out = [f"- {_grid(r)}{_cell(r['case'])}: {_cell(r['ratio'])} (target {_cell(r['target'])}); "
           f"{_cell(r.get('check', ''))}" + _floor(r, rows) + _compiled(r) for r in rows if r.get("ok") is False]
    return ["Targets missed, by how much, and what was measured beside them:", "", *out, ""] if out else []


def _floor(row: dict, rows: list[dict]) -> str:
    """For a scaling row against a peer: the bare CasADi loop's time at the same point (the floor of any code
    calling orrc's NLP), so that a reader sees whether the gap is orrc's own work or the NLP solver's."""
    d = row.get("data") or {}
    if "grid" not in d or d.get("tool") in (None, "bare"):
        return ""
    same = [r for r in rows if (r.get("data") or {}).get("grid") == d["grid"] and r["data"].get("size") == d["size"]
            and r["data"].get("tool") == "bare"]
    if not same:
        return ""
    bare = same[0]["data"]
    if "t_peer" not in bare:
        text = f"; the bare CasADi loop at this point: {_cell(bare.get('skipped', 'not run'))}"
    else:
        text = (f"; the bare CasADi loop on the same NLP at this point: {_cell(same[0]['peer'])}, "
                f"{bare['t_peer'] / d['t_peer']:.2f}× {_cell(row['case'].split(' vs ')[-1])}")
    own = [r for r in rows if (r.get("data") or {}).get("grid") == d["grid"] and r["data"].get("size") == d["size"]
           and r["data"].get("tool") == "bare_own" and "t_peer" in r["data"]]
    if own:   # orrc took another Hessian than the bare loop's: the floor with orrc's own
        text += (f"; the bare loop with orrc's Hessian: {_cell(own[0]['peer'])}, "
                 f"{own[0]['data']['t_peer'] / d['t_peer']:.2f}× {_cell(row['case'].split(' vs ')[-1])}")
    return text


def _grid(row: dict) -> str:
    """For a scaling row: its grid ("chain of masses, n grows, M=50: "), which tells apart equal sizes of two grids."""
    grid = (row.get("data") or {}).get("grid")
    return f"{_cell(grid)}: " if grid and grid != "lq" else ""


def _compiled(row: dict) -> str:
    """For a scaling row: whether orrc's NLP ran compiled (``orrc._jit``) or interpreted, and why not compiled."""
    d = row.get("data") or {}
    if "grid" not in d or "compiled" not in d or d["compiled"]:
        return ""
    return f"; orrc's NLP interpreted ({_cell(str(d.get('compile_error') or 'not compiled'))})"


class OrrcBenchmarks(Directive):
    """``.. orrc-benchmarks:: [results file]``: the measured results of ``make bench``."""

    optional_arguments = 1

    def run(self):
        env = self.state.document.settings.env
        root = Path(env.app.confdir)
        path = root / (self.arguments[0] if self.arguments else DEFAULT)
        env.note_dependency(str(path))
        try:
            doc = load(path)
        except (BenchmarksError, json.JSONDecodeError) as exc:
            raise self.error(str(exc)) from exc
        m = doc["machine"]
        load_avg = m.get("load_average") or {}
        rst = [
            f"Measured on {_cell(doc['date'])} with ``{doc['command']}``"
            + (" at the smoke-test sizes (``--quick``): these timings mean nothing" if doc.get("quick") else "")
            + f", on {_cell(m.get('cpu'))} ({m.get('cores')} cores available; {_cell(m.get('platform'))}),"
            f" BLAS thread pools {_cell(m.get('blas_threads'))}; load average {load_avg.get('start')} at the"
            f" start and {load_avg.get('end')} at the end; {doc.get('seconds', '?')} s in all."
            + (f" {len(doc['failures'])} check(s) failed or target(s) missed: "
               + "; ".join(_cell(f) for f in doc["failures"]) + "." if doc.get("failures") else
               " Every correctness check passed."),
            "",
            ".. rubric:: Versions",
            "",
            *_list_table(["library", "version"], [[k, v] for k, v in doc["versions"].items()], [50, 50]),
        ]
        parts: list = []   # reStructuredText lines, and figures as raw HTML nodes between them
        for module, rows in groups(doc):
            rst += [f".. rubric:: {_cell(TITLES.get(module, module))}", ""]
            html = figure_html(module, rows)
            if html is None:
                rst += ["This benchmark compares results, not times: its rows are in the table below.", ""]
            else:
                parts += [rst, nodes.raw("", html, format="html")]
                rst = []
            met = sum(r.get("ok") is True for r in rows)
            judged = sum(r.get("ok") is not None for r in rows)
            rst += [f"{len(rows)} row(s); {met} of {judged} target(s) met." if judged else
                    f"{len(rows)} row(s), none with a target.", ""]
            rst += missed(rows)
        # the whole table, folded: eight columns of reference data, hundreds of screens tall on a phone
        rst += [".. rubric:: The whole table", "", f".. dropdown:: Every row of the run ({len(doc['rows'])} rows)", ""]
        rst += ["   " + line if line else line for line in _list_table(
            ["benchmark", "case", "orrc (median)", "peer (median)", "ratio", "target", "met", "correctness check"],
            [[r["benchmark"], r["case"], r["orrc"], r["peer"], r["ratio"], r["target"],
              "—" if r.get("ok") is None else ("yes" if r["ok"] else "no"), r.get("check", "")]
             for r in doc["rows"]])]
        parts.append(rst)
        out = []
        for part in parts:
            if isinstance(part, nodes.Node):
                out.append(part)
                continue
            fence = "`" * 6
            node = nodes.section()
            node.document = self.state.document
            nested_parse_with_titles(self.state, StringList([f"{fence}{{eval-rst}}", *part, fence],
                                                            source=f"<orrc-benchmarks {path.name}>"), node)
            out += node.children
        return out


def setup(app):
    app.add_directive("orrc-benchmarks", OrrcBenchmarks)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
