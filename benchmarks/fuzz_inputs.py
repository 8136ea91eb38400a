"""Hostile and mutated input files through the command line, as a user runs them (issue 12).

Two sets of files, each run as a fresh ``cosmop`` process with a time limit:

* a catalogue of hostile files (the issue's list and 10 MB files of several shapes), each
  through ``validate`` and ``plan`` (scenarios) or ``check`` and ``simulate --plan`` (plans),
  and ``/dev/zero`` (an endless stream) through ``validate`` and ``check``;
* seeded random mutations of the examples' scenario files (text edits) through ``validate``,
  and of a real plan file (a leaf replaced, a byte spliced) through ``check``.

Each process is classed by its exit status (0/1/2 are answers), whether any output holds a
Python traceback, and whether it ran past the limit; its wall time and peak memory
(``wait4``'s maximum resident set) are kept.  Writes ``results/fuzz_inputs.json``.

Usage: ``python benchmarks/fuzz_inputs.py [--mutations 300] [--seed 0] [--limit 30]``.
"""

from __future__ import annotations

import argparse
import copy
import json
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _harness import save_results

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml"
PLAN = ROOT / "tests" / "data" / "plan_2x2.json"
SCENARIOS = [
    ROOT / "examples" / name / "scenario.yaml"
    for name in ("01_warehouse_2x2", "03_people_2x2", "05_deliveries", "06_choice_dfa", "08_ordered")
]
_BITS = ["[", "]", "{", "}", ":", ",", "-", " ", "\n", "&a", "*a", "!!int", "'", '"', "#", "0", "1e400", "x"]


def run(args: list[str], limit: float) -> dict:
    """One ``cosmop`` process: exit status, traceback, time, peak memory (MiB, by GNU time)."""
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        memory = Path(tmp) / "peak"
        command = [sys.executable, "-m", "cosmop", *args]
        if Path("/usr/bin/time").exists():  # the child's own peak, not this process's at the fork
            command = ["/usr/bin/time", "-f", "%M", "-o", str(memory), *command]
        try:
            proc = subprocess.run(command, capture_output=True, timeout=limit)
            status, text, timed_out = (
                proc.returncode,
                (proc.stdout + proc.stderr).decode("utf-8", "replace"),
                False,
            )
        except subprocess.TimeoutExpired as err:
            status, text, timed_out = None, ((err.stdout or b"") + (err.stderr or b"")).decode(), True
        peak = float(memory.read_text().split()[-1]) / 1024 if memory.exists() and not timed_out else None
    return {
        "command": args[0],
        "exit": status,
        "traceback": "Traceback (most recent call last)" in text,
        "timeout": timed_out,
        "seconds": round(time.perf_counter() - start, 3),
        "peak_mib": None if peak is None else round(peak, 1),
        "last_line": text.strip().splitlines()[-1][:160] if text.strip() else "",
    }


def catalogue(base: str, plan: dict) -> dict[str, str]:
    """The hostile files, by name (``.yaml`` scenarios, ``.json`` plans)."""
    walls = "".join(f"    - [[{i}, 3000], [{i}, 3100]]\n" for i in range(400_000))
    bomb = ['&a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    bomb += [f"&a{i + 1} [" + ",".join([f"*a{i}"] * 9) + "]" for i in range(9)]
    files = {
        "nested_500.yaml": base + "extra: " + "[" * 500 + "]" * 500 + "\n",
        "nested_mapping_600.yaml": base + "x: " + "{a: " * 600 + "1" + "}" * 600 + "\n",
        "integer_5000_digits.yaml": base.replace("size: 100,", "size: " + "9" * 5000 + ","),
        "nul_byte.yaml": base.replace("warehouse-2x2", "ware\x00house"),
        "alias_bomb.yaml": "name: [" + ", ".join(bomb) + "]\n",
        "alias_cycle.yaml": "name: &a [1, *a]\n",
        "tasks_300.yaml": base.replace(
            "R1: [pick O1, drop O1 at W1, return]",
            "R1: [" + ", ".join(["pick O1, drop O1 at W1"] * 150) + "]",
        ),
        "walls_10MB.yaml": base.replace("  obstacles:", "  obstacles:\n" + walls + "  _:", 1),
        "text_10MB.yaml": base.replace("warehouse-2x2", "w" * 10_000_000),
        "comment_10MB.yaml": "#" + "c" * 10_000_000 + "\n" + base,
        "flow_list_10MB.yaml": base + "extra: [" + "1," * 5_000_000 + "1]\n",
    }
    chain = "".join(
        f"    - [s{i}, '{'pick(R1,O1)' if i % 2 == 0 else 'drop(R1,O1,W1)'}', s{i + 1}]\n"
        for i in range(20_000)
    )
    head = base.split("mission:")[0].rstrip("\n")
    files["dfa_20000_states.yaml"] = head + "\nmission:\n  dfa:\n    initial: s0\n    transitions:\n" + chain

    # issue 39's findings: each passed validate and then failed, hung or misled
    def dfa(initial: str, transitions: str) -> str:
        return head + f"\nmission:\n  dfa:\n    initial: {initial}\n    transitions: {transitions}\n"

    files |= {
        "msg_not_awaited.yaml": base.replace("R1: [pick O1,", 'R1: [pick O1, "msg(R1,R2,t)",'),
        "name_escape.yaml": base.replace("name: warehouse-2x2", 'name: "ware\\e[31mhouse"'),
        "dfa_initial_typo.yaml": dfa("q9", '[[q0, "return(R1)", q1]]'),
        "dfa_no_transitions.yaml": dfa("q0", "[]"),
        "cycle_1e-9.yaml": base.replace("  robots:", "  dynamics: {cycle: 1e-9}\n  robots:", 1),
        "max_speed_1e-300.yaml": base.replace("  robots:", "  dynamics: {max_speed: 1e-300}\n  robots:", 1),
        "millimetres_in_metres.yaml": base.replace("name: warehouse-2x2", "name: warehouse-2x2\nunits: m"),
    }
    steps = plan["robots"]["R1"]["steps"]
    text = json.dumps(plan)
    long = copy.deepcopy(plan)
    long["robots"]["R1"]["steps"] = steps[:2] + [steps[2]] * 40_000 + steps[2:]
    long["robots"]["R1"]["horizon"] = len(long["robots"]["R1"]["steps"])
    huge = copy.deepcopy(plan)
    huge["robots"]["R1"]["steps"][2]["robot"][0] = 1e308
    infeasible = copy.deepcopy(plan)
    infeasible.update(feasible=False, reason="marked infeasible by hand")
    files |= {
        "plan_integer_5000_digits.json": text.replace(
            "[1750, -1000, 0]", "[" + "9" * 5000 + ", -1000, 0]", 1
        ),
        "plan_nested_3000.json": text.replace(
            "[1750, -1000, 0]", "[" + "[" * 3000 + "]" * 3000 + ", -1000, 0]", 1
        ),
        "plan_number_1e308.json": json.dumps(huge),
        "plan_40000_steps_8MB.json": json.dumps(long),
        "plan_marked_infeasible.json": json.dumps(infeasible),
        "plan_nan.json": text.replace("[1750, -1000, 0]", "[NaN, -1000, 0]", 1),
        "plan_infinity.json": text.replace("[1750, -1000, 0]", "[Infinity, -1000, 0]", 1),
        "plan_duplicate_key.json": text.replace('"horizon": ', '"horizon": 9, "horizon": ', 1),
        "plan_escape_in_reason.json": json.dumps(infeasible | {"reason": "ok\u001b[2J"}),
        "plan_msg_awaited_twice.json": json.dumps(_repeated(plan, "R1", "Req")),
        "plan_msg_sent_twice.json": json.dumps(_repeated(plan, "R2", "Res")),
    }
    return files


def _repeated(plan: dict, robot: str, primitive: str) -> dict:
    """`plan` with `robot`'s first `msg` step of `primitive` repeated right after itself."""
    data = copy.deepcopy(plan)
    steps = data["robots"][robot]["steps"]
    k = next(i for i, s in enumerate(steps) if s["primitive"] == primitive and s.get("message"))
    again = copy.deepcopy(steps[k])
    if "end" in again:  # the itinerary: the repeat starts when the step ends
        again["start"] = again["end"]
    steps.insert(k + 1, again)
    data["robots"][robot]["horizon"] += 1
    return data


def mutate_text(text: str, rng: random.Random) -> str:
    for _ in range(rng.randint(1, 4)):
        at, cut = rng.randint(0, len(text)), rng.randint(0, 12)
        text = text[:at] + "".join(rng.choice(_BITS) for _ in range(rng.randint(0, 6))) + text[at + cut :]
    return text


def mutate_plan(plan: dict, rng: random.Random) -> str:
    if rng.random() < 0.3:  # a byte spliced into the text
        text = json.dumps(plan, indent=2)
        at = rng.randint(0, len(text))
        return text[:at] + chr(rng.choice([0, 7, 34, 44, 58, 91, 93, 123, 125, 48, 45])) + text[at:]
    data = copy.deepcopy(plan)
    paths, todo = [], [((), data)]
    while todo:
        path, value = todo.pop()
        paths.append(path)
        items = (
            value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
        )
        todo.extend(((*path, k), v) for k, v in items)
    path = rng.choice(paths[1:])
    parent = data
    for part in path[:-1]:
        parent = parent[part]
    parent[path[-1]] = rng.choice([None, True, -1, 0, 10**25, 1e308, -1e-9, "x", [], {}, [1, 2], "GoTo"])
    return json.dumps(data, indent=2)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutations", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--limit", type=float, default=30.0, help="seconds before a process counts as hung")
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    base, plan = EXAMPLE.read_text(), json.loads(PLAN.read_text())
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, content in catalogue(base, plan).items():
            path = folder / name
            path.write_text(content)
            commands = (
                [["validate", str(path)], ["plan", str(path), "-o", str(folder / "out.json")]]
                if name.endswith(".yaml")
                else [["check", str(EXAMPLE), str(path)], ["simulate", str(EXAMPLE), "--plan", str(path)]]
            )
            for command in commands:
                rows.append(
                    {"set": "hostile", "file": name, "bytes": len(content.encode())}
                    | run(command, args.limit)
                )
                print(json.dumps(rows[-1]), flush=True)
        if Path("/dev/zero").exists():  # an endless stream: refused once past the size bound
            for command in (["validate", "/dev/zero"], ["check", str(EXAMPLE), "/dev/zero"]):
                rows.append({"set": "hostile", "file": "/dev/zero", "bytes": None} | run(command, args.limit))
                print(json.dumps(rows[-1]), flush=True)
        texts = [p.read_text() for p in SCENARIOS]
        for k in range(args.mutations):
            path = folder / f"mutated_{k}.yaml"
            path.write_text(mutate_text(rng.choice(texts), rng))
            rows.append(
                {"set": "mutated scenario", "file": path.name} | run(["validate", str(path)], args.limit)
            )
            path = folder / f"mutated_{k}.json"
            path.write_text(mutate_plan(plan, rng))
            rows.append(
                {"set": "mutated plan", "file": path.name}
                | run(["check", str(EXAMPLE), str(path)], args.limit)
            )
    save_results("fuzz_inputs", rows)
    for kind in ("hostile", "mutated scenario", "mutated plan"):
        some = [r for r in rows if r["set"] == kind]
        print(
            f"{kind}: {len(some)} runs; exits "
            + ", ".join(
                f"{e}: {sum(r['exit'] == e for r in some)}" for e in sorted({r["exit"] for r in some})
            )
            + f"; tracebacks {sum(r['traceback'] for r in some)}; timeouts {sum(r['timeout'] for r in some)}"
            + f"; slowest {max(r['seconds'] for r in some):.2f} s"
            + f"; peak {max(r['peak_mib'] or 0 for r in some):.0f} MiB"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
