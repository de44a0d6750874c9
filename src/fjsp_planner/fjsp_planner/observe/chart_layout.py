"""What the two schedule charts (`plan_chart`, `fjsp-solve --gantt`; `mission_chart`, the
monitor's whole mission) share so that a chart of a 300-job mission stays a picture one can
read: a width that grows with the schedule only up to MAX_WIDTH, a fixed resolution and label
font, and a job's name written only where its bar can hold it (shortened with '…' when part
of it fits, left out when not), so names never run into each other.
"""

from dataclasses import dataclass

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
from matplotlib.font_manager import FontProperties  # noqa: E402

DPI = 110
MAX_WIDTH = 27.0
"""Inches: 2970 pixels at DPI, the most a screen shows without scrolling sideways."""
LABEL_FONT = 7.0
"""Points: the job names on the bars, about 10 pixels high at DPI."""
PADDING = 2.0
"""Pixels kept free at each end of a bar."""
ELLIPSIS = '…'
MIN_SHOWN = 3
"""Characters of a name worth showing before the ellipsis."""


@dataclass(frozen=True)
class Label:
    """A name written on a bar: the text, the row it is on, its extent in pixels."""

    text: str
    row: float
    left: float
    right: float


@dataclass(frozen=True)
class Drawn:
    """What a chart shows: its size in pixels and the labels written on its bars."""

    width: int
    height: int
    labels: tuple[Label, ...]


def chart_width(units: float, per_unit: float, base: float, minimum: float) -> float:
    """Inches for a schedule of `units`: `base` plus `per_unit` each, within
    [minimum, MAX_WIDTH]."""
    return min(MAX_WIDTH, max(minimum, base + per_unit * units))


class BarLabels:
    """Names for the bars of one axes, written once the axes have their final place in the
    figure (after `tight_layout` or `subplots_adjust`): only then is it known how many
    pixels a schedule unit takes."""

    def __init__(self, ax):
        self.ax = ax
        self.pending = []

    def add(self, text: str, start: float, end: float, row: float, **style) -> None:
        self.pending.append((text, start, end, row, style))

    def write(self) -> tuple[Label, ...]:
        ax = self.ax
        renderer = ax.figure.canvas.get_renderer()
        font = FontProperties(size=LABEL_FONT)
        box = ax.get_window_extent(renderer)
        low, high = ax.get_xlim()
        scale = box.width / (high - low)
        written = []
        for text, start, end, row, style in self.pending:
            room = max(0.0, (min(end, high) - max(start, low)) * scale - 2 * PADDING)
            shown, width = _fitted(text, room, renderer, font)
            if shown is None:
                continue
            centre = (max(start, low) + min(end, high)) / 2
            ax.text(centre, row, shown, ha='center', va='center', fontsize=LABEL_FONT,
                    **style)
            x = box.x0 + (centre - low) * scale
            written.append(Label(shown, row, x - width / 2, x + width / 2))
        return tuple(written)


def _fitted(text: str, room: float, renderer, font) -> tuple[str | None, float]:
    """`text`, or its longest start with an ellipsis, that fits in `room` pixels; and its
    width."""
    for shown in [text] + [text[:n] + ELLIPSIS for n in range(len(text) - 1, MIN_SHOWN - 1,
                                                              -1)]:
        width = renderer.get_text_width_height_descent(shown, font, ismath=False)[0]
        if width <= room:
            return shown, width
    return None, 0.0


def saved(fig, path, labels: tuple[Label, ...]) -> Drawn:
    """Write `fig` (made at DPI) to `path` as PNG, close it; what it shows."""
    fig.savefig(path, dpi=DPI)
    width, height = fig.canvas.get_width_height()
    plt.close(fig)
    return Drawn(width, height, labels)
