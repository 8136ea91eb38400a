"""What a simulation run is given and gives back: settings, messages, contacts, the result.

:class:`SimResult` is the outcome of :func:`cosmop.sim.simulate`; it writes the
``cosmop.sim/1`` summary (:data:`SIM_FORMAT`) and the ``cosmop.trace/1`` trace
(:class:`cosmop.traces.Trace`, the one trace :mod:`cosmop.traces` writes and reads back).
Units: mm, mm/s, degrees and seconds (:data:`cosmop.units.INTERNAL_UNITS`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cosmop.control.dwa import DwaSettings
from cosmop.events import Event
from cosmop.io import write_atomic
from cosmop.planning.plan_types import PRIMITIVES, PlanSet
from cosmop.scene import Scenario, Scene
from cosmop.sim.delays import Delays
from cosmop.sim.realised_times import StepTimes
from cosmop.traces import Trace
from cosmop.units import INTERNAL_UNITS

__all__ = [
    "DEFAULT_TIME_LIMIT",
    "FRAME_PRIMITIVES",
    "SIM_FORMAT",
    "Contact",
    "Message",
    "SimResult",
    "SimSettings",
    "drop_holds",
    "frames_trace",
]

SIM_FORMAT = "cosmop.sim/1"
"""The ``format`` of a simulation summary (``summary.json``)."""

FRAME_PRIMITIVES = (None, *(str(p) for p in PRIMITIVES))
"""What the ``primitive`` frame array's indices stand for (0: none, the robot has finished)."""


DEFAULT_TIME_LIMIT = 900.0
"""The least time limit of a run when none is set, simulated s (:class:`SimSettings`)."""


@dataclass(frozen=True)
class SimSettings:
    """How the simulation runs (the robots' limits come from the scenario's ``dynamics``).

    Attributes
    ----------
    max_time : float or None
        Simulated seconds after which an unfinished run stops (``completed`` false).  ``None``
        (the default): three times the makespan the plans expect, and at least 900 s -- a
        team that waits for each other's messages often runs half as long again as planned,
        and a long mission must not be cut off for being long.
    goal_tolerance, pass_tolerance : float
        Distance (mm) within which a final / intermediate GoTo waypoint counts as reached.
    heading_tolerance : float
        Degrees within which a final waypoint's heading counts as reached.
    dock_tolerance : float
        Largest offset (mm) from a docking pose that the docking controller closes; farther
        away, the robot first drives there.
    dock_speed : float
        Speed of the docking controller, mm/s (at most one cycle's braking, :math:`b\\varepsilon`).
    reach : float
        How far (mm) the gripper reaches: a pick-up whose docking is blocked closer than this
        to its pose still picks the object up.  A drop waits for the exact pose: the object
        goes exactly where the plan puts it (in its workspace).
    handling_time : float
        Seconds the gripper needs to pick up or drop off.
    leave_gap : float
        Gap (mm) to walls and resting objects that a robot creeps out to, straight, before it
        drives off a pose that touches them (a plan's motion leaves such a pose to at least
        :data:`~cosmop.planning.specification.MOTION_MARGIN`).
    detour_time : float
        Seconds without progress after which a driving robot plans its global path again,
        around the robots that block it and have the right of way (less path left).
    stall_time : float
        Seconds without ``stall_progress`` mm of progress after which a driving robot replans.
    stall_progress : float
        Progress (mm of path) that resets the stall clock.
    replan : bool
        Whether stalled robots replan (else they keep trying).
    sense_range : float
        Robots and people within this gap (mm) of a stalled robot are added to its scene.
    max_horizon, rlimit : int
        Bounds of the solver when replanning.
    dwa : DwaSettings
        The dynamic window's search.
    neighbourhood : bool
        Give each robot's dynamic window only the walls and bodies within its reach
        (:mod:`cosmop.control.neighbourhood`; the commands are the same, the cost linear in the
        team).  ``False`` scores everything against everything, to compare.
    delays : Delays or None
        Robots stop at random (:mod:`cosmop.sim.delays`), drawn from the run's seed; ``None``
        (the default): never.
    """

    max_time: float | None = None
    goal_tolerance: float = 15.0
    pass_tolerance: float = 150.0
    heading_tolerance: float = 2.0
    dock_tolerance: float = 80.0
    dock_speed: float = 50.0
    reach: float = 20.0
    handling_time: float = 1.0
    leave_gap: float = 10.0
    detour_time: float = 3.0
    stall_time: float = 12.0
    stall_progress: float = 50.0
    replan: bool = True
    sense_range: float = 800.0
    max_horizon: int = 12
    rlimit: int = 10_000_000
    dwa: DwaSettings = field(default_factory=DwaSettings)
    neighbourhood: bool = True
    delays: Delays | None = None


@dataclass(frozen=True)
class Message:
    """A message on the bus: ``event`` from ``sender`` to ``receiver`` at time ``t`` (s).

    ``object`` is the object of an ``away`` answer (``None`` for a ``msg``).
    """

    t: float
    sender: str
    receiver: str
    object: str | None
    event: str

    def to_dict(self) -> dict[str, Any]:
        """The message as the summary and the trace write it (``from``, ``to``)."""
        return {
            "t": self.t,
            "from": self.sender,
            "to": self.receiver,
            "object": self.object,
            "event": self.event,
        }


@dataclass(frozen=True)
class Contact:
    """A contact episode: `robot`'s square touched `other` from time `t` on.

    ``moving`` is true if the robot had a translational speed above zero at any cycle of the
    episode -- what passive safety rules out.
    """

    t: float
    robot: str
    other: str
    moving: bool

    def to_dict(self) -> dict[str, Any]:
        """The contact as the summary's ``contact_log`` writes it."""
        return {"t": self.t, "robot": self.robot, "other": self.other, "moving": self.moving}


@dataclass(frozen=True)
class SimResult:
    """The outcome of :func:`~cosmop.sim.simulation.simulate`: status, statistics, the whole trace.

    Attributes
    ----------
    scenario : str
    completed : bool
        Every robot executed its whole plan before ``max_time``.
    sim_time_s, wall_time_s : float
        Simulated and real seconds.
    cycles : int
    dt : float
        The control cycle, s.
    contacts : tuple of Contact
    replans, replan_attempts : int
        Successful replans and all attempts.
    messages : tuple of Message
    objects : Mapping[str, (tuple of float, str or None)]
        Final ``(position (x, y), carried_by or None)`` of every object.
    robots : Mapping[str, ((float, float, float), float)]
        Final ``(pose (x, y, heading deg), distance_mm)`` of every robot.
    finished : Mapping[str, bool]
        Whether each robot executed its whole plan.
    frames : Mapping[str, ndarray]
        Per cycle arrays: ``t`` (n,), ``pose`` (n, R, 3; degrees), ``v`` (n, R), ``w``
        (n, R; deg/s), ``carrying`` (n, R; object index or -1), ``primitive`` (n, R; index in
        :data:`FRAME_PRIMITIVES`), ``waiting`` (n, R), ``delayed`` (n, R: a delay has stopped
        the robot), ``awaits`` and ``yields_to`` (n, R; objects: the message a robot waits for,
        the robot or person it gives way to, or None; :mod:`cosmop.sim.recording`), ``humans``
        (n, H, 2), ``objects`` (n, O, 2); lengths in mm, speeds in mm/s.
    robot_ids, human_ids, object_ids : tuple of str
    replan_log : tuple of dict
        Every replan attempt: ``t``, ``robot``, ``accepted`` (its new plan was ordered with the
        others' again, :mod:`cosmop.sim.recoordinate`), ``why`` not, the ``messages`` added, and
        for an accepted one its ``route`` (:func:`cosmop.sim.replan.route`).
    events : tuple of (float, str, str)
        ``(t, robot, event)``: the mission events and messages as the robots realised them --
        a pick when the gripper closes, a drop when the object lies in its workspace, a return
        when the robot ends its plan at home, a message when it is sent (and again when it is
        received).
    added : tuple of str
        The events of the tasks the planner added (:attr:`PlanSet.added
        <cosmop.planning.plan_types.PlanSet.added>`): goods moved out of a robot's way.
    steps : Mapping[str, tuple of StepTimes]
        Every robot's steps with their planned (the plan set's itinerary) and realised start
        and end (:mod:`cosmop.sim.realised_times`).
    delays : Delays or None
        The delays the run drew (``SimSettings.delays``); ``None``: none.
    stops : Mapping[str, tuple of (float, float)]
        Per robot, the delays that stopped it: ``(time, seconds)``, s (a stop the run's end cut
        short counts the seconds it lasted).
    scene : Scene or None
        The scene the run happened in (for :meth:`plot`).
    plans : PlanSet or None
        The plans it executed (for :meth:`plot`).
    """

    scenario: str
    completed: bool
    sim_time_s: float
    wall_time_s: float
    cycles: int
    dt: float
    contacts: tuple[Contact, ...]
    replans: int
    replan_attempts: int
    messages: tuple[Message, ...]
    objects: Mapping[str, tuple[tuple[float, ...], str | None]]
    robots: Mapping[str, tuple[tuple[float, float, float], float]]
    frames: Mapping[str, np.ndarray] = field(repr=False)
    finished: Mapping[str, bool] = field(default_factory=dict)
    robot_ids: tuple[str, ...] = ()
    human_ids: tuple[str, ...] = ()
    object_ids: tuple[str, ...] = ()
    events: tuple[tuple[float, str, str], ...] = ()
    added: tuple[str, ...] = ()
    replan_log: tuple[dict[str, Any], ...] = ()
    steps: Mapping[str, tuple[StepTimes, ...]] = field(default_factory=dict)
    delays: Delays | None = None
    stops: Mapping[str, tuple[tuple[float, float], ...]] = field(default_factory=dict)
    scene: Scene | None = field(default=None, repr=False, compare=False)
    plans: PlanSet | None = field(default=None, repr=False, compare=False)

    def plot(self, index: int = -1, *, title: str | None = None) -> Any:
        """A matplotlib figure of the run at frame `index`, by default its end: every robot's
        path driven and planned, where it stands and why, the people (the ``viz`` extra;
        :func:`cosmop.viz.draw_frame`).

        Parameters
        ----------
        index : int, default -1
            The frame to draw.
        title : str, optional
            The figure's title.

        Raises
        ------
        ValueError
            If the result does not know its scene (a result built by hand without one).
        """
        if self.scene is None:
            raise ValueError("this SimResult has no scene to draw: give SimResult(scene=...)")
        from cosmop.viz.animation import draw_frame  # matplotlib only when a picture is asked for

        return draw_frame(self.scene, self.trace(), index, plans=self.plans, title=title)

    def executed_word(self) -> tuple[str, ...]:
        """The mission events the run realised, in time order (messages and the events of tasks
        the planner added, :attr:`added`, left out: no mission names them)."""
        skip = set(self.added)
        return tuple(
            name
            for _, _, name in sorted(self.events)
            if not name.startswith(("msg(", "away(")) and name not in skip
        )

    @property
    def makespan(self) -> dict[str, float | None]:
        """When the team was expected to be done (``planned``, s) and was (``realised``; ``None``
        for a run that did not complete)."""
        planned = [r.planned[1] for rows in self.steps.values() for r in rows if r.planned is not None]
        realised = [r.realised[1] for rows in self.steps.values() for r in rows if r.realised is not None]
        return {
            "planned": round(max(planned), 3) if planned else None,
            "realised": round(max(realised, default=0.0), 3) if self.completed else None,
        }

    def delay_report(self) -> dict[str, Any] | None:
        """The delays of the run (``None`` when it drew none): the model, how many stops and how
        many seconds stopped in all and per robot, and every stop.

        The makespan the delays cost is not in one run: it is the realised makespan against
        that of the same seed without delays (``benchmarks/sweep_delays.py`` compares them).
        """
        if self.delays is None:
            return None
        robots = {
            rid: {"count": len(stops), "seconds": round(sum(s for _, s in stops), 3)}
            for rid, stops in self.stops.items()
        }
        log = sorted((t, rid, s) for rid, stops in self.stops.items() for t, s in stops)
        return {
            **self.delays.to_dict(),
            "count": sum(r["count"] for r in robots.values()),
            "seconds": round(sum(s for _, _, s in log), 3),
            "robots": robots,
            "log": [{"t": round(t, 6), "robot": rid, "seconds": round(s, 3)} for t, rid, s in log],
        }

    @property
    def contacts_while_moving(self) -> int:
        """Contact episodes in which the robot was moving (0 under passive safety)."""
        return sum(1 for c in self.contacts if c.moving)

    def summary(self) -> dict[str, Any]:
        """The ``cosmop.sim/1`` summary (what ``--summary`` writes)."""
        return {
            "format": SIM_FORMAT,
            "scenario": self.scenario,
            "units": dict(INTERNAL_UNITS),
            "completed": self.completed,
            "sim_time_s": round(self.sim_time_s, 6),
            "wall_time_s": round(self.wall_time_s, 6),
            "cycles": self.cycles,
            "contacts": len(self.contacts),
            "contacts_while_moving": self.contacts_while_moving,
            "replans": self.replans,
            "replan_attempts": self.replan_attempts,
            "messages": [m.to_dict() for m in self.messages],
            "events": [{"t": t, "robot": r, "event": e} for t, r, e in self.events],
            "replan_log": list(self.replan_log),
            "makespan": self.makespan,
            "delays": self.delay_report(),
            "itinerary": {rid: [row.to_dict() for row in rows] for rid, rows in self.steps.items()},
            "objects": {
                oid: {"position": [round(p[0], 3), round(p[1], 3)], "carried_by": by}
                for oid, (p, by) in self.objects.items()
            },
            "robots": {
                rid: {"pose": [round(v, 3) for v in pose], "distance_mm": round(dist, 3)}
                for rid, (pose, dist) in self.robots.items()
            },
            "contact_log": [c.to_dict() for c in self.contacts],
        }

    def trace(self) -> Trace:
        """The run as a :class:`~cosmop.traces.Trace`, one frame per cycle (what ``--trace`` writes).

        Its lengths, degrees and speeds are rounded to 0.001 and its times to 1 µs, as in its
        file: the trace of a run and the trace read back from its file are the same, and so are
        the pictures drawn from either.  The integer and boolean arrays are :attr:`frames`'
        own, as read-only views.
        """
        return frames_trace(
            self.frames,
            ids=(self.robot_ids, self.human_ids, self.object_ids),
            messages=self.messages,
            scenario=self.scenario,
            dt=self.dt,
            delays=self.delays is not None,  # (a run without: as before)
            replans=tuple(
                {"t": r["t"], "robot": r["robot"], "route": r["route"]}
                for r in self.replan_log
                if "route" in r
            ),
        )

    def save_summary(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`summary` as JSON, atomically.

        Parameters
        ----------
        path : str or path-like
            The JSON file to write.
        """
        write_atomic(path, json.dumps(self.summary(), indent=2) + "\n")

    def save_trace(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`trace` as compact JSON, atomically (:meth:`cosmop.traces.Trace.save`).

        Parameters
        ----------
        path : str or path-like
            The JSON file to write.
        """
        self.trace().save(path)

    def objects_in_workspaces(self, scenario: Scenario, plans: PlanSet) -> dict[str, bool]:
        """For every drop event of the plans' missions: is its object in its workspace now?

        Parameters
        ----------
        scenario : Scenario
            The scenario that was run.
        plans : PlanSet
            The plans that were run.
        """
        scene = plans.extend(scenario).scene
        out: dict[str, bool] = {}
        for plan in plans.robots.values():
            for event in plan.mission:
                if event.kind == "drop":
                    assert event.obj is not None  # a drop names its object
                    position, by = self.objects[event.obj]
                    out[event.obj] = by is None and drop_holds(scene, event, position)
        return out


def frames_trace(
    frames: Mapping[str, np.ndarray],
    *,
    ids: tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]],
    messages: Sequence[Message],
    scenario: str,
    dt: float,
    delays: bool = False,
    replans: tuple[Mapping[str, Any], ...] = (),
) -> Trace:
    """The :class:`~cosmop.traces.Trace` of a run's per-cycle arrays (:attr:`SimResult.frames`),
    rounded as its file is.

    Parameters
    ----------
    frames : Mapping[str, ndarray]
        The recorder's arrays (:class:`cosmop.sim.recording.Recorder`).
    ids : (robot ids, human ids, object ids)
    messages : sequence of Message
    scenario : str
    dt : float
        The control cycle, s.
    delays : bool
        Whether the run drew delays (its trace then says which robots a delay stopped).
    replans : tuple of Mapping
        The accepted replans' routes (:attr:`cosmop.traces.Trace.replans`).

    Returns
    -------
    Trace
    """
    f = frames
    robot_ids, human_ids, object_ids = ids
    return Trace(
        t=f["t"],
        robot_ids=robot_ids,
        poses=f["pose"],
        v=f["v"],
        w=f["w"],
        carrying=f["carrying"],
        primitive=f["primitive"],
        primitive_names=FRAME_PRIMITIVES,
        waiting=f["waiting"],
        delayed=f["delayed"] if delays else None,
        awaits=f.get("awaits"),
        yields_to=f.get("yields_to"),
        human_ids=human_ids,
        humans=f["humans"],
        object_ids=object_ids,
        objects=f["objects"],
        messages=tuple(m.to_dict() for m in messages),
        replans=replans,
        scenario=scenario,
        dt=dt,
    ).rounded()


def drop_holds(scene: Scene, event: Event, position: Sequence[float]) -> bool:
    """Whether a ``drop`` `event`'s object, lying at `position` (mm), is in the event's workspace
    (to within 1e-6 mm: a drop lands exactly where the plan puts it).

    Parameters
    ----------
    scene : Scene
        The scene, with the event's object and workspace.
    event : Event
        A ``drop`` event.
    position : sequence of float
        Where the object lies, ``x, y`` mm.
    """
    assert event.obj is not None and event.workspace is not None  # a drop names both
    size = scene.objects[event.obj].size
    return scene.workspaces[event.workspace].holds(position[0], position[1], size, 1e-6)
