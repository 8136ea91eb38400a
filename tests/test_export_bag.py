"""ROS 2 bag export: read the bag back with the ``mcap`` reader and check it against the trace."""

from __future__ import annotations

import json
import math

import pytest

pytest.importorskip("rosbags")
mcap_reader = pytest.importorskip("mcap.reader")
from rosbags.typesys import Stores, get_typestore  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

from cosmop.cli import app  # noqa: E402
from cosmop.export import write_bag  # noqa: E402
from cosmop.traces import load_trace  # noqa: E402
from run_2x2 import EXAMPLE, run_2x2  # noqa: E402

STORE = get_typestore(Stores.ROS2_JAZZY)
runner = CliRunner()


def read_bag(directory):
    """``{topic: [(log_time_ns, schema name, message)]}`` from the bag's MCAP file."""
    topics = {}
    with open(directory / f"{directory.name}.mcap", "rb") as handle:
        for schema, channel, message in mcap_reader.make_reader(handle).iter_messages():
            decoded = STORE.deserialize_cdr(message.data, schema.name)
            topics.setdefault(channel.topic, []).append((message.log_time, schema.name, decoded))
    return topics


def test_the_bag_holds_the_trace_in_si_units_on_standard_topics(tmp_path):
    scenario, plans, result = run_2x2()
    trace = result.trace()
    assert dict(trace.units) == {"length": "mm", "angle": "deg", "time": "s"}
    assert result.summary()["units"] == dict(trace.units)
    summary = write_bag(scenario.scene, trace, tmp_path / "run", plans=plans)
    topics = read_bag(tmp_path / "run")
    n = len(trace.t)
    assert set(topics) == {"/tf", "/R1/pose", "/R2/pose", "/R1/plan", "/R2/plan", "/scene", "/coordination"}
    assert {t: len(m) for t, m in topics.items()} == summary.counts
    assert len(topics["/tf"]) == len(topics["/R1/pose"]) == n
    assert len(topics["/R1/plan"]) == 1 and len(topics["/coordination"]) == 1
    assert topics["/R1/pose"][0][1] == "geometry_msgs/msg/PoseStamped"
    assert topics["/scene"][0][1] == "visualization_msgs/msg/MarkerArray"
    # time stamps: the frames' times, in log time and header alike
    stamps = [ns for ns, _, _ in topics["/R2/pose"]]
    assert stamps == [round(t * 1e9) for t in trace.t.tolist()]
    k = n // 2
    _, _, pose = topics["/R1/pose"][k]
    assert pose.header.stamp.sec * 10**9 + pose.header.stamp.nanosec == stamps[k]
    assert pose.header.frame_id == "map"
    # one pose against the trace: metres and a yaw quaternion (REP 103)
    x, y, heading = trace.robots_at(k)["R1"].pose
    assert pose.pose.position.x == pytest.approx(x / 1000) and pose.pose.position.y == pytest.approx(y / 1000)
    q = pose.pose.orientation
    assert math.degrees(2 * math.atan2(q.z, q.w)) == pytest.approx(heading, abs=1e-6)
    assert (q.x, q.y) == (0.0, 0.0)
    tf = topics["/tf"][k][2].transforms
    assert [t.child_frame_id for t in tf] == ["R1/base_link", "R2/base_link"]
    assert tf[0].transform.translation.x == pytest.approx(x / 1000)
    # the plan: initial pose then every GoTo pose, in metres
    path = topics["/R1/plan"][0][2]
    gotos = [s.robot for s in plans.robots["R1"].steps if s.primitive == "GoTo"]
    assert len(path.poses) == 1 + len(gotos)
    assert path.poses[-1].pose.position.x == pytest.approx(gotos[-1][0] / 1000)
    # the message, at its time, with the trace's keys
    ns, _, text = topics["/coordination"][0]
    message = json.loads(text.data)
    assert message == trace.messages[0] and ns == round(message["t"] * 1e9)
    assert message["from"] == "R2" and message["to"] == "R1"


def test_scene_markers_show_walls_goods_carriers_and_message_arrows(tmp_path):
    scenario, plans, result = run_2x2()
    trace = result.trace()
    write_bag(scenario.scene, trace, tmp_path / "run", plans=plans, rate=2.0, scene_rate=1.0)
    topics = read_bag(tmp_path / "run")
    assert len(topics["/R1/pose"]) == pytest.approx(trace.t[-1] * 2 + 1, abs=1)
    arrays = topics["/scene"]
    assert len(arrays) == pytest.approx(trace.t[-1] + 1, abs=1)
    first = {(m.ns, m.id): m for m in arrays[0][2].markers}
    walls = first[("walls", 0)]
    assert len(walls.points) == 2 * len(scenario.scene.obstacles)
    assert walls.points[0].x == scenario.scene.obstacles[0].start[0] / 1000
    assert first[("objects", 0)].scale.x == pytest.approx(0.1)  # O1's 100 mm side
    labels = {m.text for _, _, a in arrays for m in a.markers if m.ns == "robot_labels"}
    assert "R1 carries O1" in labels and "R2 carries O2" in labels
    arrows = [(ns, m) for ns, _, a in arrays for m in a.markers if m.ns == "messages"]
    t_message = trace.messages[0]["t"]
    assert arrows and all(0 <= ns / 1e9 - t_message < 2.0 for ns, _ in arrows)


def test_cli_export_and_its_bad_input(tmp_path):
    _scenario, plans, result = run_2x2()
    result.save_trace(tmp_path / "trace.json")
    plans.save(tmp_path / "plan.json")
    assert load_trace(tmp_path / "trace.json").t[0] == 0.0
    args = [
        "export",
        str(EXAMPLE),
        "--trace",
        str(tmp_path / "trace.json"),
        "--plan",
        str(tmp_path / "plan.json"),
    ]
    ok = runner.invoke(app, [*args, "--bag", str(tmp_path / "bag")])
    assert ok.exit_code == 0, ok.output
    assert "messages on 7 topics" in " ".join(ok.stdout.split())
    again = runner.invoke(app, [*args, "--bag", str(tmp_path / "bag")])
    assert again.exit_code == 2 and "exists; expected a new directory" in again.stderr
    bad = tmp_path / "bad.json"
    bad.write_text(
        json.dumps({"format": "cosmop.trace/1", "frames": [{"t": 0, "robots": {"R1": {"pose": [0]}}}]})
    )
    out = tmp_path / "nothing"
    result = runner.invoke(app, ["export", str(EXAMPLE), "--trace", str(bad), "--bag", str(out)])
    assert result.exit_code == 2 and not out.exists()
    assert f"{bad}: frames[0].robots.R1.pose: expected [x, y, heading] (mm, mm, degrees)" in result.stderr
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no staging left


def test_simulate_writes_a_bag_and_refuses_an_existing_directory_before_any_work(tmp_path):
    from dataclasses import replace

    from cosmop.team.safe_plans import make_team_safe

    scenario, plans, _ = run_2x2()
    safe = make_team_safe(scenario.scene, plans.robots)  # the CLI executes only team-safe plans
    replace(plans, robots=safe.plans, messages=safe.messages).save(tmp_path / "plan.json")
    args = ["simulate", str(EXAMPLE), "--plan", str(tmp_path / "plan.json"), "--bag", str(tmp_path / "bag")]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    topics = read_bag(tmp_path / "bag")
    assert {"/tf", "/R1/pose", "/R1/plan", "/scene", "/coordination"} <= set(topics)
    again = runner.invoke(app, [*args, "--summary", str(tmp_path / "s.json")])
    assert again.exit_code == 2 and "exists" in again.stderr
    assert not (tmp_path / "s.json").exists()  # refused before simulating


def test_a_timed_plan_stamps_each_pose_with_its_expected_time(tmp_path):
    from dataclasses import replace

    from cosmop.team.timing import itinerary

    scenario, plans, result = run_2x2()
    timed = replace(plans, itinerary=itinerary(scenario.scene, plans.robots))
    write_bag(scenario.scene, result.trace(), tmp_path / "run", plans=timed)
    path = read_bag(tmp_path / "run")["/R1/plan"][0][2]
    stamps = [p.header.stamp.sec + p.header.stamp.nanosec / 1e9 for p in path.poses]
    steps = plans.robots["R1"].steps
    expected = [0.0] + [
        timed.itinerary.slot("R1", k)[1] for k, s in enumerate(steps, 1) if s.primitive == "GoTo"
    ]
    assert stamps == pytest.approx(expected, abs=1e-9) and stamps[-1] > 0
