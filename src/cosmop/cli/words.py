"""What the command line says a verdict means, in words a warehouse engineer uses.

The formal terms (separable, assume-guarantee, assumption sizes) are printed after these
sentences, and their statistics only with ``--verbose``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from cosmop.units import UnitSystem, show_point

if TYPE_CHECKING:
    from cosmop.missions.decomposition import Decomposition
    from cosmop.missions.verification import Verification
    from cosmop.planning.plan_types import PlanSet
    from cosmop.team.mission_proof import TeamVerdict

__all__ = ["decompose_verdict", "plan_verdict"]


def decompose_verdict(
    result: Decomposition, verification: Verification, holds: bool | None = None
) -> tuple[str, bool]:
    """One sentence on what ``cosmop decompose`` found, and whether it is good news.

    Parameters
    ----------
    result : cosmop.missions.decomposition.Decomposition
        The decomposition: whether the mission is separable, its messages or re-synthesis.
    verification : cosmop.missions.verification.Verification
        Whether the local missions together satisfy the global one.
    holds : bool, optional
        The team's verdict when it differs from `verification`'s (robots ordered by messages).
    """
    holds = verification.holds if holds is None else holds
    if not result.separable and result.messaging is not None:
        count = len(result.messaging.messages)
        return (
            "The robots' missions together do exactly the team mission once they tell each other when to "
            f"go on ({count} message{'s' if count != 1 else ''}, listed below); no task is dropped"
            + (" (proven)." if holds else ", but cosmop could not prove it."),
            holds,
        )
    if result.separable and holds:
        return (
            "The robots' missions together do exactly the team mission: each robot can work on its own "
            "list, and every way they interleave is allowed (proven).",
            True,
        )
    if result.separable:
        return (
            "The robots' missions add up to the team mission only as a split: cosmop could not prove that "
            "the robots working together never break it (see the violation below).",
            False,
        )
    example = " ".join(result.counterexample or ()) or "(none)"
    fixed = result.resynthesis is not None and result.resynthesis.converged
    tail = (
        " cosmop narrowed the robots' missions so that they can no longer do that; some events are lost "
        "(listed below)."
        if fixed
        else " cosmop could not narrow the robots' missions to fix it."
    )
    return (
        "The team mission cannot be split into independent robot missions: the robots on their own "
        f"could together do something it forbids, e.g. {example}." + tail,
        False,
    )


def plan_verdict(plans: PlanSet, verification: TeamVerdict | None, units: UnitSystem = "mm") -> str:
    """One sentence on what ``cosmop plan`` found (feasible plan sets only); places in `units`,
    the scenario file's.

    Parameters
    ----------
    plans : cosmop.planning.plan_types.PlanSet
        A feasible plan set: its hand-overs, messages and added tasks are told.
    verification : cosmop.team.mission_proof.TeamVerdict or None
        The team's verification (None: none was made, so nothing is proven).
    units : {"mm", "m"}, optional
        The scenario file's units, which places are shown in.
    """
    pairs = len(plans.coordination)
    messages = len(getattr(plans, "messages", ()))
    order = (
        f"{pairs} hand-over{'s' if pairs != 1 else ''} (one robot moves goods out of another's way, then "
        "tells it) ordered so that no robot can wait forever"
        if pairs
        else "no robot needs another"
    )
    if messages:
        order += (
            f"; {messages} message{'s' if messages != 1 else ''} make robots take turns where their routes "
            "or the mission's order need it"
        )
    for task in getattr(plans, "added", ()):
        place = show_point(task.point, units)
        order += f"; {task.robot} sets {task.object} down at {place}, a task no mission names"
    proven = (
        "and together they do exactly the team mission (proven)"
        if verification is not None and verification.holds
        else "but cosmop could not prove that together they do the team mission"
    )
    return f"Every robot has a safe plan; {order}; {proven}."
