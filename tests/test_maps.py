"""Grid maps: MovingAI and ROS map_server readers, the rectangle cover, the walls, ``cosmop import-map``."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from cosmop.cli import app
from cosmop.maps import (
    MapError,
    boundary_walls,
    import_map,
    parse_movingai,
    read_pgm,
    read_ros_map,
    rectangle_cover,
    rectangle_walls,
)
from cosmop.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "10_grid_map"
runner = CliRunner()

SMALL = "type octile\nheight 3\nwidth 4\nmap\n@...\n.TW.\n..GS\n"


def test_movingai_rows_are_flipped_so_that_y_grows_upwards():
    grid = parse_movingai(SMALL, 250.0, origin=(-100.0, 50.0))
    # the file's first row is the top row: row 2 of the grid
    assert grid.blocked.tolist() == [
        [False, False, False, False],
        [False, True, True, False],  # T and W (water) are blocked for ground robots
        [True, False, False, False],
    ]
    assert grid.point(0, 0) == (-100.0, 50.0) and grid.point(3, 4) == (900.0, 800.0)


@pytest.mark.parametrize(
    ("text", "field", "line", "fragment"),
    [
        ("height 3\n", "type", 1, "type octile"),
        ("type octile\nheight x\nwidth 4\nmap\n", "height", 2, "'height N'"),
        ("type octile\nheight 1\nwidth 4\nmap\n....\n....\n", "map", 6, "found more"),
        ("type octile\nheight 1\nwidth 4\nmap\n...\n", "map", 5, "a row of 4 cells, got 3"),
        ("type octile\nheight 1\nwidth 4\nmap\n..x.\n", "map", 5, "unknown terrain 'x'"),
    ],
)
def test_movingai_errors_name_the_field_and_line(text, field, line, fragment):
    with pytest.raises(MapError) as info:
        parse_movingai(text, 1000.0, file="m.map")
    err = info.value
    assert (err.file, err.field, err.line) == ("m.map", field, line) and fragment in err.expected


def _unit_edges(segments):
    """Every unit edge of a list of axis-parallel segments between grid corners."""
    edges = set()
    for (r0, c0), (r1, c1) in segments:
        assert r0 == r1 or c0 == c1, "walls are axis-parallel"
        if r0 == r1:
            edges |= {("h", r0, c) for c in range(min(c0, c1), max(c0, c1))}
        else:
            edges |= {("v", r, c0) for r in range(min(r0, r1), max(r0, r1))}
    return edges


def _free_boundary(blocked):
    """By brute force: unit edges between a free cell and a blocked cell or the outside."""
    rows, cols = blocked.shape

    def free(i, j):
        return 0 <= i < rows and 0 <= j < cols and not blocked[i, j]

    edges = set()
    for k in range(rows + 1):
        edges |= {("h", k, j) for j in range(cols) if free(k - 1, j) != free(k, j)}
    for k in range(cols + 1):
        edges |= {("v", i, k) for i in range(rows) if free(i, k - 1) != free(i, k)}
    return edges


def test_the_cover_is_exact_and_the_walls_are_exactly_the_free_boundary():
    rng = np.random.default_rng(14)
    for _ in range(150):
        shape = tuple(rng.integers(1, 9, size=2))
        blocked = rng.random(shape) < rng.uniform(0.1, 0.9)
        rects = rectangle_cover(blocked)
        count = np.zeros(shape, dtype=int)
        for r0, c0, r1, c1 in rects:
            assert 0 <= r0 < r1 <= shape[0] and 0 <= c0 < c1 <= shape[1]
            count[r0:r1, c0:c1] += 1
        assert (count == blocked).all()  # union is exactly the blocked cells, no overlap
        walls = boundary_walls(blocked)
        assert _unit_edges(walls) == _free_boundary(blocked)
        # maximal: no two walls on one line touch end to end (they would have been merged)
        for a, b in itertools.combinations(walls, 2):
            same_line = a[0][0] == a[1][0] == b[0][0] == b[1][0] or a[0][1] == a[1][1] == b[0][1] == b[1][1]
            assert not (same_line and (a[1] == b[0] or b[1] == a[0]))
        # the boundary is the rectangles' outlines less their shared and outer edges
        assert _unit_edges(walls) <= _unit_edges(rectangle_walls(rects)) | _free_boundary(
            np.zeros(shape, dtype=bool)
        )


def test_shelves_become_one_rectangle_each():
    grid = parse_movingai((EXAMPLE / "warehouse.map").read_text(), 500.0)
    rects = rectangle_cover(grid.blocked)
    assert (2, 2, 3, 8) in rects and (8, 2, 10, 8) in rects  # a 1-row and a 2-row shelf
    assert len(rects) == 7  # 4 shelves + the T pillar as 3 (the greedy rule is not minimal)


def _write_pgm(path: Path, pixels: np.ndarray, ascii_: bool = False) -> None:
    h, w = pixels.shape
    if ascii_:
        body = "\n".join(" ".join(str(v) for v in row) for row in pixels)
        path.write_text(f"P2\n# a comment\n{w} {h}\n255\n{body}\n")
    else:
        path.write_bytes(f"P5\n# made by a test\n{w} {h}\n255\n".encode() + pixels.astype(np.uint8).tobytes())


@pytest.mark.parametrize("ascii_", [False, True])
def test_ros_map_reads_occupancy_like_map_server(tmp_path, ascii_):
    # top row: occupied (0 = black), unknown (205), free (254); bottom row: free, free, occupied
    pixels = np.array([[0, 205, 254], [254, 254, 0]])
    _write_pgm(tmp_path / "map.pgm", pixels, ascii_)
    assert (read_pgm(tmp_path / "map.pgm")[0] == pixels).all()
    doc = {
        "image": "map.pgm",
        "resolution": 0.05,
        "origin": [-1.0, 2.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    (tmp_path / "map.yaml").write_text(yaml.safe_dump(doc))
    grid = read_ros_map(tmp_path / "map.yaml")
    assert grid.cell_size == 50.0 and grid.origin == (-1000.0, 2000.0)
    assert grid.blocked.tolist() == [[False, False, True], [True, True, False]]  # unknown is blocked
    assert read_ros_map(tmp_path / "map.yaml", unknown="free").blocked.tolist() == [
        [False, False, True],
        [True, False, False],
    ]
    (tmp_path / "neg.yaml").write_text(yaml.safe_dump(doc | {"negate": 1}))
    assert read_ros_map(tmp_path / "neg.yaml").blocked.tolist() == [[True, True, False], [False, True, True]]


def test_ros_map_errors_name_the_field(tmp_path):
    _write_pgm(tmp_path / "map.pgm", np.zeros((2, 2)))
    base = {"image": "map.pgm", "resolution": 0.05, "origin": [0, 0, 0]}
    for change, field, fragment in [
        ({"origin": [0, 0, 0.5]}, "origin", "yaw 0"),
        ({"resolution": -1}, "resolution", "positive"),
        ({"image": "missing.pgm"}, None, "file not found"),
        ({"mode": "fancy"}, "mode", "trinary, scale or raw"),
    ]:
        (tmp_path / "m.yaml").write_text(yaml.safe_dump(base | change))
        with pytest.raises(MapError) as info:
            read_ros_map(tmp_path / "m.yaml")
        assert info.value.field == field and fragment in info.value.expected


def test_cli_import_map_writes_walls_that_load_as_a_scenario(tmp_path):
    out = tmp_path / "scene.yaml"
    result = runner.invoke(
        app, ["import-map", str(EXAMPLE / "warehouse.map"), "--cell-size", "500", "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert "7 rectangles, 28 walls (32 as rectangle outlines)" in " ".join(result.stdout.split())
    data = yaml.safe_load(out.read_text())
    assert len(data["scene"]["obstacles"]) == 28 and [[0, 0], [10000, 0]] in data["scene"]["obstacles"]
    # merged into the example's own scenario as a template: the example's scene again
    again = tmp_path / "again.yaml"
    args = ["import-map", str(EXAMPLE / "warehouse.map"), "--cell-size", "500", "-o", str(again)]
    result = runner.invoke(app, [*args, "--template", str(EXAMPLE / "scenario.yaml")])
    assert result.exit_code == 0, result.output
    assert load_scenario(again).scene == load_scenario(EXAMPLE / "scenario.yaml").scene
    # in metres
    si = tmp_path / "si.yaml"
    args = ["import-map", str(EXAMPLE / "warehouse.map"), "--cell-size", "500", "-o", str(si), "--units", "m"]
    assert runner.invoke(app, args).exit_code == 0
    data = yaml.safe_load(si.read_text())
    assert data["units"] == "m" and [[0, 0], [10, 0]] in data["scene"]["obstacles"]
    assert import_map(EXAMPLE / "warehouse.map", cell_size=500, walls="rectangles").walls != []


def test_cli_import_map_bad_input_exits_2_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.map"
    bad.write_text("type octile\nheight 1\nwidth 2\nmap\n.?\n")
    out = tmp_path / "out.yaml"
    result = runner.invoke(app, ["import-map", str(bad), "-o", str(out)])
    assert result.exit_code == 2 and not out.exists()
    assert f"{bad}: map: unknown terrain '?'" in result.stderr and "line 5, column 2" in result.stderr
    other = tmp_path / "map.png"
    other.write_bytes(b"\x89PNG")
    result = runner.invoke(app, ["import-map", str(other), "-o", str(out)])
    assert result.exit_code == 2 and "expected a MovingAI .map file or a ROS map .yaml" in result.stderr
