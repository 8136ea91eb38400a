"""Walls that keep a robot out of a region: how the team steers one robot's synthesis.

A robot's synthesis knows walls, not other robots.  To make a robot keep out of a place
(another robot's space, goods set aside, a lane kept for another), the place is ringed with
wall segments, grown by half the clearance, each labelled with what it keeps the robot out of
(a reason then names that, never the segment).
"""

from __future__ import annotations

import itertools

import shapely

from cosmop.scene import Wall

__all__ = ["walls_around"]


def walls_around(region: shapely.Geometry, clearance: float, label: str) -> tuple[Wall, ...]:
    """Wall segments around `region`, grown by half the clearance, labelled `label`.

    Parameters
    ----------
    region : shapely.Polygon
        The place to keep out of, mm.
    clearance : float
        The distance robots keep from each other, mm: the ring lies half of it outside `region`
        (the robot's own footprint keeps the other half).
    label : str
        What the walls keep the robot out of, in plain words (reasons quote it).
    """
    grown = region.buffer(clearance / 2.0, join_style="mitre")
    ring = list(shapely.get_coordinates(grown.exterior))
    return tuple(
        Wall((float(p[0]), float(p[1])), (float(q[0]), float(q[1])), label)
        for p, q in itertools.pairwise(ring)
        if tuple(p) != tuple(q)
    )
