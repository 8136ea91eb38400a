"""``cosmop view``: a self-contained HTML viewer, checked in a real headless Chromium.

The browser tests skip where no Chromium is installed (``apt-get install chromium``); set
``COSMOP_SCREENSHOT=path.png`` to keep the screenshot they take.
"""

from __future__ import annotations

import io
import json
import os
import re

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
    assert data["messages"] == [{"t": result.messages[0].t, "from": "R2", "to": "R1", "label": "O2", "why": why}]
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
    assert bad.exit_code == 2 and "bad.json: format: expected 'cosmop.trace/1'" in bad.stderr
    assert not (tmp_path / "x.html").exists()


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
