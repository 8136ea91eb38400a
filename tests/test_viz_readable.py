"""Pictures a user can read at any team size: colours, labels that do not collide, legends."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")
from cosmop.scenario import load_scenario
from cosmop.viz import draw_plan
from cosmop.viz.palette import TAB10, lab, robot_colours
from run_2x2 import run_2x2

ROOT = Path(__file__).resolve().parents[1]


def test_fifty_robots_get_fifty_distinguishable_colours():
    colours = np.array(robot_colours(50))
    assert len({tuple(c) for c in colours}) == 50
    distance = np.linalg.norm(lab(colours)[:, None] - lab(colours)[None], axis=-1)
    np.fill_diagonal(distance, np.inf)
    assert distance.min() > 20  # CIE76 ΔE: clearly different side by side
    assert [tuple(round(255 * v) for v in c) for c in colours[:10]] == [
        tuple(int(h[i : i + 2], 16) for i in (1, 3, 5)) for h in TAB10
    ]  # small teams keep matplotlib's tab10
    assert lab(colours)[:, 0].max() < 80  # none too light to see on white
    assert robot_colours(0) == [] and len(robot_colours(600)) == 600


def _text_boxes(fig):
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    # the text's own box (an annotation's extent would include its leader line)
    return [(t.get_text(), Text.get_window_extent(t, renderer)) for t in ax.texts if t.get_text()]


def _collisions(boxes):
    return [(a, b) for (a, ba), (b, bb) in itertools.combinations(boxes, 2) if ba.overlaps(bb)]


def test_plan_labels_do_not_collide_and_the_legend_explains_the_markers():
    import matplotlib.pyplot as plt

    scenario, plans, _ = run_2x2()
    fig = draw_plan(scenario.scene, plans)
    try:
        boxes = _text_boxes(fig)
        texts = [t for t, _ in boxes]
        assert {"O1", "O2", "R1", "R2", "W1", "W2", "?O2", "!O2", "P", "D"} <= set(texts)
        assert _collisions(boxes) == []  # O1 and O2 are 100 mm apart: "O2O1" before
        assert "1. R2→R1: O2" in texts  # the order between robots: R2 answers R1 about O2
        legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert "P: pick up" in legend and "?O: request (waits for O away)" in legend
        assert "R1: 7 steps" in legend
    finally:
        plt.close(fig)


def test_ten_robots_with_strings_of_goods_still_have_readable_labels():
    import matplotlib.pyplot as plt

    scene = load_scenario(ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml").scene
    fig = draw_plan(scene, None)
    try:
        boxes = _text_boxes(fig)
        assert len(boxes) == len(scene.robots) + len(scene.objects) + len(scene.workspaces)
        assert _collisions(boxes) == []
    finally:
        plt.close(fig)


def _gif(path):
    from PIL import Image

    with Image.open(path) as image:
        total = 0
        for k in range(image.n_frames):
            image.seek(k)
            total += image.info["duration"]
        return image.size, image.n_frames, total / 1000


def test_a_long_run_plays_in_under_a_minute_and_speed_and_size_can_be_given(tmp_path):
    from cosmop.viz import save_animation
    from test_animation import SCENE, make_trace

    long_run = make_trace(901, dt=1.0)  # a 900 s run
    path = tmp_path / "long.gif"
    save_animation(SCENE, long_run, path, max_frames=60, size=240)
    (width, _), frames, seconds = _gif(path)
    assert width == 240 and frames <= 60
    assert 40 <= seconds < 60  # 900 s at the default speed 900 / 45 = 20x
    short = make_trace(101, dt=0.1)  # 10 s: real time by default, 5x when asked
    save_animation(SCENE, short, tmp_path / "short.gif", size=200)
    assert _gif(tmp_path / "short.gif")[2] == pytest.approx(10.0, abs=0.2)
    save_animation(SCENE, short, tmp_path / "fast.gif", size=200, speed=5)
    assert _gif(tmp_path / "fast.gif")[2] == pytest.approx(2.0, abs=0.2)
    with pytest.raises(ValueError, match="speed"):
        save_animation(SCENE, short, tmp_path / "bad.gif", speed=0)


def test_animation_has_a_legend_message_arrows_and_separate_object_ids():
    from cosmop.viz import animation
    from test_animation import SCENE, make_plans, make_trace

    trace = make_trace(20, dt=0.1)
    animator = animation._Animator(SCENE, trace, make_plans(), None, 40)
    legend = [t.get_text() for t in animator.ax.get_legend().get_texts()]
    assert "waits for an answer (Req)" in legend and "message → receiver, time" in legend
    (arrow, text, message) = animator.arrows[0]
    animator.draw(0)
    assert not arrow.get_visible()
    sent = next(k for k, f in enumerate(trace["frames"]) if f["t"] >= message["t"])
    animator.draw(sent)
    assert arrow.get_visible() and text.get_text() == f"O2 @ {message['t']:.1f} s"
    r2 = trace["frames"][sent]["robots"]["R2"]["pose"][:2]
    assert tuple(arrow._posA_posB[0]) == tuple(r2)  # from the sender R2 to the receiver R1
    # O1 and O2 lie 100 mm apart: their ids go to different spots, apart
    (x1, y1), (x2, y2) = (animator.object_label[o].get_data() for o in ("O1", "O2"))
    gap = animator.mm_per_pt * 6  # one 6 pt character, in mm
    assert abs(x1[0] - x2[0]) >= 2 * gap or abs(y1[0] - y2[0]) >= gap
