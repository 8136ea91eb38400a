"""A simulation run as a ROS 2 bag (MCAP storage) with standard messages, for Foxglove, RViz and ``ros2 bag``.

Written with the pure-Python ``rosbags`` library (the ``ros`` extra); no ROS installation is
needed. Frames, units and axes follow REP 103 and REP 105: one fixed frame ``map``, x forward
and y left, metres, radians, orientations as quaternions; each robot's body frame is
``<robot>/base_link``. The topics (message definitions of ROS 2 Jazzy, bag format version 8):

``/tf`` (``tf2_msgs/msg/TFMessage``)
    every drawn frame, ``map`` -> ``<robot>/base_link`` for each robot.
``/<robot>/pose`` (``geometry_msgs/msg/PoseStamped``)
    every drawn frame, the robot's pose in ``map``.
``/<robot>/plan`` (``nav_msgs/msg/Path``)
    once, at the start: the planned path (the initial pose, then every GoTo's pose); when the
    plan file has an itinerary, each pose is stamped with the time the robot is expected to
    reach it (a timed path), else with the start.
``/scene`` (``visualization_msgs/msg/MarkerArray``)
    every scene frame: walls, workspaces, objects, people, robot bodies with their labels and
    what each carries, and an arrow from sender to receiver for 2 s after each message.
``/coordination`` (``std_msgs/msg/String``)
    each message of the run, at the time it was sent, as one JSON object with the trace's keys
    (``t``, ``from``, ``to`` and whatever else the message carries).

Time stamps are the trace's times (s) after ``start`` (default 0, the epoch), so a bag is the
same on every run. Chunks are compressed with zstd, as ``ros2 bag record
--compression-mode storage`` would.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

from cosmop.export.markers import SceneMarkers
from cosmop.io import atomic_path
from cosmop.traces import Trace, as_trace
from cosmop.units import m_from_mm
from cosmop.viz.scene_drawing import ids_with_trace

if TYPE_CHECKING:
    from cosmop.planning.plan_types import PlanSet
    from cosmop.scene import Scene

__all__ = ["BagSummary", "ros_available", "write_bag"]


def ros_available() -> bool:
    """Whether ``rosbags`` (the ``ros`` extra) can be imported."""
    import importlib.util

    return importlib.util.find_spec("rosbags") is not None


@dataclass(frozen=True)
class BagSummary:
    """What :func:`write_bag` wrote.

    Attributes
    ----------
    path : pathlib.Path
        The bag directory (``metadata.yaml`` and ``<name>.mcap``).
    counts : Mapping[str, int]
        Messages per topic.
    start_s, end_s : float
        Time stamps of the first and last message, s.
    size_bytes : int
        Size of the MCAP file.
    """

    path: Path
    counts: Mapping[str, int]
    start_s: float
    end_s: float
    size_bytes: int


class _Ros:
    """The ROS 2 Jazzy message types and small builders of them (lengths in, metres out)."""

    def __init__(self) -> None:
        try:
            from rosbags.typesys import Stores, get_typestore
        except ImportError as exc:
            raise ImportError("ROS 2 bags need rosbags: pip install 'cosmop[ros]'") from exc
        self.store = get_typestore(Stores.ROS2_JAZZY)
        self.t = self.store.types

    def stamp(self, ns: int) -> Any:
        return self.t["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)

    def header(self, ns: int, frame: str = "map") -> Any:
        return self.t["std_msgs/msg/Header"](stamp=self.stamp(ns), frame_id=frame)

    def pose(self, x_mm: float, y_mm: float, heading_deg: float) -> Any:
        """A ``geometry_msgs/Pose`` on the floor: metres, a yaw as a quaternion about z."""
        half = math.radians(heading_deg) / 2
        point = self.t["geometry_msgs/msg/Point"](x=m_from_mm(x_mm), y=m_from_mm(y_mm), z=0.0)
        quat = self.t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(half), w=math.cos(half))
        return self.t["geometry_msgs/msg/Pose"](position=point, orientation=quat)

    def pose_stamped(self, ns: int, pose: Sequence[float]) -> Any:
        return self.t["geometry_msgs/msg/PoseStamped"](header=self.header(ns), pose=self.pose(*pose[:3]))

    def transform(self, ns: int, child: str, pose: Sequence[float]) -> Any:
        p = self.pose(*pose[:3])
        vector = self.t["geometry_msgs/msg/Vector3"](x=p.position.x, y=p.position.y, z=0.0)
        transform = self.t["geometry_msgs/msg/Transform"](translation=vector, rotation=p.orientation)
        return self.t["geometry_msgs/msg/TransformStamped"](
            header=self.header(ns), child_frame_id=child, transform=transform
        )


def _frame_indices(times: Sequence[float], rate: float | None) -> list[int]:
    """Indices of the frames (at `times`, s) to write: all, or about `rate` per second (the last always)."""
    if rate is None or len(times) < 2:
        return list(range(len(times)))
    chosen, next_t = [], -math.inf
    for k, t in enumerate(times):
        if t >= next_t - 1e-9:
            chosen.append(k)
            next_t = t + 1.0 / rate
    if chosen[-1] != len(times) - 1:
        chosen.append(len(times) - 1)
    return chosen


def _ns(t: float, start_ns: int) -> int:
    return start_ns + round(t * 1e9)


def _plan_path(ros: _Ros, scene: Scene, plans: PlanSet, rid: str, ns: int, start_ns: int) -> Any | None:
    """The plan's path, published at `ns`; its poses stamped with their expected times, if any."""
    plan, robot = plans.robots.get(rid), scene.robots.get(rid)
    if plan is None or robot is None:
        return None
    times = plans.itinerary.times.get(rid) if plans.itinerary is not None else None
    stamped = [(ns, robot.pose)] + [
        (_ns(times[k][1], start_ns) if times else ns, step.robot)
        for k, step in enumerate(plan.steps)
        if step.primitive == "GoTo"
    ]
    poses = [ros.pose_stamped(stamp, pose) for stamp, pose in stamped]
    return ros.t["nav_msgs/msg/Path"](header=ros.header(ns), poses=poses)


def _write(
    writer: Any, ros: _Ros, connections: dict[str, Any], counts: dict[str, int], topic: str, ns: int, msg: Any
) -> None:
    if topic not in connections:
        connections[topic] = writer.add_connection(topic, msg.__msgtype__, typestore=ros.store)
        counts[topic] = 0
    writer.write(connections[topic], ns, ros.store.serialize_cdr(msg, msg.__msgtype__))
    counts[topic] += 1


class _Options(TypedDict):
    rate: float | None  # frames per second, None: every frame
    scene_rate: float  # scene marker arrays per second
    start_ns: int  # the stamp of t = 0, ns


def _write_all(
    writer: Any, scene: Scene, trace: Trace, plans: PlanSet | None, options: _Options
) -> dict[str, int]:
    """Write every topic of the bag from `trace`; return the number of messages per topic."""
    ros = _Ros()
    times = trace.t.tolist()
    start_ns = options["start_ns"]
    connections: dict[str, Any] = {}  # topic -> the bag's connection (rosbags' own type)
    counts: dict[str, int] = {}

    def write(topic: str, ns: int, msg: Any) -> None:
        _write(writer, ros, connections, counts, topic, ns, msg)

    def coordination(message: Mapping[str, Any]) -> None:
        text = ros.t["std_msgs/msg/String"](data=json.dumps(dict(message), sort_keys=True))
        write("/coordination", _ns(float(message["t"]), start_ns), text)

    robot_ids = ids_with_trace(scene.robots, trace, "robots")
    first_ns = _ns(times[0], start_ns)
    if plans is not None:
        for rid in robot_ids:
            path = _plan_path(ros, scene, plans, rid, first_ns, start_ns)
            if path is not None:
                write(f"/{rid}/plan", first_ns, path)
    markers = SceneMarkers(ros, scene, trace, robot_ids)
    messages = sorted(trace.messages, key=lambda m: float(m["t"]))
    pending = 0
    scene_next = -math.inf
    for k in _frame_indices(times, options["rate"]):
        t = times[k]
        ns = _ns(t, start_ns)
        while pending < len(messages) and float(messages[pending]["t"]) <= t + 1e-9:
            coordination(messages[pending])
            pending += 1
        robots = trace.robots_at(k)
        transforms = [ros.transform(ns, f"{rid}/base_link", s.pose) for rid, s in robots.items()]
        write("/tf", ns, ros.t["tf2_msgs/msg/TFMessage"](transforms=transforms))
        for rid, state in robots.items():
            write(f"/{rid}/pose", ns, ros.pose_stamped(ns, state.pose))
        if t >= scene_next - 1e-9 or k == len(times) - 1:
            write("/scene", ns, markers.array(ns, k))
            scene_next = t + 1.0 / options["scene_rate"]
    for message in messages[pending:]:  # sent after the last frame drawn
        coordination(message)
    return counts


def write_bag(
    scene: Scene,
    trace: Trace | Mapping[str, Any],
    path: str | os.PathLike[str],
    *,
    plans: PlanSet | None = None,
    rate: float | None = None,
    scene_rate: float = 5.0,
    start: float = 0.0,
) -> BagSummary:
    """Write a simulation trace as a ROS 2 bag directory (MCAP storage), atomically.

    Parameters
    ----------
    scene : Scene
        The scene simulated (walls, workspaces, sizes; mm).
    trace : Trace or Mapping
        The run (:func:`cosmop.traces.load_trace` or :meth:`cosmop.sim.SimResult.trace`), or its
        ``cosmop.trace/1`` JSON.  Poses in mm and degrees, times in s.
    path : str or os.PathLike
        The bag directory to create; it must not exist (``ros2 bag`` never overwrites either).
    plans : PlanSet, optional
        The plans executed: each robot's ``/<robot>/plan``.
    rate : float, optional
        Poses and ``/tf`` per second (Hz); default every frame of the trace.
    scene_rate : float, optional
        ``/scene`` marker arrays per second (Hz; default 5).
    start : float, optional
        Time stamp of the trace's time 0, seconds since the epoch (default 0).

    Returns
    -------
    BagSummary

    Raises
    ------
    FileExistsError
        If `path` exists.
    cosmop.traces.TraceError
        If `trace` is a mapping without the ``cosmop.trace/1`` shape.
    ImportError
        If ``rosbags`` is missing (``pip install 'cosmop[ros]'``).
    """
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

    for name, value in (("rate", rate), ("scene_rate", scene_rate)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number of messages per second, got {value!r}")
    trace = as_trace(trace)
    target = Path(path)
    if target.exists():
        raise FileExistsError(f"{target} exists; a bag is written into a new directory")
    options: _Options = {"rate": rate, "scene_rate": scene_rate, "start_ns": round(start * 1e9)}
    with atomic_path(target) as bag:  # named as the target: the MCAP file is named after its folder
        writer = Writer(bag, version=8, storage_plugin=StoragePlugin.MCAP)
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        with writer:
            counts = _write_all(writer, scene, trace, plans, options)
    times = trace.t.tolist() + [float(m["t"]) for m in trace.messages]
    return BagSummary(
        path=target,
        counts=dict(counts),
        start_s=start + min(times),
        end_s=start + max(times),
        size_bytes=(target / f"{target.name}.mcap").stat().st_size,
    )
