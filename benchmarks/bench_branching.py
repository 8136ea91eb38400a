"""Branching local missions: the automaton in CLTLB(D) against planning every word alone.

Two workloads, each in a fresh subprocess:

* ``rooms``: seeded one-robot rooms (``tests/rooms.py``) whose mission is a DFA of 8 words
  (two goods in either order, each to one of two docks, then home).  Per seed: the shortest
  K over the words planned one by one (brute force), the K of one synthesis over the
  automaton (must be equal), and the seconds of each (median of ``--repeat`` runs);
* ``chain``: the paper's 10x10, every robot's task list planned as a sequence (the until
  chain, the fast path) and as a chain automaton: K and requests must be equal; seconds.

``python benchmarks/bench_branching.py [--seeds 10] [--repeat 3]`` writes
``results/branching.json``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

from _harness import child_row, save_results

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def _timed(fn, repeat: int):
    runs = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        runs.append(time.perf_counter() - t)
    return out, statistics.median(runs)


def rooms(seed: int, repeat: int) -> dict:
    sys.path.insert(0, str(ROOT / "tests"))
    from cosmop.automata import DFA
    from cosmop.planning.checker import check_robot_plan
    from cosmop.planning.synthesis import synthesize
    from cosmop.scenario import parse_scenario
    from rooms import branching_words, room

    scene = parse_scenario(room(seed)).scene
    words = branching_words()

    def each():
        return [synthesize(scene, "R1", w, max_horizon=20, explain=False) for w in words]

    def once():
        return synthesize(scene, "R1", DFA.from_words(words), max_horizon=20, explain=False)

    alone, words_s = _timed(each, repeat)
    branching, branching_s = _timed(once, repeat)
    feasible = [r.horizon for r in alone if r.feasible]
    return {
        "workload": "rooms",
        "seed": seed,
        "best_word_K": min(feasible) if feasible else None,
        "branching_K": branching.horizon,
        "checker_errors": len(check_robot_plan(scene, "R1", branching.plan)) if branching.feasible else None,
        "words_s": round(words_s, 3),
        "branching_s": round(branching_s, 3),
    }


def chain(repeat: int) -> dict:
    from cosmop.automata import DFA
    from cosmop.planning.synthesis import synthesize
    from cosmop.scenario import load_scenario

    example = load_scenario(ROOT / "examples" / "02_warehouse_10x10" / "scenario.yaml")
    words = {r: tuple(e.name for e in evs) for r, evs in example.mission.tasks.items()}

    def plan(as_chain: bool):
        return {
            r: synthesize(example.scene, r, DFA.from_word(w, closed=False) if as_chain else w)
            for r, w in words.items()
        }

    seq, seq_s = _timed(lambda: plan(False), repeat)
    auto, auto_s = _timed(lambda: plan(True), repeat)

    def answer(res):
        return res.horizon, sorted(res.requests)

    same = all(answer(seq[r]) == answer(auto[r]) for r in words)
    return {
        "workload": "chain",
        "robots": len(words),
        "K_and_requests_equal": same,
        "K": {r: seq[r].horizon for r in words},
        "sequence_s": round(seq_s, 3),
        "automaton_s": round(auto_s, 3),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--child", nargs="*")
    args = parser.parse_args(argv)
    if args.child is not None:
        kind, *rest = args.child
        row = rooms(int(rest[0]), args.repeat) if kind == "rooms" else chain(args.repeat)
        print(json.dumps(row))
        return 0
    script = str(Path(__file__).resolve())
    rows = []
    for seed in range(args.seeds):
        rows.append(child_row(script, "--repeat", str(args.repeat), "--child", "rooms", str(seed)))
        print(json.dumps(rows[-1]), flush=True)
    rows.append(child_row(script, "--repeat", str(args.repeat), "--child", "chain"))
    print(json.dumps(rows[-1]), flush=True)
    print(f"written to {save_results('branching', rows)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
