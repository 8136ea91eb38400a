"""Robot colours that stay apart for large teams (no matplotlib needed).

The first ten are matplotlib's ``tab10``, so that small teams look as before; each further colour
is the candidate farthest (CIE 1976 ΔE in CIELAB) from all colours chosen so far, taken from a
fixed grid of hues, saturations and values that are neither too light to see on white nor grey.
The result is deterministic; 50 robots get 50 colours at least ΔE 20 apart.
"""

from __future__ import annotations

import colorsys
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

__all__ = ["TAB10", "robot_colours", "to_hex"]

TAB10 = (
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
)  # fmt: skip
"""matplotlib's ``tab10`` colours, the first ten robots'."""


def _rgb(hex_colour: str) -> tuple[float, float, float]:
    r, g, b = (int(hex_colour[i : i + 2], 16) / 255 for i in (1, 3, 5))
    return r, g, b


def to_hex(rgb: tuple[float, float, float]) -> str:
    """``(r, g, b)`` in [0, 1] as ``#rrggbb``.

    Parameters
    ----------
    rgb : tuple of float
        Red, green and blue, each in [0, 1] (clipped to it).
    """
    return "#" + "".join(f"{round(255 * max(0.0, min(1.0, c))):02x}" for c in rgb)


def lab(rgb: NDArray[np.float64]) -> NDArray[np.float64]:
    """sRGB colours (``(..., 3)`` in [0, 1]) in CIELAB (D65).

    Parameters
    ----------
    rgb : numpy.ndarray of float
        Colours, shape ``(..., 3)``, each component in [0, 1].

    Returns
    -------
    numpy.ndarray of float
        ``L*, a*, b*`` in the same shape.
    """
    c = np.asarray(rgb, dtype=float)
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    m = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
    xyz = linear @ m.T / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])], -1)


@lru_cache(maxsize=1)
def _candidates() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    rgb = np.array(
        [
            colorsys.hsv_to_rgb(h / 60, s, v)
            for h in range(60)
            for s in (0.5, 0.75, 1.0)
            for v in (0.4, 0.6, 0.8, 0.95)
        ]
    )
    lab_values = lab(rgb)
    chroma = np.hypot(lab_values[:, 1], lab_values[:, 2])
    keep = (lab_values[:, 0] < 80) & (chroma > 25)  # visible on white, not grey
    return rgb[keep], lab_values[keep]


@lru_cache(maxsize=8)
def _palette(n: int) -> tuple[tuple[float, float, float], ...]:
    chosen = [_rgb(c) for c in TAB10[:n]]
    if n <= len(TAB10):
        return tuple(chosen)
    rgb, lab_values = _candidates()
    nearest = np.min(np.linalg.norm(lab_values[:, None, :] - lab(np.array(chosen))[None], axis=-1), axis=1)
    while len(chosen) < n:
        k = int(np.argmax(nearest))
        r, g, b = (float(v) for v in rgb[k])
        chosen.append((r, g, b))
        nearest = np.minimum(nearest, np.linalg.norm(lab_values - lab_values[k], axis=-1))
    return tuple(chosen)


def robot_colours(n: int) -> list[tuple[float, float, float]]:
    """`n` distinct robot colours as ``(r, g, b)`` in [0, 1]: tab10, then farthest-point picks.

    Parameters
    ----------
    n : int
        How many colours (>= 0). Beyond the candidate grid's size (several hundred) colours
        repeat; robots are labelled by id in every picture anyway.
    """
    if n <= 0:
        return []
    rgb, _ = _candidates()
    limit = len(TAB10) + len(rgb)
    colours = _palette(min(n, limit))
    return [colours[i % len(colours)] for i in range(n)]
