"""The checks that involve several robots' plans at once (part of the exact plan checker).

A plan set is sound for the team, beyond each robot's plan being sound alone, when

* every message is sent by exactly its sender's plan and awaited by exactly its receiver's,
  once each (``message``: a second ``Req`` or ``Res`` of one message, or an answer no
  request is left for, is one too many), and the plan file's ``messages`` list names exactly
  the ``msg`` events the plans use;
* the messages cannot deadlock the team (``deadlock``): the partial order they impose on the
  steps has no cycle (:mod:`cosmop.missions.precedence`); the shortest blocking word is given;
* every conflict between two robots' plans is ordered by the messages (``conflict``,
  :mod:`cosmop.planning.conflicts`): no execution puts two robots, or a robot and goods that
  another robot moves, in one place at one time;
* every complete run of the team is a complete word of the global mission, whatever its form
  (``mission``, :func:`cosmop.missions.team.verify_team`);
* the itinerary, when the plan file has one, keeps the messages' order (``itinerary``): no
  ``Req`` is timed to end before the ``Res`` that sends its message.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from cosmop.events import Link
from cosmop.missions.mission import GlobalMission
from cosmop.missions.precedence import Precedence
from cosmop.missions.team import check_words
from cosmop.planning.conflicts import ConflictSettings, conflicts, is_ordered, occupancies
from cosmop.planning.plan_types import PlanSet, RobotPlan
from cosmop.planning.realisation import message_links, repeated_messages, unanswered_requests, unsent_answers
from cosmop.planning.report import Violation
from cosmop.scene import Scenario

__all__ = ["check_team"]


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
        How conflicts are found (default :class:`~cosmop.planning.conflicts.ConflictSettings`).
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
    # the mission's automaton reads letters: the events' names
    words = {r: tuple(e.name for e in plans[r].mission) if r in plans else () for r in scene.robots}
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
