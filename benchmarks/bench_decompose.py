"""Decomposition benchmark: the "N-robot warehouse" mission, libFAUDES versus cosmop.

Workload
--------
Robot ``i`` (``i = 1 .. N``) runs the sequence ``pick(Ri,Oi) drop(Ri,Oi,Wi) return(Ri)``,
a 4-state DFA whose states are all marked (a prefix-closed language).  The global
mission ``K`` is the synchronous product of the ``N`` sequences (``4**N`` states).  A job
of size ``N`` has three timed phases:

``build``
    construct the ``N`` robot DFAs and their product ``K`` (iterated binary products);
``project``
    project ``K`` onto each robot's 3 events (``N`` natural projections, with
    determinisation); ``project_first`` is the time of the first of them alone;
``verdict``
    decide separability: build the product ``P`` of the ``N`` projections and decide
    ``Lm(P) ⊆ Lm(K)``.

``total`` is ``build + project + verdict``.  The converse inclusion ``Lm(K) ⊆ Lm(P)``
always holds for projections; it is timed too, as ``verdict_reverse``, outside ``total``.

Side contract
-------------
A side is a function ``job(n) -> dict`` returning at least ``build``, ``project``,
``project_first``, ``verdict``, ``total`` (seconds, from :func:`time.perf_counter`) and
``states`` (states of ``K``); :func:`faudes_job` is the libFAUDES side, and the cosmop side
is ``cosmop_job`` in ``benchmarks/_cosmop_side.py``, imported lazily (only when that side
runs).

Runner
------
``python benchmarks/bench_decompose.py --sizes 2,3,4,5,6,7 --repeats 3 --timeout 300 \
--side both --out benchmarks/results/decompose.json``

Each ``(side, n, repeat)`` runs in a fresh subprocess, so that its peak resident memory
(``ru_maxrss`` at the end of the child, KiB) belongs to that run alone.  Linux carries
``ru_maxrss`` over ``execve`` from the spawning process, so the parent stays light (it
never imports faudes or rich before the runs end) and the child also records ``VmHWM``
and its ``ru_maxrss`` after imports (``maxrss_loaded_kib``, the baseline of the
interpreter and libraries).  The faudes child imports ``faudes`` without matplotlib and
pillow, which ``faudes`` would otherwise load for plotting only (+50 MB).  A run exceeding
``--timeout`` seconds is killed and recorded as a timeout; larger ``n`` are then skipped
on that side.  The runner prints medians per ``(side, n)`` and the ratio
``faudes_total / cosmop_total`` where both sides finished, and writes every run, the
summary and a description of the machine to the JSON file (atomically, after each run).
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import importlib
import importlib.metadata
import io
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
DEFAULT_OUT = HERE / "results" / "decompose.json"
SIDES = ("faudes", "cosmop")
PHASES = ("build", "project", "project_first", "verdict", "verdict_reverse", "total", "cpu_total")
TITLE = "Decomposition benchmark: medians per (side, n), times in seconds"
RATIO_TITLE = "Ratio of median totals (> 1: cosmop faster)"
REQUIRED_KEYS = ("build", "project", "project_first", "verdict", "total", "states")


# ------------------------------------------------------------------------------ workload


def robot_events(i: int) -> list[str]:
    """Return the event sequence of robot ``i``.

    Parameters
    ----------
    i : int
        Robot number, from 1.

    Returns
    -------
    list of str
        ``[pick(Ri,Oi), drop(Ri,Oi,Wi), return(Ri)]``.
    """
    return [f"pick(R{i},O{i})", f"drop(R{i},O{i},W{i})", f"return(R{i})"]


def _import_faudes() -> Any:
    """Import ``faudes`` without matplotlib and pillow, silencing what it prints.

    ``faudes`` imports ``matplotlib.pyplot`` and ``PIL`` at import time, for
    ``Generator.GraphShow`` only; that costs about 0.7 s and 50 MB of resident memory,
    which would distort the peak-memory figures.  Both are blocked during the import
    unless already loaded (the blocking entries are removed afterwards).
    """
    blocked = [name for name in ("matplotlib", "PIL") if name not in sys.modules]
    for name in blocked:
        sys.modules[name] = None  # type: ignore[assignment]  # makes "import name" fail
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            import faudes
    finally:
        for name in blocked:
            if sys.modules.get(name, 0) is None:
                del sys.modules[name]
    return faudes


def _faudes_sequence(fd: Any, events: list[str]) -> Any:
    """Build the prefix-closed sequence DFA ``events[0] events[1] ...`` as a faudes Generator."""
    gen = fd.Generator()
    for ev in events:
        gen.InsEvent(ev)
    for q in range(1, len(events) + 2):
        gen.InsState(q)
        gen.SetMarkedState(q)
    gen.SetInitState(1)
    for q, ev in enumerate(events, start=1):
        gen.SetTransition(q, gen.EventIndex(ev), q + 1)
    return gen


def faudes_job(n: int) -> dict[str, Any]:
    """Run the decomposition job of size ``n`` with libFAUDES and time its phases.

    State names are switched off (``faudes.StateNamesOff``) so that ``faudes.Parallel``
    does not build a ``"x|y"`` name per product state.

    Parameters
    ----------
    n : int
        Number of robots (``n >= 1``).

    Returns
    -------
    dict
        Phase times in seconds (``build``, ``project``, ``project_first``, ``verdict``,
        ``verdict_product``, ``verdict_inclusion``, ``verdict_reverse``, ``total``), the
        process CPU time of the timed phases ``cpu_total`` (less sensitive than ``total``
        to other load on the machine), the
        state counts (``states`` of ``K``, ``projection_states``, ``product_states``),
        ``transitions`` of ``K``, the verdict ``separable`` and ``reverse_inclusion``.
    """
    fd = _import_faudes()
    fd.StateNamesOff()
    alphabets = [robot_events(i) for i in range(1, n + 1)]

    cpu_start = time.process_time()
    t_start = time.perf_counter()
    robots = [_faudes_sequence(fd, events) for events in alphabets]
    mission = robots[0]
    for robot in robots[1:]:
        mission = fd.Parallel(mission, robot)
    t_built = time.perf_counter()

    projections = []
    project_first = 0.0
    for k, events in enumerate(alphabets):
        sigma = fd.EventSet()
        for ev in events:
            sigma.Insert(ev)
        t0 = time.perf_counter()
        projections.append(fd.Project(mission, sigma))
        if k == 0:
            project_first = time.perf_counter() - t0
    t_projected = time.perf_counter()

    product = projections[0]
    for proj in projections[1:]:
        product = fd.Parallel(product, proj)
    t_product = time.perf_counter()
    separable = bool(fd.LanguageInclusion(product, mission))
    t_end = time.perf_counter()
    cpu_total = time.process_time() - cpu_start

    reverse = bool(fd.LanguageInclusion(mission, product))
    t_reverse = time.perf_counter() - t_end

    return {
        "build": t_built - t_start,
        "project": t_projected - t_built,
        "project_first": project_first,
        "verdict": t_end - t_projected,
        "verdict_product": t_product - t_projected,
        "verdict_inclusion": t_end - t_product,
        "verdict_reverse": t_reverse,
        "total": t_end - t_start,
        "cpu_total": cpu_total,
        "states": int(mission.Size()),
        "transitions": int(mission.TransRelSize()),
        "projection_states": [int(p.Size()) for p in projections],
        "product_states": int(product.Size()),
        "separable": separable,
        "reverse_inclusion": reverse,
    }


def _load_job(side: str) -> Callable[[int], dict[str, Any]]:
    """Return the job function of ``side`` (imports the cosmop side lazily)."""
    if side == "faudes":
        _import_faudes()
        return faudes_job
    if side == "cosmop":
        if str(HERE) not in sys.path:
            sys.path.insert(0, str(HERE))
        return importlib.import_module("_cosmop_side").cosmop_job
    raise ValueError(f"unknown side {side!r}")


def _cosmop_side_available() -> bool:
    return (HERE / "_cosmop_side.py").is_file()


# --------------------------------------------------------------------------------- child


def _child_main(side: str, n: int, result_path: str) -> int:
    """Run one job in this (fresh) process and write its result as JSON to ``result_path``."""
    rss_start = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    job = _load_job(side)
    rss_loaded = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    result = job(n)
    missing = [key for key in REQUIRED_KEYS if key not in result]
    if missing:
        raise KeyError(f"{side} job result lacks {missing}")
    usage = resource.getrusage(resource.RUSAGE_SELF)
    payload = {
        "result": result,
        "cpu_user_s": usage.ru_utime,
        "cpu_sys_s": usage.ru_stime,
        "maxrss_kib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
        "maxrss_loaded_kib": rss_loaded,
        "maxrss_start_kib": rss_start,
        "vmhwm_kib": _vm_hwm_kib(),
    }
    Path(result_path).write_text(json.dumps(payload))
    return 0


def _vm_hwm_kib() -> int | None:
    """Peak resident set of this process image (``VmHWM`` in ``/proc/self/status``), KiB.

    Unlike ``ru_maxrss``, which Linux carries over an ``execve`` from the process that
    spawned us, ``VmHWM`` starts afresh with the new image.
    """
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def _faudes_version_main() -> int:
    print(_import_faudes().Version())
    return 0


# -------------------------------------------------------------------------------- runner


def run_one(side: str, n: int, timeout: float) -> dict[str, Any]:
    """Run one ``(side, n)`` job in a fresh subprocess.

    Parameters
    ----------
    side : {"faudes", "cosmop"}
        The implementation to run.
    n : int
        Number of robots.
    timeout : float
        Seconds after which the child is killed.

    Returns
    -------
    dict
        ``status`` (``"ok"``, ``"timeout"`` or ``"error"``), ``wall`` seconds and, when
        ``ok``, the job ``result`` and ``maxrss_kib`` (peak resident set of the child,
        KiB); on error, the tail of the child's stderr.
    """
    with tempfile.TemporaryDirectory(prefix="bench_decompose_") as tmp:
        result_path = os.path.join(tmp, "result.json")
        cmd = [sys.executable, str(Path(__file__).resolve()), "--child", side, "--n", str(n)]
        cmd += ["--result-file", result_path]
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
        except subprocess.TimeoutExpired:
            return {"status": "timeout", "wall": time.perf_counter() - t0}
        wall = time.perf_counter() - t0
        if proc.returncode != 0 or not os.path.exists(result_path):
            tail = (proc.stderr or proc.stdout or "").strip().splitlines()[-15:]
            return {"status": "error", "wall": wall, "returncode": proc.returncode, "stderr": tail}
        payload = json.loads(Path(result_path).read_text())
    return {"status": "ok", "wall": wall, **payload}


def machine_info(sides: list[str]) -> dict[str, Any]:
    """Describe the machine and the software versions.

    Parameters
    ----------
    sides : list of str
        The sides being run (``faudes`` is imported only when it is one of them).

    Returns
    -------
    dict
        Processor, CPU model, CPU count, total memory, OS, Python, numpy and faudes
        versions and the date (UTC, ISO 8601).
    """
    info: dict[str, Any] = {
        "processor": platform.processor(),
        "cpu_model": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "mem_total_kib": _mem_total_kib(),
        "platform": platform.platform(),
        "machine": platform.machine(),
        "python": platform.python_version(),
        "python_implementation": platform.python_implementation(),
        "numpy": _dist_version("numpy"),
        "faudes": _dist_version("faudes"),
        "libfaudes": None,
        "date": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "loadavg_1min": os.getloadavg()[0],
    }
    if info["mem_total_kib"]:
        info["mem_total_gib"] = round(info["mem_total_kib"] / 1024**2, 2)
    if "faudes" in sides:
        # in a subprocess: importing faudes here would inflate ru_maxrss of every child
        cmd = [sys.executable, str(Path(__file__).resolve()), "--faudes-version"]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)
        if proc.returncode == 0 and proc.stdout.strip():
            info["libfaudes"] = proc.stdout.strip().splitlines()[-1]
    return info


def _dist_version(name: str) -> str | None:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def _mem_total_kib() -> int | None:
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemTotal:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def _cpu_model() -> str | None:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def summarise(runs: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Compute medians per ``(side, n)`` and the faudes/cosmop ratios.

    Parameters
    ----------
    runs : list of dict
        Run records (``side``, ``n``, ``repeat``, ``status``, ...).

    Returns
    -------
    summary : list of dict
        One row per ``(side, n)``: ``status`` (``ok`` if any run finished, else the first
        run's status), ``runs_ok``, ``runs``, ``states`` and the median of each phase, of
        the peak memory (``peak_mib``) and of the child's wall time.
    ratios : list of dict
        One row per ``n`` where both sides finished: both median totals and
        ``ratio = faudes_total / cosmop_total`` (and ``cpu_ratio`` of the ``cpu_total``
        medians when both sides report it).
    """
    groups: dict[tuple[str, int], list[dict[str, Any]]] = {}
    for run in runs:
        groups.setdefault((run["side"], run["n"]), []).append(run)
    summary = []
    order = {side: k for k, side in enumerate(SIDES)}
    for (side, n), group in sorted(groups.items(), key=lambda item: (order.get(item[0][0], 99), item[0])):
        ok = [r for r in group if r["status"] == "ok"]
        row: dict[str, Any] = {
            "side": side,
            "n": n,
            "status": "ok" if ok else group[0]["status"],
            "runs_ok": len(ok),
            "runs": len(group),
        }
        if ok:
            row["states"] = ok[0]["result"]["states"]
            for phase in PHASES:
                values = [r["result"][phase] for r in ok if phase in r["result"]]
                row[phase] = statistics.median(values) if values else None
            row["peak_mib"] = statistics.median(r["maxrss_kib"] / 1024 for r in ok)
            row["loaded_mib"] = statistics.median(r["maxrss_loaded_kib"] / 1024 for r in ok)
            hwm = [r["vmhwm_kib"] / 1024 for r in ok if r.get("vmhwm_kib")]
            row["hwm_mib"] = statistics.median(hwm) if hwm else None
            row["wall"] = statistics.median(r["wall"] for r in ok)
            row["separable"] = ok[0]["result"].get("separable")
        summary.append(row)
    by_key = {(row["side"], row["n"]): row for row in summary}
    ratios = []
    for n in sorted({row["n"] for row in summary}):
        f, c = by_key.get(("faudes", n)), by_key.get(("cosmop", n))
        if f and c and f["status"] == "ok" and c["status"] == "ok" and c["total"]:
            ratios.append({"n": n, "faudes_total": f["total"], "cosmop_total": c["total"]})
            ratios[-1]["ratio"] = f["total"] / c["total"]
            if f.get("cpu_total") and c.get("cpu_total"):
                ratios[-1]["cpu_ratio"] = f["cpu_total"] / c["cpu_total"]
    return summary, ratios


def write_json_atomic(path: Path, data: Any) -> None:
    """Write ``data`` as JSON to ``path`` atomically (temporary file + :func:`os.replace`).

    Parameters
    ----------
    path : Path
        Destination; its directory is created if needed.
    data : Any
        JSON-serialisable data.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.fchmod(fd, 0o666 & ~umask)  # mkstemp creates 0600 files
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=2)
            fh.write("\n")
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _fmt(value: Any, digits: int = 4) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}" if value < 100 else f"{value:.1f}"
    return str(value)


def print_tables(summary: list[dict[str, Any]], ratios: list[dict[str, Any]]) -> None:
    """Print the medians and ratios, with :mod:`rich` when it is installed.

    Parameters
    ----------
    summary, ratios : list of dict
        As returned by :func:`summarise`.
    """
    headers = ["side", "n", "states", "runs", *PHASES, "peak MiB", "status"]
    rows = []
    for row in summary:
        rows.append(
            [
                row["side"],
                str(row["n"]),
                _fmt(row.get("states")),
                f"{row['runs_ok']}/{row['runs']}",
                *(_fmt(row.get(p)) for p in PHASES),
                _fmt(row.get("peak_mib"), 1),
                row["status"],
            ]
        )
    ratio_headers = ["n", "faudes total", "cosmop total", "faudes / cosmop", "same, CPU time"]
    ratio_rows = [
        [
            str(r["n"]),
            _fmt(r["faudes_total"]),
            _fmt(r["cosmop_total"]),
            f"{r['ratio']:.2f}",
            f"{r['cpu_ratio']:.2f}" if "cpu_ratio" in r else "-",
        ]
        for r in ratios
    ]
    try:
        from rich.console import Console
        from rich.table import Table
    except ImportError:
        _print_plain(TITLE, headers, rows)
        if ratio_rows:
            _print_plain(RATIO_TITLE, ratio_headers, ratio_rows)
        return
    console = Console()
    if not console.is_terminal:
        console = Console(width=max(console.width, 140))
    for title, head, body in (
        (TITLE, headers, rows),
        (RATIO_TITLE, ratio_headers, ratio_rows),
    ):
        if not body:
            continue
        table = Table(title=title)
        for i, h in enumerate(head):
            table.add_column(h, justify="left" if i == 0 or h == "status" else "right")
        for r in body:
            table.add_row(*r)
        console.print(table)


def _print_plain(title: str, headers: list[str], rows: list[list[str]]) -> None:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)]
    print(title)
    print("  ".join(h.rjust(w) for h, w in zip(headers, widths, strict=True)))
    for r in rows:
        print("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)))
    print()


def run_benchmark(
    sizes: list[int], repeats: int, timeout: float, sides: list[str], out: Path, quiet: bool = False
) -> dict[str, Any]:
    """Run the benchmark and write the results JSON after every run.

    Parameters
    ----------
    sizes : list of int
        Numbers of robots, run in increasing order.
    repeats : int
        Runs per ``(side, n)``.
    timeout : float
        Per-run timeout in seconds; after a timeout the larger sizes of that side are
        skipped.
    sides : list of str
        Sides to run, among ``"faudes"`` and ``"cosmop"``.
    out : Path
        Results file.
    quiet : bool, optional
        Do not print progress lines.

    Returns
    -------
    dict
        The data written to ``out``.
    """
    data: dict[str, Any] = {
        "benchmark": "decompose",
        "workload": (
            "N-robot warehouse: robot i runs pick(Ri,Oi) drop(Ri,Oi,Wi) return(Ri) (4-state prefix-closed"
            " DFA); K = product of the N sequences (4^N states); project K onto each robot's events;"
            " verdict = Lm(product of projections) included in Lm(K)"
        ),
        "machine": machine_info(sides),
        "config": {"sizes": sizes, "repeats": repeats, "timeout": timeout, "sides": sides},
        "runs": [],
        "summary": [],
        "ratios": [],
    }
    for side in sides:
        stopped_at: int | None = None
        for n in sorted(sizes):
            for rep in range(repeats):
                record: dict[str, Any] = {"side": side, "n": n, "repeat": rep}
                if stopped_at is not None:
                    record |= {"status": "skipped", "reason": f"timeout at n={stopped_at}"}
                else:
                    record["loadavg_1min"] = os.getloadavg()[0]  # other load on the machine
                    record |= run_one(side, n, timeout)
                    if record["status"] == "timeout":
                        stopped_at = n
                data["runs"].append(record)
                if not quiet and record["status"] != "skipped":
                    detail = f"total {record['result']['total']:.4f} s" if record["status"] == "ok" else ""
                    print(f"[{side} n={n} rep={rep}] {record['status']} {detail}", flush=True)
                data["summary"], data["ratios"] = summarise(data["runs"])
                write_json_atomic(out, data)
    return data


def _parse_sizes(text: str) -> list[int]:
    try:
        sizes = sorted({int(part) for part in text.split(",") if part.strip()})
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"bad --sizes {text!r}: {exc}") from exc
    if not sizes or sizes[0] < 1:
        raise argparse.ArgumentTypeError("--sizes needs positive integers")
    return sizes


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point (see the module docstring).

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status.
    """
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=_parse_sizes, default=_parse_sizes("2,3,4,5,6,7"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per run")
    parser.add_argument("--side", choices=[*SIDES, "both"], default="both")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    parser.add_argument("--child", choices=SIDES, help=argparse.SUPPRESS)
    parser.add_argument("--n", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--result-file", help=argparse.SUPPRESS)
    parser.add_argument("--faudes-version", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    if args.faudes_version:
        return _faudes_version_main()
    if args.child:
        return _child_main(args.child, args.n, args.result_file)

    sides = list(SIDES) if args.side == "both" else [args.side]
    if "cosmop" in sides and not _cosmop_side_available():
        if args.side == "cosmop":
            parser.error(f"the cosmop side needs {HERE / '_cosmop_side.py'} (defining cosmop_job)")
        print(f"warning: {HERE / '_cosmop_side.py'} not found; running the faudes side only", file=sys.stderr)
        sides.remove("cosmop")
    if args.repeats < 1 or args.timeout <= 0:
        parser.error("--repeats and --timeout must be positive")
    data = run_benchmark(args.sizes, args.repeats, args.timeout, sides, args.out, quiet=args.quiet)
    print_tables(data["summary"], data["ratios"])
    print(f"results written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
