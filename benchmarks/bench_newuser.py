"""Six kinds of scene a new user writes first: each planned, checked and executed as a user runs them.

The scenes (issue 39's trial): a relay between two halls (``examples/12_relay``), three goods
into one dock at the back of a bay (``tests/data/shared_dock.yaml``), the 2x2 example in
metres with a robot turned by -1.5708 rad, people walking through the corridor example, six
deliveries without named robots on the MovingAI warehouse map, and a person in a doorway
(``examples/04_doorway_2x2``).  Each is planned (``cosmop plan``), checked (``cosmop check``)
and simulated from its plan (``cosmop simulate --plan``), one fresh process each.  A row says
whether each step succeeded, the planning wall time (process start and file writing
included), the planned and simulated makespans and their ratio, and the replans.

``python benchmarks/bench_newuser.py [--out NAME]`` writes ``results/NAME.json`` (default
``newuser``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

from _harness import save_results

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def scenes() -> dict[str, dict]:
    """The six scenes, as the data of their YAML files."""
    sys.path.insert(0, str(HERE))
    from movingai_gen import movingai_warehouse

    def load(path: Path) -> dict:
        return yaml.safe_load(path.read_text())

    metres = load(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
    metres = _in_metres(metres)
    metres["scene"]["robots"]["R1"]["pose"][2] = -1.5708
    corridor = load(ROOT / "examples" / "07_corridor" / "scenario.yaml")
    corridor["scene"]["humans"] = {  # a person walks through the corridor to the east room and stays
        "H1": {"size": 300, "speed": 600, "path": [[-3500, -1000], [-2000, 0], [2000, 0], [3500, 1000]]}
    }
    warehouse = movingai_warehouse(6, 2)
    tasks = warehouse["mission"].pop("tasks")
    warehouse["mission"] = {
        "deliveries": [{"object": t[0].split()[1], "to": t[1].split()[-1]} for t in tasks.values()],
        "return": True,
    }
    return {
        "relay": load(ROOT / "examples" / "12_relay" / "scenario.yaml"),
        "shared dock": load(ROOT / "tests" / "data" / "shared_dock.yaml"),
        "metres, turned robot": metres,
        "people in a corridor": corridor,
        "deliveries, MovingAI map": warehouse,
        "person in a doorway": load(ROOT / "examples" / "04_doorway_2x2" / "scenario.yaml"),
    }


def _in_metres(data: dict) -> dict:
    """A millimetre scenario written in metres (lengths / 1000, headings in radians)."""
    import math

    scene = data["scene"]
    scene["obstacles"] = [[[v / 1000 for v in p] for p in wall] for wall in scene["obstacles"]]
    for robot in scene["robots"].values():
        robot["size"] /= 1000
        x, y, h = robot["pose"]
        robot["pose"] = [x / 1000, y / 1000, math.radians(h)]
    for obj in scene["objects"].values():
        obj["size"] /= 1000
        obj["position"] = [v / 1000 for v in obj["position"]]
    for ws in scene["workspaces"].values():
        for axis in ("x", "y"):
            ws[axis] = [v / 1000 for v in ws[axis]]
    return {"units": "m", **data}


def run(name: str, data: dict, folder: Path, timeout: float) -> dict:
    """Plan, check and simulate one scene as a user does."""
    cosmop = [sys.executable, "-m", "cosmop"]
    path, plan, summary = folder / "scene.yaml", folder / "plan.json", folder / "summary.json"
    path.write_text(yaml.safe_dump(data, sort_keys=False, default_flow_style=None))
    row: dict = {"scene": name}
    t = time.perf_counter()
    planned = subprocess.run(
        [*cosmop, "plan", str(path), "-o", str(plan)], capture_output=True, timeout=timeout
    )
    row["plan_s"] = round(time.perf_counter() - t, 2)
    row["plan"] = {0: "feasible", 1: "infeasible"}.get(planned.returncode, f"exit {planned.returncode}")
    if planned.returncode != 0:
        row["why"] = planned.stdout.decode()[-400:] + planned.stderr.decode()[-400:]
        return row
    checked = subprocess.run([*cosmop, "check", str(path), str(plan)], capture_output=True, timeout=timeout)
    row["check"] = "valid" if checked.returncode == 0 else f"exit {checked.returncode}"
    makespan = max(
        (s["end"] for r in json.loads(plan.read_text())["robots"].values() for s in r["steps"]), default=0.0
    )
    row["planned_s"] = round(makespan, 1)
    sim = subprocess.run(
        [*cosmop, "simulate", str(path), "--plan", str(plan), "--summary", str(summary)],
        capture_output=True,
        timeout=timeout,
    )
    if not summary.exists():
        return row | {"completed": False, "sim": f"exit {sim.returncode}"}
    result = json.loads(summary.read_text())
    row |= {
        "completed": result["completed"],
        "simulated_s": round(result["sim_time_s"], 1),
        "simulated_over_planned": round(result["sim_time_s"] / makespan, 2) if makespan else None,
        "replans": result["replans"],
        "contacts_while_moving": result["contacts_while_moving"],
    }
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout", type=float, default=1200.0)
    parser.add_argument("--out", default="newuser")
    args = parser.parse_args()
    rows = []
    for name, data in scenes().items():
        with tempfile.TemporaryDirectory() as tmp:
            row = run(name, data, Path(tmp), args.timeout)
        rows.append(row)
        print(json.dumps(row), flush=True)
    print(f"written {save_results(args.out, rows)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
