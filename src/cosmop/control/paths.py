"""Global paths: short routes with clearance for a square robot among walls and objects.

The robot is an axis-aligned square of half side :math:`h`, so its centre must stay out of the
Minkowski sum of every obstacle with that square (its *configuration-space obstacle*): a wall
segment grows into a hexagon (the convex hull of the squares at its ends) and an object of half
side :math:`k` into the square of half side :math:`k + h`.  Shortest paths among polygons run
through their corners, so the route is found in the *visibility graph* of those corners plus
the start and the goal (Lozano-Pérez and Wesley), searched with A* that tests a corner's edges
only when it reaches that corner (:func:`_a_star`).  Corners are also
offered pushed out by the wanted clearance, and edges that pass closer than it cost more, so
the route keeps its distance where there is room and squeezes through where it must; touching
is allowed (a docking pose touches its object).  Units are millimetres.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import Polygon

from cosmop.control.geometry import segment_bounds
from cosmop.squares import square, swept_square

__all__ = ["GlobalPath", "plan_path", "straight_path"]

Point = tuple[float, float]


@dataclass(frozen=True)
class GlobalPath:
    """A polyline from start to goal that the robot's square can follow.

    Attributes
    ----------
    points : tuple of (float, float)
        The vertices, start first and goal last (mm).
    margin : float
        The least Euclidean clearance (mm) of the route from the grown obstacles, capped at the
        clearance wanted.
    length : float
        Total length (mm).
    """

    points: tuple[Point, ...]
    margin: float

    @property
    def length(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.points, self.points[1:], strict=False))

    @cached_property
    def _segments(
        self,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Each segment's start, direction and length, and the length with 1 for a zero one
        (made once: a robot asks for its look-ahead point every cycle)."""
        pts = np.asarray(self.points, dtype=float)
        a, d = pts[:-1], pts[1:] - pts[:-1]
        lengths = np.hypot(d[:, 0], d[:, 1])
        return a, d, lengths, np.where(lengths > 0, lengths, 1.0)

    @cached_property
    def _projecting(self) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Each segment's squared length (1 for a zero one) and whether it has a length."""
        _, _, lengths, safe_len = self._segments
        return safe_len**2, lengths > 0

    def _projection(self, position: Point) -> tuple[int, NDArray[np.float64]]:
        """The segment nearest `position` and, for every segment, where along it (0..1) the
        point nearest `position` lies."""
        a, d, _, _ = self._segments
        squared, long = self._projecting
        t = ((position[0] - a[:, 0]) * d[:, 0] + (position[1] - a[:, 1]) * d[:, 1]) / squared
        t = np.minimum(np.maximum(np.where(long, t, 0.0), 0.0), 1.0)  # np.clip, cheaper
        if len(t) == 1:  # one segment: it is the nearest (most drives are a straight line)
            return 0, t
        proj = a + t[:, None] * d
        return int(np.argmin(np.hypot(proj[:, 0] - position[0], proj[:, 1] - position[1]))), t

    def beyond(self, position: Point, distance: float) -> tuple[Point | None, tuple[Point, ...]]:
        """The point `distance` mm further along the path than `position`'s projection, and the
        vertices after it; ``(None, ())`` when the path ends before (mm).

        Parameters
        ----------
        position : (float, float)
            Where the robot is, mm (anywhere: it is projected onto the path).
        distance : float
            How far beyond the projection, mm.
        """
        if len(self.points) == 1:
            return None, ()
        a, d, lengths, _ = self._segments
        i, t = self._projection(position)
        along = distance + t[i] * lengths[i]  # from the start of segment i
        for k in range(i, len(lengths)):
            if along < lengths[k]:
                s = along / lengths[k]
                point = (float(a[k, 0] + s * d[k, 0]), float(a[k, 1] + s * d[k, 1]))
                return point, self.points[k + 1 :]
            along -= lengths[k]
        return None, ()

    def lookahead(self, position: Point, distance: float, corner: float = 30.0) -> tuple[Point, float]:
        """The point up to `distance` mm further along the path than `position`'s projection.

        The point does not pass the next vertex unless that vertex is within `corner` mm:
        cutting a corner would aim the robot into the obstacle the path goes around.

        Returns the point and the length of the path left after the projection (mm).

        Parameters
        ----------
        position : (float, float)
            Where the robot is, mm (anywhere: it is projected onto the path).
        distance : float
            The most the point lies beyond the projection, mm.
        corner : float, default 30.0
            How near (mm) the next vertex must be for the point to pass it.
        """
        if len(self.points) == 1:
            return self.points[0], 0.0
        a, d, lengths, _ = self._segments
        i, t = self._projection(position)
        left = float((1.0 - t[i]) * lengths[i] + lengths[i + 1 :].sum())
        budget = distance
        along = t[i] * lengths[i]  # how far into segment i the projection is
        while i < len(lengths):
            ahead = lengths[i] - along
            if budget <= ahead or ahead > corner:
                step = min(budget, ahead)
                s = (along + step) / lengths[i] if lengths[i] > 0 else 1.0
                return (float(a[i, 0] + s * d[i, 0]), float(a[i, 1] + s * d[i, 1])), left
            budget -= ahead
            along = 0.0
            i += 1
        return self.points[-1], left


def _grown(walls: NDArray[np.float64], boxes: NDArray[np.float64], half: float) -> list[Polygon]:
    """Obstacles grown by the robot's square of half side `half` (configuration-space obstacles)."""
    out: list[Polygon] = [swept_square((x1, y1), (x2, y2), 2.0 * half) for x1, y1, x2, y2 in walls]
    out += [square(x, y, 2.0 * (k + half)) for x, y, k in boxes]
    return out


def plan_path(
    start: Point,
    goal: Point,
    half: float,
    walls: NDArray[np.float64],
    boxes: NDArray[np.float64],
    *,
    margin: float = 150.0,
    penalty: float = 3.0,
    squeeze: float = 10.0,
    budget: int = 1_000_000,
) -> GlobalPath | None:
    r"""The shortest route of a square robot's centre from `start` to `goal`, with clearance.

    Nodes are the start, the goal and the corners of the grown obstacles pushed out by 1 mm
    and by `margin`; an edge is a straight segment that does not enter any grown obstacle
    (touching is allowed).  An edge of length :math:`\ell` that passes within clearance
    :math:`c < m` (Euclidean, mm) of the grown obstacles costs
    :math:`\ell\,(1 + p\,(1 - c/m)) + q\,m\,(1 - c/m)`, so the route keeps its distance
    where it can and squeezes through where it must.

    **Near first.**  The search first runs in a box around `start` and `goal`, reaching
    :math:`\rho` beyond them (at least :data:`NEAR` and twice their distance), with only the
    obstacles whose grown shape comes within `margin` of the box and only the corners inside
    it; a box is convex, so every edge stays inside, and an obstacle left out can neither block
    an edge nor change its cost (it is farther than the margin).  A route leaving the box
    is at least :math:`2\rho` long and costs at least that much (an edge costs at least its
    length), so a route found inside costing at most :math:`2\rho` is a cheapest one of the
    whole map; otherwise :math:`\rho` doubles, until the box holds every obstacle (the search
    of the whole map).  The cost is the whole map's; on a map within the first box, so is
    everything else.  A start or goal inside an obstacle has no route (every edge from or to
    it enters the obstacle), which is seen at once.

    **Bounded.**  A route that squeezes along an aisle lined with goods costs several times its
    length, so its box grows to most of a large map (16,835 corners on the MovingAI warehouse:
    74 s for one search).  At most `budget` edges are tested over all boxes; past it, the route
    a smaller box found is taken (free of every obstacle, perhaps not the cheapest), else there
    is none (``None``) and the caller drives on as it can (the dynamic window stops short of
    anything in the way, and a robot that stalls re-plans).  A detour around a person or a
    robot tests about ten thousand.

    Parameters
    ----------
    start, goal : (float, float)
        Centres (mm).
    half : float
        Half side of the robot (mm).
    walls : ndarray, shape (n, 4)
        Wall segments ``x1, y1, x2, y2`` (mm).
    boxes : ndarray, shape (m, 3)
        Resting objects and standing robots as ``x, y, half side`` (mm).
    margin : float
        The clearance wanted, :math:`m` (mm).
    penalty : float
        :math:`p`, the extra cost factor of an edge with no clearance at all.
    squeeze : float
        :math:`q`, the fixed extra cost of such an edge, in units of the margin.
    budget : int
        The most edges tested (each a segment against the grown obstacles).

    Returns
    -------
    GlobalPath or None
        ``None`` when the goal cannot be reached even touching the obstacles, or no route is
        found within `budget`.
    """
    walls, boxes = (
        np.asarray(walls, dtype=float).reshape(-1, 4),
        np.asarray(boxes, dtype=float).reshape(-1, 3),
    )
    ends = np.array([start, goal], dtype=float)
    wall_lo, wall_hi = segment_bounds(walls)
    lows = np.vstack([wall_lo - half, boxes[:, :2] - (boxes[:, 2:] + half)])
    highs = np.vstack([wall_hi + half, boxes[:, :2] + (boxes[:, 2:] + half)])
    for point in ends:  # inside an obstacle: every edge from or to it enters that obstacle
        holds = np.all((lows <= point) & (highs >= point), axis=1)
        near = _grown(walls[holds[: len(walls)]], boxes[holds[len(walls) :]], half)
        if near and shapely.intersects_xy(_interior(shapely.unary_union(near)), *point):
            return None
    reach = max(NEAR, 2.0 * float(np.abs(ends[1] - ends[0]).max()))
    weights = (margin, penalty, squeeze)
    found: GlobalPath | None = None  # the last box's route, free but perhaps not the cheapest
    while budget > 0:
        lo, hi = ends.min(axis=0) - reach, ends.max(axis=0) + reach
        # an obstacle farther than the margin from the box changes no edge's cost inside it
        meets = np.all((lows <= hi + margin) & (highs >= lo - margin), axis=1)
        if meets.all():  # the whole map
            return _route(ends, half, walls, boxes, None, weights, budget)[0] or found
        inside = meets[: len(walls)], meets[len(walls) :]
        path, cost, tested = _route(ends, half, walls[inside[0]], boxes[inside[1]], (lo, hi), weights, budget)
        if path is not None and cost <= 2.0 * reach:
            return path
        found, reach, budget = path or found, reach * 2.0, budget - tested
    return found


NEAR = 5000.0
"""How far beyond its start and goal (mm) :func:`plan_path` looks first."""


def _route(
    ends: NDArray[np.float64],
    half: float,
    walls: NDArray[np.float64],
    boxes: NDArray[np.float64],
    region: tuple[NDArray[np.float64], NDArray[np.float64]] | None,
    weights: tuple[float, float, float],
    budget: int,
) -> tuple[GlobalPath | None, float, int]:
    """The cheapest route among `walls` and `boxes` with corners inside `region` (``(lo, hi)``
    corners of a box, or ``None``: anywhere), its cost and the edges tested (:func:`plan_path`;
    `weights`: its margin, penalty and squeeze; no route past `budget` edges tested)."""
    margin = weights[0]
    grown = shapely.unary_union(_grown(walls, boxes, half))
    if not _one_piece(ends, grown, region, margin):
        return None, math.inf, 0  # walled apart: the search would try every corner in vain
    # Touching is allowed: only the open interior blocks (shrink by a hair against round-off).
    inner = _interior(grown)
    corners = [_corners(grown, inner, offset) for offset in (1.0, margin)]
    nodes = np.vstack([ends, *corners])
    if region is not None:
        nodes = nodes[
            np.all((nodes >= region[0]) & (nodes <= region[1]), axis=1) | (np.arange(len(nodes)) < 2)
        ]
    costs = _EdgeCosts(nodes, inner, None if grown.is_empty else grown.boundary, *weights)
    found = _a_star(nodes, costs, budget)
    if found is None:
        return None, math.inf, costs.tested
    route, least, cost = found
    path = GlobalPath(tuple((float(x), float(y)) for x, y in nodes[route]), min(least, margin))
    return path, cost, costs.tested


def straight_path(
    start: Point, goal: Point, half: float, walls: NDArray[np.float64], boxes: NDArray[np.float64]
) -> GlobalPath | None:
    """The straight segment from `start` to `goal` when the robot's square can follow it.

    A plan's drive is a straight segment proved free of walls and resting objects (touching
    allowed); the executor follows it as it is -- a shortest path among the grown obstacles
    would hug their corners, and in a passage one robot wide that puts the robot against a
    corner it cannot leave.  ``None`` when something now stands on the segment (a parked robot,
    a person), for :func:`plan_path` to find a way around.  The path's margin is its clearance
    to the grown obstacles, capped at :data:`CLEARANCE_CAP` (only obstacles that near are
    measured).

    Parameters
    ----------
    start, goal : (float, float)
        The segment's ends, the robot's centre (mm).
    half : float
        Half side of the robot (mm).
    walls : ndarray, shape (n, 4)
        Wall segments ``x1, y1, x2, y2`` (mm).
    boxes : ndarray, shape (m, 3)
        Resting objects, standing robots and people as ``x, y, half side`` (mm).
    """
    walls, boxes = (
        np.asarray(walls, dtype=float).reshape(-1, 4),
        np.asarray(boxes, dtype=float).reshape(-1, 3),
    )
    ends = np.array([start, goal], dtype=float)
    lo, hi = ends.min(axis=0) - (CLEARANCE_CAP + half), ends.max(axis=0) + (CLEARANCE_CAP + half)
    wall_lo, wall_hi = segment_bounds(walls)
    near_walls = np.all((wall_lo <= hi) & (wall_hi >= lo), axis=1)
    near_boxes = np.all((boxes[:, :2] - boxes[:, 2:] <= hi) & (boxes[:, :2] + boxes[:, 2:] >= lo), axis=1)
    grown = shapely.unary_union(_grown(walls[near_walls], boxes[near_boxes], half))
    clearance = CLEARANCE_CAP
    if not grown.is_empty:
        line = shapely.linestrings([start, goal])
        if shapely.intersects(_interior(grown), line):
            return None
        clearance = min(float(shapely.distance(grown.boundary, line)), CLEARANCE_CAP)
    return GlobalPath(((float(start[0]), float(start[1])), (float(goal[0]), float(goal[1]))), clearance)


CLEARANCE_CAP = 1000.0
"""The most clearance (mm) :func:`straight_path` measures."""


def _one_piece(
    ends: NDArray[np.float64],
    grown: Any,
    region: tuple[NDArray[np.float64], NDArray[np.float64]] | None,
    margin: float,
) -> bool:
    """Whether the start and the goal (`ends`) lie in one piece of the free space in `region`
    (``None``: around everything), the grown obstacles taken out.

    A route runs in the closure of the free space, so it never leaves the piece it starts in;
    pieces that touch, or nearly (a pinch under 2 mm), are taken as one, so that no route the
    search could find is refused.  On a large map a goal walled in by standing robots would
    otherwise cost a search of every corner of the map (ten minutes and more on the MovingAI
    warehouse) for no route.
    """
    if grown.is_empty:
        return True
    if region is None:
        x0, y0, x1, y1 = grown.bounds
        lo = np.minimum([x0, y0], ends.min(axis=0)) - 2.0 * margin
        hi = np.maximum([x1, y1], ends.max(axis=0)) + 2.0 * margin
    else:
        lo, hi = region
    free = shapely.box(lo[0], lo[1], hi[0], hi[1]).difference(grown).buffer(1.0)
    start, goal = shapely.points(ends)
    for piece in getattr(free, "geoms", (free,)):
        if piece.intersects(start):
            return bool(piece.intersects(goal))
    return True  # the start in no piece: leave it to the search


def _interior(geometry: Any) -> Any:
    """The open interior, shrunk by half a millimetre against round-off, prepared."""
    inner = geometry.buffer(-0.5, join_style="mitre") if not geometry.is_empty else geometry
    shapely.prepare(inner)
    return inner


def _corners(grown: Any, exact_inner: Any, offset: float) -> NDArray[np.float64]:
    """Corners of the grown obstacles, pushed out by `offset`, that are outside every obstacle."""
    if grown.is_empty:
        return np.zeros((0, 2))
    rings = []
    for poly in getattr(grown, "geoms", [grown]):
        rings.append(poly.exterior)
        rings.extend(poly.interiors)
    pts = []
    for ring in rings:
        xy = np.asarray(ring.coords)[:-1]
        if len(xy) < 3:
            continue
        prev, nxt = np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0)
        # Push each corner outwards along the sum of its two edge normals (L-infinity-sized).
        bisector = (xy - prev) / np.maximum(np.linalg.norm(xy - prev, axis=1, keepdims=True), 1e-9)
        bisector -= (nxt - xy) / np.maximum(np.linalg.norm(nxt - xy, axis=1, keepdims=True), 1e-9)
        norm = np.linalg.norm(bisector, axis=1, keepdims=True)
        pts.append(xy + offset * bisector / np.maximum(norm, 1e-9))
    if not pts:
        return np.zeros((0, 2))
    cand = np.vstack(pts)
    outside = ~shapely.contains_xy(grown, cand[:, 0], cand[:, 1])
    cand = cand[outside]
    inside_exact = shapely.intersects_xy(exact_inner, cand[:, 0], cand[:, 1])
    corners: NDArray[np.float64] = cand[~inside_exact]
    return corners


class _EdgeCosts:
    """The edges from one node of the roadmap to many: which are free, their cost and clearance.

    An edge is a straight segment that does not enter the interior of any grown obstacle; its
    cost is its length, raised where its clearance to the grown obstacles is below the margin
    (:func:`plan_path`).  Evaluated for one node's edges at a time, when the search reaches it.
    """

    def __init__(
        self,
        nodes: NDArray[np.float64],
        inner: Any,
        boundary: Any,
        margin: float,
        penalty: float,
        squeeze: float,
    ) -> None:
        self.nodes, self.inner, self.boundary = nodes, inner, boundary
        self.margin, self.penalty, self.squeeze = margin, penalty, squeeze
        self.tested = 0  # edges tested so far

    def __call__(
        self, u: int, others: NDArray[np.intp]
    ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
        """The free edges from `u` to `others`: their far ends, costs and clearances."""
        self.tested += len(others)
        ends = self.nodes[others]
        lines = shapely.linestrings(np.stack([np.broadcast_to(self.nodes[u], ends.shape), ends], axis=1))
        free = ~shapely.intersects(self.inner, lines)
        others, lines, ends = others[free], lines[free], ends[free]
        length = np.hypot(*(ends - self.nodes[u]).T)
        if self.boundary is None or self.margin <= 0:
            return others, length, np.full(len(others), np.inf)
        clearance = shapely.distance(self.boundary, lines)
        short = np.clip(1.0 - clearance / self.margin, 0.0, 1.0)
        # A squeeze costs by its length and once: a short gap must not look cheap.
        cost = length * (1.0 + self.penalty * short) + self.squeeze * short * self.margin
        return others, cost, clearance


def _a_star(
    nodes: NDArray[np.float64], costs: _EdgeCosts, budget: int
) -> tuple[list[int], float, float] | None:
    """Cheapest route from node 0 to node 1, the least clearance along it, and its cost;
    ``None`` when there is none, or none found before `budget` edges are tested.

    A* with the straight-line distance to the goal, which never overestimates (an edge costs
    at least its length) and is consistent, so a node taken off the queue is final and the
    route is a cheapest one over the whole roadmap.  The edges are evaluated lazily, one
    node's at a time and only to nodes not yet final: the work is the nodes the search
    reaches times the nodes, instead of every pair of nodes.
    """
    n = len(nodes)
    to_goal = np.hypot(*(nodes - nodes[1]).T)
    dist, parent, clear = np.full(n, np.inf), np.full(n, -1), np.full(n, np.inf)
    final = np.zeros(n, dtype=bool)
    dist[0] = 0.0
    heap = [(float(to_goal[0]), 0.0, 0)]
    while heap:
        _, d, u = heapq.heappop(heap)
        if final[u]:
            continue
        final[u] = True
        if u == 1 or costs.tested >= budget:
            break
        ends, cost, clearance = costs(u, np.flatnonzero(~final))
        via = d + cost
        better = via < dist[ends]
        ends, via, clearance = ends[better].tolist(), via[better].tolist(), clearance[better].tolist()
        for v, dv, cv in zip(ends, via, clearance, strict=True):
            dist[v], parent[v], clear[v] = dv, u, cv
            heapq.heappush(heap, (dv + float(to_goal[v]), dv, v))
    if not final[1]:
        return None
    route = [1]
    while route[-1] != 0:
        route.append(int(parent[route[-1]]))
    least = min((float(clear[v]) for v in route[:-1]), default=math.inf)
    return route[::-1], least, float(dist[1])
