"""Global paths: short routes with clearance for a square robot among walls and objects.

The robot is an axis-aligned square of half side :math:`h`, so its centre must stay out of the
Minkowski sum of every obstacle with that square (its *configuration-space obstacle*): a wall
segment grows into a hexagon (the convex hull of the squares at its ends) and an object of half
side :math:`k` into the square of half side :math:`k + h`.  Shortest paths among polygons run
through their corners, so the route is found in the *visibility graph* of those corners plus
the start and the goal (Lozano-Pérez and Wesley) with Dijkstra's algorithm.  Corners are also
offered pushed out by the wanted clearance, and edges that pass closer than it cost more, so
the route keeps its distance where there is room and squeezes through where it must; touching
is allowed (a docking pose touches its object).  Units are millimetres.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

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

    def lookahead(self, position: Point, distance: float, corner: float = 30.0) -> tuple[Point, float]:
        """The point up to `distance` mm further along the path than `position`'s projection.

        The point does not pass the next vertex unless that vertex is within `corner` mm:
        cutting a corner would aim the robot into the obstacle the path goes around.

        Returns the point and the length of the path left after the projection (mm).
        """
        pts = np.asarray(self.points, dtype=float)
        if len(pts) == 1:
            return self.points[0], 0.0
        a, b = pts[:-1], pts[1:]
        d = b - a
        lengths = np.hypot(d[:, 0], d[:, 1])
        safe_len = np.where(lengths > 0, lengths, 1.0)
        t = ((position[0] - a[:, 0]) * d[:, 0] + (position[1] - a[:, 1]) * d[:, 1]) / safe_len**2
        t = np.clip(np.where(lengths > 0, t, 0.0), 0.0, 1.0)
        proj = a + t[:, None] * d
        dist = np.hypot(proj[:, 0] - position[0], proj[:, 1] - position[1])
        i = int(np.argmin(dist))
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


def _grown(walls: np.ndarray, boxes: np.ndarray, half: float) -> list[Polygon]:
    """Obstacles grown by the robot's square of half side `half` (configuration-space obstacles)."""
    out: list[Polygon] = [swept_square((x1, y1), (x2, y2), 2.0 * half) for x1, y1, x2, y2 in walls]
    out += [square(x, y, 2.0 * (k + half)) for x, y, k in boxes]
    return out


def _free(lines_from: np.ndarray, lines_to: np.ndarray, blocked) -> np.ndarray:
    """Which straight segments avoid the interior of `blocked` (a prepared geometry)."""
    if len(lines_from) == 0:
        return np.zeros(0, dtype=bool)
    coords = np.stack([lines_from, lines_to], axis=1)
    lines = shapely.linestrings(coords)
    return ~shapely.intersects(blocked, lines)


def plan_path(
    start: Point,
    goal: Point,
    half: float,
    walls: np.ndarray,
    boxes: np.ndarray,
    *,
    margin: float = 150.0,
    penalty: float = 3.0,
    squeeze: float = 10.0,
) -> GlobalPath | None:
    r"""The shortest route of a square robot's centre from `start` to `goal`, with clearance.

    Nodes are the start, the goal and the corners of the grown obstacles pushed out by 1 mm
    and by `margin`; an edge is a straight segment that does not enter any grown obstacle
    (touching is allowed).  An edge of length :math:`\ell` that passes within clearance
    :math:`c < m` (Euclidean, mm) of the grown obstacles costs
    :math:`\ell\,(1 + p\,(1 - c/m)) + q\,m\,(1 - c/m)`, so the route keeps its distance
    where it can and squeezes through where it must.

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

    Returns
    -------
    GlobalPath or None
        ``None`` when the goal cannot be reached even touching the obstacles.
    """
    grown = shapely.unary_union(_grown(walls, boxes, half))
    # Touching is allowed: only the open interior blocks (shrink by a hair against round-off).
    inner = _interior(grown)
    s = np.asarray(start, dtype=float)
    g = np.asarray(goal, dtype=float)
    corners = [_corners(grown, inner, offset) for offset in (1.0, margin)]
    nodes = np.vstack([s[None, :], g[None, :], *corners])
    i, j = np.triu_indices(len(nodes), k=1)
    ok = _free(nodes[i], nodes[j], inner)
    i, j = i[ok], j[ok]
    length = np.hypot(*(nodes[i] - nodes[j]).T)
    if grown.is_empty or margin <= 0:
        cost = length
        clearance = np.full(len(i), np.inf)
    else:
        lines = shapely.linestrings(np.stack([nodes[i], nodes[j]], axis=1))
        clearance = shapely.distance(grown.boundary, lines)
        short = np.clip(1.0 - clearance / margin, 0.0, 1.0)
        # A squeeze costs by its length and once: a short gap must not look cheap.
        cost = length * (1.0 + penalty * short) + squeeze * short * margin
    route = _dijkstra(nodes, i, j, cost)
    if route is None:
        return None
    used = {(min(a, b), max(a, b)) for a, b in itertools.pairwise(route)}
    index = {(int(a), int(b)): k for k, (a, b) in enumerate(zip(i, j, strict=True))}
    least = min((float(clearance[index[e]]) for e in used), default=float("inf"))
    return GlobalPath(tuple((float(x), float(y)) for x, y in nodes[route]), min(least, margin))


def straight_path(
    start: Point, goal: Point, half: float, walls: np.ndarray, boxes: np.ndarray
) -> GlobalPath | None:
    """The straight segment from `start` to `goal` when the robot's square can follow it.

    A plan's drive is a straight segment proved free of walls and resting objects (touching
    allowed); the executor follows it as it is -- a shortest path among the grown obstacles
    would hug their corners, and in a passage one robot wide that puts the robot against a
    corner it cannot leave.  ``None`` when something now stands on the segment (a parked robot,
    a person), for :func:`plan_path` to find a way around.
    """
    grown = shapely.unary_union(_grown(walls, boxes, half))
    if not grown.is_empty:
        line = shapely.linestrings([start, goal])
        if shapely.intersects(_interior(grown), line):
            return None
        clearance = float(shapely.distance(grown.boundary, line))
    else:
        clearance = float("inf")
    return GlobalPath((tuple(map(float, start)), tuple(map(float, goal))), clearance)


def _interior(geometry):
    """The open interior, shrunk by half a millimetre against round-off, prepared."""
    inner = geometry.buffer(-0.5, join_style="mitre") if not geometry.is_empty else geometry
    shapely.prepare(inner)
    return inner


def _corners(grown, exact_inner, offset: float) -> np.ndarray:
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
    return cand[~inside_exact]


def _dijkstra(nodes: np.ndarray, i: np.ndarray, j: np.ndarray, weights: np.ndarray) -> list[int] | None:
    """Cheapest path from node 0 to node 1 over the undirected edges ``(i, j)``."""
    n = len(nodes)
    adjacency: list[list[tuple[int, float]]] = [[] for _ in range(n)]
    for a, b, w in zip(i.tolist(), j.tolist(), weights.tolist(), strict=True):
        adjacency[a].append((b, w))
        adjacency[b].append((a, w))
    dist = [math.inf] * n
    parent = [-1] * n
    dist[0] = 0.0
    heap = [(0.0, 0)]
    while heap:
        d, u = heapq.heappop(heap)
        if d > dist[u]:
            continue
        if u == 1:
            break
        for v, w in adjacency[u]:
            nd = d + w
            if nd < dist[v]:
                dist[v] = nd
                parent[v] = u
                heapq.heappush(heap, (nd, v))
    if math.isinf(dist[1]):
        return None
    route = [1]
    while route[-1] != 0:
        route.append(parent[route[-1]])
    return route[::-1]
