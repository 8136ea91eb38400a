"""Step 4 of the loop: the plans made team-safe, with detours where waiting cannot or should not do.

Every place two plans share is ordered by a message (:func:`cosmop.team.safe_plans.make_team_safe`).
A conflict no order resolves (a robot parked for good where another must pass) is resolved by
re-planning one robot with the other's space as walls (:func:`make_safe`); where both places
are ones re-planning keeps (a robot's start against the pose another picks from), goods at rest
are dropped elsewhere or goods to pick are picked from another side.  Then, where waiting
for a shared place costs the team more than a way around, the way around is taken
(:func:`shorten_waits`): two robots pass each other in lanes, or the waiting robot drives
around what it waits for.
"""

from __future__ import annotations

import time
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass

import shapely
from shapely.geometry.base import BaseGeometry

from cosmop.events import Event
from cosmop.planning.plan_types import RobotPlan
from cosmop.planning.realisation import at_pose
from cosmop.planning.synthesis import Synthesis
from cosmop.scene import Scene, Wall
from cosmop.team.aside import handover_spot
from cosmop.team.conflicts import Conflict, ConflictSettings, Futile, Occupancy, kept_out
from cosmop.team.lanes import lanes
from cosmop.team.planner import Planner, Window, ends_away, goods_at
from cosmop.team.safe_plans import TeamSafety, Wait, make_team_safe
from cosmop.team.walls import walls_around
from cosmop.units import show_point

__all__ = ["MIN_WAIT", "OUT_OF_BUDGET", "TRIAL_STEPS", "MadeSafe", "make_safe", "shorten_waits"]

TRIAL_STEPS = 2
"""Steps a way around may add to a robot's plan: a trial searches no longer plans."""

MIN_WAIT = 2.0
"""Expected seconds of a wait below which no way around is tried: a detour rarely costs less."""

# robot -> the conflicts it gives way in, and the space it keeps out of in each
_Moves = dict[str, list[tuple[Conflict, Occupancy]]]

OUT_OF_BUDGET = "no team plan found within the planning budget"
"""How a reason given when the planning budget ran out begins (:meth:`Planner.set_budget`)."""


@dataclass(frozen=True)
class MadeSafe:
    """What step 4 did: the team-safe plans, or why the plans cannot be made safe.

    Attributes
    ----------
    results : mapping of str to Synthesis
        Every robot's synthesis now.
    safety : TeamSafety
        The conflicts between the plans and the messages that order them.
    replans : tuple of str
        Why robots were re-planned, in plain words.
    reasons : tuple of str
        Why the team cannot be planned (empty: the plans are team-safe).
    stuck : Conflict or None
        When that is why: the conflict that no order resolves and no re-plan moves (none
        applies, or only ways around known not to work).
    """

    results: Mapping[str, Synthesis]
    safety: TeamSafety
    replans: tuple[str, ...] = ()
    reasons: tuple[str, ...] = ()
    stuck: Conflict | None = None

    @property
    def ok(self) -> bool:
        """Whether the step worked (no reasons)."""
        return not self.reasons


def _plans(results: Mapping[str, Synthesis]) -> dict[str, RobotPlan]:
    return {r: res.plan for r, res in results.items() if res.plan is not None}


def make_safe(
    current: Mapping[str, tuple[Event, ...]],
    results: Mapping[str, Synthesis],
    planner: Planner,
    settings: ConflictSettings,
    max_rounds: int = 6,
    max_total: int = 16,
    explain: bool = True,
) -> MadeSafe:
    """Order every conflict by messages; re-plan around the ones no order resolves (step 4).

    Each round, the robots that give way in unresolved conflicts (:func:`_give_way`) are
    re-planned with the space of the other side as an obstacle, until the conflicts are
    ordered, or `max_rounds` rounds pass without fewer unresolved conflicts than before (a
    large team may need more rounds, each resolving some), or `max_total` rounds are spent.
    A robot that cannot keep clear is given back its plan and the other side gives way instead,
    where it can.  Where neither side can give way (both are places re-planning keeps), goods
    at rest are dropped elsewhere (:func:`_drop_elsewhere`) or goods to pick are picked from
    another side (:func:`_pick_elsewhere`).

    Parameters
    ----------
    current : mapping of str to tuple of Event
        Each robot's word with its messages (what a re-plan plans).
    results : mapping of str to Synthesis
        Each robot's feasible synthesis.
    planner : Planner
        The team's planner (walls added for a detour are kept there).
    settings : ConflictSettings
        How conflicts are found (clearance, cuts).
    max_rounds, max_total : int
        Rounds without progress, and rounds in all, after which the step gives up.
    explain : bool
        Whether a re-plan that fails says why (false: a trial, whose reasons nobody reads; the
        first failure's reason is sought only with it, later ones never).
    """
    results = dict(results)
    replans: list[str] = []
    futile: Futile = frozenset()  # ways around that failed, or left a plan as it was
    refused: tuple[str, ...] = ()  # why the first of them failed
    best, since = None, 0
    for n in range(max_total + 1):
        safety = _team_safe(planner, _plans(results), settings, futile)
        if safety.safe:
            return MadeSafe(results, safety, tuple(replans))
        left = len(safety.unresolved)
        best, since = (left, 0) if best is None or left < best else (best, since + 1)
        over = planner.over_budget()
        last = since >= max_rounds or n == max_total or over
        stuck = [c for c in safety.unresolved if not safety.detours(c)]
        unstuck = _unstick(stuck, safety, current, planner, settings) if stuck and not last else None
        if unstuck is not None:  # goods put or picked elsewhere, or a robot sent home: order again
            results.update(unstuck.results)
            replans.extend(unstuck.replans)
            continue
        if stuck or last:
            conflict = (stuck or list(safety.unresolved))[0]
            why = f"no order or re-plan keeps {' and '.join(conflict.robots)} apart: {conflict.describe()}"
            if over:  # stopped, not proved: say so first
                first = (refused or (why,))[0]
                why = f"{OUT_OF_BUDGET} of {planner.budget:g} s ({first})"
                return MadeSafe(results, safety, tuple(replans), (why,))
            return MadeSafe(results, safety, tuple(replans), refused or (why,), stuck[0] if stuck else None)
        step = _give_way_round(planner, current, results, safety, settings, explain=explain and not refused)
        replans.extend(step.replans)
        learned, futile = step.futile - futile, futile | step.futile
        if step.failed:
            reasons = tuple(
                f"{robot} cannot keep clear of the space it shares with another robot "
                f"({conflict.describe()}): {why}"
                for robot, (conflict, why) in step.failed.items()
            )
            if not learned:  # nothing new known: the same round would come again
                return MadeSafe(results, safety, tuple(replans), refused or reasons)
            # the search sets aside another conflict of the same cycle next round, where one has
            # a way around that may work (another robot's drive, say)
            refused = refused or reasons
        results.update(step.results)
    return MadeSafe(results, safety, tuple(replans))


def _unstick(
    stuck: Sequence[Conflict],
    safety: TeamSafety,
    current: Mapping[str, tuple[Event, ...]],
    planner: Planner,
    settings: ConflictSettings,
) -> _Detoured | None:
    """What may settle conflicts no order resolves and no way around moves, in this order: goods
    that rest for good in the way dropped elsewhere (:func:`_drop_elsewhere`), goods picked from
    another side (:func:`_pick_elsewhere`), a robot done in the way sent home
    (:func:`_send_home`); ``None`` when none of them works."""
    moved = _drop_elsewhere(stuck, safety, current, planner, settings)
    if moved:
        return _Detoured(
            {r: res for r, (res, _) in moved.items()}, tuple(why for _, why in moved.values()), {}
        )
    picked = _pick_elsewhere(stuck, safety, current, planner, settings)
    if picked is not None:
        return picked
    return _send_home(stuck, current, planner, safety.plans)


def _send_home(
    conflicts: Sequence[Conflict],
    current: Mapping[str, tuple[Event, ...]],
    planner: Planner,
    plans: Mapping[str, RobotPlan],
) -> _Detoured | None:
    """Robots done where their missions end, in the way of others (a dock others drop in, a way
    they must pass), re-planned to drive home when done (:attr:`Planner.homing`): a robot whose
    mission does not say where to stop may stop where it started, out of the way (its home is a
    place the scene gave it, kept clear of the others' plans).  The drive is motion only: the
    robot's word stays its mission's.

    The robots that stand for good in `conflicts` are sent home first; where none of them can
    go, every robot of `conflicts` that does not end at home (its end may close their cycle from
    afar; `plans`, the team's, say where each ends).  ``None`` when no such robot has a plan home.
    """
    standing = [
        s.what for c in conflicts for s in (c.a, c.b) if s.what in s.parties and s.last is None and s.movable
    ]
    for robots in (standing, [r for c in conflicts for r in c.robots]):
        results: dict[str, Synthesis] = {}
        why: list[str] = []
        for robot in dict.fromkeys(robots):  # in order, once each
            if robot in planner.homing or robot not in current or not ends_away(current[robot]):
                continue
            plan, home = plans.get(robot), planner.scenario.scene.robots[robot].pose
            if plan is None or not plan.steps or at_pose(plan.steps[-1].robot, home):
                continue  # at home at the end already: nothing to change
            planner.homing.add(robot)
            result = _replan_asking_no_more(planner, current, robot)
            if not result.feasible:
                planner.homing.discard(robot)
                continue
            results[robot] = result
            why.append(f"{robot} drives home when done, out of the others' way")
        if results:
            return _Detoured(results, tuple(why), {})
    return None


def _replan_asking_no_more(
    planner: Planner, current: Mapping[str, tuple[Event, ...]], robot: str
) -> Synthesis:
    """`robot` re-planned under the planner's restrictions, asking for no goods it does not ask
    for already: the requests are answered by now, and a new one would have no answer.  A robot
    that finds no plan gets its restrictions back.  A trial: an answer without a plan does not
    say why (proving why costs unsat cores, and only a plan is of use here)."""
    saved = planner.restrictions()
    _ask_no_more(planner, current, robot)
    result = planner.run({robot: current[robot]}, explain=False)[robot]
    if not result.feasible:
        planner.restore(saved)
    return result


def _ask_no_more(planner: Planner, current: Mapping[str, tuple[Event, ...]], robot: str) -> None:
    """From now on `robot` may request only the goods its word `current[robot]` asks for already
    (the requests are settled: a new one would have no answer)."""
    asked = {e.obj for e in current[robot] if e.kind == "away" and e.receiver == robot and e.obj}
    planner.forbid(robot, frozenset(planner.scenario.scene.objects) - asked)


def _give_way_round(
    planner: Planner,
    current: Mapping[str, tuple[Event, ...]],
    results: Mapping[str, Synthesis],
    safety: TeamSafety,
    settings: ConflictSettings,
    explain: bool = True,
) -> _Detoured:
    """One round of :func:`make_safe`'s ways around: the robots that give way in the unresolved
    conflicts (:func:`_give_way`) re-planned around the other side; where one fails, the other
    side of its conflicts instead, where it can.  A re-plan that gives the robot the plan it had
    counts as failed: the conflict would come back as it is.  The result's ``futile`` names the
    ways that failed; without `explain` a re-plan that fails only says so (a trial: the reason
    given is an earlier round's)."""
    moves = _give_way(safety, safety.unresolved)
    step = _detour(planner, current, moves, settings, safety.fixed, results, explain)
    fresh, failed, replans = dict(step.results), dict(step.failed), list(step.replans)
    futile = {(robot, keep.label) for robot in failed for _, keep in moves[robot]}
    instead = _give_way(safety, [c for r in failed for c, _ in moves[r]], set(failed))
    if instead:  # the other side of their conflicts gives way instead, where it can
        again = _detour(planner, current, instead, settings, safety.fixed, results, explain)
        fresh.update(again.results)
        replans.extend(again.replans)
        failed = dict(again.failed)
        futile |= {(robot, keep.label) for robot in failed for _, keep in instead[robot]}
    return _Detoured(fresh, tuple(replans), failed, frozenset(futile))


def _drop_elsewhere(
    stuck: Iterable[Conflict],
    safety: TeamSafety,
    current: Mapping[str, tuple[Event, ...]],
    planner: Planner,
    settings: ConflictSettings,
) -> dict[str, tuple[Synthesis, str]]:
    """Goods that would rest for good where another robot stands for good, dropped elsewhere.

    Walls cannot settle such a conflict when the robot that drops the goods must itself pass
    through the other's place (to pick them, say): instead the drop is pinned to another spot
    of its workspace, one the robot can dock to whose square keeps the clearance from the other
    side and from every other robot's fixed places, or else only what the conflict rule asks
    (:func:`_drop_avoid`; :func:`cosmop.team.aside.handover_spot` with `avoid`), and the robot
    is re-planned.  Returns, per robot re-planned, its synthesis and
    why; a robot whose re-plan fails keeps its plan and its drop.
    """
    scene = planner.scenario.scene
    out: dict[str, tuple[Synthesis, str]] = {}
    for conflict in stuck:
        for goods, other in ((conflict.a, conflict.b), (conflict.b, conflict.a)):
            if goods.what not in scene.objects or not goods.movable or goods.first is None:
                continue
            robot = goods.first[0]
            drops = [e for e in current[robot] if e.kind == "drop" and e.obj == goods.what]
            if robot in out or len(drops) != 1 or drops[0].workspace is None:
                continue
            if any(goods.what in placed for r, placed in planner.placed.items() if r != robot):
                continue  # handed over or packed: others' models have the goods at that spot
            own = goods_at(scene, planner.placed.get(robot, {}))
            for avoid in _drop_avoid(robot, other, safety.fixed, settings):
                spot = handover_spot(own, goods.what, drops[0].workspace, (robot,), avoid=avoid)
                if spot is None or planner.spots.get(robot, {}).get(drops[0]) == spot:
                    continue  # no spot, or the one it has already: nothing new to try
                saved = dict(planner.spots.get(robot, {}))
                planner.spots.setdefault(robot, {})[drops[0]] = spot
                result = _replan_asking_no_more(planner, current, robot)
                if result.feasible:
                    where = show_point(spot, scene.units)
                    out[robot] = (
                        result,
                        f"{robot} drops {goods.what} at {where} instead: {conflict.describe()}",
                    )
                    break
                planner.spots[robot] = saved
            if robot in out:
                break
    return out


def _drop_avoid(
    robot: str, other: Occupancy, fixed: Mapping[str, Sequence[BaseGeometry]], settings: ConflictSettings
) -> tuple[BaseGeometry, BaseGeometry]:
    """Where goods `robot` drops elsewhere must not lie, the roomier choice first: the other
    side and every other robot's fixed places grown by the clearance (room to pass them), then
    only what the conflict rule asks of goods at rest (a robot's body and the room it may stop
    off its pose, :attr:`ConflictSettings.rest`): a dock that holds a robot's home may have no
    spot that keeps the clearance from it, but one the goods can rest in once dropped."""
    others = [g for r, places in fixed.items() if r != robot for g in places]
    wide = shapely.unary_union([other.region, *others]).buffer(settings.clearance, join_style="mitre")
    shrink = settings.rest - settings.clearance / 2  # fixed places are grown by half the clearance
    bodies = [g.buffer(shrink, join_style="mitre") for g in others]
    return wide, shapely.unary_union([other.body or other.region, *bodies])


def _pick_elsewhere(
    stuck: Iterable[Conflict],
    safety: TeamSafety,
    current: Mapping[str, tuple[Event, ...]],
    planner: Planner,
    settings: ConflictSettings,
) -> _Detoured | None:
    """A robot that stands to pick goods where another robot must stand (at its start, say),
    re-planned to pick them elsewhere: from another side, or after another way there.

    Where a robot picks from counts as a place re-planning cannot move
    (:func:`~cosmop.team.conflicts.fixed_places`), and rightly so for every other conflict; but
    when it meets another such place (the other robot's start, say, while the other's first pose
    is on the picking robot's start), no order and no re-plan around places resolves them.  The
    picking robot is then re-planned with the other side's space as walls (its own pose there
    left out of its fixed places), once for each such space.  Returns the first re-plan that
    has a plan (:func:`_detour`), or ``None``.
    """
    for conflict in stuck:
        for side, other in ((conflict.a, conflict.b), (conflict.b, conflict.a)):
            robot = side.what
            if side.movable or robot not in side.parties or side.first is None or side.last is None:
                continue  # not a robot standing to pick and leaving again afterwards
            fixed = {**safety.fixed, robot: [g for g in safety.fixed.get(robot, ()) if g is not side.region]}
            walls = _keep_out(robot, other, fixed, settings.clearance)
            if set(walls) <= set(planner.obstacles.get(robot, ())):
                continue  # kept out of that space already: nothing new to try
            # a trial: only a plan is of use here, not why there is none
            step = _detour(planner, current, {robot: [(conflict, other)]}, settings, fixed, explain=False)
            if step.results:
                return step
    return None


def _team_safe(
    planner: Planner, plans: Mapping[str, RobotPlan], settings: ConflictSettings, futile: Futile = frozenset()
) -> TeamSafety:
    """:func:`make_team_safe` of `plans`, its new messages named apart from those the plans
    already send, timed as the conflict phase (`futile`: ways around known not to work)."""
    used = {e for p in plans.values() for e in p.mission if e.kind == "msg"}
    t0 = time.perf_counter()
    safety = make_team_safe(planner.scenario.scene, plans, settings=settings, used=used, futile=futile)
    planner.count_time("conflicts", time.perf_counter() - t0)
    return safety


def _give_way(safety: TeamSafety, conflicts: Iterable[Conflict], exclude: Iterable[str] = ()) -> _Moves:
    """Who gives way in which of `conflicts`: ``robot -> [(conflict, space to avoid)]``.

    Each conflict's best way (:meth:`TeamSafety.detours`), the conflicts with the best ways
    first, except that two robots never avoid each other in one round (each would wall itself
    off from the other's old places, both may be shut out, as two goods meant for one dock
    spot were): such a conflict waits for the next round, when the other's new plan may have
    settled it.  Robots in `exclude` keep their plans.
    """
    excluded = frozenset(exclude)
    moves: _Moves = {}
    avoids: set[tuple[str | None, str | None]] = set()
    best = {
        c: next(((n, r, k) for n, r, k in safety.detours(c) if r not in excluded), None) for c in conflicts
    }
    ranked = sorted(((way, c) for c, way in best.items() if way is not None), key=lambda item: item[0][0])
    for (_, robot, keep), conflict in ranked:
        keeper = next((r for r in conflict.robots if r != robot), None)
        if (keeper, robot) in avoids:
            continue  # the two would avoid each other: next round
        moves.setdefault(robot, []).append((conflict, keep))
        avoids.add((robot, keeper))
    return moves


@dataclass(frozen=True)
class _Detoured:
    """The robots re-planned around their spaces, why, for each that failed its conflict and
    why, and the ways around that failed (``(robot, label of the space)``)."""

    results: Mapping[str, Synthesis]
    replans: tuple[str, ...]
    failed: Mapping[str, tuple[Conflict, str]]
    futile: Futile = frozenset()


def _detour(
    planner: Planner,
    current: Mapping[str, tuple[Event, ...]],
    moves: _Moves,
    settings: ConflictSettings,
    fixed: Mapping[str, Sequence[BaseGeometry]],
    results: Mapping[str, Synthesis] | None = None,
    explain: bool = True,
) -> _Detoured:
    """Re-plan every robot in `moves` around its spaces (`fixed`: each robot's fixed places,
    :func:`~cosmop.team.conflicts.fixed_places`); a robot that fails gets its walls back, and
    so does one whose new plan is its plan in `results` (the walls changed nothing).  Without
    `explain`, a robot that fails is not told why (:func:`_replan_within`)."""
    saved = dict(planner.obstacles)
    walls = {
        robot: tuple(w for _, keep in items for w in _keep_out(robot, keep, fixed, settings.clearance))
        for robot, items in moves.items()
    }
    fresh = _replan_within(planner, current, walls, explain)
    failed = {}
    for robot, res in list(fresh.items()):
        same = results is not None and res.feasible and res.plan == results[robot].plan
        if not res.feasible or same:
            failed[robot] = (
                moves[robot][0][0],
                "its plan keeps out of that space already" if same else res.reason or "",
            )
            planner.obstacles[robot] = saved.get(robot, ())
            if not planner.obstacles[robot]:
                del planner.obstacles[robot]
            del fresh[robot]
    replans = tuple(
        f"{robot} re-planned around the space it shares: {items[0][0].describe()}"
        for robot, items in moves.items()
        if robot in fresh
    )
    return _Detoured(fresh, replans, failed)


def _keep_out(
    robot: str, keep: Occupancy, fixed: Mapping[str, Sequence[BaseGeometry]], clearance: float
) -> tuple[Wall, ...]:
    """The walls that keep `robot` out of `keep`: the clearance away from it, or only the gap
    the scene gave where it placed the robots closer (:func:`~cosmop.team.conflicts.kept_out`)."""
    label = f"the space of {keep.label}"
    avoid = kept_out(robot, keep, fixed, clearance)
    return walls_around(keep.region, clearance, label) if avoid is None else walls_around(avoid, 0.0, label)


def _replan_within(
    planner: Planner,
    current: Mapping[str, tuple[Event, ...]],
    walls: Mapping[str, tuple[Wall, ...]],
    explain: bool = True,
    windows: Mapping[str, Window] | None = None,
) -> dict[str, Synthesis]:
    """Every robot of `walls` re-planned with them added to its walls (kept in the planner).

    The requests are settled by now: a re-plan may ask only for goods the robot already asks
    for.  With `explain` false an infeasible answer only says so (a trial); `windows` bounds
    the lengths searched (:meth:`Planner.run`).
    """
    for robot, extra in walls.items():
        planner.wall_off(robot, extra)
        _ask_no_more(planner, current, robot)
    return planner.run({robot: current[robot] for robot in walls}, explain=explain, windows=windows)


def shorten_waits(
    current: Mapping[str, tuple[Event, ...]],
    made: MadeSafe,
    planner: Planner,
    settings: ConflictSettings,
    budget: int,
) -> MadeSafe:
    """Where waiting for a shared place costs the team more than a way around, take the way around.

    Each robot was planned alone, so its route ignores the others; the conflict step then makes
    robots wait for each other.  The waits on the itinerary's critical path
    (:attr:`~cosmop.team.safe_plans.Wait.critical`; no other wait, shortened, ends the team
    sooner), the longest first, get the ways around that apply (:func:`_ways_around`): the
    two robots re-planned to pass each other in lanes, or the waiting robot re-planned with the
    other's occupancy as walls.  A way is kept when the plans stay team-safe and the team's
    expected makespan goes down; else the robots keep their plans and walls.  At most `budget`
    ways are tried (each one synthesis per robot re-planned, both robots' at once, of at most
    :data:`TRIAL_STEPS` steps more than its plan, and one conflict step), so that planning time
    stays bounded.

    Parameters
    ----------
    current : mapping of str to tuple of Event
        Each robot's word with its messages.
    made : MadeSafe
        Team-safe plans (step 4's result).
    planner : Planner
        The team's planner.
    settings : ConflictSettings
        How conflicts are found.
    budget : int
        Ways around tried, at most.
    """
    scene = planner.scenario.scene
    results, safety, replans = dict(made.results), made.safety, list(made.replans)
    tried: set[Hashable] = set()
    while budget > 0 and not planner.over_budget():
        worth = (w for w in safety.waits if w.critical and w.seconds >= MIN_WAIT)
        way = next(
            (way for w in worth for way in _ways_around(w, safety, scene, settings) if way[0] not in tried),
            None,
        )
        if way is None:
            break
        key, why, walls = way
        tried.add(key)
        budget -= 1
        saved = planner.restrictions()
        # with more walls no plan is shorter than the robot's; a way much longer is no way round
        windows = {
            r: (least, least + TRIAL_STEPS) for r in walls if (least := results[r].horizon) is not None
        }
        fresh = _replan_within(planner, current, walls, False, windows)
        if all(res.feasible for res in fresh.values()):
            candidate = _team_safe(planner, _plans({**results, **fresh}), settings, safety.futile)
            if candidate.safe and candidate.makespan < safety.makespan - 1e-6:
                replans.append(
                    f"{why}: the team is expected done in {candidate.makespan:.1f} s instead of "
                    f"{safety.makespan:.1f} s"
                )
                results.update(fresh)
                safety = candidate
                continue
        planner.restore(saved)
    return MadeSafe(results, safety, tuple(replans))


_Way = tuple[Hashable, str, dict[str, tuple[Wall, ...]]]  # (key, why, robot -> walls)


def _ways_around(wait: Wait, safety: TeamSafety, scene: Scene, settings: ConflictSettings) -> list[_Way]:
    """The ways around one wait, to try in order: ``(key, why, robot -> walls)``.

    Two robots that drive head-on through a place wide enough for both pass each other in
    lanes (:func:`cosmop.team.lanes.lanes`); the waiting robot can keep out of what it
    waits for, where that leaves its fixed places free (:meth:`TeamSafety.detours`).
    """
    out: list[_Way] = []
    robot, other = wait.robot, wait.other
    if wait.drives is not None:
        shared = wait.first.region.intersection(wait.then.region)
        drives = {other: wait.drives[0], robot: wait.drives[1]}
        keep = lanes(scene, drives, shared, settings.clearance, safety.fixed)
        if keep is not None:
            walls = {
                r: walls_around(
                    region, settings.clearance, f"the lane {next(o for o in keep if o != r)} keeps to"
                )
                for r, region in keep.items()
            }
            key = (
                "lanes",
                *sorted((r, tuple(round(v) for v in region.bounds)) for r, region in keep.items()),
            )
            why = (
                f"{robot} and {other} re-planned to pass each other in lanes instead of {robot} waiting "
                f"{wait.seconds:.1f} s where {wait.conflict.describe()}"
            )
            out.append((key, why, walls))
    for _, mover, keep_out in safety.detours(wait.conflict):
        if mover == robot:
            walls = {robot: _keep_out(robot, keep_out, safety.fixed, settings.clearance)}
            why = (
                f"{robot} re-planned around the space of {keep_out.label} instead of waiting "
                f"{wait.seconds:.1f} s"
            )
            out.append((("around", robot, keep_out.label), why, walls))
            break
    return out
