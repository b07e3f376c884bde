"""One style for every figure: the palette of the column types, labels and
object-oriented matplotlib figures (no pyplot state, no backend switch)."""
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

COLUMN_LABELS = {"drums": "multi-drum column", "monolithic": "monolithic column",
                 "block": "test block"}
COLUMN_COLOURS = {"drums": "tab:blue", "monolithic": "tab:red", "block": "tab:green"}
COLUMN_MARKERS = {"drums": "s", "monolithic": "o", "block": "^"}
DPI = 120


def figure(**kwargs):
    """A matplotlib Figure with an Agg canvas (savefig works, no GUI, no pyplot)."""
    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


def new_figure(nrows=1, ncols=1, subplot_kw=None, squeeze=True, **kwargs):
    """(figure, axes) like pyplot.subplots, object-oriented."""
    fig = figure(**kwargs)
    return fig, fig.subplots(nrows, ncols, subplot_kw=subplot_kw, squeeze=squeeze)


def colour(column, k=0):
    """Colour of a column type (others cycle through C2, C3, ...)."""
    return COLUMN_COLOURS.get(column, f"C{k + 2}")
