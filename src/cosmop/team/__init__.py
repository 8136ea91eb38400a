"""The team: everything that coordinates robots, above one robot's planning.

:mod:`~cosmop.team.loop` is the top-down / bottom-up loop (:func:`~cosmop.team.loop.plan_team`);
its steps are modules of their own: the team's :mod:`~cosmop.team.planner` (every synthesis,
under the team's restrictions), :mod:`~cosmop.team.choices` (a mission with choices committed to
its cheapest way), :mod:`~cosmop.team.initial_plans` (shared docks, relays),
:mod:`~cosmop.team.requests` (goods moved away on request, or set aside),
:mod:`~cosmop.team.detours` (the plans made team-safe, ways around long waits) and
:mod:`~cosmop.team.walls`; :mod:`~cosmop.team.cluster` runs the syntheses on a Dask cluster.

Beneath the loop: the temporal plan graph (:mod:`~cosmop.team.precedence`), conflicts between
plans and their order (:mod:`~cosmop.team.conflicts`, :mod:`~cosmop.team.conflict_search`,
:mod:`~cosmop.team.conflict_order`, :mod:`~cosmop.team.safe_plans`, :mod:`~cosmop.team.lanes`),
the itinerary (:mod:`~cosmop.team.timing`), goods set aside (:mod:`~cosmop.team.aside`), the
words with messages and their proof (:mod:`~cosmop.team.mission_proof`,
:mod:`~cosmop.team.coordination_events`, :mod:`~cosmop.team.handover`) and the exact checker of
a plan set (:mod:`~cosmop.team.plan_set_checker`).
"""
