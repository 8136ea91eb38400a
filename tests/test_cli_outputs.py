"""Output paths are checked before any work: a missing folder, a folder named as a file, a file
named as a folder are exit 2 with one line naming the option, and nothing is written."""

from __future__ import annotations

import os
import socket
import stat
import threading
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cosmop.cli import app

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = str(ROOT / "examples" / "01_warehouse_2x2" / "scenario.yaml")
runner = CliRunner()


def _commands(tmp: Path) -> list[tuple[list[str], str, Path]]:
    missing = tmp / "no-such-folder"
    return [
        (["plan", SCENARIO, "-o", str(missing / "plan.json")], "-o", missing),
        (["plan", SCENARIO, "-o", str(tmp / "p.json"), "--png", str(missing / "p.png")], "--png", missing),
        (["simulate", SCENARIO, "--summary", str(missing / "s.json")], "--summary", missing),
        (["simulate", SCENARIO, "--trace", str(missing / "t.json")], "--trace", missing),
        (["view", SCENARIO, "-o", str(missing / "v.html")], "-o", missing),
    ]


@pytest.mark.parametrize("index", range(5))
def test_an_output_in_a_missing_folder_is_refused_before_any_work(tmp_path, index):
    command, option, missing = _commands(tmp_path)[index]
    result = runner.invoke(app, command)
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert f"{option}: the folder {missing} does not exist" in result.stderr
    assert list(tmp_path.iterdir()) == []  # nothing written, not even the plan of a later output


def test_a_folder_is_not_a_file_and_a_file_is_not_a_folder(tmp_path):
    result = runner.invoke(app, ["plan", SCENARIO, "-o", str(tmp_path)])
    assert result.exit_code == 2 and "-o: is a folder; expected the path of a file" in result.stderr
    file = tmp_path / "taken"
    file.write_text("x")
    result = runner.invoke(app, ["decompose", SCENARIO, "--dot", str(file)])
    assert result.exit_code == 2 and "--dot: is a file; expected a folder" in result.stderr
    assert file.read_text() == "x"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX's")
def test_an_output_through_a_named_pipe_is_written_through_and_the_pipe_kept(tmp_path):
    # issue 39: -o naming a FIFO (or /dev/null, as root) replaced it with a plain file
    fifo = tmp_path / "view.html"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()), daemon=True)
    reader.start()
    result = runner.invoke(app, ["view", SCENARIO, "-o", str(fifo)])
    reader.join(timeout=60)
    assert result.exit_code == 0, result.output
    assert stat.S_ISFIFO(fifo.lstat().st_mode)  # still the pipe
    assert received and received[0].rstrip().endswith(b"</html>")
    assert [p.name for p in tmp_path.iterdir()] == ["view.html"]  # no staging folder


def test_a_device_is_written_through_never_replaced(monkeypatch):
    import tempfile

    from cosmop.io import check_writable, write_atomic

    def replaced(*args, **kwargs):
        raise AssertionError("a device node must never be replaced")

    # nothing may be staged or moved: /dev/null is only ever opened and written
    monkeypatch.setattr(os, "replace", replaced)
    monkeypatch.setattr(tempfile, "mkdtemp", replaced)
    check_writable("/dev/null", "-o")
    write_atomic("/dev/null", "nothing")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_a_link_is_kept_and_the_file_it_names_replaced(tmp_path):
    from cosmop.io import write_atomic

    (tmp_path / "real.json").write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to("real.json")
    write_atomic(link, "new")
    assert link.is_symlink() and (tmp_path / "real.json").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.json", "real.json"]


@pytest.mark.skipif(not hasattr(socket, "AF_UNIX"), reason="needs Unix sockets")
def test_a_socket_is_no_output(tmp_path):
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(tmp_path / "s"))
        result = runner.invoke(app, ["view", SCENARIO, "-o", str(tmp_path / "s")])
    assert result.exit_code == 2
    assert (
        result.stderr == f"error: {tmp_path / 's'}: -o: is a socket; expected the path of a file to write\n"
    )


def test_an_interrupt_waits_for_outputs_that_belong_together():
    import signal

    from cosmop.io import uninterrupted

    done = []
    # as in a terminal: a suite started in the background inherits SIGINT ignored, and then
    # Ctrl-C is rightly ignored after the block too
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt), uninterrupted():
            signal.raise_signal(signal.SIGINT)  # Ctrl-C between the two writes
            done.append("trace")
            done.append("summary")
    finally:
        signal.signal(signal.SIGINT, previous)
    assert done == ["trace", "summary"]


def test_the_program_answers_ctrl_c_with_one_line_and_130(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    import yaml

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from warehouse_gen import warehouse

    scenario = tmp_path / "warehouse.yaml"  # 30 robots: planning takes far longer than the wait
    scenario.write_text(yaml.safe_dump(warehouse(30, seed=1), sort_keys=False))
    command = [sys.executable, "-m", "cosmop", "plan", str(scenario)]
    proc = subprocess.Popen(
        [*command, "-o", str(tmp_path / "plan.json")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, as a terminal's Ctrl-C reaches it
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    time.sleep(4.0)  # planning, with its worker processes
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip().splitlines()[-1] == "interrupted" and "Traceback" not in err
    assert not (tmp_path / "plan.json").exists()
