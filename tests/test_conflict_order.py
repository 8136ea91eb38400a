"""Ordering conflicts between plans: what `order_conflicts` promises, on seeded random teams.

Each team has a few robots with plans of a few steps; occupancies hold a place over a run of
one robot's steps, some for good (a robot parked at its end, goods left where they lie); random
pairs of occupancies of different robots are conflicts.  Whatever the search and the schedule
decide, the answer must be

* sound: the chosen start edges order every conflict not returned as unresolved, and the team's
  order with them cannot deadlock;
* irredundant: each unresolved conflict, given back alone, cannot be ordered with the others
  (so no robot is re-planned for a conflict that messages could have ordered).
"""

from __future__ import annotations

import random

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from cosmop.events import Link, message
from cosmop.team import conflict_order
from cosmop.team.conflict_order import _Dominance, _Schedule, order_conflicts
from cosmop.team.conflict_search import CorrectionSetPicker, Search, backjump, possible_orientations
from cosmop.team.conflicts import Conflict, Occupancy, is_ordered
from cosmop.team.precedence import Precedence, RetractedEdges
from cosmop.team.safe_plans import _reduce


def _team(seed: int, robots: int = 4, steps: int = 6, conflicts: int = 24):
    rng = random.Random(seed)
    horizons = {f"R{i}": steps for i in range(1, robots + 1)}
    durations = {r: [rng.uniform(0.5, 5.0) for _ in range(steps)] for r in horizons}
    spots = [shapely.box(x, 0, x + 1, 1) for x in range(12)]

    def occupancy(robot: str) -> Occupancy:
        first = rng.randint(1, steps)
        forever = rng.random() < 0.25
        last = None if forever else (robot, rng.randint(first, steps))
        return Occupancy(
            robot, frozenset({robot}), rng.choice(spots), (robot, first), last, f"{robot}@{first}"
        )

    found = []
    while len(found) < conflicts:
        a, b = rng.sample(sorted(horizons), 2)
        found.append(Conflict(occupancy(a), occupancy(b)))
    return found, horizons, durations


@pytest.mark.parametrize("seed", range(12))
def test_orders_are_sound_and_unresolved_conflicts_irredundant(seed):
    found, horizons, durations = _team(seed)
    _assert_sound_and_irredundant(
        found, horizons, durations, order_conflicts(found, horizons, [], [], durations)
    )


@pytest.mark.parametrize(
    ("seed", "robots", "conflicts"), [(0, 4, 24), (72, 5, 40), (147, 5, 40), (215, 4, 24), (349, 5, 40)]
)
def test_the_search_settles_every_conflict_without_the_solver(seed, robots, conflicts, monkeypatch):
    # teams for which the solver was asked before (0), and conflicts set aside early that are
    # given back later: the search proves its own dead ends
    found, horizons, durations = _team(seed, robots=robots, conflicts=conflicts)
    with monkeypatch.context() as patch:
        patch.setattr(conflict_order, "_Schedule", _no_solver)
        answer = order_conflicts(found, horizons, [], [], durations)
    _assert_sound_and_irredundant(found, horizons, durations, answer)


def _tangle():
    """Three conflicts, of robots A-B, C-D and E-F, tied by given start edges so that each way
    of A-B leaves no way to order one of the others: A first closes both ways of C-D (through
    C1 -> A2 -> B1 -> D2 and D1 -> A2 -> B1 -> C2), B first both of E-F.  A-B is a choice
    (neither way closes a cycle by itself) and the search tries A first (A is the shorter)."""
    spot = shapely.box(0, 0, 1, 1)

    def held(robot):
        return Occupancy(robot, frozenset({robot}), spot, (robot, 1), (robot, 2), f"{robot}1-2")

    horizons = {r: 2 for r in "ABCDEF"}
    durations = {"A": [0.5, 0.5], **{r: [3.0, 3.0] for r in "BCDEF"}}
    starts = [
        *((("C", 1), ("A", 2)), (("D", 1), ("A", 2)), (("B", 1), ("C", 2)), (("B", 1), ("D", 2))),
        *((("E", 1), ("B", 2)), (("F", 1), ("B", 2)), (("A", 1), ("E", 2)), (("A", 1), ("F", 2))),
    ]
    found = [Conflict(held("A"), held("B")), Conflict(held("C"), held("D")), Conflict(held("E"), held("F"))]
    return found, horizons, starts, durations


def test_a_choice_that_ends_in_a_dead_end_is_taken_back(monkeypatch):
    found, horizons, starts, durations = _tangle()
    found = found[:2]  # A-B and C-D: B first orders both
    team = (horizons, [], starts, durations)
    # A first is a dead end
    assert backjump(found, _Dominance(found), team, CorrectionSetPicker(None), 0)[0] is None
    monkeypatch.setattr(conflict_order, "_Schedule", _no_solver)
    chosen, unresolved = order_conflicts(found, horizons, [], starts, durations)
    assert unresolved == []
    assert (("B", 2), ("A", 1)) in [edge for edge, _ in chosen]
    _assert_sound_and_irredundant(found, horizons, durations, (chosen, unresolved), starts)


def test_a_core_found_through_a_choice_taken_back_is_a_core(monkeypatch):
    # B first, forced by the dead end of A first, leaves E-F no way: the core is all three
    found, horizons, starts, durations = _tangle()
    team = (horizons, [], starts, durations)
    _, aside, cores = backjump(found, _Dominance(found), team, CorrectionSetPicker(None), 5)
    assert [sorted(map(found.index, core)) for core in cores.values()] == [[0, 1, 2]]
    schedule = _Schedule(found, horizons, [], starts, durations, 200_000_000)
    assert schedule.solve(cores[id(aside[0])]) is not None
    monkeypatch.setattr(conflict_order, "_Schedule", _no_solver)
    answer = order_conflicts(found, horizons, [], starts, durations)
    assert len(answer[1]) == 1
    _assert_sound_and_irredundant(found, horizons, durations, answer, starts)


def test_the_search_jumps_back_to_the_latest_choice_a_dead_end_follows_from(monkeypatch):
    # A-B is chosen first (A first), then C-D (C first); together they close both ways of E-F
    # (through A2 -> B1 and C2 -> D1), a dead end that follows from both choices.  The latest,
    # C-D, is at fault: D first orders everything.  Taking A-B back instead would leave G-H no
    # way (B first closes both of its ways) and set a conflict aside that an order resolves.
    spot = shapely.box(0, 0, 1, 1)

    def held(robot):
        return Occupancy(robot, frozenset({robot}), spot, (robot, 1), (robot, 2), f"{robot}1-2")

    horizons = {r: 2 for r in "ABCDEFGH"}
    durations = {"A": [0.5, 0.5], "C": [0.5, 0.5], **{r: [3.0, 3.0] for r in "BDEFGH"}}
    starts = [
        *((("F", 1), ("A", 2)), (("E", 1), ("A", 2)), (("B", 1), ("C", 2))),
        *((("D", 1), ("E", 2)), (("D", 1), ("F", 2))),
        *((("G", 1), ("B", 2)), (("H", 1), ("B", 2)), (("A", 1), ("G", 2)), (("A", 1), ("H", 2))),
    ]
    found = [Conflict(held(a), held(b)) for a, b in ("AB", "CD", "EF", "GH")]
    monkeypatch.setattr(conflict_order, "_Schedule", _no_solver)
    chosen, unresolved = order_conflicts(found, horizons, [], starts, durations)
    assert unresolved == []
    assert {(("A", 2), ("B", 1)), (("D", 2), ("C", 1))} <= {edge for edge, _ in chosen}
    _assert_sound_and_irredundant(found, horizons, durations, (chosen, unresolved), starts)


def test_the_solver_takes_over_when_the_search_runs_out_of_dead_ends(monkeypatch):
    found, horizons, starts, durations = _tangle()
    asked = []
    schedule = conflict_order._Schedule

    def counted(*args, **kwargs):
        asked.append(1)
        return schedule(*args, **kwargs)

    monkeypatch.setattr(conflict_order, "_Schedule", counted)
    answer = order_conflicts(found, horizons, [], starts, durations, max_backtracks=0)
    assert asked
    assert len(answer[1]) == 1
    _assert_sound_and_irredundant(found, horizons, durations, answer, starts)


def test_when_neither_the_search_nor_the_solver_decides_the_answer_is_still_sound():
    # no dead end to spare and no solver budget: the depth-first fallback orders what it can
    # and leaves what it fails on unresolved (sound, not necessarily irredundant)
    found, horizons, starts, durations = _tangle()
    chosen, unresolved = order_conflicts(found, horizons, [], starts, durations, max_backtracks=0, rlimit=1)
    assert unresolved
    precedence = Precedence(horizons, (), [*starts, *(edge for edge, _ in chosen)], durations)
    assert precedence.complete
    gone = {id(c) for c in unresolved}
    assert all(is_ordered(c, precedence) for c in found if id(c) not in gone)


def _no_solver(*args, **kwargs):
    raise AssertionError("the solver was asked")


def _assert_sound_and_irredundant(found, horizons, durations, answer, starts=()):
    chosen, unresolved = answer
    edges = [*starts, *(edge for edge, _ in chosen)]
    precedence = Precedence(horizons, (), edges, durations)
    assert precedence.complete  # no deadlock
    gone = {id(c) for c in unresolved}
    assert all(is_ordered(c, precedence) for c in found if id(c) not in gone)
    schedule = _Schedule(found, horizons, [], list(starts), durations, 200_000_000)
    ordered = [c for c in found if id(c) not in gone]
    assert schedule.solve(ordered) is None
    for conflict in unresolved:
        assert schedule.solve([*ordered, conflict]) is not None, conflict


def test_a_search_stopped_at_its_limit_of_conflicts_set_aside_answers_soundly():
    # a hand-over's ordering stops once it has set aside more conflicts than its limit (one
    # already means the attempt fails): it answers with what it has, the edges taken so far
    # acyclic, and a limit the search stays within changes nothing
    stopped = 0
    for seed in range(30):
        found, horizons, durations = _team(seed, robots=5, conflicts=40)
        full = order_conflicts(found, horizons, [], [], durations)
        answer = order_conflicts(found, horizons, [], [], durations, max_set_aside=1)
        search = Search(found, _Dominance(found), (horizons, [], [], durations), CorrectionSetPicker(None))
        if search.run(200, limit=1) is not None or not search.stopped:
            assert answer == full  # within the limit: the whole answer
            continue
        stopped += 1
        assert answer == (search.edges, search.set_aside)
        assert len(answer[1]) >= 2 and full[1]  # past the limit; and no order resolves them all
        assert Precedence(horizons, (), [edge for edge, _ in answer[0]], durations).complete
        schedule = _Schedule(found, horizons, [], [], durations, 200_000_000)
        for conflict in answer[1]:  # each set aside from a set that no order resolves
            assert schedule.solve(search.cores[id(conflict)]) is not None
    assert stopped >= 3  # the limit was reached in the sample


@pytest.mark.parametrize("seed", range(4))
def test_the_search_watches_every_step_it_reads(seed):
    # the order keeps up to date only the copies of the steps the search names
    # (Precedence.watch): every place it reads, for whether a side holds or closes a cycle and
    # for when an occupancy is expected to start, must be in a watched step
    found, horizons, durations = _team(seed, robots=5, conflicts=40)
    search = Search(found, _Dominance(found), (horizons, [], [], durations), CorrectionSetPicker(None))
    order, tests = search.precedence, search.orientations
    bits = order.done_bits.shape[1] * 8
    done, begin = order._watched
    for places, watched in ((tests.cycle_at, done), (tests.hold_at, begin)):
        rows = places[(places != order.never) & (places != order.always)] // bits
        assert len(rows) and set(rows.tolist()) <= watched
    assert set(tests.first_row[~tests.from_start].tolist()) <= begin


def test_the_sample_has_unresolvable_teams():
    # the property above is only worth something if some teams cannot be ordered in full
    assert sum(bool(order_conflicts(*_args(seed))[1]) for seed in range(12)) >= 4


def _args(seed):
    found, horizons, durations = _team(seed)
    return found, horizons, [], [], durations


@pytest.mark.parametrize("seed", range(6))
def test_an_implied_conflict_is_ordered_by_every_way_of_the_one_that_implies_it(seed):
    found, horizons, durations = _team(seed, robots=3, steps=8, conflicts=40)
    implied = _Dominance(found)
    pairs = [(stronger, c) for c in found for stronger in implied.by(c)]
    assert pairs  # the sample has conflicts that imply others
    for stronger, weaker in pairs:
        for edge in possible_orientations(stronger):
            precedence = Precedence(horizons, (), [edge], durations)
            if precedence.complete:
                assert is_ordered(weaker, precedence), (stronger, weaker, edge)
    needed = implied.needed(found)
    assert len(needed) < len(found)
    # what is left out is implied by something kept
    kept = {id(c) for c in needed}
    assert all(any(id(d) in kept for d in implied.by(c)) for c in found if id(c) not in kept)


@given(st.data())
@settings(max_examples=150, deadline=None)
def test_conflicts_imply_each_other_exactly_as_their_ways_do(data):
    """`_implied` against its definition: d implies c when both are between the same robots
    and each way of d that exists implies some way of c that exists (the same robots in the
    same roles, i_d >= i_c, j_d <= j_c); of two that imply each other, the earlier stands for
    both.  Two pairs of robots, so that conflicts of different pairs never imply each other."""
    m = data.draw(st.integers(0, 12))
    pairs = [(0, 1), (1, 2)]
    pair = np.array([data.draw(st.integers(0, 1)) for _ in range(m)], dtype=np.int64)
    present = np.zeros((m, 2), dtype=bool)
    ends = np.zeros((m, 2, 4), dtype=np.int64)
    for n in range(m):
        x, y = pairs[pair[n]] if data.draw(st.booleans()) else pairs[pair[n]][::-1]
        for w, (first, then) in enumerate(((x, y), (y, x))):
            if data.draw(st.integers(0, 4)):  # one way in five is missing
                present[n, w] = True
                ends[n, w] = (first, data.draw(st.integers(1, 5)), then, data.draw(st.integers(1, 5)))

    def implies_way(way, other):
        return way[0] == other[0] and way[2] == other[2] and way[1] >= other[1] and way[3] <= other[3]

    def implies(d, c):
        return pair[d] == pair[c] and all(
            any(present[c, v] and implies_way(ends[d, w], ends[c, v]) for v in (0, 1))
            for w in (0, 1)
            if present[d, w]
        )

    expected = sorted(
        (int(pair[c]), d, c)
        for d in range(m)
        for c in range(m)
        if d != c and implies(d, c) and (d < c or not implies(c, d))
    )
    stronger, weaker = conflict_order._implied(pair, present, ends)
    assert [(int(pair[c]), int(d), int(c)) for d, c in zip(stronger, weaker, strict=True)] == expected


@pytest.mark.parametrize("seed", range(20))
def test_the_messages_kept_are_exactly_the_orders_the_others_do_not_imply(seed):
    # `_reduce` keeps a set of start edges that implies every edge dropped and in which no edge
    # is implied by the others; the oracle is the vector clocks of `Precedence`
    rng = random.Random(seed)
    robots = [f"R{i}" for i in range(rng.randint(2, 5))]
    horizons = {r: rng.randint(2, 8) for r in robots}
    links = (
        [Link(message(robots[0], robots[1], "m"), robots[0], 1, robots[1], horizons[robots[1]])]
        if seed % 2
        else []
    )
    chosen = []
    for _ in range(rng.randint(3, 25)):
        a, b = rng.sample(robots, 2)
        edge = ((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b])))
        if Precedence(horizons, links, [e for e, _ in chosen] + [edge]).complete:
            chosen.append((edge, f"c{len(chosen)}"))
    kept = _reduce(horizons, links, chosen)
    kept_edges = [e for e, _ in kept]
    together = Precedence(horizons, links, kept_edges)
    assert all(together.before_start(*e) for e, _ in chosen)
    for n, edge in enumerate(kept_edges):
        others = Precedence(horizons, links, kept_edges[:n] + kept_edges[n + 1 :])
        assert not others.before_start(*edge), edge


def test_of_two_equal_orders_the_first_is_kept():
    # each message protects the conflict it was chosen for: the first of two equal edges stays
    horizons = {"A": 4, "B": 4, "C": 4}
    edge, other = (("A", 2), ("B", 3)), (("C", 1), ("B", 2))
    chosen = [(edge, "first"), (other, "other"), (edge, "second")]
    assert _reduce(horizons, [], chosen) == [(edge, "first"), (other, "other")]
    # and one implied through the other robot's plan and a message goes
    links = [Link(message("A", "C", "m"), "A", 1, "C", 1)]
    assert _reduce(horizons, links, [(other, "x"), ((("A", 1), ("B", 4)), "implied")]) == [(other, "x")]


def test_the_cores_the_search_finds_are_cores():
    # each conflict set aside comes with a core: a set of conflicts that no schedule orders
    # together (asked of Z3, which knows nothing of it)
    cores = 0
    for seed in range(24):
        found, horizons, durations = _team(seed)
        team = (horizons, [], [], durations)
        _, aside, found_cores = backjump(found, _Dominance(found), team, CorrectionSetPicker(None), 200)
        assert set(found_cores) == {id(c) for c in aside}
        schedule = _Schedule(found, horizons, [], [], durations, 200_000_000)
        for core in found_cores.values():
            cores += 1
            assert schedule.solve(core) is not None, core
    assert cores >= 5


def _assert_same_order(built: Precedence, at_once: Precedence) -> None:
    assert np.array_equal(built.done_bits, at_once.done_bits)
    assert np.array_equal(built.begin_bits, at_once.begin_bits)
    assert np.array_equal(built.finish_flat, at_once.finish_flat)
    assert np.array_equal(built.started_flat, at_once.started_flat)


@pytest.mark.parametrize("seed", range(6))
def test_start_edges_added_and_taken_back_give_the_order_built_with_them_at_once(seed):
    # the search adds start edges one at a time and takes them back (vector clocks and times
    # raised incrementally): the order must be the one built from scratch with the same edges
    rng = random.Random(seed)
    horizons = {f"R{i}": rng.randint(2, 6) for i in range(1, 5)}
    durations = {r: [rng.uniform(0.5, 4.0) for _ in range(k)] for r, k in horizons.items()}
    incremental = Precedence(horizons, (), (), durations)
    added, logs = [], []
    for _ in range(30):
        if logs and rng.random() < 0.3:
            incremental.undo(logs.pop())
            added.pop()
        else:
            a, b = rng.sample(sorted(horizons), 2)
            edge = ((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b])))
            if incremental.would_cycle(*edge):
                continue
            logs.append(incremental.add_start(edge))
            added.append(edge)
        _assert_same_order(incremental, Precedence(horizons, (), added, durations))


@pytest.mark.parametrize("seed", range(8))
def test_start_edges_added_in_batches_give_the_order_of_one_at_a_time(seed):
    # the search adds a run of forced edges in one pass (Precedence.add_starts): with messages
    # between the robots, each edge refused exactly when it closes a cycle with those before it
    rng = random.Random(seed)
    horizons = {f"R{i}": rng.randint(3, 8) for i in range(1, 6)}
    durations = {r: [rng.uniform(0.5, 4.0) for _ in range(k)] for r, k in horizons.items()}
    links = []
    for n in range(4):
        a, b = rng.sample(sorted(horizons), 2)
        link = Link(message(a, b, f"m{n}"), a, rng.randint(1, horizons[a]), b, rng.randint(1, horizons[b]))
        if Precedence(horizons, [*links, link], (), durations).complete:
            links.append(link)
    built, one_by_one = (Precedence(horizons, links, (), durations) for _ in range(2))
    added, logs, refusals = [], [], 0
    for _ in range(30):
        if logs and rng.random() < 0.25:
            built.undo(logs.pop())
            del added[-1]
            one_by_one = Precedence(horizons, links, [e for b in added for e in b], durations)
            continue
        batch = []
        for _ in range(rng.randint(1, 8)):
            a, b = rng.sample(sorted(horizons), 2)
            batch.append(((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b]))))
        log, refused = built.add_starts(batch)
        expected = []
        for n, edge in enumerate(batch):
            if one_by_one.would_cycle(*edge):
                expected.append(n)
            else:
                one_by_one.add_start(edge)
        assert refused == expected
        refusals += len(refused)
        logs.append(log)
        added.append([e for n, e in enumerate(batch) if n not in refused])
        _assert_same_order(built, one_by_one)
        _assert_same_order(built, Precedence(horizons, links, [e for b in added for e in b], durations))
    assert refusals and logs and links  # cycles met, with messages


def _assert_trail_holds(search: Search, horizons, durations) -> None:
    """The search's order is that of its trail's edges, built from scratch; its places and
    graph follow the trail; every way forced by a cycle has that cycle before it."""
    edges = [edge for _, edge, _, _ in search.trail]
    _assert_same_order(search.precedence, Precedence(horizons, (), edges, durations))
    assert search.at == {i: n for n, (i, _, _, _) in enumerate(search.trail)}
    assert [pushed[:2] for pushed in search.graph.pushed] == [search.precedence.rows(e) for e in edges]
    for n, (i, edge, _, reason) in enumerate(search.trail):
        for other in search.orientations.edges[i] if reason is True else ():
            if other is not None and other != edge and other[0][0] != other[1][0]:
                assert search.graph.path(*other, before=n) is not None, (n, other)


@pytest.mark.parametrize(
    ("seed", "robots", "conflicts"), [(0, 4, 24), (72, 5, 40), (147, 5, 40), (349, 5, 40), (3, 8, 120)]
)
def test_the_order_the_search_keeps_is_always_that_of_its_trail(seed, robots, conflicts, monkeypatch):
    # runs of forced ways are added in one pass and taken back as one, also when the search
    # jumps back into the middle of one; a dead end takes back only what needs what goes and
    # keeps the rest in place: after every take-back the clocks must be those of the edges left
    # on the trail, built from scratch, and every reason kept must still hold
    found, horizons, durations = _team(seed, robots=robots, conflicts=conflicts)
    checks = []
    back_to, retract = Search._back_to, Search._retract

    def checked_back_to(search, place):
        back_to(search, place)
        _assert_trail_holds(search, horizons, durations)
        checks.append("back")

    def checked_retract(search, place, gone, first=None):
        kept_before = [e[:2] for e in search.trail[:place]]
        retract(search, place, gone, first)
        assert [e[:2] for e in search.trail[:place]] == kept_before[: len(search.trail)]
        _assert_trail_holds(search, horizons, durations)
        checks.append("choice" if first else "core")

    monkeypatch.setattr(Search, "_back_to", checked_back_to)
    monkeypatch.setattr(Search, "_retract", checked_retract)
    search = Search(found, _Dominance(found), (horizons, [], [], durations), CorrectionSetPicker(None))
    assert search.run(budget=200) is not None
    for conflict in list(search.set_aside):
        search.give_back(conflict, budget=200)
    assert "core" in checks  # the search took something back
    search._back_to(0)  # the undo logs of what was kept in place restore the order without edges
    _assert_same_order(search.precedence, Precedence(horizons, (), (), durations))


def _conflict(a: tuple[str, int, int], b: tuple[str, int, int]) -> Conflict:
    def occupancy(robot: str, first: int, last: int) -> Occupancy:
        return Occupancy(
            robot, frozenset({robot}), shapely.box(0, 0, 1, 1), (robot, first), (robot, last), robot
        )

    return Conflict(occupancy(*a), occupancy(*b))


def test_a_choice_kept_after_a_flip_that_lost_its_other_way_counts_as_forced():
    # after a choice takes its other way, later choices are kept in place; one of them may have
    # lost its other way to a cycle by then.  A dead end through it must not jump back to it
    # (its other way would close a cycle): it counts as forced, and the set is traced again
    found = [
        _conflict(("A", 1, 1), ("B", 3, 3)),  # 0: A1 -> B3
        _conflict(("B", 1, 1), ("A", 3, 3)),  # 1: B1 -> A3
        _conflict(("A", 1, 2), ("B", 2, 3)),  # 2: A2 -> B2; its other way B3 -> A1 closes a cycle with 0
        _conflict(("A", 1, 4), ("B", 1, 2)),  # 3: A4 -> B1 closes one with 1, B2 -> A1 one with 2
    ]
    horizons, durations = {"A": 4, "B": 4}, {"A": [1.0] * 4, "B": [1.0] * 4}
    search = Search(found, _Dominance(found), (horizons, [], [], durations), CorrectionSetPicker(None))
    for i in range(3):
        search._take(i, search.orientations.edges[i][0], None)
    assert search.precedence.would_cycle(*search.orientations.edges[2][1])
    core, choices = search._dead_end_set(3)
    assert core == {0, 1, 2, 3}
    assert sorted(choices) == [0, 1]
    assert search.trail[2][3] is True
    _assert_trail_holds(search, horizons, durations)


def _five_robots(rng: random.Random) -> tuple[dict, dict, list]:
    """Five robots of 2 to 7 steps with random durations, R1 telling R2 once."""
    horizons = {f"R{i}": rng.randint(2, 7) for i in range(1, 6)}
    durations = {r: [rng.uniform(0.5, 4.0) for _ in range(k)] for r, k in horizons.items()}
    return horizons, durations, [Link(message("R1", "R2", "m"), "R1", 1, "R2", 2)]


@pytest.mark.parametrize("seed", range(8))
def test_start_edges_taken_back_from_the_middle_leave_the_order_of_the_rest(seed):
    # a dead end keeps in place what does not need the edges that go (Precedence.retract):
    # the order must be that of the edges left, built from scratch, and the one undo log it
    # returns must restore the order before the first of them, also after a second take-back
    rng = random.Random(seed)
    horizons, durations, links = _five_robots(rng)
    order = Precedence(horizons, links, (), durations)

    def batch() -> tuple[list, list]:
        edges = []
        for _ in range(rng.randint(1, 6)):
            a, b = rng.sample(sorted(horizons), 2)
            edges.append(((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b]))))
        log, refused = order.add_starts(edges)
        return log, [e for n, e in enumerate(edges) if n not in refused]

    before = [e for _ in range(3) for e in batch()[1]]
    saved = Precedence(horizons, links, before, durations)
    logs, edges = zip(*(batch() for _ in range(6)), strict=True)
    since = [e for added in edges for e in added]
    gone = rng.sample(since, len(since) // 2)
    merged = order.retract(list(logs), gone)
    left = list(since)
    for edge in gone:
        del left[len(left) - 1 - left[::-1].index(edge)]
    _assert_same_order(order, Precedence(horizons, links, before + left, durations))
    log, more = batch()
    again = order.retract([merged, log], more[:1])
    _assert_same_order(order, Precedence(horizons, links, before + left + more[1:], durations))
    order.undo(again)
    _assert_same_order(order, saved)
    assert gone and left  # edges went and stayed


@pytest.mark.parametrize("seed", range(6))
def test_watched_rows_are_read_exactly_and_the_rest_when_the_tables_are_read(seed):
    # the search keeps up to date only the copies of the rows it reads (Precedence.watch): at
    # every step those reads must be the order's built from scratch, and reading the tables as
    # attributes brings every other row up to date
    rng = random.Random(seed)
    horizons, durations, links = _five_robots(rng)
    order = Precedence(horizons, links, (), durations)
    done, begin = (rng.sample(range(order.size), order.size // 3) for _ in range(2))
    order.watch(done, begin)
    steps = np.arange(order.size)
    added: list[list] = []
    logs: list = []
    for _ in range(40):
        move = rng.random()
        if logs and move < 0.2:
            order.undo(logs.pop())
            added.pop()
        elif len(logs) > 1 and move < 0.35:  # the last two batches merged, one edge of them gone
            gone = rng.choice(added[-1] + added[-2] or [None])
            if gone is None:
                continue
            logs[-2:] = [order.retract(logs[-2:], [gone])]
            both = added[-2] + added[-1]
            del both[len(both) - 1 - both[::-1].index(gone)]
            added[-2:] = [both]
        else:
            edges = []
            for _ in range(rng.randint(1, 5)):
                a, b = rng.sample(sorted(horizons), 2)
                edges.append(((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b]))))
            log, refused = order.add_starts(edges)
            logs.append(log)
            added.append([e for n, e in enumerate(edges) if n not in refused])
        fresh = Precedence(horizons, links, [e for batch in added for e in batch], durations)
        for rows, start in ((done, False), (begin, True)):
            at = order.places(np.repeat(steps, len(rows)), np.tile(rows, order.size))
            read = order.completes_before(at, start=start)
            assert np.array_equal(read, fresh.completes_before(at, start=start))
        assert np.array_equal(order.start_times(np.array(begin)), fresh.started_flat[begin])
        if rng.random() < 0.3:
            _assert_same_order(order, fresh)
    _assert_same_order(order, Precedence(horizons, links, [e for batch in added for e in batch], durations))


@pytest.mark.parametrize("seed", range(6))
def test_a_cycle_no_edge_taken_back_may_pass_stays_when_they_go(seed):
    # RetractedEdges says which cycles may run through edges about to go; one it clears must
    # survive their going (the test is one-sided: it may flag a cycle that survives too)
    rng = random.Random(seed)
    horizons = {f"R{i}": rng.randint(3, 7) for i in range(1, 5)}
    edges = []
    order = Precedence(horizons)
    for _ in range(14):
        a, b = rng.sample(sorted(horizons), 2)
        edge = ((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b])))
        if not order.would_cycle(*edge):
            order.add_start(edge)
            edges.append(edge)
    gone = rng.sample(edges, len(edges) // 3)
    through = RetractedEdges(order)
    for edge in gone:
        through.add(*order.rows(edge))
    rest = list(edges)
    for edge in gone:
        rest.remove(edge)
    after = Precedence(horizons, starts=rest)
    steps = [(r, k) for r, n in horizons.items() for k in range(1, n + 1)]
    closing = [(x, y) for x in steps for y in steps if x[0] != y[0] and order.would_cycle(x, y)]
    cleared = [e for e in closing if not through.may_pass(*order.rows(e))]
    assert all(after.would_cycle(*e) for e in cleared)
    assert cleared and len(cleared) < len(closing)  # both answers were met


@pytest.mark.parametrize("seed", range(6))
def test_the_order_stays_topological_and_answers_in_bulk_as_one_step_at_a_time(seed):
    # the order keeps its steps in a topological order as edges come and go (each batch, each
    # take-back), and its packed tables say what `precedes`, `before_start` and `completed` say
    rng = random.Random(seed)
    horizons = {f"R{i}": rng.randint(2, 7) for i in range(1, 6)}
    order = Precedence(horizons, [Link(message("R1", "R2", "m"), "R1", 1, "R2", 2)])
    logs = []
    for _ in range(25):
        if logs and rng.random() < 0.3:
            order.undo(logs.pop())
        else:
            batch = []
            for _ in range(rng.randint(1, 5)):
                a, b = rng.sample(sorted(horizons), 2)
                batch.append(((a, rng.randint(1, horizons[a])), (b, rng.randint(1, horizons[b]))))
            logs.append(order.add_starts(batch)[0])
        place = order._ord
        for row in range(order.size):
            assert all(place[row] < place[after] for after, _ in order._successors(row))
        steps = [(r, k) for r, n in horizons.items() for k in range(1, n + 1)]
        pairs = [(x, y) for x in steps for y in steps if x[0] != y[0]]
        rows = np.array([order.offsets[r] + k for r, k in (y for _, y in pairs)])
        bits = np.array([order.offsets[r] + k for r, k in (x for x, _ in pairs)])
        done = order.completes_before(order.places(bits, rows))
        begun = order.completes_before(order.places(bits, rows), start=True)
        assert done.tolist() == [order.precedes(x, y) for x, y in pairs]
        assert begun.tolist() == [order.before_start(x, y) for x, y in pairs]
        for step in steps:
            for robot in horizons:
                before = [k for r, k in steps if r == robot and order.precedes((r, k), step)]
                assert order.completed(step, robot) == max(before, default=0)
    assert any(order.completes_before(order.places(bits, rows)))  # some steps were ordered
