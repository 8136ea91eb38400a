"""ROS ``map_server`` maps: a ``map.yaml`` beside a PGM image.

The YAML says::

    image: map.pgm          # relative to the YAML file
    resolution: 0.05        # metres per cell
    origin: [-10.0, -10.0, 0.0]   # the lower-left pixel's pose in the map frame: x, y (m), yaw (rad)
    negate: 0
    occupied_thresh: 0.65
    free_thresh: 0.25
    mode: trinary           # optional: trinary (default), scale or raw

As in ``map_server``, a pixel of value ``v`` (of ``maxval``) has occupancy
``p = (maxval - v) / maxval`` (``p = v / maxval`` when ``negate``); it is occupied when
``p > occupied_thresh``, free when ``p < free_thresh`` and unknown otherwise. In ``raw`` mode
``v`` is the occupancy in percent (0 to 100; anything else is unknown). The image is a PGM
(binary ``P5`` or ASCII ``P2``); other image formats must be converted first. cosmop's walls are
axis-aligned, so the origin's yaw must be 0.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from cosmop.io import read_bytes, read_text
from cosmop.maps.grid import MapError, OccupancyGrid
from cosmop.reading import load_yaml

__all__ = ["read_pgm", "read_ros_map"]


def read_pgm(path: str | os.PathLike[str]) -> tuple[NDArray[np.int64], int]:
    """Read a PGM image (``P5`` binary or ``P2`` ASCII).

    Parameters
    ----------
    path : str or os.PathLike
        The image file.

    Returns
    -------
    pixels : numpy.ndarray
        Integer array of shape ``(height, width)``, top row first, as in the file.
    maxval : int
        The largest possible pixel value (255 for 8-bit images).
    """
    file = os.fspath(path)
    data = read_bytes(path, MapError, "a PGM image")
    magic = data[:2]
    if magic not in (b"P5", b"P2"):
        raise MapError(f"expected a PGM image (P5 or P2), got the start {data[:8]!r}", file=file)
    tokens: list[bytes] = []
    pos = 2
    while len(tokens) < 3:  # width, height, maxval, with comments and white space between
        while pos < len(data) and data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.find(b"\n", pos) + 1 or len(data)
            continue
        start = pos
        while pos < len(data) and not data[pos : pos + 1].isspace() and data[pos : pos + 1] != b"#":
            pos += 1
        if start == pos:
            raise MapError("expected width, height and maxval in the PGM header", file=file)
        tokens.append(data[start:pos])
    try:
        width, height, maxval = (int(t) for t in tokens)
    except ValueError:
        raise MapError(f"expected numbers in the PGM header, got {tokens!r}", file=file) from None
    if width < 1 or height < 1 or not 0 < maxval < 65536:
        raise MapError(f"expected a non-empty image with 0 < maxval < 65536, got {tokens!r}", file=file)
    count = width * height
    if magic == b"P5":
        body = data[pos + 1 :]  # exactly one white-space character ends the header
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype("u1")
        if len(body) < count * dtype.itemsize:
            raise MapError(f"expected {count} pixels, the image data is cut short", file=file)
        pixels = np.frombuffer(body, dtype=dtype, count=count).astype(np.int64)
    else:
        values = data[pos:].split()
        if len(values) < count:
            raise MapError(f"expected {count} pixels, found {len(values)}", file=file)
        try:
            pixels = np.array([int(v) for v in values[:count]], dtype=np.int64)
        except ValueError:
            raise MapError("expected integer pixel values in the P2 image", file=file) from None
    if pixels.max(initial=0) > maxval:
        raise MapError(f"a pixel exceeds maxval {maxval}", file=file)
    return pixels.reshape(height, width), maxval


def _number(doc: dict[str, Any], key: str, file: str, default: float | None = None) -> float:
    value = doc.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise MapError(f"expected a number, got {value!r}", file=file, field=key)
    return float(value)


def _occupancy(
    pixels: NDArray[np.int64], maxval: int, doc: dict[str, Any], file: str
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Boolean arrays ``(occupied, free)`` of the pixels, as ``map_server`` reads them."""
    occupied_thresh = _number(doc, "occupied_thresh", file, 0.65)
    free_thresh = _number(doc, "free_thresh", file, 0.25)
    mode = doc.get("mode", "trinary")
    if mode not in ("trinary", "scale", "raw"):
        raise MapError(f"expected trinary, scale or raw, got {mode!r}", file=file, field="mode")
    if mode == "raw":
        known = pixels <= 100
        percent = np.where(known, pixels, 0)
        return known & (percent > 100 * occupied_thresh), known & (percent < 100 * free_thresh)
    negate = doc.get("negate", 0)
    if negate not in (0, 1, True, False):
        raise MapError(f"expected 0 or 1, got {negate!r}", file=file, field="negate")
    p = pixels / maxval if negate else (maxval - pixels) / maxval
    return p > occupied_thresh, p < free_thresh


def read_ros_map(
    path: str | os.PathLike[str],
    *,
    unknown: Literal["blocked", "free"] = "blocked",
    cell_size: float | None = None,
) -> OccupancyGrid:
    """Read a ROS ``map_server`` map (the YAML file; its image is found beside it).

    Parameters
    ----------
    path : str or os.PathLike
        The ``map.yaml`` file.
    unknown : {"blocked", "free"}, optional
        What unknown cells are (default blocked: a robot never plans through them).
    cell_size : float, optional
        Side of a cell in mm; by default the YAML's ``resolution`` (m) times 1000.

    Returns
    -------
    OccupancyGrid
        Lengths in mm; the origin is the YAML's ``origin`` (x, y) in mm.

    Raises
    ------
    MapError
        If a file cannot be read, a key is missing or wrong, the yaw is not 0, or the image is
        not a PGM; the error names the file and the field.
    """
    file = os.fspath(path)
    doc, _ = load_yaml(read_text(path, MapError, "a ROS map YAML file"), file, MapError)
    if not isinstance(doc, dict):
        raise MapError("expected a mapping with image, resolution and origin", file=file)
    image = doc.get("image")
    if not isinstance(image, str) or not image:
        raise MapError("expected the image file name (a PGM beside the YAML)", file=file, field="image")
    resolution = _number(doc, "resolution", file)
    if resolution <= 0:
        raise MapError(
            f"expected a positive number of metres per cell, got {resolution:g}",
            file=file,
            field="resolution",
        )
    origin = doc.get("origin")
    if not (
        isinstance(origin, list)
        and len(origin) == 3
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in origin)
    ):
        raise MapError(f"expected [x, y, yaw] (m, m, rad), got {origin!r}", file=file, field="origin")
    if origin[2] != 0:
        raise MapError(
            f"expected yaw 0: cosmop's walls are axis-aligned, got {origin[2]!r} rad",
            file=file,
            field="origin",
        )
    pixels, maxval = read_pgm(Path(file).parent / image)
    occupied, free = _occupancy(pixels, maxval, doc, file)
    blocked = occupied | (~free if unknown == "blocked" else np.zeros_like(occupied))
    size = 1000.0 * resolution if cell_size is None else cell_size
    return OccupancyGrid(blocked[::-1], size, (1000.0 * origin[0], 1000.0 * origin[1]))
