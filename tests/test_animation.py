"""Animations of simulation traces (``cosmop.trace/1``): GIF/MP4 output, subsampling, atomic writes.

The trace is synthetic: in the 2x2 warehouse R1 drives to O1 and carries it back, R2 waits for an
answer (Req) and then sends a message, and a human walks across. Figures are rendered at a low
dpi so that the whole module runs in a few seconds.
"""

from __future__ import annotations

import itertools
import math
import os
import subprocess
import sys
import time
import types

import pytest

pytest.importorskip("matplotlib")
from PIL import Image  # matplotlib (hence Pillow) is installed

from cosmop.events import parse_event
from cosmop.planning import PlanSet, plan_from_actions
from cosmop.scenario import parse_scenario
from cosmop.viz import animation as animation_module
from cosmop.viz import save_animation, video_available

SCENARIO = parse_scenario(
    {
        "name": "warehouse-2x2",
        "scene": {
            "obstacles": [
                [[-2500, -2500], [2500, -2500]],
                [[2500, -2500], [2500, 2500]],
                [[2500, 2500], [-2500, 2500]],
                [[-2500, 2500], [-2500, -2500]],
                [[0, 0], [0, 2500]],
                [[-1000, 0], [1000, 0]],
            ],
            "robots": {
                "R1": {"size": 400, "pose": [-2000, -1000, 0]},
                "R2": {"size": 400, "pose": [-2000, -2000, 0]},
            },
            "objects": {
                "O1": {"size": 100, "position": [2000, -1000]},
                "O2": {"size": 100, "position": [1900, -1000]},
            },
            "workspaces": {"W1": {"x": [-1500, -1000], "y": [2000, 2500]}, "W2": {"point": [1250, 2250]}},
        },
        "mission": {"tasks": {"R1": ["pick O1", "drop O1 at W1", "return"], "R2": ["return"]}},
    }
)
SCENE = SCENARIO.scene
DPI = 25  # tiny frames: the tests check files, not looks


def make_trace(n: int = 20, dt: float = 0.1) -> dict:
    """R1 goes right and carries O1 back in the second half; R2 waits, then answers; H1 walks."""
    frames = []
    for k in range(n):
        t = k * dt
        s = k / (n - 1)
        carrying = s >= 0.5
        x1 = -2000 + 3750 * (2 * s if not carrying else 2 - 2 * s)
        frames.append(
            {
                "t": round(t, 6),
                "robots": {
                    "R1": {
                        "pose": [x1, -1000, 0 if not carrying else 180],
                        "v": 300.0,
                        "w": 0.0,
                        "carrying": "O1" if carrying else None,
                        "primitive": "GoTo",
                        "waiting": False,
                    },
                    "R2": {
                        "pose": [-2000 + 500 * s, -2000, 90 * s],
                        "v": 50.0,
                        "w": 90.0,
                        "carrying": None,
                        "primitive": "Req" if s < 0.3 else "GoTo",
                        "waiting": s < 0.3,
                    },
                },
                "humans": {"H1": [-2000 + 4000 * s, 1000 + 200 * math.sin(t)]},
                "objects": {"O1": [x1, -1000] if carrying else [2000, -1000], "O2": [1900, -1000]},
            }
        )
    message = {"t": 0.3 * (n - 1) * dt, "from": "R2", "to": "R1", "object": "O2", "event": "away(O2,R1,R2)"}
    return {
        "format": "cosmop.trace/1",
        "scenario": "warehouse-2x2",
        "dt": dt,
        "frames": frames,
        "messages": [message],
    }


def make_plans() -> PlanSet:
    r1 = plan_from_actions(
        SCENE,
        "R1",
        [parse_event("pick(R1,O1)"), parse_event("drop(R1,O1,W1)"), parse_event("return(R1)")],
        [
            ("GoTo", (1750, -1000, 0)),
            ("PickUp", "O1"),
            ("GoTo", (-1500, -200, 0)),
            ("GoTo", (-1500, 2000, 0)),
            ("DropOff", "O1"),
            ("GoTo", (-2000, -1000, 0)),
        ],
    )
    return PlanSet(scenario="warehouse-2x2", feasible=True, robots={"R1": r1})


def gif_frames(path) -> tuple[int, int]:
    """Number of frames and the first frame's duration (ms) of a GIF."""
    with Image.open(path) as image:
        assert image.format == "GIF"
        return image.n_frames, image.info["duration"]


def test_gif_is_written_with_one_frame_per_cycle(tmp_path):
    path = tmp_path / "run.gif"
    count = save_animation(SCENE, make_trace(20, dt=0.1), path, plans=make_plans(), dpi=DPI)
    assert count == 20
    n_frames, duration = gif_frames(path)
    assert n_frames == count > 1
    assert duration == 100  # real time: 10 frames per second for dt = 0.1 s
    assert os.listdir(tmp_path) == ["run.gif"]  # no temporary file left behind


def test_max_frames_subsamples_and_sets_the_real_time_rate(tmp_path):
    path = tmp_path / "run.gif"
    count = save_animation(SCENE, make_trace(50, dt=0.1), path, max_frames=10, dpi=DPI)
    assert 1 < count <= 10
    n_frames, duration = gif_frames(path)
    assert n_frames == count
    assert duration == 600  # stride 6 (49 / 9 rounded up): 0.6 s of simulation per frame


def test_fps_is_capped_to_20_and_can_be_given(tmp_path):
    fast = tmp_path / "fast.gif"
    save_animation(SCENE, make_trace(6, dt=0.01), fast, dpi=DPI)
    assert gif_frames(fast)[1] == 50  # 100 frames per second of real time, capped to 20
    given = tmp_path / "given.gif"
    save_animation(SCENE, make_trace(6, dt=0.01), given, fps=5, dpi=DPI)
    assert gif_frames(given)[1] == 200


@pytest.mark.parametrize(
    ("n", "max_frames"), [(1, 1), (5, 1), (5, 5), (6, 5), (100, 7), (401, 400), (1000, 400)]
)
def test_subsampling_keeps_the_first_and_last_frames(n, max_frames):
    indices, stride = animation_module._frame_indices(n, max_frames)
    assert len(indices) <= max_frames
    assert indices[-1] == n - 1
    assert indices == sorted(set(indices))
    assert all(b - a <= stride for a, b in itertools.pairwise(indices))
    if max_frames > 1:
        assert indices[0] == 0


def test_unknown_suffix_is_a_value_error_and_writes_nothing(tmp_path):
    for name in ("run.avi", "run"):
        with pytest.raises(ValueError, match=r"\.gif.*\.mp4"):
            save_animation(SCENE, make_trace(), tmp_path / name, dpi=DPI)
    assert os.listdir(tmp_path) == []


def test_malformed_trace_is_a_value_error(tmp_path):
    with pytest.raises(ValueError, match="frames"):
        save_animation(SCENE, {"format": "cosmop.trace/1", "frames": []}, tmp_path / "run.gif")
    with pytest.raises(ValueError, match="format"):
        save_animation(SCENE, {**make_trace(), "format": "other/1"}, tmp_path / "run.gif")
    with pytest.raises(ValueError, match="max_frames"):
        save_animation(SCENE, make_trace(), tmp_path / "run.gif", max_frames=0)
    assert os.listdir(tmp_path) == []


def _fail_on_third_frame(monkeypatch):
    update = animation_module._Animator.update

    def failing(self, index):
        if index == 2:
            raise RuntimeError("boom")
        update(self, index)

    monkeypatch.setattr(animation_module._Animator, "update", failing)


def _fail_when_finishing(monkeypatch):
    import matplotlib.animation

    def failing(self):
        raise OSError("disk full")

    monkeypatch.setattr(matplotlib.animation.PillowWriter, "finish", failing)


@pytest.mark.parametrize("fail", [_fail_on_third_frame, _fail_when_finishing])
def test_failure_midway_leaves_no_file_and_keeps_the_old_one(tmp_path, monkeypatch, fail):
    fail(monkeypatch)
    with pytest.raises((RuntimeError, OSError)):
        save_animation(SCENE, make_trace(), tmp_path / "new.gif", dpi=DPI)
    assert os.listdir(tmp_path) == []
    old = tmp_path / "old.gif"
    old.write_bytes(b"previous animation")
    with pytest.raises((RuntimeError, OSError)):
        save_animation(SCENE, make_trace(), old, dpi=DPI)
    assert os.listdir(tmp_path) == ["old.gif"]
    assert old.read_bytes() == b"previous animation"


def test_an_interrupted_animation_is_abandoned_not_finished(tmp_path, monkeypatch):
    # issue 39: Ctrl-C while drawing had Pillow write every frame drawn so far (seconds) only to
    # throw the file away; an MP4's ffmpeg is killed, not waited for
    import matplotlib.animation

    finished = []
    monkeypatch.setattr(matplotlib.animation.PillowWriter, "finish", lambda self: finished.append(self))
    update = animation_module._Animator.update

    def interrupted(self, index):
        if index == 2:
            raise KeyboardInterrupt
        update(self, index)

    monkeypatch.setattr(animation_module._Animator, "update", interrupted)
    with pytest.raises(KeyboardInterrupt):
        save_animation(SCENE, make_trace(), tmp_path / "run.gif", dpi=DPI)
    assert finished == [] and os.listdir(tmp_path) == []
    ffmpeg = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"], stdin=subprocess.PIPE)
    start = time.perf_counter()
    animation_module._abandon(types.SimpleNamespace(_proc=ffmpeg))
    assert ffmpeg.returncode is not None and time.perf_counter() - start < 10


def test_frames_are_still_written_when_the_canvas_cannot_be_taken_as_is(tmp_path, monkeypatch):
    monkeypatch.setattr(animation_module._Animator, "rgba", lambda self, size: None)  # savefig fallback
    path = tmp_path / "run.gif"
    count = save_animation(SCENE, make_trace(5), path, dpi=DPI)
    assert gif_frames(path)[0] == count == 5


def _with_person():
    """The scene with the person H1 (600 mm) that the synthetic trace walks."""
    return types.SimpleNamespace(
        obstacles=SCENE.obstacles,
        robots=SCENE.robots,
        objects=SCENE.objects,
        workspaces=SCENE.workspaces,
        humans={"H1": types.SimpleNamespace(size=600)},
        units="mm",
    )


def test_what_a_frame_shows():
    trace = make_trace(20, dt=0.1)
    scene = _with_person()
    animator = animation_module._Animator(scene, trace, make_plans(), "demo", DPI, shown=1.0)
    r1, r2 = animator.artists["R1"], animator.artists["R2"]
    animator.draw(0)
    assert r2["question"].get_visible() and not r1["question"].get_visible()
    assert not r2["bang"].get_visible() and not r1["cargo"].get_visible()
    assert animator.object_patch["O1"].get_visible()
    assert animator.title.get_text() == "demo    t = 0.0 s"
    disc, _ = animator.human_artists["H1"]
    assert disc.get_radius() == 300 and disc.get_visible()
    animator.draw(8)  # t = 0.8 s: R2 answered at 0.57 s and no longer waits
    assert r2["bang"].get_visible() and not r2["question"].get_visible()
    animator.draw(19)  # t = 1.9 s: more than 1 s after the message; R1 carries O1
    assert not r2["bang"].get_visible()
    assert r1["cargo"].get_visible() and not animator.object_patch["O1"].get_visible()
    x, y = r1["trail"].get_data()
    assert len(x) == 20 and (x[-1], y[-1]) == tuple(trace["frames"][19]["robots"]["R1"]["pose"][:2])
    assert animator.ax.get_xlim()[0] < -2500 and animator.ax.get_xlim()[1] > 2500


def test_mp4_starts_with_an_ftyp_box(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    assert video_available()
    path = tmp_path / "run.mp4"
    count = save_animation(SCENE, make_trace(8), path, dpi=DPI)
    assert count == 8
    assert path.read_bytes()[4:8] == b"ftyp"
    assert os.listdir(tmp_path) == ["run.mp4"]


def test_mp4_without_imageio_ffmpeg_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # importing it now fails
    with pytest.raises(ImportError, match=r"cosmop\[video\]"):
        save_animation(SCENE, make_trace(), tmp_path / "run.mp4", dpi=DPI)
    assert os.listdir(tmp_path) == []


def test_no_pyplot_figure_is_left_open(tmp_path):
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    save_animation(SCENE, make_trace(3), tmp_path / "run.gif", dpi=DPI)
    assert plt.get_fignums() == before


def test_a_frame_says_why_a_robot_stands_and_a_replan_redraws_its_path():
    trace = make_trace(20, dt=0.1)
    for k, frame in enumerate(trace["frames"]):
        if frame["robots"]["R2"]["waiting"]:
            frame["robots"]["R2"]["awaits"] = "msg(R1,R2,clear1)"
        if 12 <= k <= 14:
            frame["robots"]["R1"]["yields_to"] = "H1"
    route = {
        "from": [0, -1000, 0],
        "steps": [{"pose": [-1500, 2000, 90], "primitive": "GoTo", "about": None}],
    }
    trace["replans"] = [{"t": 1.0, "robot": "R1", "route": route}]
    scene = _with_person()
    animator = animation_module._Animator(scene, trace, make_plans(), "demo", DPI, shown=1.0)
    r1, r2 = animator.artists["R1"], animator.artists["R2"]
    (planned, _), (replanned, _) = [(line, t) for t, line in animator.plan_lines["R1"]]
    animator.draw(0)
    assert r2["why"].get_visible() and r2["why"].get_text() == "waits for a message from R1 (clear1)"
    assert not r1["why"].get_visible()
    assert planned.get_visible() and not replanned.get_visible()
    animator.draw(13)  # t = 1.3 s: R1 stands for the person, on the path of its replan
    assert r1["why"].get_visible() and r1["why"].get_text() == "waits for H1 (a person) to pass"
    assert not r2["why"].get_visible()
    assert replanned.get_visible() and not planned.get_visible()
    assert list(replanned.get_xdata()) == [0, -1500]
