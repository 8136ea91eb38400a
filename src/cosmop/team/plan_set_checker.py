"""The exact checker of a plan set: each robot's plan, and the rules that involve several robots.

:func:`check_plan` checks every robot's plan (:func:`cosmop.planning.checker.check_robot_plan`)
and adds the checks that involve the whole plan set: the plan names the
scenario, every robot exists, a task-list mission is contained in each robot's plan (the
coordinator only adds ``away`` events), and request/response pairs agree with the missions.

A plan set is sound for the team (:func:`check_team`), beyond each robot's plan being sound
alone, when

* every message is sent by exactly its sender's plan and awaited by exactly its receiver's,
  once each (``message``: a second ``Req`` or ``Res`` of one message, or an answer no
  request is left for, is one too many), and the plan file's ``messages`` list names exactly
  the ``msg`` events the plans use;
* the messages cannot deadlock the team (``deadlock``): the partial order they impose on the
  steps has no cycle (:mod:`cosmop.team.precedence`); the shortest blocking word is given;
* every conflict between two robots' plans is ordered by the messages (``conflict``,
  :mod:`cosmop.team.conflicts`): no execution puts two robots, or a robot and goods that
  another robot moves, in one place at one time;
* every complete run of the team is a complete word of the global mission, whatever its form
  (``mission``, :func:`cosmop.team.mission_proof.verify_team`);
* the itinerary, when the plan file has one, keeps the messages' order (``itinerary``): no
  ``Req`` is timed to end before the ``Res`` that sends its message.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from cosmop.events import Event, Link, Primitive
from cosmop.missions.mission import GlobalMission
from cosmop.planning.checker import check_robot_plan
from cosmop.planning.plan_types import PlanSet, RobotPlan
from cosmop.planning.realisation import message_links, repeated_messages, unanswered_requests, unsent_answers
from cosmop.planning.report import CheckReport, Violation
from cosmop.scene import Scenario
from cosmop.team.conflicts import ConflictSettings, conflicts, is_ordered, occupancies
from cosmop.team.mission_proof import check_words
from cosmop.team.precedence import Precedence

__all__ = ["check_plan", "check_team"]


def _violation(robot: str | None, instant: int | None, rule: str, message: str) -> Violation:
    return Violation(robot, instant, rule, message)


def _messages(plan: PlanSet, plans: Mapping[str, RobotPlan]) -> list[Violation]:
    out = []
    links = message_links(plans)
    for link in links:
        if link.send is None:
            out.append(
                _violation(
                    link.receiver,
                    link.wait,
                    "message",
                    f"{link.receiver} waits at instant {link.wait} for {link.event.name}, which "
                    f"{link.sender}'s plan never sends: the robot would wait forever",
                )
            )
        if link.wait is None:
            out.append(
                _violation(
                    link.sender,
                    link.send,
                    "message",
                    f"{link.sender} sends {link.event.name} at instant {link.send}, but "
                    f"{link.receiver}'s plan never waits for it",
                )
            )
    for robot, instant, obj in unanswered_requests(plans):
        out.append(
            _violation(
                robot,
                instant,
                "message",
                f"{robot} waits at instant {instant} for {obj} to be moved away, but its mission has "
                f"no away({obj},{robot},...) event left: no robot answers, it would wait forever",
            )
        )
    for robot, instant, obj in unsent_answers(plans):
        out.append(
            _violation(
                robot,
                instant,
                "message",
                f"{robot} answers Res({obj}) at instant {instant}, but its mission has no "
                f"away({obj},...,{robot}) event left: every request is answered once, so this answer "
                "is one too many",
            )
        )
    for robot, instant, event, first in repeated_messages(plans):
        does = "sends" if event.sender == robot else "awaits"
        out.append(
            _violation(
                robot,
                instant,
                "message",
                f"{robot} {does} {event.name} again at instant {instant} (first at instant {first}); "
                "every message is sent once and awaited once",
            )
        )
    used = {link.event.name for link in links if link.event.kind == "msg"}
    listed = {m.event.name for m in plan.messages}
    for name in sorted(used - listed):
        out.append(_violation(None, None, "message", f"the plans use {name}, but the messages list lacks it"))
    for name in sorted(listed - used):
        out.append(_violation(None, None, "message", f"the messages list has {name}, but no plan uses it"))
    return out


def check_team(
    scenario: Scenario, plan: PlanSet, settings: ConflictSettings | None = None
) -> list[Violation]:
    """The violations of the team-level rules (module docstring) by a feasible plan set.

    Parameters
    ----------
    scenario : Scenario
        The scenario the plans are for (scene and global mission).
    plan : PlanSet
        The plan file: every robot's plan, the messages list, the itinerary if any.
    settings : ConflictSettings, optional
        How conflicts are found (default :class:`~cosmop.team.conflicts.ConflictSettings`).
    """
    scene = scenario.scene
    plans = {r: p for r, p in plan.robots.items() if r in scene.robots}
    violations = _messages(plan, plans)
    links = message_links(plans)
    precedence = Precedence({r: p.horizon for r, p in plans.items()}, links)
    if not precedence.complete:
        done = [f"{r}@{k}" for r, k in precedence.order]
        stuck = ", ".join(f"{r} at instant {k}" for r, k in precedence.stuck.items())
        violations.append(
            _violation(
                None,
                None,
                "deadlock",
                f"the plans' messages can deadlock: after the steps {' '.join(done) or '(none)'} "
                f"nobody can go on ({stuck} wait for messages that are never sent)",
            )
        )
        return violations
    violations += _itinerary(plan, links)
    items, problems = occupancies(scene, plans, precedence, settings)
    violations += [_violation(None, None, "conflict", text) for text in problems]
    for conflict in conflicts(items, settings.clearance if settings else None):
        if not is_ordered(conflict, precedence):
            violations.append(
                _violation(
                    None,
                    None,
                    "conflict",
                    f"{conflict.describe()}, and no message orders them: the robots may meet there",
                )
            )
    words = {r: plans[r].word if r in plans else () for r in scene.robots}
    verdict = check_words(GlobalMission.from_scenario(scenario), words)
    if not verdict.holds:
        violations.append(_violation(None, None, "mission", f"{verdict.reason()}"))
    return violations


def _itinerary(plan: PlanSet, links: Sequence[Link]) -> list[Violation]:
    """Every awaited message is timed to be sent before its wait ends (1 ms of rounding)."""
    it = plan.itinerary
    if it is None:
        return []
    out = []
    for link in links:
        if link.send is None or link.wait is None or not {link.sender, link.receiver} <= set(it.times):
            continue
        sent = it.slot(link.sender, link.send)[1]
        waited = it.slot(link.receiver, link.wait)[1]
        if waited < sent - 1e-3:
            out.append(
                _violation(
                    link.receiver,
                    link.wait,
                    "itinerary",
                    f"the itinerary has {link.receiver} stop waiting for {link.event.name} at {waited:g} s "
                    f"(instant {link.wait}), but {link.sender} sends it at {sent:g} s (instant {link.send})",
                )
            )
    return out


def check_plan(scenario: Scenario, plan: PlanSet) -> CheckReport:
    """Check a plan set against its scenario.

    Every robot plan is checked with :func:`check_robot_plan`. The plan set as a whole must
    also name the scenario; when the mission is given as task lists and the plan is feasible,
    every robot with tasks has a plan whose mission contains its tasks in order, with only
    ``away`` events added; every ``away`` event of a mission has its coordination pair, and
    every pair appears in the missions of the requester and the responder.  The plan's added
    tasks (goods moved out of a robot's way) extend the scene by their places and the task
    lists by their two events; their places must not reuse a workspace id of the scenario.

    Parameters
    ----------
    scenario : Scenario
        The scenario the plan is for.
    plan : PlanSet
        The plans.

    Returns
    -------
    CheckReport
        ``ok`` when there is no violation; ``checked_steps`` counts the steps of the robots of
        the scene.
    """
    violations: list[Violation] = [
        Violation(
            t.robot,
            None,
            "mission",
            f"{t.robot}: the added task sets {t.object} down at {t.workspace}, but the scenario has a "
            f"workspace {t.workspace} already; name the place anew",
        )
        for t in plan.added
        if t.workspace in scenario.scene.workspaces
    ]
    scenario = plan.extend(scenario)
    scene = scenario.scene
    if plan.scenario != scenario.name:
        violations.append(
            Violation(
                None,
                None,
                "scenario",
                f"the plan is for scenario {plan.scenario!r}, but the scenario is {scenario.name!r}",
            )
        )
    checked = 0
    moved = {
        s.object
        for p in plan.robots.values()
        for s in p.steps
        if s.primitive == Primitive.PICKUP and s.object is not None  # (a PickUp always has one)
    }
    for robot_id, robot_plan in plan.robots.items():
        violations.extend(check_robot_plan(scene, robot_id, robot_plan, moved=moved))
        if robot_id in scene.robots:
            checked += robot_plan.horizon
    tasks = scenario.mission.tasks if scenario.mission is not None else None
    if tasks is not None and plan.feasible:
        added: dict[str, set[Event]] = {}
        for task in plan.added:
            added.setdefault(task.robot, set()).update(task.events)
        for robot_id in sorted(set(tasks) | set(added), key=str):
            sequence = tasks.get(robot_id, ())
            violations.extend(
                _check_tasks(robot_id, sequence, plan.robots.get(robot_id), added.get(robot_id, set()))
            )
    violations.extend(_check_coordination(plan))
    if not plan.feasible:
        violations.append(
            Violation(None, None, "infeasible", f"the plan file marks the scenario infeasible: {plan.reason}")
        )
    elif not violations:  # the team-level rules presume sound single plans
        violations.extend(check_team(scenario, plan))
    return CheckReport(not violations, tuple(violations), checked)


def _check_tasks(
    robot_id: str, sequence: tuple[Event, ...], plan: RobotPlan | None, extra: set[Event]
) -> list[Violation]:
    """The plan's mission holds the tasks in order, adding only messages and the `extra` events."""
    if not sequence and not extra:
        return []
    tasks = ", ".join(e.name for e in sequence) or "none"
    if plan is None:
        return [
            Violation(
                robot_id,
                None,
                "mission",
                f"{robot_id}: the scenario gives {robot_id} the tasks {tasks}, "
                f"but the plan has no plan for {robot_id}",
            )
        ]
    events = plan.mission
    matched: set[int] = set()
    position = 0
    for task in sequence:
        while position < len(events) and events[position] != task:
            position += 1
        if position == len(events):
            return [
                Violation(
                    robot_id,
                    None,
                    "mission",
                    f"{robot_id}: the plan's mission ({', '.join(e.name for e in plan.mission) or 'empty'}) "
                    f"does not contain the scenario's tasks ({tasks}) in order; {task.name} is missing",
                )
            ]
        matched.add(position)
        position += 1
    missing = sorted(e.name for e in extra if e not in events)
    if missing:
        return [
            Violation(
                robot_id,
                None,
                "mission",
                f"{robot_id}: the plan file adds a task for {robot_id}, but its mission lacks "
                f"{', '.join(missing)}",
            )
        ]
    added = [e.name for i, e in enumerate(events) if i not in matched and not e.is_message and e not in extra]
    if added:
        return [
            Violation(
                robot_id,
                None,
                "mission",
                f"{robot_id}: the plan's mission adds {', '.join(added)}, which the scenario's tasks "
                f"({tasks}) do not have; only messages (away, msg) may be added",
            )
        ]
    return []


def _check_coordination(plan: PlanSet) -> list[Violation]:
    violations = []
    pairs = {pair.event for pair in plan.coordination}
    for robot_id, robot_plan in plan.robots.items():
        for event in robot_plan.mission:
            if event.kind == "away" and robot_id in event.owners and event not in pairs:
                violations.append(
                    Violation(
                        robot_id,
                        None,
                        "coordination",
                        f"{robot_id}: the mission has {event.name}, but the plan's coordination list "
                        f"has no pair {{object: {event.obj}, requester: {event.robot}, "
                        f"responder: {event.responder}}}",
                    )
                )
    for pair in plan.coordination:
        event = pair.event
        for role, robot_id in (("requester", pair.requester), ("responder", pair.responder)):
            planned = plan.robots.get(robot_id)
            if planned is None:
                if plan.feasible:
                    violations.append(
                        Violation(
                            robot_id,
                            None,
                            "coordination",
                            f"{robot_id}: the coordination pair {event.name} names {robot_id} as {role}, "
                            f"but the plan has no plan for {robot_id}",
                        )
                    )
            elif event not in planned.mission:
                primitive = Primitive.REQ if role == "requester" else Primitive.RES
                violations.append(
                    Violation(
                        robot_id,
                        None,
                        "coordination",
                        f"{robot_id}: the coordination pair {event.name} names {robot_id} as {role}, but its "
                        f"mission does not include {event.name} (realised by {primitive}({pair.object}))",
                    )
                )
    return violations
