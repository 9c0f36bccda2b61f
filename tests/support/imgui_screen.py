"""Find meshlap's ImGui panel and its widgets in a screenshot, by colour and layout alone.

polyscope draws its ImGui windows inside the GL window, so no X11 tool can see a widget. This
module reads the picture the way a user does: the panel is the right-most ImGui window (the one
polyscope opens for the user callback), collapsing headers are full-width bars of the theme's
green, buttons are shorter green bars, and input fields, sliders, check boxes, combos and plots
are grey frames; a combo is a frame with one green arrow square at its right end. Rows between
two headers form a *section* (section 0 starts with the first header, "Mesh" today).

Nothing depends on pixel positions of a particular build: positions are measured on every
screenshot, so window size, panel width and row heights may change. What the tour assumes is
the *order* of widgets inside a section (e.g. "the first combo of the Mesh section is the mesh
list"); that order is stated once, in ``tests/window/test_tour.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


# ---------------------------------------------------------------------------- pixel classes
def _rgb(img: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The three channels as int16 planes (per-channel ops: reductions over a last axis of
    length 3 are slow in numpy)."""
    return img[..., 0].astype(np.int16), img[..., 1].astype(np.int16), img[..., 2].astype(np.int16)


def _spread(r: np.ndarray, g: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel (min, max) over the channels."""
    return np.minimum(np.minimum(r, g), b), np.maximum(np.maximum(r, g), b)


def green(img: np.ndarray) -> np.ndarray:
    """Pixels of polyscope's theme green (headers, buttons, combo arrows, title bars)."""
    r, g, b = _rgb(img)
    return (g - r >= 25) & (g - b >= 8) & (g >= 95) & (g <= 215)


def frame(img: np.ndarray, ref: np.ndarray | None = None) -> np.ndarray:
    """Pixels of an ImGui frame (grey, drawn translucent over the scene, hence tinted).

    Over a light scene a frame is brighter than any panel background can be (mean >= 86).
    Over a dark scene (a close-up that fills the view) the translucent frame darkens too;
    ``ref``, the mean level of the panel background next to the pixels (broadcast against
    them), then tells it apart: a frame is at least 30 levels above the background it is
    drawn on, text excluded (mean <= 180 as always).
    """
    r, g, b = _rgb(img)
    lo, hi = _spread(r, g, b)
    total = r + g + b  # 3 x mean
    level = total >= 3 * 86
    if ref is not None:
        ref = np.asarray(ref, dtype=np.int16)
        level |= (ref <= 80) & (total >= 3 * (ref + 16))
    return (hi - lo <= 30) & level & (total <= 3 * 180) & ~green(img)


def bright(img: np.ndarray) -> np.ndarray:
    """Text pixels (the theme draws text near-white)."""
    lo, hi = _spread(*_rgb(img))
    return (lo >= 170) & (hi - lo <= 40)


def runs(mask: np.ndarray, min_len: int = 1, max_gap: int = 0) -> list[tuple[int, int]]:
    """Inclusive ``(start, end)`` index pairs of the True runs of a 1-D mask.

    Runs separated by at most ``max_gap`` False entries are merged; runs shorter than
    ``min_len`` (after merging) are dropped.
    """
    idx = np.flatnonzero(np.asarray(mask, dtype=bool))
    if len(idx) == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > max_gap + 1)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    return [(int(s), int(e)) for s, e in zip(starts, ends, strict=True) if e - s + 1 >= min_len]


# ---------------------------------------------------------------------------- layout
@dataclass
class Item:
    """One row of the panel: a header, a frame widget, a row of buttons, or a plot."""

    kind: str  # "header", "combo", "input", "slider", "checkbox", "buttons", "plot"
    y0: int
    y1: int
    x0: int
    x1: int
    buttons: list[tuple[int, int]] = field(default_factory=list)  # green bars on the row

    @property
    def center(self) -> tuple[int, int]:
        return (self.x0 + self.x1) // 2, (self.y0 + self.y1) // 2


@dataclass
class Layout:
    """The panel's box and its rows, grouped into sections that each start with a header."""

    left: int
    right: int
    top: int
    bottom: int
    sections: list[list[Item]]

    def find(self, section: int, kind: str, nth: int = 0) -> Item:
        """The ``nth`` item of ``kind`` in a section (negative ``nth`` counts from the end)."""
        items = [it for it in self.sections[section] if it.kind == kind]
        if not items or not -len(items) <= nth < len(items):
            kinds = [it.kind for it in self.sections[section]]
            raise LookupError(f"no {kind} #{nth} in section {section}: it holds {kinds}")
        return items[nth]

    def describe(self) -> str:
        return "; ".join(
            f"section {i}: " + ", ".join(it.kind for it in sec)
            for i, sec in enumerate(self.sections)
        )


def find_panel(img: np.ndarray) -> tuple[int, int, int, int]:
    """Box ``(left, right, top, bottom)`` of the right-most ImGui window with green bars."""
    g = green(img)
    h, w = g.shape
    bars = []  # (y, x0, x1) of long green runs: title bars and headers
    for y in np.flatnonzero(g.sum(axis=1) >= 150):
        for x0, x1 in runs(g[y], min_len=150, max_gap=2):
            bars.append((int(y), x0, x1))
    if not bars:
        raise LookupError("no ImGui window (no green title bar or header) on screen")
    right = max(b[2] for b in bars)
    mine = [b for b in bars if b[2] >= right - 12]
    left = min(b[1] for b in mine)
    top = min(b[0] for b in mine)
    # below its last header the panel goes on while its left margin is panel background
    column = img[:, min(left + 3, w - 1)].astype(np.int16).mean(axis=-1)
    bottom = max(b[0] for b in mine)
    while bottom + 1 < h and column[bottom + 1] < 100:
        bottom += 1
    return left, right, top, bottom


def parse(img: np.ndarray) -> Layout:
    """Read meshlap's panel: its rows, classified, grouped by collapsing header."""
    left, right, top, bottom = find_panel(img)
    sub = img[top : bottom + 1, left : right + 1]
    g, f, t = green(sub), frame(sub), bright(sub)
    # every widget starts at the content's left margin: probe just right of it (check boxes
    # and buttons may be narrow)
    # (white text and a header's arrow are neutral)
    is_g = ((g | t | f)[:, 10:24].mean(axis=1) > 0.8) & (g[:, 10:24].mean(axis=1) > 0.3)
    # the panel's background in its left margin, row by row: frames over a dark scene
    margin = sub[:, 3:7].astype(np.int16).mean(axis=(1, 2))
    probe = f[:, 10:30] | frame(sub[:, 10:30], margin[:, None])
    is_f = (probe | t[:, 10:30]).mean(axis=1) > 0.6
    width = right - left
    items: list[Item] = []
    for kind, mask in (("g", is_g), ("f", is_f & ~is_g)):
        for y0, y1 in runs(mask, min_len=18, max_gap=1):
            item = _classify(kind, sub, g, f, t, int(y0), int(y1), width)
            if item is not None:
                items.append(item)
    items.sort(key=lambda it: it.y0)
    # the first green bar at the top is the window's title bar
    if items and items[0].kind == "header" and items[0].y0 <= 4:
        items = items[1:]
    # frames share one item width; the scene seen through a frame may cut its measured span
    combos = [it.x1 for it in items if it.kind == "combo"]
    if combos:
        full = max(set(combos), key=combos.count)
        for it in items:
            if it.kind in ("input", "slider") and it.x1 < full:
                if not any(it.x1 < b0 < full for b0, _ in it.buttons):
                    it.x1 = full
    sections: list[list[Item]] = []
    for it in items:
        it.x0, it.x1, it.y0, it.y1 = it.x0 + left, it.x1 + left, it.y0 + top, it.y1 + top
        it.buttons = [(a + left, b + left) for a, b in it.buttons]
        if it.kind == "header" or not sections:
            sections.append([])
        sections[-1].append(it)
    return Layout(left, right, top, bottom, sections)


def _classify(
    kind: str,
    sub: np.ndarray,
    g: np.ndarray,
    f: np.ndarray,
    t: np.ndarray,
    y0: int,
    y1: int,
    width: int,
) -> Item | None:
    h = y1 - y0 + 1
    row = min(y0 + 2, y1)  # above the text, which is centred in the row
    greens = runs(g[row], min_len=6, max_gap=2)
    if kind == "g":
        if not greens:
            return None
        x0, x1 = greens[0]
        if x1 - x0 > 0.8 * (width - 16):
            return Item("header", y0, y1, x0, x1)
        return Item("buttons", y0, y1, greens[0][0], greens[-1][1], buttons=greens)
    if h > 60:
        spans = runs(f[(y0 + y1) // 2] | t[(y0 + y1) // 2], min_len=20, max_gap=6)
        x0, x1 = spans[0] if spans else (0, width)
        return Item("plot", y0, y1, x0, x1)
    # the frame's top rows hold no text; the scene seen through it may darken a few pixels.
    # Over a dark scene, compare with the panel background in the gap just above the row
    gap = sub[max(y0 - 3, 0) : max(y0 - 1, 1)].astype(np.int16).mean(axis=2).min(axis=0)
    f_row = f[row] | frame(sub[row : row + 1], gap[None, :])[0]
    spans = runs(f_row[6:], min_len=h - 6, max_gap=10)
    if not spans:
        return None
    x0, x1 = spans[0][0] + 6, spans[0][1] + 6
    after = [gr for gr in greens if gr[0] >= x1 - 2]
    if x1 - x0 <= h + 4 and not (after and after[0][0] - x1 <= 3):
        return Item("checkbox", y0, y1, x0, x1, buttons=after)
    # a combo ends in one green arrow square; an integer field ends in two (- and +)
    square = [gr for gr in after if h - 8 <= gr[1] - gr[0] + 1 <= h + 4]
    if square and square[0] is after[0]:
        lone = len(after) == 1 or after[1][0] - after[0][1] > 8
        if lone:
            return Item("combo", y0, y1, x0, after[0][1], buttons=after[1:])
    c = sub[y0 + 3 : y1 - 2, x0:x1].astype(np.int16).mean(axis=-1)
    grab_cols = np.all((c >= 130) & (c <= 180), axis=0)
    if runs(grab_cols, min_len=5):
        return Item("slider", y0, y1, x0, x1, buttons=after)
    return Item("input", y0, y1, x0, x1, buttons=after)


def popup_lines(img: np.ndarray, under: Item) -> list[tuple[int, int]]:
    """Screen ``(x, y)`` centres of the text lines of the list that a combo opened below it.

    The popup starts right under the combo's frame, is dark, and holds one text line per
    entry (the hovered entry is drawn green).
    """
    x0, x1 = under.x0, under.x1
    column = img[:, x0 + 2]
    c = column.astype(np.int16)
    dark = c.mean(axis=-1) < 62
    dark |= green(column[None])[0]
    y = under.y1 + 1
    while y < len(c) and not dark[y] and y < under.y1 + 6:
        y += 1
    y_top = y
    while y < len(c) and (dark[y] or bright(column[None, y])[0]):
        y += 1
    y_bottom = y - 1
    if y_bottom - y_top < 8:
        return []
    text = bright(img[y_top : y_bottom + 1, x0 : x1 + 1]).sum(axis=1) >= 2
    return [((x0 + x1) // 2, y_top + (a + b) // 2) for a, b in runs(text, min_len=4, max_gap=3)]


def subject_point(img: np.ndarray, layout: Layout) -> tuple[int, int] | None:
    """A pixel of the shown mesh left of the panel: the coloured/shaded pixel at least 12
    pixels inside the mesh's silhouette nearest to the median of all such pixels (the white
    background and the pale ground shadow excluded)."""
    h, w = img.shape[:2]
    x_lo, x_hi = int(0.3 * w), layout.left - 10
    y_lo, y_hi = int(0.1 * h), int(0.9 * h)
    if x_hi <= x_lo:
        return None
    c = img[y_lo:y_hi, x_lo:x_hi].astype(np.int16)
    mean = c.mean(axis=-1)
    spread = c.max(axis=-1) - c.min(axis=-1)
    mask = (spread > 40) | (mean < 180)
    mask &= ~green(img[y_lo:y_hi, x_lo:x_hi])
    for _ in range(12):  # erode: a click near a silhouette or a hole may miss the mesh
        inner = mask.copy()
        inner[1:] &= mask[:-1]
        inner[:-1] &= mask[1:]
        inner[:, 1:] &= mask[:, :-1]
        inner[:, :-1] &= mask[:, 1:]
        mask = inner
    ys, xs = np.nonzero(mask)
    if len(ys) < 200:
        return None
    my, mx = np.median(ys), np.median(xs)
    k = int(np.argmin((ys - my) ** 2 + (xs - mx) ** 2))
    return int(xs[k]) + x_lo, int(ys[k]) + y_lo


def changed_fraction(a: np.ndarray, b: np.ndarray, box: tuple[int, int, int, int]) -> float:
    """Fraction of pixels in ``box = (x0, y0, x1, y1)`` that differ by more than 24 levels."""
    x0, y0, x1, y1 = box
    a, b = a[y0:y1, x0:x1], b[y0:y1, x0:x1]
    d = np.maximum(a, b)
    d -= np.minimum(a, b)  # |a - b| in uint8 (ten times faster than through int16)
    big = (d[..., 0] > 24) | (d[..., 1] > 24) | (d[..., 2] > 24)
    return float(big.mean()) if big.size else 0.0


# ---------------------------------------------------------------------------- the scene
COLORBAR_BOX = (0, 0, 175, 300)
"""``(x0, y0, x1, y1)`` of polyscope's on-screen colour bar (top-left, fixed size in pixels):
not part of the subject."""


def subject_mask(img: np.ndarray, layout: Layout) -> np.ndarray:
    """Pixels of the 3D subject left of meshlap's panel: shaded or coloured, not the white
    background nor the pale ground shadow, not the colour bar and its title row."""
    c = img[:, : layout.left].astype(np.int16)
    mask = (c.max(axis=-1) - c.min(axis=-1) > 40) | (c.mean(axis=-1) < 180)
    x0, y0, x1, y1 = COLORBAR_BOX
    mask[y0:y1, x0:x1] = False
    mask[:32] = False  # the colour bar's title
    return mask


def subjects(img: np.ndarray, layout: Layout) -> list[tuple[int, int]]:
    """Horizontal extents ``(x0, x1)`` of the objects left of the panel (meshes side by side
    are separated by background columns; captions and labels are too thin to count)."""
    cols = subject_mask(img, layout).sum(axis=0) >= 24
    return runs(cols, min_len=24, max_gap=12)


def behind_panel(img: np.ndarray, layout: Layout) -> bool:
    """Does the subject run into meshlap's panel (subject pixels in the 6 columns left of it)?"""
    strip = subject_mask(img, layout)[layout.top : layout.bottom, layout.left - 6 :]
    return bool(strip.sum(axis=0).max(initial=0) >= 12)
