"""GoTo region constraints are sound against the exact geometry of the swept square.

Soundness: whenever both end centres of a straight motion lie in one region of a wall (or
object), the swept area (convex hull of the two end squares) does not overlap the wall
(interiors disjoint; touching allowed), checked with shapely.  Tightness: a square exactly
touching an axis-aligned wall is admitted.
"""

from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, box
from shapely.ops import unary_union

from cosmop.planning.regions import HalfPlane, object_regions, wall_regions

coord = st.integers(min_value=-3000, max_value=3000)
point = st.tuples(coord, coord)
side = st.integers(min_value=50, max_value=800)


def swept(start, end, s):
    h = s / 2
    return unary_union(
        [
            box(start[0] - h, start[1] - h, start[0] + h, start[1] + h),
            box(end[0] - h, end[1] - h, end[0] + h, end[1] + h),
        ]
    ).convex_hull


def motion_is_clear(regions, start, end):
    """The first region holding both end centres of a straight motion (the specification's
    rule for a motion clear of one obstacle), or None."""
    for region in regions:
        if region.contains(*start) and region.contains(*end):
            return region
    return None


def overlaps_segment(poly, a, b) -> bool:
    seg = LineString([a, b])
    return seg.intersects(poly) and not seg.touches(poly)


@settings(max_examples=600, deadline=None, derandomize=True)
@given(point, point, point, point, side)
def test_wall_regions_are_sound(p, q, start, end, s):
    if p == q:
        return
    region = motion_is_clear(wall_regions(p, q, s), start, end)
    if region is not None:
        assert not overlaps_segment(swept(start, end, s), p, q), region.label


@settings(max_examples=600, deadline=None, derandomize=True)
@given(point, st.integers(min_value=20, max_value=400), point, point, side)
def test_object_regions_are_sound(o, b, start, end, s):
    region = motion_is_clear(object_regions(o, b, s), start, end)
    if region is not None:
        hb = b / 2
        obj = box(o[0] - hb, o[1] - hb, o[0] + hb, o[1] + hb)
        hull = swept(start, end, s)
        assert not (hull.intersects(obj) and not hull.touches(obj)), region.label


def test_touching_an_axis_aligned_wall_is_admitted():
    # the 2x2 example's inner wall x = 0 from y = 0 to 2500, robot side 400: centres at x = -200 touch it
    left, right, before, after = wall_regions((0, 0), (0, 2500), 400)
    assert left.contains(-200, 100) and left.contains(-200, 2400)  # touching on the west side
    assert right.contains(200, 100) and right.contains(200, 2400)  # touching on the east side
    assert not right.contains(-199, 100) and not left.contains(-199, 100)  # overlapping: no side holds it
    assert before.contains(1000, -200) and not before.contains(1000, -199)  # below the start, touching
    assert after.contains(0, 2700)


def test_diagonal_wall_uses_the_square_support():
    # wall along y = x: the square of half-side 100 reaches 100*(|1|+|1|) = 200 along the normal (-1, 1)
    regions = wall_regions((0, 0), (1000, 1000), 200)
    upper = regions[0]
    assert upper.contains(300, 500)  # n.(c-p) = 200
    assert not upper.contains(301, 500)
    assert all(isinstance(v, Fraction) for v in (upper.a, upper.b, upper.c))


def test_objects_use_the_papers_clearance():
    left, right, below, above = object_regions((2000, -1000), 100, 400)
    assert left.contains(1750, -1000) and not left.contains(1751, -1000)  # d = 250: the pick pose touches
    assert above.contains(0, -750) and not below.contains(0, -1000)
    assert right.contains(2250, 0) and not right.contains(2249, 0)


def test_degenerate_wall_is_rejected():
    with pytest.raises(ValueError):
        wall_regions((1, 1), (1, 1), 100)


def test_half_plane_is_exact():
    h = HalfPlane(Fraction(1, 3), Fraction(0), Fraction(1))
    assert h.contains(3, 0) and not h.contains(2.999999, 0)
