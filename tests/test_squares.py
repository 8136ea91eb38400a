"""The separating-axis overlap of convex regions against GEOS, and the conflicts decided with it.

Plans' regions are squares and the convex hulls of two squares (a drive).  `overlap_depths`
decides whether two of them overlap without building their intersection; wherever it is sure
(depth beyond 1e-6 mm) it must agree with GEOS's area of the intersection, and two regions that
share an edge or a corner only touch.
"""

from __future__ import annotations

import random

import numpy as np
import shapely

from cosmop.squares import overlap_depths, square, swept_square
from cosmop.team.conflicts import Occupancy, conflicts


def _region(rng: random.Random):
    x, y = rng.randint(0, 20) * 250, rng.randint(0, 20) * 250
    side = rng.choice([100, 400, 500])
    if rng.random() < 0.4:
        return square(x, y, side)
    angle = rng.choice([0, 30, 45, 90, 135, 200]) if rng.random() < 0.7 else rng.uniform(0, 360)
    length = rng.choice([250, 500, 1000, 1700.5])
    end = (x + length * np.cos(np.radians(angle)), y + length * np.sin(np.radians(angle)))
    return swept_square((x, y), end, side)


def test_the_depth_agrees_with_the_area_of_the_intersection():
    rng = random.Random(3)
    shapes = np.array([_region(rng) for _ in range(300)], dtype=object)
    left, right = np.triu_indices(len(shapes), 1)
    near = shapely.intersects(shapely.envelope(shapes[left]), shapely.envelope(shapes[right]))
    left, right = left[near], right[near]
    depth = overlap_depths(shapes, left, right)
    area = shapely.area(shapely.intersection(shapes[left], shapes[right]))
    sure = np.abs(depth) > 1e-6
    assert ((depth > 0) == (area > 1e-9))[sure].all()
    assert sure.sum() > 1000 and (depth[sure] > 0).any() and (depth[sure] < 0).any()
    touching = ~sure
    assert touching.any() and (area[touching] <= 1e-9).all()  # grid squares that share an edge


def test_regions_that_share_an_edge_or_a_corner_only_touch():
    shapes = np.array([square(0, 0, 2), square(2, 0, 2), square(2, 2, 2), swept_square((0, 0), (4, 0), 2)])
    depth = overlap_depths(shapes, np.array([0, 0, 3, 0]), np.array([1, 2, 2, 3]))
    assert depth.tolist() == [0.0, 0.0, 0.0, 2.0]


def test_other_shapes_are_left_to_the_area():
    shapes = np.array(
        [
            square(0, 0, 2),
            shapely.Polygon([(0, 0), (4, 0), (4, 4), (2, 1), (0, 4)]),  # not convex
            square(0, 0, 4).difference(square(0, 0, 1)),  # a hole
            shapely.Point(0, 0),
            shapely.MultiPolygon([square(0, 0, 1), square(5, 5, 1)]),
        ],
        dtype=object,
    )
    depth = overlap_depths(shapes, np.zeros(4, dtype=np.int64), np.arange(1, 5))
    assert np.isnan(depth).all()


def _robot_occupancy(robot, region, n):
    """An occupancy of `robot` alone, from its step 1 to its step 2."""
    return Occupancy(robot, frozenset({robot}), region, (robot, 1), (robot, 2), f"o{n}")


def test_the_conflicts_are_those_of_the_area_of_the_intersection():
    # the depth decides what it can; the rest (touching regions, other shapes) by the area
    rng = random.Random(11)
    robots = [f"R{i}" for i in range(8)]
    items = []
    for n in range(160):
        robot = rng.choice(robots)
        region = _region(rng) if n % 10 else square(rng.randint(0, 20) * 250, 0, 400).buffer(30)
        items.append(_robot_occupancy(robot, region, n))
    found = {(id(c.a), id(c.b)) for c in conflicts(items)}
    expected = set()
    for i, a in enumerate(items):
        for b in items[i + 1 :]:
            if a.what != b.what and a.region.intersection(b.region).area > 1e-9:
                expected.add((id(a), id(b)))
    assert found == expected and len(found) > 50


def test_the_conflicts_of_one_robot_are_those_of_the_team_in_the_same_order():
    # a robot ordered again among plans already ordered (`about`, with the pairs of `also`)
    # asks the R-tree about its own regions only; the conflicts kept, and their order (which
    # decides the ordering's ties), must be those of all the team's conflicts filtered
    rng = random.Random(5)
    robots = [f"R{i}" for i in range(12)]
    items = []
    for n in range(400):
        robot = rng.choice(robots)
        if n % 8 == 0:  # goods two robots move, or goods nobody moves
            movers = frozenset(rng.sample(robots, 2)) if n % 16 else frozenset()
            items.append(Occupancy(f"O{n}", movers, _region(rng), None, None, f"o{n}"))
        else:
            items.append(_robot_occupancy(robot, _region(rng), n))
    every = conflicts(items)
    for about, also in (("R3", ()), ("R7", (("R1", "R2"), ("R0", "R11"))), ("R11", (("R4", "R5"),))):
        mine = [
            (id(c.a), id(c.b))
            for c in every
            if about in c.a.parties | c.b.parties or tuple(sorted(c.a.parties | c.b.parties)) in also
        ]
        found = [(id(c.a), id(c.b)) for c in conflicts(items, about=about, also=also)]
        assert found == mine and len(mine) > 20
