"""The team: everything that coordinates robots, above one robot's planning.

:mod:`~cosmop.team.loop` is the top-down / bottom-up loop (:func:`~cosmop.team.loop.plan_team`);
its steps are modules of their own: the team's :mod:`~cosmop.team.planner` (every synthesis,
under the team's restrictions), :mod:`~cosmop.team.choices` (a mission with choices committed to
its cheapest way), :mod:`~cosmop.team.initial_plans` (shared docks, relays),
:mod:`~cosmop.team.requests` (goods moved away on request, or set aside),
:mod:`~cosmop.team.detours` (the plans made team-safe, ways around long waits) and
:mod:`~cosmop.team.walls`; :mod:`~cosmop.team.cluster` runs the syntheses on a Dask cluster.
"""
