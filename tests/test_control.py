"""Passive safety, L-infinity geometry, global paths and people's walks."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import LineString

from cosmop.control import (
    GlobalPath,
    admissible_speed,
    box_gaps,
    is_safe,
    paths,
    plan_path,
    point_segment_linf,
    segment_array,
)
from cosmop.control.geometry import swept_wall_gaps
from cosmop.planning import overlaps, swept_square
from cosmop.planning.checker import square
from cosmop.scene import Dynamics, Human
from cosmop.sim.humans import Walker

DYN = Dynamics()


@given(
    gap=st.floats(0.0, 5000.0),
    v=st.floats(0.0, 750.0),
    speed=st.floats(0.0, 1500.0),
)
def test_corollary_speed_is_the_bound_of_safe(gap, v, speed):
    bound = float(admissible_speed(gap, speed, DYN))
    if abs(v - bound) > 1e-6:
        assert bool(is_safe(gap, v, speed, DYN)) == (v < bound)


def test_safe_keeps_stopping_distance():
    # Braking from any admissible speed with an obstacle closing at V never closes the gap.
    a, b, eps = DYN.acceleration, DYN.braking, DYN.cycle
    for gap in (50.0, 300.0, 1500.0):
        for V in (0.0, 600.0):
            v = float(admissible_speed(gap, V, DYN)) - 1e-6
            if v <= 0:
                continue
            # worst case: accelerate for one cycle, then brake; the obstacle runs at V meanwhile
            v1 = v + a * eps
            travel = v * eps + a * eps**2 / 2 + v1**2 / (2 * b)
            closing = V * (eps + v1 / b)
            assert travel + closing < gap


@given(
    px=st.floats(-3000, 3000),
    py=st.floats(-3000, 3000),
    seg=st.tuples(*[st.floats(-3000, 3000)] * 4),
)
def test_linf_distance_to_segment_matches_sampling(px, py, seg):
    x1, y1, x2, y2 = seg
    exact = float(point_segment_linf(np.array([px, py]), np.array([seg]))[0])
    t = np.linspace(0.0, 1.0, 20001)
    sampled = np.maximum(np.abs(x1 + t * (x2 - x1) - px), np.abs(y1 + t * (y2 - y1) - py)).min()
    assert exact <= sampled + 1e-6
    assert exact >= sampled - np.hypot(x2 - x1, y2 - y1) / 20000 - 1e-6


@given(
    way=st.tuples(*[st.floats(-2000, 2000)] * 4),
    wall=st.tuples(*[st.floats(-2000, 2000)] * 4),
    half=st.floats(0, 300),
)
def test_a_swept_square_is_as_far_from_a_wall_as_its_nearest_sample(way, wall, half):
    # exact where sampling the sweep is not: a square swept diagonally past a wall's end can cut
    # the corner between two samples
    x1, y1, x2, y2 = way
    exact = float(swept_wall_gaps((x1, y1), (x2, y2), half, np.array([wall]))[0])
    t = np.linspace(0.0, 1.0, 4001)[:, None]
    centres = np.array([x1, y1]) + t * np.array([x2 - x1, y2 - y1])
    sampled = float(point_segment_linf(centres, np.array([wall])).min()) - half
    assert exact <= sampled + 1e-6
    assert exact >= sampled - np.hypot(x2 - x1, y2 - y1) / 4000 - 1e-6


def test_a_square_swept_past_a_walls_end_touches_it_where_its_samples_do_not():
    walls = np.array([[6800.0, -3000.0, 7800.0, -3000.0], [7800.0, -3000.0, 7800.0, 3000.0]])
    start, end = (8000.6, -3197.6), (7920.6, -3226.3)  # 200 mm robot squares, 1 mm from the corner
    ends = point_segment_linf(np.array([start, end]), walls).min() - 200.0
    assert ends > 0
    assert swept_wall_gaps(start, end, 200.0, walls).min() < -1.0


def test_a_set_per_row_measures_each_row_against_its_own_set_and_padding_is_infinitely_far():
    rng = np.random.default_rng(7)
    walls = rng.uniform(-3000, 3000, (9, 4))
    walls[:4, 2] = walls[:4, 0]  # axis-parallel ones beside diagonal ones
    boxes = np.column_stack([rng.uniform(-3000, 3000, (9, 2)), rng.uniform(50, 300, 9)])
    points = rng.uniform(-3000, 3000, (3, 5, 2))  # 3 rows of 5 points
    chosen = [[0, 5, 8], [1, 2], [6]]
    padded = np.full((3, 3, 4), np.inf)
    padded_boxes = np.tile([np.inf, np.inf, 0.0], (3, 3, 1))
    for row, keep in enumerate(chosen):
        padded[row, : len(keep)] = walls[keep]
        padded_boxes[row, : len(keep)] = boxes[keep]
    together = point_segment_linf(points, padded)
    gaps = box_gaps(points, 100.0, padded_boxes)
    for row, keep in enumerate(chosen):
        np.testing.assert_array_equal(
            together[row, :, : len(keep)], point_segment_linf(points[row], walls[keep])
        )
        np.testing.assert_array_equal(gaps[row, :, : len(keep)], box_gaps(points[row], 100.0, boxes[keep]))
        assert (
            np.isposinf(together[row, :, len(keep) :]).all() and np.isposinf(gaps[row, :, len(keep) :]).all()
        )


WALLS_2X2 = [
    ((-2500, -2500), (2500, -2500)),
    ((2500, -2500), (2500, 2500)),
    ((2500, 2500), (-2500, 2500)),
    ((-2500, 2500), (-2500, -2500)),
    ((0, 0), (0, 2500)),
    ((-1000, 0), (1000, 0)),
]


@pytest.mark.parametrize(
    ("start", "goal"),
    [((-2000, -1000), (-1300, 2000)), ((1250, 2000), (-2000, -2000)), ((1650, -1000), (1250, 2000))],
)
def test_global_path_never_crosses_a_wall(start, goal):
    walls = segment_array(WALLS_2X2)
    boxes = np.array([[1900.0, -1000.0, 50.0]])
    path = plan_path(start, goal, 200.0, walls, boxes)
    assert path is not None and path.points[0] == start and path.points[-1] == goal
    for a, b in zip(path.points, path.points[1:], strict=False):
        swept = swept_square(a, b, 400.0)
        for (x1, y1), (x2, y2) in WALLS_2X2:
            assert not overlaps(LineString([(x1, y1), (x2, y2)]), swept)
        assert not overlaps(square(1900, -1000, 100), swept)


def test_global_path_reports_no_way():
    walls = segment_array(
        [
            ((-1000, -1000), (1000, -1000)),
            ((1000, -1000), (1000, 1000)),
            ((1000, 1000), (-1000, 1000)),
            ((-1000, 1000), (-1000, -1000)),
        ]
    )
    assert plan_path((0, 0), (3000, 0), 200.0, walls, np.zeros((0, 3))) is None


def _scattered(seed: int, side: float = 60_000.0):
    """A wide map of scattered walls and boxes, and a start and goal a few metres apart."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(0, side, 80)
    walls = np.column_stack([start[:40], start[40:], start[:40], start[40:]])
    along = rng.integers(0, 2, 40) == 0
    length = rng.uniform(1000, 8000, 40)
    walls[along, 2] += length[along]
    walls[~along, 3] += length[~along]
    boxes = np.column_stack([rng.uniform(0, side, (60, 2)), rng.uniform(100, 400, 60)])
    a = rng.uniform(side / 3, 2 * side / 3, 2)
    return tuple(a), tuple(a + rng.uniform(-6000, 6000, 2)), walls, boxes


@pytest.mark.parametrize("seed", range(12))
def test_a_route_found_near_first_costs_what_the_whole_map_search_finds(seed):
    start, goal, walls, boxes = _scattered(seed)
    near = plan_path(start, goal, 200.0, walls, boxes)
    ends, weights = np.array([start, goal]), (150.0, 3.0, 10.0)
    whole, cost, _ = paths._route(ends, 200.0, walls, boxes, None, weights, 10**9)
    assert (near is None) == (whole is None)
    if near is not None:
        assert near.points[0] == start and near.points[-1] == goal
        # every edge of the near route is free of every obstacle of the whole map, and the
        # route costs what the cheapest route of the whole map costs
        grown = shapely.unary_union(paths._grown(walls, boxes, 200.0))
        inner = paths._interior(grown)
        edges = paths._EdgeCosts(np.array(near.points), inner, grown.boundary, 150.0, 3.0, 10.0)
        total = 0.0
        for u in range(len(near.points) - 1):
            free, each, _ = edges(u, np.array([u + 1]))
            assert list(free) == [u + 1]  # free of the whole map's obstacles
            total += float(each[0])
        assert total == pytest.approx(cost, rel=1e-9)


def test_the_search_widens_until_it_finds_the_way_round():
    # a wall 40 m long right across the way, open only at its far end: no route near the two
    # ends, one far away
    walls = segment_array([((0, -20_000), (0, 20_000)), ((-3000, 20_000), (3000, 20_000))])
    path = plan_path((-1000, 0), (1000, 0), 200.0, walls, np.zeros((0, 3)))
    assert path is not None and max(y for _, y in path.points) > 20_000
    assert path.length > 40_000


def test_a_goal_walled_in_is_refused_without_a_search(monkeypatch):
    # a goal ringed by standing robots on a wide map of scattered obstacles: no route, and no
    # search of every corner of the map to learn it (it took ten minutes on the MovingAI map)
    start, _, walls, boxes = _scattered(0)
    goal = (start[0] + 3000.0, start[1])
    ring = [(goal[0] + dx, goal[1] + dy, 250.0) for dx in (-600, 0, 600) for dy in (-600, 0, 600) if dx or dy]
    boxes = np.vstack([boxes, ring])

    def no_search(*_):
        raise AssertionError("searched a goal walled in")

    monkeypatch.setattr(paths, "_a_star", no_search)
    assert plan_path(start, goal, 200.0, walls, boxes) is None
    # the same goal with one robot of the ring gone: one piece, searched and found
    monkeypatch.undo()
    opened = np.array([b for b in boxes if tuple(b) != (goal[0] + 600, goal[1], 250.0)])
    assert len(opened) == len(boxes) - 1
    path = plan_path(start, goal, 200.0, walls, opened)
    assert path is not None and path.points[-1] == goal


def test_a_goal_inside_an_obstacle_has_no_route():
    boxes = np.array([[5000.0, 0.0, 300.0]])
    assert plan_path((0, 0), (5100, 0), 200.0, np.zeros((0, 4)), boxes) is None


def test_a_route_search_stops_at_its_budget():
    # a route squeezing along an aisle lined with goods grew its search to most of a large map
    # (74 s); the edges tested are bounded, and past the bound there is no route (unless a
    # smaller box found one)
    start, goal, walls, boxes = _scattered(0)
    found = plan_path(start, goal, 200.0, walls, boxes)
    assert found is not None and len(found.points) > 2  # a way around, not the straight line
    assert plan_path(start, goal, 200.0, walls, boxes, budget=10) is None
    assert plan_path(start, goal, 200.0, walls, boxes, budget=10**9) == found


def test_a_point_beyond_on_a_path_and_the_vertices_after_it():
    path = GlobalPath(((0.0, 0.0), (1000.0, 0.0), (1000.0, 1000.0)), 5.0)
    # from beside the first segment, 500 mm on: still on it; 1500 mm on: up the second
    assert path.beyond((100.0, 10.0), 500.0) == ((600.0, 0.0), ((1000.0, 0.0), (1000.0, 1000.0)))
    assert path.beyond((100.0, 10.0), 1500.0) == ((1000.0, 600.0), ((1000.0, 1000.0),))
    assert path.beyond((100.0, 10.0), 5000.0) == (None, ())  # past the end
    assert GlobalPath(((3.0, 4.0),), 0.0).beyond((0.0, 0.0), 1.0) == (None, ())


def test_walker_follows_its_path_and_stands():
    person = Human("H1", 400, 500, ((0, 0, 0), (1000, 0, 2.0), (1000, 1000, 0)), loop=True)
    walker = Walker(person, np.zeros((0, 4)), np.random.default_rng(0))
    for _ in range(20):  # 2 s at 500 mm/s: at the second point
        walker.step(0.1)
    assert walker.position == pytest.approx([1000, 0])
    for _ in range(20):  # standing there for 2 s
        walker.step(0.1)
    assert walker.position == pytest.approx([1000, 0])
    speeds = []
    for _ in range(100):
        before = walker.position.copy()
        walker.step(0.1)
        speeds.append(np.hypot(*(walker.position - before)) / 0.1)
    assert max(speeds) <= 500 + 1e-6


def test_random_walk_is_seeded_and_stays_in_its_area():
    person = Human("H1", 400, 600, ((0, 0, 0),), walk=((-1000, 1000), (-500, 500)))
    runs = []
    for seed in (1, 1, 2):
        walker = Walker(person, np.zeros((0, 4)), np.random.default_rng(seed))
        track = []
        for _ in range(300):
            walker.step(0.1)
            track.append(walker.position.copy())
        runs.append(np.array(track))
    assert np.array_equal(runs[0], runs[1]) and not np.array_equal(runs[0], runs[2])
    assert (np.abs(runs[0][:, 0]) <= 1000 + 1e-9).all() and (np.abs(runs[0][:, 1]) <= 500 + 1e-9).all()


@pytest.mark.parametrize("per_row", [False, True])
def test_the_retreat_steps_away_else_aside_farther_from_the_box_else_stays(per_row):
    from cosmop.control.dwa import _open_retreat

    xy = np.array([[0.0, 0.0], [0.0, 5000.0], [0.0, 5000.0], [0.0, 10000.0]])
    away = np.tile([1.0, 0.0], (4, 1))  # each away from a box on its left
    delta = np.array([[300.0, 0.0], [300.0, 50.0], [300.0, -50.0], [300.0, 0.0]])  # box to robot
    walls = np.array(
        [
            [250.0, 4000.0, 250.0, 11000.0],  # right of rows 1 to 3: away is blocked
            [-500.0, 10250.0, 500.0, 10250.0],  # above and below row 3: boxed in
            [-500.0, 9750.0, 500.0, 9750.0],
        ]
    )
    if per_row:
        walls = np.repeat(walls[None], 4, axis=0)
    out = _open_retreat(xy, np.full(4, 100.0), away, delta, walls, 200.0)
    # free: away; blocked: aside, the side the robot already stands off the box first; else put
    np.testing.assert_array_equal(out, [[200.0, 0.0], [0.0, 5200.0], [0.0, 4800.0], [0.0, 10000.0]])


def _aisle_driver(heading_deg: float, v: float):
    """A robot of 500 mm at `v` in a 1 m aisle along x, between goods of 200 mm on both
    shelf faces: 50 mm to each side, its target 2 m ahead on the aisle's centre line."""
    from cosmop.control.dwa import Drivers, Obstacles
    from cosmop.control.safety import Limits

    walls = segment_array([((-5000.0, 500.0), (5000.0, 500.0)), ((-5000.0, -500.0), (5000.0, -500.0))])
    goods = np.array([[x, side * 400.0, 100.0] for x in range(-3000, 3001, 500) for side in (1, -1)])
    drivers = Drivers(
        pose=np.array([[0.0, 0.0, np.radians(heading_deg)]]),
        v=np.array([v]),
        half=np.array([250.0]),
        limits=Limits.of([Dynamics()]),
        target=np.array([[2000.0, 0.0]]),
        stop_distance=np.array([np.inf]),
    )
    return drivers, Obstacles(walls, goods, np.zeros(len(goods)))


@pytest.mark.parametrize("heading", [0.0, 3.0, -5.0])
def test_a_robot_keeps_its_speed_along_an_aisle_lined_with_goods(heading):
    # 50 mm from goods on both sides, safe (any direction) allows about 160 mm/s; braking
    # straight on along the aisle keeps clear, so the window keeps the top speed, and a heading
    # a few degrees off is turned back within the cycle instead of braking
    from cosmop.control.dwa import dwa_commands

    drivers, obstacles = _aisle_driver(heading, 750.0)
    cmd = dwa_commands(drivers, obstacles)
    assert not cmd.safe[0]
    assert cmd.v[0] > 750.0 - Dynamics().braking * Dynamics().cycle  # not braking
    assert np.sign(cmd.w[0]) == -np.sign(heading)  # back towards the aisle's axis (0: straight)


def test_a_robot_heading_into_the_goods_beside_an_aisle_brakes():
    # 20 degrees off, braking straight on from the top speed would reach the goods: no arc of
    # the window turns it back in one cycle, so it brakes
    from cosmop.control.dwa import dwa_commands

    drivers, obstacles = _aisle_driver(20.0, 750.0)
    cmd = dwa_commands(drivers, obstacles)
    assert cmd.v[0] == pytest.approx(750.0 - Dynamics().braking * Dynamics().cycle)


def test_the_standoff_sends_a_robot_away_from_robots_not_from_goods_it_passes():
    from cosmop.control.dwa import DwaSettings, Obstacles, _retreat

    drivers, _ = _aisle_driver(0.0, 300.0)
    box = np.array([[0.0, 390.0, 100.0]])  # 40 mm beside the robot, within the 50 mm standoff
    gap = np.array([[40.0]])
    unsafe = np.array([True])
    goods = Obstacles(np.zeros((0, 4)), box, np.zeros(1)).per_driver(1)
    resting = _retreat(drivers, goods, gap, unsafe, DwaSettings())
    np.testing.assert_array_equal(resting.target, drivers.target)  # goods: on along the aisle
    robot = Obstacles(np.zeros((0, 4)), box, np.zeros(1), agents=np.array([True])).per_driver(1)
    moved = _retreat(drivers, robot, gap, unsafe, DwaSettings())
    assert moved.target[0, 1] < 0.0  # a robot there: away from it first
