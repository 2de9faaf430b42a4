"""Matplotlib set-up shared by every figure: Agg backend, atomic PNG writes."""

from __future__ import annotations


def new_figure(*args, **kwargs):
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


def picture_height(width_in: float, w: int, h: int) -> float:
    """Inches of height for a picture of w x h pixels drawn ``width_in`` inches wide: its aspect,
    held between 1:8 and 2:1 (a 1x1000 video drawn to scale was an 8000-inch figure, out of memory)."""
    return width_in * min(max(h / max(w, 1), 1 / 8), 2.0)


def picture_aspect(w: int, h: int) -> str:
    """imshow's aspect for :func:`picture_height`: to scale, unless the height was held."""
    return "equal" if 1 / 8 <= h / max(w, 1) <= 2.0 else "auto"


def save_figure(fig, path, *, force: bool = False, dpi: int = 120) -> None:
    import matplotlib.pyplot as plt
    from matplotlib.text import Text

    from wallcli.io.text import escape_surrogates
    from wallcli.io.writer import atomic_path

    try:
        # a file name that is not UTF-8 (titles name the input) holds lone surrogates, which
        # matplotlib's font code refuses outright: shown escaped, as in the JSON
        for text in fig.findobj(Text):
            label = text.get_text()
            if isinstance(label, str) and escape_surrogates(label) != label:
                text.set_text(escape_surrogates(label))
        with atomic_path(path, force=force) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png", bbox_inches="tight")
    finally:
        plt.close(fig)
