"""Texts drawn onto animation frames by PIL (``plots.frame_text``) land where matplotlib draws
them: for each kind of text the animations use (a boxed monospace caption, round boxes aligned
to the top corners, a bold coloured label, a centred text of two lines, an axes title of two
lines), the pixels it changes span the same box as matplotlib's to within a pixel."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib import patheffects
from matplotlib.text import Text
from PIL import Image

from mosys.plots.frame_text import draw_text, drawable
from mosys.plots.style import new_figure, plot_style

ROUND = {"boxstyle": "round,pad=0.3", "facecolor": "white", "alpha": 0.9}
SQUARE = {"facecolor": "white", "alpha": 0.85, "edgecolor": "0.6"}
MONOSPACE = {"family": "monospace"}
TOP_RIGHT = {"ha": "right", "va": "top", "fontsize": 11, "fontweight": "bold", "color": "tab:red"}
CASES = {  # name: (position in axes fractions, string, style)
    "boxed caption": ((0.03, 0.03), "t =  1.23 s   controller D", {**MONOSPACE, "bbox": SQUARE}),
    "round box, top left": ((0.02, 0.97), "t = 14.56 s", {**MONOSPACE, "va": "top", "bbox": ROUND}),
    "bold label, top right": ((0.98, 0.97), "walk (Rex)", {**TOP_RIGHT, "bbox": ROUND}),
    "two lines, centred": (
        (0.5, 0.5),
        "centred\ntwo lines, the longer",
        {"ha": "center", "va": "center"},
    ),
    "bottom, baseline": ((0.4, 0.2), "g-jpq\nbaseline (last line)", {"va": "baseline"}),
}
DPI = 80


def changed_box(before: np.ndarray, after: np.ndarray) -> tuple[int, int, int, int]:
    """(left, top, right, bottom) of the pixels that differ by more than a faint antialiasing
    shade."""
    rows, columns = np.nonzero(np.abs(after.astype(int) - before.astype(int)).max(axis=2) > 24)
    return columns.min(), rows.min(), columns.max(), rows.max()


def frames_of(place) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The canvas without the text, with matplotlib's text and with frame_text's."""
    with plot_style():
        figure = new_figure(4.8, 3.0)
        figure.set_dpi(DPI)
        ax = figure.add_subplot()
        text = place(ax)
        text.set_animated(True)
        figure.canvas.draw()
        background = np.asarray(figure.canvas.buffer_rgba())[..., :3].copy()
        drawn = Image.fromarray(background.copy())
        assert drawable(text)
        draw_text(drawn, text, figure.dpi)
        figure.draw_artist(text)
        by_matplotlib = np.asarray(figure.canvas.buffer_rgba())[..., :3].copy()
    return background, by_matplotlib, np.asarray(drawn)


@pytest.mark.parametrize("case", list(CASES))
def test_a_text_lands_where_matplotlib_draws_it(case):
    position, string, style = CASES[case]
    background, by_matplotlib, by_pil = frames_of(
        lambda ax: ax.text(*position, string, transform=ax.transAxes, **style)
    )
    expected = changed_box(background, by_matplotlib)
    got = changed_box(background, by_pil)
    assert np.abs(np.subtract(got, expected)).max() <= 1, (got, expected)


def test_a_title_of_two_lines_lands_where_matplotlib_draws_it():
    def title(ax) -> Text:
        text = ax.set_title(" \n ", fontsize=10)  # as the Luxo animation reserves its room
        ax.figure.canvas.draw()
        text.set_text("t =  1.00 s   motion 1 of 3: hop\ndriven by the time-based hop")
        return text

    background, by_matplotlib, by_pil = frames_of(title)
    expected = changed_box(background, by_matplotlib)
    got = changed_box(background, by_pil)
    assert np.abs(np.subtract(got, expected)).max() <= 1, (got, expected)


def test_an_empty_or_hidden_text_draws_nothing():
    def hidden(ax) -> Text:
        text = ax.text(0.5, 0.5, "hidden", bbox=SQUARE)
        text.set_visible(False)
        return text

    for place in (lambda ax: ax.text(0.5, 0.5, "", bbox=SQUARE), hidden):
        background, _, by_pil = frames_of(place)
        assert np.array_equal(background, by_pil)


def test_rotated_mathtext_outlined_and_wrapped_texts_are_left_to_matplotlib():
    with plot_style():
        figure = new_figure(2.0, 2.0)
        ax = figure.add_subplot()
        assert not drawable(ax.text(0.5, 0.5, "up", rotation=90))
        assert not drawable(ax.text(0.5, 0.5, r"$\omega$"))
        assert not drawable(ax.text(0.5, 0.5, "sawtooth", bbox={"boxstyle": "sawtooth"}))
        assert not drawable(ax.text(0.5, 0.5, "wrapped", wrap=True))
        outlined = ax.text(0.5, 0.5, "outlined")
        outlined.set_path_effects([patheffects.withStroke(linewidth=3, foreground="white")])
        assert not drawable(outlined)
        assert drawable(ax.text(0.5, 0.5, "plain"))
