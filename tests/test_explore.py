"""The contract of orrc.viz.explore: one plotting function, live widget + static frames.

The static HTML (what the rendered book shows) must hold one ``div.orrc-frames`` with
one ``input.orrc-slider[type=range]`` per parameter, as many positions as values, and
an ``img.orrc-frame[data-variant=wide]`` (plus a ``narrow`` one for a frame wider than a
phone's column) showing the frame of the initial values; the frame data holds one PNG
per combination and variant, each drawn by the same ``plot`` function at 100 dpi. The
browser test (tests/test_book.py) checks that moving a slider flips the image in Chromium.
"""
from __future__ import annotations

import base64
import html.parser
import io
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from orrc.viz import explore  # noqa: E402
from orrc.viz.explore import figure_to_png  # noqa: E402


class _Frames(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.divs, self.sliders, self.imgs, self.outputs, self.variants = [], [], [], [], []
        self.data, self._in_data = "", False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        cls = (a.get("class") or "").split()
        if tag == "div" and "orrc-frames" in cls:
            self.divs.append(a)
        if tag == "input" and "orrc-slider" in cls:
            self.sliders.append(a)
        if tag == "img" and "orrc-frame" in cls:
            self.imgs.append(a)
            self.variants.append(a.get("data-variant"))
        if tag == "output":
            self.outputs.append(a)
        self._in_data = tag == "script" and "orrc-frame-data" in cls

    def handle_endtag(self, tag):
        if tag == "script":
            self._in_data = False

    def handle_data(self, data):
        if self._in_data:
            self.data += data


def parse(html_text: str) -> _Frames:
    p = _Frames()
    p.feed(html_text)
    return p


def line_plot(calls, width=2.0):
    def plot(M, gamma):
        calls.append((M, gamma))
        fig, ax = plt.subplots(figsize=(width, 1.5))
        ax.plot([0, 1], [M, gamma])  # a different picture for every (M, gamma)
        ax.set_ylim(0, 12)
        return fig
    return plot


def test_static_frames_follow_the_contract():
    calls = []
    Ms, gammas = [2, 5, 10], [1.0, 2.0]
    ex = explore(line_plot(calls), M=Ms, gamma=gammas, live=False)
    # the plot function was called once per combination, with exactly the grid's values
    assert sorted(calls) == sorted((M, g) for M in Ms for g in gammas)
    p = parse(ex.html)
    assert len(p.divs) == 1 and p.variants == ["wide"]   # a 2-inch frame needs no narrow variant
    assert len(p.sliders) == 2
    for s, (name, vals) in zip(p.sliders, [("M", Ms), ("gamma", gammas)]):
        assert s["type"] == "range" and s["data-name"] == name
        assert (int(s["min"]), int(s["max"]), int(s["step"])) == (0, len(vals) - 1, 1)
        assert s["value"] == "0"  # the first value by default
        assert s["data-labels"].split("|") == [f"{v:g}" if isinstance(v, float) else str(v) for v in vals]
    assert [o["for"] for o in p.outputs] == [s["id"] for s in p.sliders]
    data = json.loads(p.data)
    assert data["mime"] == "image/png"
    assert sorted(data["images"]) == sorted(f"{i}_{j}" for i in range(3) for j in range(2))
    assert len(set(data["images"].values())) == 6, "every combination is its own image"
    assert data["narrow"] is None
    # the image shown first is the frame of the initial values
    assert p.imgs[0]["src"] == "data:image/png;base64," + data["images"]["0_0"]
    from PIL import Image

    for b64 in data["images"].values():
        img = Image.open(io.BytesIO(base64.b64decode(b64)))
        assert img.format == "PNG" and img.size == (200, 150)    # 2 x 1.5 inches at 100 dpi
        assert img.info["dpi"] == pytest.approx((100, 100), abs=0.1)
    # the text/html of the notebook output is exactly this HTML (the book shows it)
    bundle = ex._repr_mimebundle_()
    assert bundle["text/html"] == ex.html
    assert "application/vnd.jupyter.widget-view+json" not in bundle


def test_initial_values_choose_the_slider_positions_and_the_first_frame():
    ex = explore(line_plot([]), M=[2, 5, 10], gamma=[1.0, 2.0], initial={"M": 5, "gamma": 2.0},
                 live=False)
    p = parse(ex.html)
    assert [s["value"] for s in p.sliders] == ["1", "1"]
    assert p.imgs[0]["src"].endswith(json.loads(p.data)["images"]["1_1"])
    assert [s["id"] for s in p.sliders][0] != [s["id"] for s in p.sliders][1]


def test_two_explorers_on_one_page_do_not_share_ids():
    a = parse(explore(line_plot([]), M=[1, 2], gamma=[1.0], live=False).html)
    b = parse(explore(line_plot([]), M=[1, 2], gamma=[1.0], live=False).html)
    assert a.divs[0]["id"] != b.divs[0]["id"]


def test_live_widget_uses_the_same_plot_function():
    calls = []
    ex = explore(line_plot(calls), M=[2, 5], gamma=[1.0], live=True)
    bundle = ex._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle and "text/html" in bundle
    # the widget drew the initial view with the same function (one extra call after the 2 frames)
    assert calls[:2] == [(2, 1.0), (5, 1.0)] and calls[2:] == [(2, 1.0)]


def test_wide_frames_carry_a_narrow_variant_for_phones():
    ex = explore(line_plot([], width=7.0), M=[1, 2], gamma=[1.0], live=False)
    p = parse(ex.html)
    assert p.variants == ["wide", "narrow"]
    data = json.loads(p.data)
    assert sorted(data["narrow"]) == sorted(data["images"]) == ["0_0", "1_0"]
    from PIL import Image

    sizes = {v: Image.open(io.BytesIO(base64.b64decode(d["0_0"]))).size
             for v, d in (("wide", data["images"]), ("narrow", data["narrow"]))}
    assert sizes["wide"][0] == 700 and sizes["narrow"][0] == 340   # 7 in and 3.4 in at 100 dpi
    wide, narrow = p.imgs
    assert wide["src"].endswith(data["images"]["0_0"]) and narrow["src"].endswith(data["narrow"]["0_0"])
    # the page's CSS shows the narrow frame when the column is narrower than the wide one
    assert "@container (max-width: 699px)" in ex.html


def test_frames_below_100_dpi_are_refused():
    with pytest.raises(ValueError, match="dpi must be an integer >= 100; got 70"):
        explore(line_plot([]), M=[1], gamma=[1.0], live=False, dpi=70)


def test_figure_to_png_closes_the_figure():
    fig, _ = plt.subplots()
    n = len(plt.get_fignums())
    png = figure_to_png(fig)
    assert png.startswith(b"\x89PNG") and len(plt.get_fignums()) == n - 1


@pytest.mark.parametrize("args, kwargs, match", [
    (("not a function",), {"M": [1]}, "plot must be a function"),
    ((lambda M: None,), {}, "at least one parameter"),
    ((lambda M: None,), {"M": []}, "'M' has no values"),
    ((lambda M: None,), {"M": [1, 2], "initial": {"M": 3}}, "initial value 3 of 'M'"),
])
def test_bad_input_is_a_clear_value_error(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        explore(*args, live=False, **kwargs)
