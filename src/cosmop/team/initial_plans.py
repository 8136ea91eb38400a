"""The team's first plans: goods packed into shared docks, givers of goods before receivers.

Each robot's shortest plan is first found as if it were alone, with two exceptions the team
settles beforehand.  Robots that drop goods into one workspace would each pick the same spot:
the goods get a slot each (:func:`pack_docks`).  A robot that picks goods another robot drops
(a relay) must find them where the giver's plan puts them: givers are planned before their
receivers (:func:`plan_in_turn`).
"""

from __future__ import annotations

from collections.abc import Mapping

from cosmop.events import Event, Primitive
from cosmop.planning.plan_types import RobotPlan
from cosmop.planning.synthesis import Synthesis
from cosmop.scene import Workspace
from cosmop.team.aside import dock_slots, handover_spot
from cosmop.team.handover import Handover, Handovers
from cosmop.team.planner import Planner, goods_at

__all__ = ["pack_docks", "plan_in_turn"]


def pack_docks(base: Mapping[str, tuple[Event, ...]], planner: Planner) -> tuple[str, ...]:
    """Give goods that several robots drop into one workspace a slot each; why not (``()``: done).

    Each robot picks its own drop spot when planned alone, and robots sharing a dock would
    pick the same one: the goods are packed first (:func:`cosmop.team.aside.dock_slots`),
    each robot's drop is pinned to its goods' slot, and a robot knows the goods packed before
    its own in their slots from the start (it docks beside them).  The conflict step then
    orders the drops.

    Parameters
    ----------
    base : mapping of str to tuple of Event
        Each robot's word.
    planner : Planner
        The team's planner: its drops pinned to slots and goods placed are set here.
    """
    drops: dict[str, dict[str, tuple[str, Event]]] = {}
    for robot, word in base.items():
        for event in word:
            if event.kind == "drop" and event.robot == robot and event.workspace and event.obj:
                drops.setdefault(event.workspace, {}).setdefault(event.obj, (robot, event))
    why_not = []
    scene = planner.scenario.scene
    for workspace, goods in drops.items():
        if len({robot for robot, _ in goods.values()}) < 2:
            continue  # one robot's model holds all its goods: its plan packs them itself
        packing = dock_slots(scene, workspace, {o: robot for o, (robot, _) in goods.items()})
        if packing.left_out:
            size = scene.workspaces[workspace]
            why_not.append(
                f"{workspace} holds {len(packing.slots)} of the {len(goods)} goods dropped there: no "
                f"room to dock {', '.join(packing.left_out)} beside the others "
                f"({_extent(size)}, goods {', '.join(f'{o} {scene.objects[o].size:g}' for o in goods)})"
            )
            continue
        for n, (obj, spot) in enumerate(packing.slots):
            robot, event = goods[obj]
            planner.spots.setdefault(robot, {})[event] = spot
            for later, _ in packing.slots[n + 1 :]:
                if goods[later][0] != robot:
                    planner.placed.setdefault(goods[later][0], {})[obj] = spot
    return tuple(why_not)


def _extent(workspace: Workspace) -> str:
    """A rectangular workspace's size in words (mm)."""
    (x0, x1), (y0, y1) = workspace.ranges
    return f"{x1 - x0:g} x {y1 - y0:g} mm"


def plan_in_turn(
    base: Mapping[str, tuple[Event, ...]], givers: Handovers, planner: Planner
) -> dict[str, Synthesis]:
    """Every robot's first plan, givers of goods before their receivers.

    Robots that receive nothing are planned together; once a giver is planned, the spot where
    its plan drops the goods becomes the receiver's (:meth:`Planner.hand_over`), and the
    receiver is planned in a later turn.  A receiver that cannot pick them there, and a cycle
    of givers and receivers, get a spot chosen for both
    (:func:`cosmop.team.aside.handover_spot`): the giver is planned again to drop there.

    Parameters
    ----------
    base : mapping of str to tuple of Event
        Each robot's word.
    givers : Handovers
        The hand-overs of the mission and the turns they impose.
    planner : Planner
        The team's planner.
    """
    results: dict[str, Synthesis] = {}
    for robots, chosen in givers.turns(tuple(base)):
        for h in chosen:
            _choose_spot(h, planner)
        results.update(planner.run({r: base[r] for r in robots}))
        for h in givers.items:
            if h.giver not in robots:
                continue
            pinned = planner.spots.get(h.giver, {}).get(h.drop)
            plan = results[h.giver].plan
            spot = pinned if pinned is not None else _drop_spot(plan, h) if plan is not None else None
            if spot is None:
                continue
            planner.hand_over(h, spot)
            if pinned is None:  # its plan drops there already: its answer with the spot pinned too
                planner.cache[planner.key(h.giver, base[h.giver])] = results[h.giver]
        stuck = [h for h in givers.items if h.receiver in robots and not results[h.receiver].feasible]
        for h in stuck:  # the giver's spot does not suit the receiver: one for both
            if _choose_spot(h, planner):
                results.update(planner.run({r: base[r] for r in (h.giver, h.receiver)}))
    return results


def _choose_spot(handover: Handover, planner: Planner) -> bool:
    """Give `handover` a spot both robots can dock to, clear of the spots other goods are
    handed over at; whether there is a new one."""
    scene = planner.scenario.scene
    spots = {o: p for placed in planner.placed.values() for o, p in placed.items() if o != handover.obj}
    scene = goods_at(scene, spots)
    robots = (handover.giver, handover.receiver)
    assert handover.drop.workspace is not None  # a drop names its workspace
    spot = handover_spot(scene, handover.obj, handover.drop.workspace, robots)
    if spot is None or planner.placed.get(handover.receiver, {}).get(handover.obj) == spot:
        return False
    planner.hand_over(handover, spot)
    return True


def _drop_spot(plan: RobotPlan, handover: Handover) -> tuple[float, float] | None:
    """Where `plan` puts the goods of `handover` down: its `nth` DropOff of them."""
    drops = [s for s in plan.steps if s.primitive == Primitive.DROPOFF and s.object == handover.obj]
    if handover.nth >= len(drops):
        return None
    x, y = drops[handover.nth].objects[handover.obj].position
    return (x, y)
