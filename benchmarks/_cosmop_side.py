"""The cosmop side of ``bench_decompose.py``: the same job through the library's own path.

``build`` composes the N robot sequences into the explicit global DFA ``K`` (4^N states);
``project`` and ``verdict`` are what :func:`cosmop.missions.decomposition.decompose` runs on a
mission given as one DFA: :func:`project_locally` (N natural projections) and
:func:`separability_counterexample` (the product of the projections and its inclusion in
``K``).  ``verdict_reverse`` times the converse inclusion, outside ``total``.
"""

from __future__ import annotations

import time
from typing import Any

from cosmop.automata import inclusion_counterexample, parallel
from cosmop.missions.decomposition import project_locally, separability_counterexample
from cosmop.missions.mission import GlobalMission, sequence_automaton


def cosmop_job(n: int) -> dict[str, Any]:
    """Run the decomposition job of size ``n`` with cosmop and time its phases."""
    alphabets = {
        f"R{i}": [f"pick(R{i},O{i})", f"drop(R{i},O{i},W{i})", f"return(R{i})"] for i in range(1, n + 1)
    }
    cpu_start = time.process_time()
    t_start = time.perf_counter()
    k = parallel(*(sequence_automaton(seq) for seq in alphabets.values()))
    mission = GlobalMission.from_dfa(k, robots=alphabets)
    t_built = time.perf_counter()
    sigma = mission.alphabets
    first = project_locally(mission.automaton, {"R1": sigma["R1"]})
    t_first = time.perf_counter()
    local = first | project_locally(mission.automaton, {r: s for r, s in sigma.items() if r != "R1"})
    t_projected = time.perf_counter()
    cex = separability_counterexample(mission.automaton, local)
    t_end = time.perf_counter()
    cpu_total = time.process_time() - cpu_start
    reverse = inclusion_counterexample(k, parallel(*local.values())) is None
    t_reverse = time.perf_counter() - t_end
    return {
        "build": t_built - t_start,
        "project": t_projected - t_built,
        "project_first": t_first - t_built,
        "verdict": t_end - t_projected,
        "verdict_reverse": t_reverse,
        "total": t_end - t_start,
        "cpu_total": cpu_total,
        "states": k.n_states,
        "transitions": k.n_transitions,
        "projection_states": [d.n_states for d in local.values()],
        "separable": cex is None,
        "reverse_inclusion": reverse,
    }
