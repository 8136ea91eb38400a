"""The neighbourhood cut-off, and the window's own pruning, give its commands bit for bit, and cut.

Random crowded warehouses (seeded): drivers among walls, resting objects, moving robots and
people, some of them inside another's standoff or against a wall so that ``safe`` fails and
the escape arcs and the retreat run.  The commands of :func:`dwa_commands_near` (with its own
cells, and with cells much smaller than the reach) must equal those of one call of
:func:`dwa_commands` with everything.
"""

from __future__ import annotations

import numpy as np
import pytest

from cosmop.control import dwa, neighbourhood
from cosmop.control.dwa import Drivers, DwaSettings, Obstacles, dwa_commands, first_true, take_columns
from cosmop.control.neighbourhood import dwa_commands_near, reach
from cosmop.control.safety import Limits
from cosmop.scene import Dynamics


def _crowd(seed: int, side: float = 40_000.0) -> tuple[Drivers, Obstacles, np.ndarray]:
    rng = np.random.default_rng(seed)
    R, n_walls, n_objects, n_people = 24, 60, 30, 8
    start = rng.uniform(0, side, (n_walls, 2))
    along = rng.integers(0, 2, n_walls)[:, None] == 0
    length = rng.uniform(500, 6000, (n_walls, 1))
    walls = np.hstack([start, start + np.where(along, [[1.0, 0.0]], [[0.0, 1.0]]) * length])
    xy = rng.uniform(0, side, (R, 2))
    # a third of the drivers stand close to another robot or a wall: inside the standoff
    for i in range(0, R, 3):
        xy[i] = xy[i + 1] + rng.choice([-1, 1], 2) * rng.uniform(350, 450, 2) * [1, 0]
    xy[2] = walls[0, :2] + [0.0, 230.0]
    pose = np.column_stack([xy, rng.uniform(-np.pi, np.pi, R)])
    v = rng.uniform(300, 750, R)
    v[::4] = 0.0
    limits = Limits.of([Dynamics()] * R)
    drivers = Drivers(
        pose=pose,
        v=v,
        half=np.full(R, 200.0),
        limits=limits,
        target=xy + rng.uniform(-2000, 2000, (R, 2)),
        stop_distance=rng.choice([np.inf, 300.0], R),  # 300 mm: the stop caps the window's speed
        room_cap=rng.uniform(20, 200, R),
    )
    objects = np.column_stack([rng.uniform(0, side, (n_objects, 2)), np.full(n_objects, 150.0)])
    people = np.column_stack([rng.uniform(0, side, (n_people, 2)), np.full(n_people, 250.0)])
    robots = np.column_stack([xy, drivers.half])
    boxes = np.vstack([objects, robots, people])
    speed = np.concatenate([np.zeros(n_objects), np.full(R, 750.0), np.full(n_people, 1200.0)])
    heading = rng.uniform(-np.pi, np.pi, len(boxes))
    now = np.concatenate([np.zeros(n_objects), v, rng.uniform(0, 1200, n_people)])
    velocity = np.column_stack([now * np.cos(heading), now * np.sin(heading)])
    acceleration = np.concatenate([np.zeros(n_objects), np.full(R, 500.0), np.full(n_people, np.inf)])
    agents = np.arange(len(boxes)) >= n_objects
    obstacles = Obstacles(walls, boxes, speed, velocity, acceleration, agents)
    own = np.zeros((R, len(boxes)), dtype=bool)
    own[np.arange(R), n_objects + np.arange(R)] = True
    return drivers, obstacles, own


@pytest.mark.parametrize("seed", range(6))
def test_the_cut_off_gives_the_same_commands(seed):
    drivers, obstacles, own = _crowd(seed)
    settings = DwaSettings()
    full = dwa_commands(drivers, obstacles, settings, ignore=own)
    assert not full.safe.all()  # the escape arcs and the retreat are exercised
    for cell in (None, 1500.0):
        near = dwa_commands_near(drivers, obstacles, settings, ignore=own, cell=cell)
        np.testing.assert_array_equal(near.v, full.v)
        np.testing.assert_array_equal(near.w, full.w)
        np.testing.assert_array_equal(near.safe, full.safe)
        close = np.isfinite(near.gap)
        np.testing.assert_array_equal(near.gap[close], full.gap[close])
        walls, boxes = reach(drivers, obstacles, settings)
        assert (full.gap[~close] > np.minimum(walls, boxes)[~close]).all()


def test_the_cut_off_drops_what_is_out_of_reach(monkeypatch):
    drivers, obstacles, _ = _crowd(0, side=400_000.0)  # ten times wider: most things are far
    walls, boxes = reach(drivers, obstacles, DwaSettings())
    assert 1_000 < walls.max() < 20_000 and 1_000 < boxes.max() < 20_000  # metres, not the map
    seen = []

    def counting(drivers, sub, settings, **kw):
        # one call for every driver, each with its own set (padded at infinity to one width)
        assert sub.walls.shape[0] == sub.boxes.shape[0] == len(drivers.v)
        real = np.isfinite(sub.walls[..., 0]).sum(axis=1) + np.isfinite(sub.boxes[..., 0]).sum(axis=1)
        seen.append((sub.walls.shape[1] + sub.boxes.shape[1], real))
        return dwa_commands(drivers, sub, settings, **kw)

    monkeypatch.setattr("cosmop.control.neighbourhood.dwa_commands", counting)
    dwa_commands_near(drivers, obstacles)
    [(width, real)] = seen
    everything = len(obstacles.walls) + len(obstacles.boxes)
    assert width < everything / 4 and (real <= width).all() and real.min() >= 1  # at least itself


def test_a_robot_in_danger_does_not_lift_another_robots_stop_at_its_goal():
    # before the fix, one unsafe robot in the batch cleared every robot's stop distance, so a
    # robot arriving at its goal elsewhere lost the cap that lets it stop there
    drivers, obstacles, own = _crowd(2)
    full = dwa_commands(drivers, obstacles, ignore=own)
    calm = np.flatnonzero(full.safe & np.isfinite(drivers.stop_distance))
    assert (~full.safe).any() and calm.size
    for i in calm:
        alone = dwa_commands(drivers[[i]], obstacles, ignore=own[[i]])
        assert (alone.v[0], alone.w[0]) == (full.v[i], full.w[i])


def test_one_call_with_a_set_per_driver_equals_a_call_per_driver():
    # dwa_commands_near pads each driver's set with obstacles at infinity; one call with those
    # sets must give each driver exactly the commands of a call with its own set alone
    drivers, obstacles, own = _crowd(4, side=12_000.0)
    rng = np.random.default_rng(4)
    R, W, M = len(drivers.v), len(obstacles.walls), len(obstacles.boxes)
    walls = [np.sort(rng.choice(W, rng.integers(0, W // 2), replace=False)) for _ in range(R)]
    boxes = [
        np.union1d(rng.choice(M, rng.integers(1, M // 2), replace=False), np.flatnonzero(own[i]))
        for i in range(R)
    ]
    wall_rows, box_rows = np.zeros((R, W), dtype=bool), np.zeros((R, M), dtype=bool)
    for i in range(R):
        wall_rows[i, walls[i]], box_rows[i, boxes[i]] = True, True
    wall_index, box_index = first_true(wall_rows), first_true(box_rows)
    assert (wall_index == W).any() and (box_index == M).any()  # some sets are padded
    sets = obstacles.take(wall_index, box_index)
    ignore = take_columns(own, box_index)
    together = dwa_commands(drivers, sets, ignore=ignore)
    assert not together.safe.all()
    for i in range(R):
        alone = dwa_commands(drivers[[i]], obstacles.select(walls[i], boxes[i]), ignore=own[[i]][:, boxes[i]])
        assert (alone.v[0], alone.w[0], alone.safe[0], alone.gap[0]) == (
            together.v[i],
            together.w[i],
            together.safe[i],
            together.gap[i],
        )


def test_few_obstacles_go_to_the_window_whole(monkeypatch):
    # with few obstacles, choosing the near ones costs more than it saves: one plain call
    drivers, obstacles, own = _crowd(1, side=6_000.0)
    few = obstacles.select(np.arange(4), np.arange(neighbourhood._FEW - 4))
    seen = []

    def counting(drivers, sub, settings, **kw):
        seen.append(sub)
        return dwa_commands(drivers, sub, settings, **kw)

    monkeypatch.setattr("cosmop.control.neighbourhood.dwa_commands", counting)
    near = dwa_commands_near(drivers, few, ignore=own[:, : neighbourhood._FEW - 4])
    assert len(seen) == 1 and seen[0] is few  # the very set, not a choice of it
    more = obstacles.select(np.arange(5), np.arange(neighbourhood._FEW - 4))
    dwa_commands_near(drivers, more, ignore=own[:, : neighbourhood._FEW - 4])
    assert len(seen) == 2 and seen[1] is not more  # one more: the near ones are chosen
    assert len(near.v) == len(drivers.v)


@pytest.mark.parametrize(("seed", "clearance"), [(0, 60.0), (1, 60.0), (2, 60.0), (3, 60.0), (20, -400.0)])
def test_the_window_drops_far_boxes_without_changing_a_command(seed, clearance, monkeypatch):
    # a crowded 8 m square: the clearance and the escape arcs measure only what can matter; a
    # negative clearance cap (no room wanted) still reads the gaps at or below zero
    drivers, obstacles, own = _crowd(seed, side=8_000.0)
    settings = DwaSettings(clearance=clearance)
    grip = np.zeros_like(own)
    grip[np.arange(4), np.arange(4)] = True  # four drivers hold an object
    widths = []
    real = dwa._without_far

    def recording(obstacles, *args):
        kept, columns = real(obstacles, *args)
        widths.append((obstacles.boxes.shape[-2], kept.boxes.shape[-2]))
        return kept, columns

    monkeypatch.setattr(dwa, "_without_far", recording)
    pruned = dwa_commands(drivers, obstacles, settings, ignore=own, grip=grip)
    # the clearance once, the escape arcs once a batch: every call cut
    assert len(widths) >= 2 and all(after < before for before, after in widths)
    # everything measured: no obstacle dropped, every escape arc checked at once
    monkeypatch.setattr(dwa, "_far_for_the_score", lambda d, o, ignore, *rest: (o, ignore))
    monkeypatch.setattr(dwa, "_far_for_escape", lambda d, pts, longest, slack, o, skip, keep: (o, skip, keep))
    monkeypatch.setattr(dwa, "_ESCAPE_BATCH", 10**6)
    whole = dwa_commands(drivers, obstacles, settings, ignore=own, grip=grip)
    assert not whole.safe.all()
    for name in ("v", "w", "safe", "gap"):
        np.testing.assert_array_equal(getattr(pruned, name), getattr(whole, name))


@pytest.mark.parametrize("seed", [0, 1, 3])
def test_one_driver_drops_far_obstacles_without_changing_a_command(seed, monkeypatch):
    # small arrays (one driver, as most cycles of a small map): one choice of walls and boxes
    # for the window's score, the same commands as with everything
    drivers, obstacles, own = _crowd(seed, side=20_000.0)
    widths = []
    real = dwa._clearance

    def measuring(d, o, *rest):
        widths.append(o.boxes.shape[-2])
        return real(d, o, *rest)

    monkeypatch.setattr(dwa, "_clearance", measuring)
    rows = [np.array([r]) for r in range(len(drivers.v))]
    pruned = [dwa_commands(drivers[r], obstacles, ignore=own[r]) for r in rows]
    assert max(widths) < len(obstacles.boxes) and min(widths) == 0  # some far boxes, at times all
    settings = DwaSettings()
    crowd, crowded, crowd_own = _crowd(seed, side=8_000.0)  # boxes near the caps
    for r in rows:  # what the score reads of the clearance, driver by driver
        one, sets = crowd[r], crowded.per_driver(1)
        _, _, V, W = dwa._window(one, settings)
        t, pts, _ = dwa._arcs(one, V, W, settings)
        gaps = dwa.robot_gaps(one.pose[:, :2], one.half, sets.walls, sets.boxes)
        near = dwa._far_for_the_score(one, sets, crowd_own[r], t, pts, settings, gaps)
        caps = (settings.clearance, settings.personal_space)
        cut, whole = real(one, *near, t, pts), real(one, sets, crowd_own[r], t, pts)
        for a, b, cap in zip(cut, whole, caps, strict=True):
            np.testing.assert_array_equal(np.minimum(a, cap), np.minimum(b, cap))
    monkeypatch.setattr(dwa, "_far_for_the_score", lambda d, o, ignore, *rest: (o, ignore))
    for r, cut in zip(rows, pruned, strict=True):
        whole = dwa_commands(drivers[r], obstacles, ignore=own[r])
        for name in ("v", "w", "safe", "gap"):
            np.testing.assert_array_equal(getattr(cut, name), getattr(whole, name))


def _small_scene(rng: np.random.Generator) -> tuple[Drivers, Obstacles, np.ndarray, np.ndarray | None]:
    """A few drivers among a few walls and boxes (small arrays), some values odd: NaN or inf
    positions and sizes, some sets per driver (padded), ignored and gripped boxes."""
    R, W, M = int(rng.integers(1, 4)), int(rng.integers(0, 6)), int(rng.integers(1, 12))
    side = float(rng.choice([1500.0, 4000.0]))
    xy = rng.uniform(0, side, (R, 2))
    start, along = rng.uniform(0, side, (W, 2)), rng.uniform(-3000, 3000, (W, 2))
    along[np.arange(W), rng.integers(0, 2, W)] = 0.0
    boxes = np.column_stack([rng.uniform(0, side, (M, 2)), rng.uniform(0, 300, M)])
    boxes[: min(M, R), :2] = xy[: min(M, R)]  # the drivers' own boxes
    j = int(rng.integers(0, M))
    boxes[j, int(rng.integers(0, 3))] = rng.choice([np.nan, np.inf])  # one odd value
    velocity = rng.uniform(-1500, 1500, (M, 2))
    obstacles = Obstacles(
        np.hstack([start, start + along]), boxes, rng.uniform(0, 1500, M), velocity, np.full(M, 500.0)
    )
    if R > 1 and rng.random() < 0.5:
        obstacles = obstacles.take(first_true(rng.random((R, W)) < 0.7), first_true(rng.random((R, M)) < 0.7))
    M = obstacles.boxes.shape[-2]
    v = rng.uniform(0, 800, R)
    drivers = Drivers(
        pose=np.column_stack([xy, rng.uniform(-np.pi, np.pi, R)]),
        v=v,
        half=np.full(R, 200.0),
        limits=Limits.of([Dynamics()] * R),
        target=xy + rng.uniform(-3000, 3000, (R, 2)),
        stop_distance=np.full(R, np.inf),
    )
    ignore = rng.random((R, M)) < 0.3
    grip = (rng.random((R, M)) < 0.1) if rng.random() < 0.5 else None
    return drivers, obstacles, ignore, grip


def test_small_arrays_drop_far_obstacles_without_changing_a_command(monkeypatch):
    # several drivers, one choice of columns for all (a union), and odd values: an ignored box
    # of unknown size is measured as NaN, as it always was, not dropped
    rng = np.random.default_rng(5)
    scenes = [_small_scene(rng) for _ in range(150)]
    with np.errstate(invalid="ignore"):  # the odd values: inf - inf
        pruned = [dwa_commands(d, o, ignore=ignore, grip=grip) for d, o, ignore, grip in scenes]
        monkeypatch.setattr(dwa, "_far_for_the_score", lambda d, o, ignore, *rest: (o, ignore))
        wholes = [dwa_commands(d, o, ignore=ignore, grip=grip) for d, o, ignore, grip in scenes]
    for cut, whole in zip(pruned, wholes, strict=True):
        for name in ("v", "w", "safe", "gap"):
            np.testing.assert_array_equal(getattr(cut, name), getattr(whole, name))


@pytest.mark.parametrize(
    ("seed", "side", "batch"), [(2, 8_000.0, dwa._ESCAPE_BATCH), (2, 20_000.0, 3), (3, 20_000.0, 1)]
)
def test_the_best_escape_is_the_best_scored_admitted_arc(seed, side, batch, monkeypatch):
    # checking the arcs a few at a time, best first, must find what checking all of them finds
    # (these scenes have drivers that may take some of their arcs, not all, not none)
    drivers, obstacles, own = _crowd(seed, side=side)
    R = len(drivers.v)
    sets = obstacles.per_driver(R)
    _, _, V, W = dwa._window(drivers, DwaSettings())
    keep = np.full((R, len(obstacles.boxes)), -np.inf)
    with monkeypatch.context() as whole:  # every arc against every box
        whole.setattr(dwa, "_LARGE", np.inf)
        ok = dwa._escape_ok(drivers, V, W, sets, own, keep)
    # many ties, and the arcs it refuses scored above those it admits: the search must go past
    score = np.random.default_rng(seed).integers(0, 6, V.shape) + 10.0 * ~ok
    monkeypatch.setattr(dwa, "_ESCAPE_BATCH", batch)
    pick, found = dwa._best_escapes(drivers, V, W, score, sets, own, keep)
    np.testing.assert_array_equal(found, ok.any(axis=1))
    best = np.argmax(np.where(ok, score, -np.inf), axis=1)
    np.testing.assert_array_equal(pick[found], best[found])
    order = np.argsort(-score, axis=1, kind="stable")
    rank = np.argmax(order == pick[:, None], axis=1)  # where each pick is in its driver's order
    assert found.any() and (rank[found] >= batch).any()  # some searches went past the first batch


@pytest.mark.parametrize(
    ("seed", "one"), [(0, None), (1, None), (2, None), (3, None), (0, 8), (1, 16), (3, 2)]
)
def test_the_clearance_without_far_obstacles_reads_the_same_up_to_the_caps(seed, one, monkeypatch):
    # what the score reads of the clearance: up to the cap, up to the personal space for
    # movers, and the value itself at or below zero; all drivers at once (large arrays: far
    # walls and boxes dropped row by row) or one (small arrays: one choice for all rows)
    drivers, obstacles, own = _crowd(seed, side=8_000.0)
    if one is not None:
        drivers, own = drivers[[one]], own[[one]]
    settings = DwaSettings()
    sets = obstacles.per_driver(len(drivers.v))
    _, _, V, W = dwa._window(drivers, settings)
    t, pts, _ = dwa._arcs(drivers, V, W, settings)
    gaps = dwa.robot_gaps(drivers.pose[:, :2], drivers.half, sets.walls, sets.boxes)
    measured = []
    real = dwa.point_segment_linf
    monkeypatch.setattr(dwa, "point_segment_linf", lambda *a: measured.append(a) or real(*a))
    near, near_own = dwa._far_for_the_score(drivers, sets, own, t, pts, settings, gaps)
    clear, movers = dwa._clearance(drivers, near, near_own, t, pts)
    if (seed, one) in ((0, 8), (1, 16)):
        assert not measured  # every wall too far: none measured
    if one is not None:  # small arrays: the boxes too far for the one driver are dropped too
        assert 0 < near.boxes.shape[-2] < sets.boxes.shape[-2] // 2
        assert near_own.shape == near.speed.shape
    whole_clear, whole_movers = dwa._clearance(drivers, sets, own, t, pts)  # everything
    np.testing.assert_array_equal(
        np.minimum(clear, settings.clearance), np.minimum(whole_clear, settings.clearance)
    )
    np.testing.assert_array_equal(
        np.minimum(movers, settings.personal_space), np.minimum(whole_movers, settings.personal_space)
    )
    if one is None:
        assert (whole_clear <= 0).any() and (whole_movers < settings.personal_space).any()  # both caps bind


def test_a_nan_score_is_taken_first_as_argmax_takes_it(monkeypatch):
    drivers, obstacles, own = _crowd(2, side=8_000.0)
    R = len(drivers.v)
    sets = obstacles.per_driver(R)
    _, _, V, W = dwa._window(drivers, DwaSettings())
    keep = np.full((R, len(obstacles.boxes)), -np.inf)
    ok = dwa._escape_ok(drivers, V, W, sets, own, keep)
    row = int(np.flatnonzero(ok.any(axis=1) & ~ok.all(axis=1))[0])  # some arcs admitted, not all
    score = np.tile(np.arange(V.shape[1], dtype=float), (R, 1))
    admitted = np.flatnonzero(ok[row])
    score[row, admitted[len(admitted) // 2]] = np.nan  # an admitted arc with no score
    pick, found = dwa._best_escapes(drivers, V, W, score, sets, own, keep)
    assert found[row] and pick[row] == np.argmax(np.where(ok, score, -np.inf), axis=1)[row]
