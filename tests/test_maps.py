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


# The example's scenario as a user would write it before importing the map: comments above,
# beside and below, flow-style lines, a blank line, and no walls yet.
COMMENTED_TEMPLATE = """\
# Our warehouse, drawn by hand first.
# Robots start in opposite corners.
name: grid-warehouse   # keep this name
scene:
  # the robots, one per corner
  robots:
    R1: {size: 400, pose: [500, 500, 0]}      # bottom left
    R2: {size: 400, pose: [9500, 5500, 180]}  # top right

  objects:   # goods on the shelves
    O1: {size: 100, position: [2500, 3500]}
    O2: {size: 100, position: [8000, 2500]}
  workspaces:
    W1: {x: [8000, 9500], y: [3000, 3800]}
    W2: {x: [500, 2000], y: [5200, 5800]}
# each robot fetches one object and comes home
mission:
  tasks: {R1: [pick O1, drop O1 at W1, return], R2: [pick O2, drop O2 at W2, return]}
"""


def _import_with(template: Path, out: Path) -> str:
    args = ["import-map", str(EXAMPLE / "warehouse.map"), "--cell-size", "500", "-o", str(out)]
    result = runner.invoke(app, [*args, "--template", str(template)])
    assert result.exit_code == 0, result.output
    return out.read_text()


def test_import_map_keeps_the_templates_comments_and_order(tmp_path):
    template = tmp_path / "template.yaml"
    template.write_text(COMMENTED_TEMPLATE)
    text = _import_with(template, tmp_path / "scenario.yaml")
    # every line of the template is there, in its order: only the walls and the header are new
    lines = text.splitlines()
    at = [lines.index(line) for line in COMMENTED_TEMPLATE.splitlines()]
    assert at == sorted(at)
    new = [line for line in lines if line not in COMMENTED_TEMPLATE.splitlines()]
    assert new[0].startswith("# Imported by cosmop import-map from warehouse.map")
    assert new[2] == "  obstacles:" and len(new) == 3 + 28
    assert text.index("  obstacles:") < text.index("  # the robots, one per corner")  # walls first
    data = yaml.safe_load(text)
    assert list(data) == ["name", "scene", "mission"]
    assert list(data["scene"]) == ["obstacles", "robots", "objects", "workspaces"]
    assert load_scenario(tmp_path / "scenario.yaml").scene == load_scenario(EXAMPLE / "scenario.yaml").scene


def test_import_map_replaces_walls_in_place_with_the_comments_around_them(tmp_path):
    # walls last in the scene, a note on their key, a note on an old wall, a comment after them
    template = tmp_path / "template.yaml"
    old_walls = "  obstacles:      # replaced by the map\n    - [[0, 0], [1, 0]]   # a stub\n\n"
    template.write_text(
        COMMENTED_TEMPLATE.replace("# each robot fetches", old_walls + "# each robot fetches")
    )
    text = _import_with(template, tmp_path / "scenario.yaml")
    assert "  obstacles:      # replaced by the map\n    - [[0, 0], [10000, 0]]\n" in text  # as indented
    assert "# a stub" not in text  # it was about the old wall
    assert (
        "    - [[10000, 0], [10000, 6000]]\n\n# each robot fetches one object and comes home\nmission:"
        in text
    )
    assert list(yaml.safe_load(text)["scene"]) == ["robots", "objects", "workspaces", "obstacles"]
    # the new walls and the template's name, asked for another
    again = tmp_path / "again.yaml"
    args = ["import-map", str(EXAMPLE / "warehouse.map"), "--cell-size", "500", "-o", str(again)]
    assert runner.invoke(app, [*args, "--template", str(template), "--name", "renamed"]).exit_code == 0
    named = next(line for line in again.read_text().splitlines() if line.startswith("name:"))
    assert named.split() == ["name:", "renamed", "#", "keep", "this", "name"]  # the comment kept its column


def test_importing_the_example_into_itself_gives_it_back(tmp_path):
    # the earlier import's header is replaced, not stacked
    example = EXAMPLE / "scenario.yaml"
    assert _import_with(example, tmp_path / "scenario.yaml") == example.read_text()


def test_a_template_ruamel_cannot_keep_is_written_plainly(tmp_path, monkeypatch):
    import cosmop.maps.to_scenario as scene_module

    def fail(*args, **kwargs):
        raise ValueError("ruamel could not")

    monkeypatch.setattr(scene_module, "merge_walls", fail)
    template = tmp_path / "template.yaml"
    template.write_text(COMMENTED_TEMPLATE)
    text = _import_with(template, tmp_path / "scenario.yaml")
    assert "# (The template's comments could not be kept" in text and "# bottom left" not in text
    assert load_scenario(tmp_path / "scenario.yaml").scene == load_scenario(EXAMPLE / "scenario.yaml").scene


def test_merge_walls_writes_numbers_yaml_1_1_reads_as_numbers():
    from cosmop.maps.template import merge_walls

    text = merge_walls("name: n\nscene:\n  robots: {}\n", [[[1e-05, 0.5], [1e17, 2]]])
    assert "[[1.0e-05, 0.5], [1.0e+17, 2]]" in text
    assert yaml.safe_load(text)["scene"]["obstacles"] == [[[1e-05, 0.5], [1e17, 2]]]
