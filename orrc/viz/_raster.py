"""A matplotlib figure as pixels: drawn once by Agg, and in an adaptive palette of 256 colours.

Used by :func:`orrc.viz.figures.figure_to_png`.
"""
from __future__ import annotations


def palette(image):
    """``image`` (PIL) in an adaptive palette of 256 colours."""
    from PIL import Image

    return image.convert("RGB").quantize(colors=256, method=Image.Quantize.FASTOCTREE)


def agg_rgba(fig, dpi: int):
    """``fig`` drawn once by Agg at ``dpi`` (its layout engine runs inside that draw), as a PIL image
    (RGBA). The same pixels as ``savefig`` at the figure's size, in one draw instead of two: under a
    layout engine ``savefig`` draws the whole figure once without rendering (to lay it out) and then
    again."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    old_canvas, old_dpi = fig.canvas, fig.dpi
    canvas = old_canvas if isinstance(old_canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    try:
        fig.dpi = dpi
        canvas.draw()
        rgba = canvas.buffer_rgba()
        return Image.frombuffer("RGBA", (rgba.shape[1], rgba.shape[0]), bytes(rgba), "raw", "RGBA", 0, 1)
    finally:
        fig.dpi = old_dpi
        if canvas is not old_canvas:
            fig.set_canvas(old_canvas)
