"""Texts drawn onto animation frames by PIL instead of matplotlib.

An animation's caption changes every frame (the time, the active controller), and matplotlib
lays out and rasterises a changed text anew each time: a pendulum GIF's boxed caption took
0.55 s of its 1.05 s. PIL draws the same string in about 0.1 ms. ``draw_text`` reads a
matplotlib Text artist as it stands (string, position, alignment, font, colour and box) and
draws it onto a frame so that it sits where matplotlib would put it: the font file matplotlib
would use at the figure's resolution, matplotlib's line layout (every line at least as tall as
the font's typographic ascent and descent, a line gap between lines) and its alignments, and
the text's box (square or round, its padding, face and edge colours with their alpha). Glyphs
are rasterised by FreeType in both, so the two differ by antialiasing and a pixel of placement
at most.
"""

from __future__ import annotations

from functools import lru_cache

from matplotlib import font_manager
from matplotlib.colors import to_rgba
from matplotlib.patches import BoxStyle
from matplotlib.text import Text
from PIL import Image, ImageDraw, ImageFont

POINTS_PER_INCH = 72.0
BOX_STYLES = (BoxStyle.Square, BoxStyle.Round)


@lru_cache(maxsize=32)
def _font(path: str, pixels: float) -> ImageFont.FreeTypeFont:
    """The font at ``pixels`` per em, laid out as matplotlib lays it out: glyph by glyph at
    hinted (whole-pixel) advances, no shaping (PIL's RAQM layout sets monospace 5 % tighter)."""
    return ImageFont.truetype(path, pixels, layout_engine=ImageFont.Layout.BASIC)


@lru_cache(maxsize=32)
def _least_line(path: str, pixels: float) -> tuple[float, float, float]:
    """(ascent, descent, line gap), px: what matplotlib's layout gives every line at least (a
    line gap only between lines), from the font's OS/2 typographic metrics, else its hhea
    ones, as ``Text._get_layout`` takes them; (0, 0, 0) for a font with neither."""
    font = font_manager.get_font(path)
    scale = pixels / font.get_sfnt_table("head")["unitsPerEm"]
    for table_name, gap, ascent, descent in (
        ("OS/2", "sTypoLineGap", "sTypoAscender", "sTypoDescender"),
        ("hhea", "lineGap", "ascent", "descent"),
    ):
        table = font.get_sfnt_table(table_name)
        if table is not None:
            return table[ascent] * scale, -table[descent] * scale, table[gap] * scale
    return 0.0, 0.0, 0.0


def _rgba(color, alpha: float | None = None) -> tuple[int, int, int, int]:
    """``color`` (with ``alpha``, if given) as PIL's 0–255 RGBA."""
    return tuple(round(255 * channel) for channel in to_rgba(color, alpha))


def drawable(text: Text) -> bool:
    """Whether ``draw_text`` draws ``text`` as matplotlib would: unrotated, no mathtext or TeX,
    no path effects or wrapping, and a square or round box if any."""
    patch = text.get_bbox_patch()
    return (
        text.get_rotation() == 0
        and not text.get_usetex()
        and "$" not in text.get_text()
        and not text.get_path_effects()
        and not text.get_wrap()
        and (patch is None or isinstance(patch.get_boxstyle(), BOX_STYLES))
    )


def draw_text(image: Image.Image, text: Text, dpi: float) -> None:
    """Draw the matplotlib Text artist ``text`` of a figure at ``dpi`` onto ``image`` (RGB, the
    figure's canvas: its pixels, origin at the top left), box first; nothing when the text is
    empty or hidden. ``drawable(text)`` must hold."""
    content = text.get_text()
    if not content or not text.get_visible():
        return
    pixels = text.get_fontproperties().get_size_in_points() * dpi / POINTS_PER_INCH
    path = font_manager.findfont(text.get_fontproperties())
    font = _font(path, pixels)
    least_ascent, least_descent, gap = _least_line(path, pixels)
    gap = gap if "\n" in content else 0.0
    x, y = text.get_transform().transform(text.get_unitless_position())
    y = image.height - y
    lines = content.split("\n")
    widths = [font.getlength(line) for line in lines]
    depths = []  # each line's baseline below the layout's top
    height = 0.0
    for line in lines:
        _, top, _, bottom = font.getbbox(line, anchor="ls") if line else (0, 0, 0, 0)
        ascent = max(-top, least_ascent) + gap / 2
        descent = max(bottom, least_descent) + gap / 2
        depths.append(height + ascent)
        height += ascent + descent
    width = max(widths)
    left = x - {"left": 0.0, "center": width / 2, "right": width}[text.get_horizontalalignment()]
    top = (
        y
        - {  # the anchor's depth below the layout's top, as in matplotlib's layout
            "top": 0.0,
            "center": height / 2,
            "bottom": height,
            "baseline": depths[-1],
            "center_baseline": depths[-1] / 2,
        }[text.get_verticalalignment()]
    )
    draw = ImageDraw.Draw(image, "RGBA")
    patch = text.get_bbox_patch()
    if patch is not None:
        style = patch.get_boxstyle()
        pad = style.pad * pixels
        corners = (left - pad, top - pad, left + width + pad, top + height + pad)
        edge = _rgba(patch.get_edgecolor())
        edge_width = round(patch.get_linewidth() * dpi / POINTS_PER_INCH) if edge[3] else 0
        outline = edge if edge_width else None
        face = _rgba(patch.get_facecolor())
        if isinstance(style, BoxStyle.Round):
            radius = (style.rounding_size or style.pad) * pixels
            draw.rounded_rectangle(corners, radius, face, outline, edge_width)
        else:
            draw.rectangle(corners, face, outline, edge_width)
    fill = _rgba(text.get_color(), text.get_alpha())
    align = text.get_horizontalalignment()  # each line as the whole (no ``multialignment``)
    for line, line_width, depth in zip(lines, widths, depths, strict=True):
        offset = {"left": 0.0, "center": (width - line_width) / 2}.get(align, width - line_width)
        draw.text((left + offset, top + depth), line, fill=fill, font=font, anchor="ls")
