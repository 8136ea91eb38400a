"""What a lifelong run reports: throughput, each order's wait, utilisation, safety, the trace.

:class:`FleetResult` is the value :func:`cosmop.lifelong.run_fleet` returns.  Its summary
(:data:`RUN_FORMAT`, what ``cosmop run --summary`` writes) holds the orders (released,
delivered, lost, and each one's record), the deliveries per hour, the waits from release to
delivery (p50, p95, max), each robot's utilisation (the share of the run it served an order),
failures, the dispatcher's log, messages, replans and contacts.  Each delivered order's word
(the events the robots did with its goods, :attr:`OrderRecord.word`) is checked against its
delivery mission (:attr:`OrderRecord.as_ordered`).  Its trace is a
``cosmop.trace/1`` file (:mod:`cosmop.traces`), so ``cosmop view`` and ``cosmop export`` read it;
:meth:`FleetResult.plot` draws the deliveries over time.  Units: mm, degrees, seconds.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from cosmop.events import Event
from cosmop.io import write_atomic
from cosmop.missions.mission import GlobalMission
from cosmop.scene import Delivery, Mission, Scenario, Scene
from cosmop.sim.result import Contact, Message, frames_trace
from cosmop.traces import Trace
from cosmop.units import INTERNAL_UNITS

if TYPE_CHECKING:
    from cosmop.lifelong.dispatch import OrderState
    from cosmop.sim.world import World

__all__ = ["RUN_FORMAT", "FleetResult", "OrderRecord"]

RUN_FORMAT = "cosmop.run/1"
"""The ``format`` of a lifelong run's summary."""


@dataclass(frozen=True)
class OrderRecord:
    """One order and what became of it.

    Attributes
    ----------
    index : int
        Its place in the stream.
    object : str
    at : float
        Released, s.
    to : tuple of str
        The docks it may go to.
    robot : str or None
        The robot it was last given to.
    assigned, delivered : float or None
        When a robot took it and when its goods lay in the dock, s.
    lost : str or None
        Why it will never be delivered.
    refused : str or None
        Its last refused hand-over: which robot, when and why (why a pending order waits).
    by : tuple of str
        The robots that may serve it.
    word : tuple of Event
        What the robots did with its goods from its release to its delivery, in time order
        (picks and drops of its object, as the simulated world recorded them).
    """

    index: int
    object: str
    at: float
    to: tuple[str, ...]
    robot: str | None
    assigned: float | None
    delivered: float | None
    lost: str | None
    refused: str | None = None
    by: tuple[str, ...] = ()
    word: tuple[Event, ...] = ()

    @property
    def wait(self) -> float | None:
        """Release to delivery, s."""
        return None if self.delivered is None else self.delivered - self.at

    @property
    def as_ordered(self) -> bool | None:
        r"""Whether the order was served as ordered: its :attr:`word` is a complete word of its
        delivery mission (None while it is not delivered).

        The delivery mission is the deliveries form of the order,
        :math:`K = \{\mathit{pick}(r, o)\,\mathit{drop}(r, o, w) : r \in by, w \in to\}`
        (:meth:`cosmop.missions.mission.GlobalMission.from_mission`): the goods picked once,
        by a robot that may serve the order, and dropped by the same robot in one of its docks,
        with nothing else done with them.
        """
        if self.delivered is None:
            return None
        # only the allowed robots that took part: the others' factors see the empty word, which
        # they accept, and a robot the order does not allow has no events in the alphabet
        robots = tuple(r for r in self.by if any(r in e.owners for e in self.word))
        if not robots:
            return False
        mission = Mission(deliveries=(Delivery(self.object, self.to, robots),))
        language = GlobalMission.from_mission(mission, robots)
        return language.is_complete_word([e.name for e in self.word])

    def to_dict(self) -> dict[str, Any]:
        """The record as the summary writes it."""
        rounded = {
            k: None if v is None else round(v, 3)
            for k, v in (("assigned", self.assigned), ("delivered", self.delivered))
        }
        return {
            "index": self.index,
            "object": self.object,
            "at": self.at,
            "to": list(self.to),
            "robot": self.robot,
            **rounded,
            "lost": self.lost,
            "refused": self.refused,
            "by": list(self.by),
            "word": [e.name for e in self.word],
            "as_ordered": self.as_ordered,
        }


@dataclass(frozen=True)
class FleetResult:
    """The outcome of a lifelong run (module docstring).

    Attributes
    ----------
    scenario : str
    until : float
        Simulated seconds the run lasted.
    orders : tuple of OrderRecord
        Every order of the stream (those released after `until` included, never released).
    utilisation : Mapping[str, float]
        Per robot, the share of the run it served an order (0 to 1).
    failures : Mapping[str, Mapping]
        Per failed robot: when (``t``), where it came to rest (``at``), what it carries,
        whether the others could be ordered around it (``recoordinated``, ``why`` not), the
        robots re-planned around it for that (``replanned``) and those whose home it stands on
        (``homes_taken``: they stay where their plans end from then on).
    dispatch_log : tuple of Mapping
        Every hand-over tried: ``t``, ``order``, ``robot``, ``accepted``, ``why`` not,
        ``wall_s``, the wall time it took (plan, coordinate, check), s, and ``plan_wall_s``, the
        part of it that planned the robot's mission (the rest ordered it with the others).
    contacts : tuple of Contact
    messages : tuple of Message
    replans : int
        Replans of stalled robots accepted.
    frames : Mapping[str, ndarray]
        The per-cycle arrays (:class:`cosmop.sim.result.SimResult`'s).
    robot_ids, human_ids, object_ids : tuple of str
    dt : float
    scene : Scene or None
    interrupted : bool
        Whether Ctrl-C ended the run before its time (`until` is then the time reached).
    reorders : tuple of Mapping
        Every robot whose conflicts were ordered again while it stood for a message: ``t``,
        ``robot``, ``waited_s``, ``due_in_s`` (when its message was expected, the order kept),
        ``accepted``, ``why`` not, ``messages`` added, ``due_after_s`` (when it is expected after;
        ``None``: it waits no more), ``shortened`` (by ``reorder_after`` seconds, or to within
        them), ``wall_s``.
    window : int
        Orders the dispatcher chose among at a time (``FleetSettings.reveal`` times the robots).
    """

    scenario: str
    until: float
    orders: tuple[OrderRecord, ...]
    utilisation: Mapping[str, float]
    failures: Mapping[str, Mapping[str, Any]]
    dispatch_log: tuple[Mapping[str, Any], ...]
    contacts: tuple[Contact, ...]
    messages: tuple[Message, ...]
    replans: int
    frames: Mapping[str, np.ndarray] = field(repr=False)
    robot_ids: tuple[str, ...] = ()
    human_ids: tuple[str, ...] = ()
    object_ids: tuple[str, ...] = ()
    dt: float = 0.1
    scene: Scene | None = field(default=None, repr=False, compare=False)
    interrupted: bool = False
    reorders: tuple[Mapping[str, Any], ...] = ()
    window: int = 1

    @classmethod
    def of(
        cls,
        scenario: Scenario,
        world: World,
        frames: Mapping[str, np.ndarray],
        states: Sequence[OrderState],
        busy: Mapping[str, float],
        failed: Mapping[str, Mapping[str, Any]],
        log: Sequence[Mapping[str, Any]],
        *,
        reorders: Sequence[Mapping[str, Any]] = (),
        interrupted: bool = False,
        window: int = 1,
    ) -> FleetResult:
        """The result of a finished run (:func:`cosmop.lifelong.run_fleet` calls it).

        Parameters
        ----------
        scenario : Scenario
            The scenario that was run.
        world : World
            The simulation at the end of the run.
        frames : Mapping of str to numpy.ndarray
            The recorded frames (:meth:`cosmop.sim.recording.Recorder.frames`).
        states : sequence of OrderState
            What became of each order, in stream order.
        busy : Mapping of str to float
            Per robot, the time it served orders, s.
        failed : Mapping of str to Mapping
            Per failed robot, its record (``t``, ``at``, ``carrying``, ``homes_taken``,
            ``recoordinated``, ``why``, ``replanned``).
        log : sequence of Mapping
            The dispatcher's log, one record per plan handed over or refused.
        reorders : sequence of Mapping
            One record per robot whose conflicts were ordered again while it waited.
        interrupted : bool
            Whether Ctrl-C ended the run before its time.
        window : int
            Orders the dispatcher chose among at a time.

        Returns
        -------
        FleetResult
        """
        orders = tuple(
            OrderRecord(
                s.index,
                s.order.object,
                s.order.at,
                s.order.to,
                s.served_by,
                s.assigned,
                s.delivered,
                s.lost,
                s.refused,
                s.order.by,
                _word(world.events, s),
            )
            for s in states
        )
        span = max(world.t, 1e-9)
        return cls(
            scenario=scenario.name,
            until=world.t,
            orders=orders,
            utilisation={rid: round(min(1.0, busy[rid] / span), 4) for rid in world.robot_ids},
            failures=dict(failed),
            dispatch_log=tuple(log),
            reorders=tuple(reorders),
            window=window,
            contacts=tuple(world.contacts),
            messages=tuple(world.messages),
            replans=world.replans,
            frames=frames,
            robot_ids=world.robot_ids,
            human_ids=world.human_ids,
            object_ids=world.object_ids,
            dt=world.dt,
            scene=scenario.scene,
            interrupted=interrupted,
        )

    # -- what the operator watches ---------------------------------------------------------------

    @property
    def released(self) -> int:
        """Orders released during the run."""
        return sum(1 for o in self.orders if o.at <= self.until)

    @property
    def delivered(self) -> int:
        return sum(1 for o in self.orders if o.delivered is not None)

    @property
    def lost(self) -> int:
        """Orders that will never be delivered (a robot failed carrying the goods, no plan)."""
        return sum(1 for o in self.orders if o.lost is not None)

    @property
    def deliveries_per_hour(self) -> float:
        return self.delivered * 3600.0 / max(self.until, 1e-9)

    @property
    def contacts_while_moving(self) -> int:
        return sum(1 for c in self.contacts if c.moving)

    @property
    def not_as_ordered(self) -> tuple[OrderRecord, ...]:
        """The delivered orders whose word is not a word of their delivery mission
        (:attr:`OrderRecord.as_ordered`; empty when every delivery kept its order)."""
        return tuple(o for o in self.orders if o.as_ordered is False)

    def wait_s(self) -> dict[str, float | None]:
        """Release to delivery of the delivered orders, s: median, 95th percentile, maximum."""
        return _spread([o.wait for o in self.orders if o.wait is not None])

    def handover_wall_s(self) -> dict[str, float | None]:
        """Wall time of the hand-overs tried (plan, coordinate, check), s: median, 95th
        percentile, maximum.  The only figures of the result that depend on the machine."""
        return _spread([e["wall_s"] for e in self.dispatch_log if e.get("wall_s") is not None])

    def summary(self) -> dict[str, Any]:
        """The ``cosmop.run/1`` summary (what ``cosmop run --summary`` writes)."""
        return {
            "format": RUN_FORMAT,
            "scenario": self.scenario,
            "units": dict(INTERNAL_UNITS),
            "until_s": round(self.until, 6),
            "interrupted": self.interrupted,
            "orders": {
                "released": self.released,
                "delivered": self.delivered,
                "lost": self.lost,
                "pending": self.released - self.delivered - self.lost,
            },
            "deliveries_per_hour": round(self.deliveries_per_hour, 3),
            "dispatch_window": self.window,
            "as_ordered": {"checked": self.delivered, "broken": len(self.not_as_ordered)},
            "wait_s": self.wait_s(),
            "handover_wall_s": self.handover_wall_s(),
            "utilisation": dict(self.utilisation),
            "failures": {rid: dict(f) for rid, f in self.failures.items()},
            "contacts": len(self.contacts),
            "contacts_while_moving": self.contacts_while_moving,
            "messages": len(self.messages),
            "replans": self.replans,
            "reorders": {
                "tried": len(self.reorders),
                "accepted": sum(1 for r in self.reorders if r["accepted"]),
                "shortened": sum(1 for r in self.reorders if r.get("shortened")),
                "wall_s": _spread([r["wall_s"] for r in self.reorders]),
            },
            "order_log": [o.to_dict() for o in self.orders],
            "dispatch_log": [dict(e) for e in self.dispatch_log],
            "reorder_log": [dict(r) for r in self.reorders],
            "contact_log": [c.to_dict() for c in self.contacts],
        }

    def save_summary(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`summary` as JSON, atomically.

        Parameters
        ----------
        path : str or os.PathLike
            The JSON file to write.
        """
        write_atomic(path, json.dumps(self.summary(), indent=2) + "\n")

    def trace(self) -> Trace:
        """The run as a ``cosmop.trace/1`` :class:`~cosmop.traces.Trace` (shipped goods absent)."""
        ids = (self.robot_ids, self.human_ids, self.object_ids)
        return frames_trace(self.frames, ids=ids, messages=self.messages, scenario=self.scenario, dt=self.dt)

    def deliveries(self) -> tuple[np.ndarray, np.ndarray]:
        """The delivery times (s, sorted) and the count delivered by each."""
        times = np.sort([o.delivered for o in self.orders if o.delivered is not None])
        return times, np.arange(1, len(times) + 1)

    def plot(self) -> Any:
        """A matplotlib figure of the orders released and delivered over time (the viz extra)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(7, 4), dpi=100)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        released = np.sort([o.at for o in self.orders if o.at <= self.until])
        ax.step(released, np.arange(1, len(released) + 1), where="post", label="released", color="grey")
        times, counts = self.deliveries()
        ax.step(times, counts, where="post", label="delivered", color="tab:blue")
        ax.set_xlim(0, self.until)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("orders")
        ax.set_title(
            f"{self.scenario}: {self.delivered} delivered, {self.deliveries_per_hour:.0f} per hour",
            fontsize=10,
        )
        ax.legend(loc="upper left", frameon=False)
        fig.tight_layout()
        return fig

    def save_plot(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`plot` as a PNG, atomically.

        Parameters
        ----------
        path : str or os.PathLike
            The PNG file to write.
        """
        import io

        buffer = io.BytesIO()
        self.plot().savefig(buffer, format="png")
        write_atomic(path, buffer.getvalue())


def _word(events: Sequence[tuple[float, str, Event]], state: OrderState) -> tuple[Event, ...]:
    """The mission events about `state`'s goods from its release to its delivery (or now)."""
    end = math.inf if state.delivered is None else state.delivered
    return tuple(
        event
        for t, _, event in events
        if event.obj == state.order.object and not event.is_message and state.order.at <= t <= end
    )


def _spread(values: Sequence[float]) -> dict[str, float | None]:
    """Median, 95th percentile and maximum of `values` (None for each when there are none)."""
    if not values:
        return {"p50": None, "p95": None, "max": None}
    p50, p95 = np.percentile(values, [50, 95])
    return {"p50": round(float(p50), 3), "p95": round(float(p95), 3), "max": round(float(max(values)), 3)}
