"""``cosmop view``: a self-contained HTML viewer, checked in a real headless Chromium.

The browser tests skip where no Chromium is installed (``apt-get install chromium``); set
``COSMOP_SCREENSHOT=path.png`` to keep the screenshot they take.
"""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from browser import Browser, find_chromium
from cosmop.cli import app
from cosmop.viz.web import render_html, save_html
from run_2x2 import EXAMPLE, run_2x2

runner = CliRunner()
CHROMIUM = find_chromium()


def test_the_page_is_self_contained_and_carries_the_run():
    scenario, plans, result = run_2x2()
    html = render_html(scenario.scene, plans=plans, trace=result.trace())
    # nothing fetched from anywhere: no external scripts, styles, images or fonts
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", html)
    assert "@import" not in html and "url(http" not in html
    data = json.loads(re.search(r'id="cosmop-data">(.*?)</script>', html, re.S).group(1))
    assert set(data["robots"]) == {"R1", "R2"} and data["robots"]["R1"]["steps"] == 7
    assert len(data["walls"]) == len(scenario.scene.obstacles)
    why = "R1 waits for R2 to move O2 out of its way"  # in plain words, from the plans
    assert data["messages"] == [
        {"t": result.messages[0].t, "from": "R2", "to": "R1", "label": "O2", "why": why}
    ]
    assert len(data["trace"]["t"]) == len(result.trace().t)  # short runs keep every frame
    small = render_html(scenario.scene, plans=plans, trace=result.trace(), max_frames=50)
    trace = json.loads(re.search(r'id="cosmop-data">(.*?)</script>', small, re.S).group(1))["trace"]
    assert len(trace["t"]) <= 51 and trace["t"][-1] == result.trace().t[-1]


def test_cli_view_writes_the_page_and_rejects_bad_input(tmp_path):
    _, plans, result = run_2x2()
    result.save_trace(tmp_path / "trace.json")
    plans.save(tmp_path / "plan.json")
    out = tmp_path / "run.html"
    args = [
        "view",
        str(EXAMPLE),
        "--plan",
        str(tmp_path / "plan.json"),
        "--trace",
        str(tmp_path / "trace.json"),
    ]
    ok = runner.invoke(app, [*args, "-o", str(out)])
    assert ok.exit_code == 0, ok.output
    assert out.read_text().startswith("<!DOCTYPE html>") and "wrote" in ok.stdout
    (tmp_path / "bad.json").write_text("{}")
    bad = runner.invoke(
        app, ["view", str(EXAMPLE), "--trace", str(tmp_path / "bad.json"), "-o", str(tmp_path / "x.html")]
    )
    assert bad.exit_code == 2 and "bad.json: format: missing required key 'format'" in bad.stderr
    assert not (tmp_path / "x.html").exists()


def test_simulate_writes_the_page_of_its_run_and_says_where(tmp_path):
    plan = Path(__file__).resolve().parent / "data" / "plan_2x2.json"  # cosmop plan of EXAMPLE
    out = tmp_path / "run.html"
    ran = runner.invoke(app, ["simulate", str(EXAMPLE), "--plan", str(plan), "--html", str(out)])
    assert ran.exit_code == 0, ran.output
    assert out.read_text().startswith("<!DOCTYPE html>")
    assert f"wrote {out}: open it in a browser, {out.as_uri()}" in " ".join(ran.stdout.split())
    data = json.loads(re.search(r'id="cosmop-data">(.*?)</script>', out.read_text(), re.S).group(1))
    assert data["trace"] is not None and data["plans"]["R1"][0]["t"] is None
    assert any(words.startswith("waits for R2 to") for words in data["waits"].values())


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    if CHROMIUM is None:
        pytest.skip("no Chromium found: apt-get install chromium (or set COSMOP_CHROMIUM)")
    scenario, plans, result = run_2x2()
    path = tmp_path_factory.mktemp("view") / "run.html"
    save_html(scenario.scene, path, plans=plans, trace=result.trace())
    browser = Browser(CHROMIUM)
    try:
        browser.open(path.as_uri())
        yield browser, result.trace().to_json()  # the page against the trace's file
    finally:
        browser.close()


def _pose(browser, rid):
    g = f"document.getElementById('robot-{rid}')"
    return browser.evaluate(f"[Number({g}.dataset.x), Number({g}.dataset.y)]")


def _seek(browser, k):
    script = (
        f"const s = document.getElementById('time'); s.value = '{k}'; s.dispatchEvent(new Event('input'));"
    )
    browser.evaluate(f"(() => {{ {script} }})()")


def test_the_page_loads_in_chromium_without_errors_and_draws_the_scene(page):
    browser, trace = page
    assert browser.errors == []
    assert browser.evaluate("document.querySelectorAll('line.wall').length") == 6
    assert browser.evaluate("document.querySelectorAll('g.robot').length") == 2
    assert browser.evaluate("window.cosmopViewer.frames") == len(trace["frames"])
    assert browser.evaluate("document.getElementById('clock').textContent").startswith("t = 0.0 s")


def test_the_slider_moves_the_robots_to_the_trace_poses(page):
    browser, trace = page
    frames = trace["frames"]
    assert _pose(browser, "R1") == [round(v) for v in frames[0]["robots"]["R1"]["pose"][:2]]
    carrying = next(k for k, f in enumerate(frames) if f["robots"]["R1"]["carrying"] == "O1")
    _seek(browser, carrying)
    assert _pose(browser, "R1") == [round(v) for v in frames[carrying]["robots"]["R1"]["pose"][:2]]
    assert _pose(browser, "R1") != [round(v) for v in frames[0]["robots"]["R1"]["pose"][:2]]
    assert browser.evaluate("document.getElementById('robot-R1').dataset.carrying") == "O1"
    assert browser.evaluate("document.getElementById('object-O1').getAttribute('visibility')") == "hidden"
    sent = next(k for k, f in enumerate(frames) if f["t"] >= trace["messages"][0]["t"])
    _seek(browser, sent)
    assert browser.evaluate("document.getElementById('message-0').getAttribute('visibility')") == "visible"
    assert "O2 at" in browser.evaluate("document.getElementById('message-0').textContent")
    _seek(browser, len(frames) - 1)
    assert browser.evaluate("document.getElementById('message-0').getAttribute('visibility')") == "hidden"
    assert browser.errors == []


def test_play_advances_the_clock(page):
    browser, _ = page
    _seek(browser, 0)
    browser.evaluate("document.getElementById('play').click()")
    browser.call(
        "Runtime.evaluate",
        {"expression": "new Promise((d) => setTimeout(d, 400))", "awaitPromise": True},
        session=True,
    )
    assert int(browser.evaluate("document.getElementById('time').value")) > 0
    browser.evaluate("document.getElementById('play').click()")  # pause


def test_a_screenshot_shows_the_scene(page):
    from PIL import Image

    browser, trace = page
    _seek(browser, len(trace["frames"]) // 2)
    png = browser.screenshot()
    if os.environ.get("COSMOP_SCREENSHOT"):
        with open(os.environ["COSMOP_SCREENSHOT"], "wb") as handle:
            handle.write(png)
    image = Image.open(io.BytesIO(png)).convert("RGB")
    assert image.size == (1280, 800)
    colours = image.getcolors(maxcolors=1 << 20)
    counts = {rgb: n for n, rgb in colours}
    dark = sum(n for rgb, n in counts.items() if max(rgb) < 60)  # walls and text
    blue = sum(n for rgb, n in counts.items() if rgb == (0x1F, 0x77, 0xB4))  # R1's colour
    assert dark > 2000 and blue > 50


# -- a big map: the MovingAI warehouse with the work in one corner --------------------------------


def _corner_of_movingai():
    """The MovingAI warehouse's walls with three robots at work in its lower left corner, and a
    made-up run: R1 drives 6 m, R2 waits for R1's message, R3 gives way to R1, then replans."""
    import sys

    import numpy as np

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from cosmop.scenario import parse_scenario
    from cosmop.traces import Trace
    from movingai_gen import movingai_warehouse

    data = movingai_warehouse(3, 0)
    # in the aisles of the first shelf rows (y 4.5, 7.5 and 10.5 m), at the dock area's edge
    data["scene"]["robots"] = {f"R{i}": {"size": 500, "pose": [22500, 1500 + 3000 * i, 0]} for i in (1, 2, 3)}
    data["scene"]["objects"] = {"O1": {"size": 200, "position": [30500, 10100]}}
    data["scene"]["workspaces"] = {"W1": {"x": [17000, 18000], "y": [5000, 6000]}}
    data["mission"] = {"tasks": {"R1": ["pick O1", "drop O1 at W1"]}}
    scene = parse_scenario(data).scene
    n = 61
    t = np.linspace(0.0, 30.0, n)
    poses = np.zeros((n, 3, 3))
    for i in range(3):
        poses[:, i] = [22500, 1500 + 3000 * (i + 1), 0]
    poses[:, 0, 0] += np.linspace(0, 6000, n)
    awaits = np.full((n, 3), None, dtype=object)
    awaits[10:30, 1] = "msg(R1,R2,clear1)"
    yields = np.full((n, 3), None, dtype=object)
    yields[30:40, 2] = "R1"
    waiting = np.array([[False, v is not None, False] for v in awaits[:, 1]])
    replan = {
        "t": 20.0,
        "robot": "R3",
        "route": {
            "from": [22500, 10500, 0],
            "steps": [{"pose": [30000, 10500, 0], "primitive": "GoTo", "about": None}],
        },
    }
    trace = Trace(
        t=t, robot_ids=("R1", "R2", "R3"), poses=poses, waiting=waiting, awaits=awaits, yields_to=yields,
        messages=({"t": 15.0, "from": "R1", "to": "R2", "event": "msg(R1,R2,clear1)"},),
        replans=(replan,), scenario="movingai-corner",
    )  # fmt: skip
    return scene, trace


@pytest.fixture(scope="module")
def big_map(tmp_path_factory):
    if CHROMIUM is None:
        pytest.skip("no Chromium found: apt-get install chromium (or set COSMOP_CHROMIUM)")
    scene, trace = _corner_of_movingai()
    path = tmp_path_factory.mktemp("view") / "movingai.html"
    save_html(scene, path, trace=trace, title="movingai-corner")
    browser = Browser(CHROMIUM)
    try:
        browser.open(path.as_uri())
        yield browser, scene
    finally:
        browser.close()


def _keep(browser, name):
    """Keep a screenshot in ``$COSMOP_SCREENSHOT_DIR`` (benchmarks/results keeps the last ones)."""
    folder = os.environ.get("COSMOP_SCREENSHOT_DIR")
    if folder:
        with open(os.path.join(folder, name), "wb") as handle:
            handle.write(browser.screenshot())


def _mouse(browser, kind, x, y, **extra):
    browser.call("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, **extra}, session=True)


def _svg_centre(browser):
    return browser.evaluate(
        "(() => { const r = document.getElementById('scene').getBoundingClientRect();"
        " return [r.left + r.width / 2, r.top + r.height / 2]; })()"
    )


def test_a_big_map_opens_fitted_to_the_robots(big_map):
    browser, scene = big_map
    assert browser.errors == []
    x0, x1, y0, y1 = browser.evaluate("window.cosmopViewer.view()")
    walls = [p for w in scene.obstacles for p in (w.start, w.end)]
    map_width = max(p[0] for p in walls) - min(p[0] for p in walls)
    assert x1 - x0 < 0.4 * map_width  # the corner, not the 161 m map
    for robot in scene.robots.values():
        assert x0 < robot.pose[0] < x1 and y0 < robot.pose[1] < y1
    assert x1 > 28500  # and where R1 drives to
    _keep(browser, "viewer_movingai_fitted.png")
    browser.evaluate("document.getElementById('whole').click()")
    wx0, wx1, _, _ = browser.evaluate("window.cosmopViewer.view()")
    assert wx1 - wx0 > map_width
    browser.evaluate("document.getElementById('fit').click()")
    assert browser.evaluate("window.cosmopViewer.view()") == [x0, x1, y0, y1]


def test_the_wheel_zooms_about_the_pointer_and_a_drag_pans(big_map):
    browser, _ = big_map
    browser.evaluate("window.cosmopViewer.fit()")
    before = browser.evaluate("window.cosmopViewer.view()")
    cx, cy = _svg_centre(browser)
    _mouse(browser, "mouseWheel", cx, cy, deltaX=0, deltaY=-400)
    zoomed = browser.evaluate("window.cosmopViewer.view()")
    ratio = (zoomed[1] - zoomed[0]) / (before[1] - before[0])
    assert 0.4 < ratio < 0.7  # wheel up: closer
    # about the pointer: the centre of the view stays where it was
    assert abs((zoomed[0] + zoomed[1]) / 2 - (before[0] + before[1]) / 2) < 0.02 * (before[1] - before[0])
    _keep(browser, "viewer_movingai_zoomed.png")
    unit = (zoomed[1] - zoomed[0]) / browser.evaluate(
        "document.getElementById('scene').getBoundingClientRect().width"
    )
    _mouse(browser, "mousePressed", cx, cy, button="left", buttons=1, clickCount=1)
    _mouse(browser, "mouseMoved", cx + 60, cy + 30, button="left", buttons=1)
    _mouse(browser, "mouseMoved", cx + 120, cy + 60, button="left", buttons=1)
    _mouse(browser, "mouseReleased", cx + 120, cy + 60, button="left", buttons=0, clickCount=1)
    panned = browser.evaluate("window.cosmopViewer.view()")
    # dragged right and down: the world moves with the pointer, so the view goes left and up
    assert panned[0] == pytest.approx(zoomed[0] - 120 * unit, rel=0.05, abs=5 * unit)
    assert panned[2] == pytest.approx(zoomed[2] + 60 * unit, rel=0.05, abs=5 * unit)
    _keep(browser, "viewer_movingai_panned.png")
    assert browser.errors == []


def test_a_standing_robot_says_why_and_a_replan_redraws_its_path(big_map):
    browser, _ = big_map
    browser.evaluate("window.cosmopViewer.fit()")
    _seek(browser, 20)
    words = browser.evaluate("document.getElementById('robot-R2').dataset.why")
    assert words.startswith("waits for a message from R1")  # no plans: the message's sender
    assert "R2 waits for a message from R1" in browser.evaluate("document.getElementById('why').textContent")
    assert browser.evaluate("document.getElementById('plan-R3-0').getAttribute('visibility')") == "hidden"
    _seek(browser, 35)  # t = 17.5 s
    assert browser.evaluate("document.getElementById('robot-R3').dataset.why") == "gives way to R1"
    assert browser.evaluate("document.getElementById('robot-R2').dataset.why") == ""
    _seek(browser, 45)  # t = 22.5 s: R3 replanned at 20 s
    assert browser.evaluate("document.getElementById('plan-R3-0').getAttribute('visibility')") == "visible"
    _keep(browser, "viewer_movingai_waiting.png")
    assert browser.errors == []


def test_a_metres_file_is_shown_in_metres_on_the_page():
    from dataclasses import replace

    from cosmop.planning.plan_file import load_plan
    from cosmop.scenario import load_scenario

    plans = load_plan(Path(__file__).resolve().parent / "data" / "plan_2x2.json")
    scene = load_scenario(EXAMPLE).scene
    pages = {}
    for units in ("mm", "m"):  # the same scene, written in mm or in metres
        html = render_html(replace(scene, units=units), plans=plans)
        pages[units] = json.loads(re.search(r'id="cosmop-data">(.*?)</script>', html, re.S).group(1))
    assert "scenario file: m and radians" in pages["m"]["units_text"]
    assert "mm and degrees" in pages["mm"]["units_text"]
    places = [w for w in pages["m"]["waits"].values() if " at (" in w]
    assert places and all(w.endswith(") m") for w in places)
    assert all(w.endswith(") mm") for w in pages["mm"]["waits"].values() if " at (" in w)

    # the same place, in the file's units: (1380, -1000) mm is (1.38, -1) m
    def first(words):
        return float(words.split(" at (")[1].split(",")[0])

    name = next(n for n, w in pages["mm"]["waits"].items() if " at (" in w)
    assert first(pages["m"]["waits"][name]) == pytest.approx(first(pages["mm"]["waits"][name]) / 1000)
