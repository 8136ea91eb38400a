"""Why a robot stands: the trace records it (``awaits``, ``yields_to``, ``replans``) and the
pictures say it in plain words (:mod:`cosmop.viz.explain`)."""

from __future__ import annotations

import json
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from cosmop.events import parse_event
from cosmop.planning.plan_types import PlanMessage
from cosmop.scenario import load_scenario
from cosmop.traces import Trace, TraceError, load_trace
from cosmop.viz.explain import Explainer, waiting_words
from run_2x2 import EXAMPLE, run_2x2

PEOPLE = EXAMPLE.parents[1] / "03_people_2x2" / "scenario.yaml"


def test_the_trace_says_which_message_a_waiting_robot_waits_for():
    scenario, plans, result = run_2x2()
    trace = result.trace()
    r1 = trace.robot_ids.index("R1")
    waits = [k for k in range(len(trace.t)) if trace.waiting[k, r1]]
    named = [k for k in waits if trace.awaits[k, r1] == "away(O2,R1,R2)"]
    # every frame it waits names the message, but the cycle it has come (the robot still brakes)
    assert len(named) >= len(waits) - 1 > 50
    assert all(v is None for k, v in enumerate(trace.awaits[:, r1].tolist()) if k not in named)
    assert waiting_words(scenario.scene, plans)["away(O2,R1,R2)"] == "waits for R2 to move O2 out of its way"


def test_reasons_and_replans_survive_the_file_and_are_left_out_when_null(tmp_path):
    _, _, result = run_2x2()
    trace = result.trace()
    yields = np.full(trace.awaits.shape, None, dtype=object)
    yields[5, 0] = "H1"
    replan = {"t": 1.5, "robot": "R1", "route": {"from": [0.0, 0.0, 0.0], "steps": []}}
    trace = replace(trace, yields_to=yields, replans=(replan,))
    data = trace.to_json()
    assert "yields_to" not in data["frames"][0]["robots"]["R1"]  # null: not written
    assert data["frames"][5]["robots"]["R1"]["yields_to"] == "H1"
    assert data["replans"] == [replan]
    trace.save(tmp_path / "t.json")
    assert json.loads((tmp_path / "t.json").read_text()) == data
    back = load_trace(tmp_path / "t.json")
    assert back.awaits.tolist() == trace.awaits.tolist() and back.yields_to.tolist() == yields.tolist()
    assert back.replans == (replan,)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda d: d["frames"][0]["robots"]["R1"].update(awaits=3), "frames[0].robots.R1.awaits"),
        (lambda d: d["frames"][1]["robots"]["R2"].update(yields_to=[]), "frames[1].robots.R2.yields_to"),
        (lambda d: d.update(replans={}), "replans"),
        (lambda d: d.update(replans=[{"t": 1, "robot": "R1"}]), "replans[0].route"),
        (
            lambda d: d.update(replans=[{"t": 1, "robot": "R1", "route": {"from": [0, 0], "steps": []}}]),
            "replans[0].route.from",
        ),
        (
            lambda d: d.update(
                replans=[
                    {"t": 1, "robot": "R1", "route": {"from": [0, 0, 0], "steps": [{"pose": [0, 0, 0]}]}}
                ]
            ),
            "replans[0].route.steps[0].primitive",
        ),
    ],
)
def test_a_bad_reason_or_replan_is_named(change, field):
    _, _, result = run_2x2()
    data = result.trace().to_json()
    change(data)
    with pytest.raises(TraceError) as info:
        Trace.from_json(data, "t.json")
    assert info.value.field == field


def _plans(near: tuple[float, float]):
    """Two robots' plans as the explanations read them: R1 drops O1 in W1, then sends R2 a
    message the mission orders; a conflict message at `near` (mm) and one far from any workspace."""

    def step(primitive, obj=None, message=None):
        return SimpleNamespace(primitive=primitive, object=obj, message=message)

    r1 = SimpleNamespace(
        steps=(step("GoTo"), step("DropOff", "O1"), step("Res", message=parse_event("msg(R1,R2,after)"))),
        mission=(parse_event("drop(R1,O1,W1)"), parse_event("msg(R1,R2,after)")),
    )
    x, y = near
    messages = (
        PlanMessage(parse_event("msg(R1,R2,after)"), "order", "the mission orders ..."),
        PlanMessage(
            parse_event("msg(R2,R1,clear1)"), "conflict", "...", (x - 100, y - 100, x + 100, y + 100)
        ),
        PlanMessage(
            parse_event("msg(R2,R1,clear2)"), "conflict", "...", (-9000.0, -9000.0, -8800.0, -8600.0)
        ),
        PlanMessage(parse_event("msg(R1,R2,hello)"), "mission", "the mission's message"),
    )
    return SimpleNamespace(robots={"R1": r1}, messages=messages)


def test_plain_words_for_every_reason():
    scene = load_scenario(PEOPLE).scene  # people H1 and H2, workspaces W1 and W2
    plans = _plans(near=scene.workspaces["W2"].center)
    explain = Explainer(scene, plans)
    assert explain.awaits("msg(R1,R2,after)") == "waits for R1 to drop O1 in W1 first (the mission's order)"
    assert explain.awaits("msg(R2,R1,clear1)") == "waits for R2 to clear the way near W2"
    assert explain.awaits("msg(R2,R1,clear2)") == "waits for R2 to clear the way at (-8900, -8800) mm"
    assert explain.awaits("msg(R1,R2,hello)") == "waits for R1's message hello (the mission's)"
    assert explain.awaits("msg(R3,R2,other)") == "waits for a message from R3 (other)"
    assert explain.awaits("away(O2,R1,R2)") == "waits for R2 to move O2 out of its way"
    assert explain.yields("H1") == "waits for H1 (a person) to pass"
    assert explain.yields("R2") == "gives way to R2"
    in_metres = Explainer(replace(scene, units="m"), plans)
    assert in_metres.awaits("msg(R2,R1,clear2)") == "waits for R2 to clear the way at (-8.9, -8.8) m"


def test_the_closing_line_says_which_contacts_were_people_walking_into_a_standing_robot():
    from cosmop.cli.simulate import _contacts_said
    from cosmop.sim.result import Contact

    loaded = load_scenario(PEOPLE)
    contacts = (
        Contact(1.0, "R1", "H1", False),
        Contact(2.0, "R1", "R2", False),
        Contact(3.0, "R2", "H2", False),
    )
    result = SimpleNamespace(contacts=contacts, contacts_while_moving=0)
    assert (
        _contacts_said(loaded, result)
        == "contacts 3, while moving 0 (2 a person walking into a standing robot)"
    )
    assert (
        _contacts_said(loaded, SimpleNamespace(contacts=(), contacts_while_moving=0))
        == "contacts 0, while moving 0"
    )
