"""Which robot serves which order, and its next mission: the dispatcher of a lifelong run.

Released orders wait in a pool, oldest first.  The dispatcher chooses among the oldest few of
them (a window of about one order per robot, as the League of Robot Runners reveals a task pool
of ``numTasksReveal`` tasks per robot): of every pair of an order of the window and an idle
robot that may serve it (``Order.by``), the pair of least estimated work, the L1 distance from
where the robot stands to the goods and from the goods to the nearest of the order's docks
(mm).  Choosing among several orders lets a robot take work near where it stands, instead of
crossing the warehouse for the oldest order while others cross it the other way; so that no
order waits for ever, an order passed over for younger ones as many times as the window holds
orders is served next (:func:`choose_assignment`).  A window of one order is the strict
oldest-first rule.  A robot that is busy competes again as soon as it has dropped its goods
(from the dock, its way home still ahead) or is idle, so among busy robots the one whose order
is done soonest is served first.  The mission handed over is the order's delivery and the way
home: ``pick``, ``drop`` at that dock, ``return``; the way home is replaced by the next order
when one is given at the dock, and left out for a robot whose home a failed robot stands on.
A robot that found no plan for an order from where it stood is passed over for it while another
idle robot may serve it (:attr:`OrderState.no_plan_by`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from cosmop.events import Event
from cosmop.scene import Order, Scene

__all__ = ["Offer", "OrderState", "choose_assignment", "delivery_events", "window_size"]


@dataclass
class OrderState:
    """What became of an order during a run (mutable: the run fills it in).

    Attributes
    ----------
    order : Order
    index : int
        Its place in the stream.
    robot : str or None
        The robot serving it now (None: in the pool, or done).
    served_by : str or None
        The robot it was last given to.
    assigned : float or None
        When a robot took it, s.
    delivered : float or None
        When its goods lay in the dock, s.
    lost : str or None
        Why it will never be delivered (a robot failed carrying the goods).
    tries : int
        Plans tried for it that were not handed over.
    refused : str or None
        The last refusal: which robot, when, and why (an order still pending says so).
    no_plan_by : dict of str to float
        The robots that found no plan for it from where they stood, each with when it first
        did, s: the order goes to another idle robot first.
    retry_at : float
        Not tried again before this time, s.
    passed : int
        Times a younger order of the dispatcher's window was given to a robot that could have
        served this one (:func:`choose_assignment`).
    """

    order: Order
    index: int
    robot: str | None = None
    served_by: str | None = None
    assigned: float | None = None
    delivered: float | None = None
    lost: str | None = None
    tries: int = 0
    refused: str | None = None
    no_plan_by: dict[str, float] = field(default_factory=dict)
    retry_at: float = 0.0
    passed: int = 0


def _l1(a: Sequence[float], b: Sequence[float]) -> float:
    return abs(a[0] - b[0]) + abs(a[1] - b[1])


def _dock(scene: Scene, order: Order, goods: Sequence[float]) -> str:
    """The order's dock nearest the goods (L1 to the workspace's centre)."""
    return min(order.to, key=lambda w: (_l1(scene.workspaces[w].center, goods), w))


def delivery_events(
    scene: Scene, robot: str, order: Order, goods: Sequence[float], *, home: bool = True
) -> tuple[Event, ...]:
    """The mission that serves `order` by `robot`: pick the goods (lying at `goods`, mm), drop
    them at the nearest of the order's docks, and go home (unless `home` is false: a robot
    whose home is taken for good stays at the dock, until it is given the next order).

    Parameters
    ----------
    scene : Scene
        The scene (its workspaces place the docks).
    robot : str
        The robot that serves the order.
    order : Order
        The order to serve.
    goods : sequence of float
        Where the order's goods lie ``(x, y)``, mm.
    home : bool
        Whether the robot goes home after the drop.

    Returns
    -------
    tuple of Event
        ``pick``, ``drop`` at the nearest dock, ``return`` (with `home`).
    """
    dock = _dock(scene, order, goods)
    events = (Event("pick", robot, obj=order.object), Event("drop", robot, obj=order.object, workspace=dock))
    return (*events, Event("return", robot)) if home else events


@dataclass(frozen=True)
class Offer:
    """An order the dispatcher may give now.

    Attributes
    ----------
    order : Order
    goods : tuple of float
        Where its goods lie ``(x, y)``, mm.
    passed_over : frozenset of str
        Robots that found no plan for it from where they stood (:attr:`OrderState.no_plan_by`):
        given it only when no other idle robot may serve it.
    overdue : bool
        Served before every order that is not (passed over too often for younger ones).
    """

    order: Order
    goods: tuple[float, ...]
    passed_over: frozenset[str] = frozenset()
    overdue: bool = False


def choose_assignment(
    scene: Scene, offers: Sequence[Offer], idle: Sequence[tuple[str, Sequence[float]]]
) -> tuple[int, str] | None:
    """The next order to give and its robot: ``(index in offers, robot)``, or None when no idle
    robot may serve any of them.

    Each offer's robot is the idle robot of least estimated work that may serve it (one of its
    `passed_over` only when no other may); of those pairs the dispatcher takes an overdue offer
    first (the oldest), else the one of least estimated work, the oldest on a tie.  Over a
    window of offers this is the greedy task assignment of lifelong MAPF (each free robot the
    task nearest to it); over one offer, the strict oldest-first rule.

    Parameters
    ----------
    scene : Scene
        The scene (its workspaces place the docks).
    offers : sequence of Offer
        The orders the dispatcher may give now, oldest first.
    idle : sequence of (str, (float, float))
        The idle robots and where they stand (mm).

    Returns
    -------
    tuple of (int, str) or None
    """
    best: tuple[tuple[bool, float, int], str] | None = None
    for k, offer in enumerate(offers):
        found = _least_work(scene, offer, idle)
        if found is None:
            continue
        work, robot = found
        key = (not offer.overdue, 0.0 if offer.overdue else work, k)
        if best is None or key < best[0]:
            best = (key, robot)
    return None if best is None else (best[0][2], best[1])


def window_size(reveal: float, robots: int) -> int:
    """How many of the oldest orders the dispatcher chooses among: ``ceil(reveal * robots)``,
    at least one (``reveal`` orders per robot, the League of Robot Runners' ``numTasksReveal``).

    Parameters
    ----------
    reveal : float
        Orders per robot (>= 0).
    robots : int
        Robots in the fleet.
    """
    return max(1, math.ceil(reveal * robots))


def _least_work(
    scene: Scene, offer: Offer, idle: Sequence[tuple[str, Sequence[float]]]
) -> tuple[float, str] | None:
    """The idle robot of least work for `offer`, with that work (mm); a robot it passed over
    only when no other idle robot may serve it; None when none may."""
    # the work: L1 from the robot to the goods, then on to the nearest of the order's docks
    goods = offer.goods
    onward = _l1(goods, scene.workspaces[_dock(scene, offer.order, goods)].center)  # the same for every robot
    work = [(_l1(at, goods) + onward, rid) for rid, at in idle if rid in offer.order.by]
    fresh = [w for w in work if w[1] not in offer.passed_over]
    return min(fresh or work) if work else None
