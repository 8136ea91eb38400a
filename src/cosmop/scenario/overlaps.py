"""Is a scene physically possible: bodies may touch, never overlap.

Every body of a scene at the start is an axis-aligned square: a robot of side ``size`` at its
pose, an object at its position, a person at the first point of its path (people may overlap
one another: the simulation lets them pass through each other).  Two squares overlap
when their interiors meet, :math:`|x_a - x_b| < (s_a + s_b)/2` and :math:`|y_a - y_b| < (s_a +
s_b)/2`; a square overlaps a wall segment when the segment meets its interior.  Touching (equal
to the bound) is allowed everywhere, as in the planner.  A tolerance of :data:`TOUCH` mm keeps
rounding of a file in metres from turning a touch into an overlap.

:func:`overlaps` lists every overlap with the scenario field to blame (the later body in the
file, or the body for a wall) and what it collides with; the loader (:mod:`cosmop.scenario.build`)
rejects the first as bad input.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from cosmop.scene import Scene
from cosmop.squares import square
from cosmop.units import UnitSystem, show_length, shown

__all__ = ["TOUCH", "Overlap", "overlaps"]

TOUCH = 1e-6
"""mm two bodies may cross and still count as touching (rounding of converted units)."""


@dataclass(frozen=True)
class Overlap:
    """Two bodies of a scene that overlap at the start.

    Attributes
    ----------
    field : tuple
        The scenario field to blame, e.g. ``("scene", "robots", "R1", "pose")``.
    body : str
        The body, in words (``robot R1 (400 mm square at (-2450, -1000))``).
    other : str
        What it overlaps, in words (a wall with its end points, or another body).
    """

    field: tuple[str | int, ...]
    body: str
    other: str

    def describe(self) -> str:
        return f"{self.body} overlaps {self.other}; bodies may touch but not overlap"


@dataclass(frozen=True)
class _Body:
    kind: str
    ident: str
    size: float
    x: float
    y: float
    field: tuple[str | int, ...]

    def words(self, units: UnitSystem) -> str:
        at = f"({shown(self.x, units):g}, {shown(self.y, units):g})"
        return f"{self.kind} {self.ident} ({show_length(self.size, units)} square at {at})"


def _bodies(scene: Scene) -> list[_Body]:
    out = [
        _Body("robot", r.id, r.size, r.pose[0], r.pose[1], ("scene", "robots", r.id, "pose"))
        for r in scene.robots.values()
    ]
    out += [
        _Body("object", o.id, o.size, *o.position, ("scene", "objects", o.id, "position"))
        for o in scene.objects.values()
    ]
    out += [
        _Body("person", h.id, h.size, *h.start, ("scene", "humans", h.id, "path", 0))
        for h in scene.humans.values()
    ]
    return out


def overlaps(scene: Scene, *, units: UnitSystem = "mm") -> list[Overlap]:
    """Every overlap between the scene's bodies, and between a body and a wall.

    Parameters
    ----------
    scene : Scene
        In millimetres.
    units : {"mm", "m"}
        The units the file was written in: lengths in messages are shown in them.

    Returns
    -------
    list of Overlap
        In file order of the blamed body: first the walls each body overlaps, then the earlier
        bodies it overlaps.

    Examples
    --------
    >>> from cosmop.scene import MovableObject, Robot, Scene, Wall
    >>> scene = Scene((Wall((0, -1000), (0, 1000)),), {"R1": Robot("R1", 400, (150, 0, 0))},
    ...               {"O1": MovableObject("O1", 100, (400, 0))})  # O1 touches R1: allowed
    >>> [o.describe() for o in overlaps(scene)]  # doctest: +NORMALIZE_WHITESPACE
    ['robot R1 (400 mm square at (150, 0)) overlaps wall [[0, -1000], [0, 1000]]; bodies may touch
      but not overlap']
    """
    bodies = _bodies(scene)
    if not bodies:
        return []
    size = np.array([b.size for b in bodies])
    xy = np.array([(b.x, b.y) for b in bodies])
    found: dict[int, list[str]] = {}
    if scene.obstacles:
        # arrays: shapely builds them all at once (square's types name one square)
        boxes = square(xy[:, 0], xy[:, 1], size - 2.0 * TOUCH)  # type: ignore[arg-type]
        walls = [shapely.LineString([w.start, w.end]) for w in scene.obstacles]
        hits = shapely.STRtree(walls).query(boxes, predicate="intersects")
        for i, j in sorted(zip(hits[0].tolist(), hits[1].tolist(), strict=True)):
            ends = ", ".join(f"[{shown(x, units):g}, {shown(y, units):g}]" for x, y in walls[j].coords)
            found.setdefault(i, []).append(f"wall [{ends}]")
    reach = (size[:, None] + size[None, :]) / 2.0 - TOUCH
    apart = np.abs(xy[:, None, :] - xy[None, :, :])
    clash = (apart[..., 0] < reach) & (apart[..., 1] < reach)
    person = np.array([b.kind == "person" for b in bodies])
    clash &= ~(person[:, None] & person[None, :])  # people walk through one another in the simulation
    for i, j in zip(*np.nonzero(np.tril(clash, k=-1)), strict=True):
        found.setdefault(int(i), []).append(bodies[int(j)].words(units))
    return [
        Overlap(bodies[i].field, bodies[i].words(units), other) for i in sorted(found) for other in found[i]
    ]
