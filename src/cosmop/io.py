"""Small file-system helpers."""

from __future__ import annotations

import contextlib
import gc
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from types import FrameType
from typing import Any

from cosmop.errors import CosmopInputError, OutputPathError

__all__ = [
    "MAX_FILE_BYTES",
    "abandon_staging",
    "atomic_path",
    "check_writable",
    "collector_paused",
    "compact_json",
    "interrupt_at_safe_points",
    "read_bytes",
    "read_text",
    "uninterrupted",
    "write_atomic",
]


@contextlib.contextmanager
def uninterrupted() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back while the block runs; it arrives, if pressed, right after.

    For outputs that belong together (a run's summary and its trace): each is written
    atomically, and together they are written all or nothing.  The signal is caught by a
    handler that only notes it (Python runs handlers in the main thread, whichever thread the
    system delivers the signal to, so a progress bar's thread cannot let it through), and the
    previous handler is called with it after the block.  Outside the main thread the block
    runs as it is.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pressed: list[tuple[int, FrameType | None]] = []
    old = signal.signal(signal.SIGINT, lambda number, frame: pressed.append((number, frame)))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        if pressed:
            _pass_on(old, *pressed[0])


def _pass_on(handler: Any, number: int, frame: FrameType | None) -> None:
    """Give a Ctrl-C that was held back to the SIGINT `handler` it was held from: call it, or,
    for the system's default, raise KeyboardInterrupt (an ignored one is dropped).  Python's own
    default handler is callable and raises it itself."""
    import signal

    if callable(handler):
        handler(number, frame)
    elif handler == signal.SIG_DFL:
        raise KeyboardInterrupt


@contextlib.contextmanager
def interrupt_at_safe_points() -> Iterator[Callable[[], None]]:
    """Hold Ctrl-C (SIGINT) back until the block calls the function it is given (a safe point,
    such as between two cycles of a run), which then gives it to the previous handler (which
    raises KeyboardInterrupt).

    Inside a call into a C library (Z3, through ctypes) Python turns KeyboardInterrupt into
    another exception, which says nothing of the interrupt; at a safe point it is a plain
    KeyboardInterrupt that the caller can answer (a run writes what it did so far).  A second
    Ctrl-C before the next safe point goes to the previous handler at once.  Outside the main
    thread, or where Ctrl-C is ignored, the block runs as it is.
    """
    import signal
    import threading

    old = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or old == signal.SIG_IGN:
        yield lambda: None
        return
    pressed: list[tuple[int, FrameType | None]] = []

    def note(number: int, frame: FrameType | None) -> None:
        if pressed:  # a second one: at once
            signal.signal(signal.SIGINT, old)
            _pass_on(old, number, frame)
            raise KeyboardInterrupt
        pressed.append((number, frame))

    def safe_point() -> None:
        if pressed:  # the previous handler takes it now, as if Ctrl-C came here
            _pass_on(old, *pressed[0])
            raise KeyboardInterrupt

    signal.signal(signal.SIGINT, note)
    try:
        yield safe_point
    finally:
        signal.signal(signal.SIGINT, old)


def check_writable(path: str | os.PathLike[str] | None, option: str, *, folder: bool = False) -> None:
    """Raise :class:`OutputPathError` unless `path` can be written (check before any work).

    Parameters
    ----------
    path : str or os.PathLike or None
        An output the user named (``None``: not asked for, nothing to check).
    option : str
        The command-line option that named it (``-o``, ``--png``), for the message.
    folder : bool
        Whether the output is a folder to create (then it must not exist yet as a file).

    Notes
    -----
    A character device or a named pipe (``/dev/null``, a FIFO) is a writable file output when
    it may be written (:func:`atomic_path` writes through it); a block device or a socket never is.
    """
    if path is None:
        return
    target = Path(path)
    if not folder and _stream(target):  # written through (atomic_path): its folder is not touched
        if not os.access(target, os.W_OK):
            raise OutputPathError("is not writable", file=target, field=option)
        return
    kind = _special(target)
    if kind is not None:
        expected = "a folder to write into" if folder else "the path of a file to write"
        raise OutputPathError(f"is {kind}; expected {expected}", file=target, field=option)
    target = _followed(target)
    parent = target.parent
    if not folder and target.is_dir():
        raise OutputPathError("is a folder; expected the path of a file to write", file=target, field=option)
    if folder and target.exists() and not target.is_dir():
        raise OutputPathError("is a file; expected a folder to write into", file=target, field=option)
    if not parent.is_dir():
        missing = f"the folder {parent} does not exist; create it first"
        raise OutputPathError(missing, file=target, field=option)
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputPathError(f"the folder {parent} is not writable", file=target, field=option)


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Pause Python's cyclic garbage collector while a large output that holds no cycles is
    built, or work that makes many objects but no cycles runs, and restore it as it was,
    whatever happens.  Also a decorator (``@collector_paused()``).

    A trace's JSON is some 100,000 dicts and lists that all stay alive until it is written;
    the collector would walk them again and again and free nothing (a quarter of the time of
    building the 10×10's trace).  The ordering of a team's conflicts makes millions of tuples
    and integers, which reference counting frees; the collector would walk the whole heap each
    time (a sixth of the conflict step of 50 robots).
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def write_atomic(path: str | os.PathLike[str], data: str | bytes) -> None:
    """Replace the file at `path` with `data`, all at once.

    The data are written through :func:`atomic_path`: to a file of the same name in a hidden
    staging folder beside `path`, flushed to disk with ``fsync`` and moved over `path` with
    :func:`os.replace`, which is atomic on POSIX and Windows. Readers therefore see either the
    old file or the complete new one, never a half-written file; if anything fails the staging
    folder is removed and `path` is untouched.  (A character device or a named pipe, such as
    ``/dev/null``, is written through instead, never replaced: see :func:`atomic_path`.)

    Parameters
    ----------
    path : str or os.PathLike
        The destination. Its directory must exist.
    data : str or bytes
        The new content; text is encoded as UTF-8 (newlines are written as given).

    Notes
    -----
    A new file gets the usual permissions (``0o666`` masked by the process umask); an
    existing file keeps its permission bits.
    """
    if isinstance(data, str):
        payload = data.encode("utf-8")
    elif isinstance(data, bytes | bytearray | memoryview):
        payload = bytes(data)
    else:
        raise TypeError(f"write_atomic needs str or bytes, got {type(data).__name__}")
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        handle.write(payload)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path to write `path` through, moved onto `path` when the block succeeds.

    For writers that take a file name rather than data (matplotlib's animation writers, a ROS
    bag writer): the block writes a file or creates a folder at the yielded path, which has
    the same name as `path` (so writers that pick the format by the suffix, or name a folder's
    files after it, behave the same) inside a new hidden staging folder beside `path`, on the
    same file system. On success a file is flushed to disk (``fsync``), takes the permission
    bits of the file it replaces, and is moved onto `path` with :func:`os.replace` (atomic on
    POSIX and Windows); a folder is moved as it is, which needs `path` to be missing (or, on
    POSIX, an empty folder). The staging folder is always removed, so a failure, inside the
    block or in the move, leaves `path` untouched and nothing behind.

    Two kinds of `path` are not replaced.  A character device or a named pipe (``/dev/null``,
    a FIFO; a link to one) is yielded itself and written through, as a shell's ``>`` does:
    moving a file onto it would replace the device node or the pipe with a plain file (and
    nothing in a stream can be written atomically).  A symbolic link is kept, and the file it
    names is replaced.

    Parameters
    ----------
    path : str or os.PathLike
        The destination file or folder. Its directory must exist.

    Yields
    ------
    pathlib.Path
        ``<staging folder>/<name of path>``, where nothing exists yet; or `path` itself, for
        a character device or a named pipe.

    Raises
    ------
    FileNotFoundError
        If the directory of `path` is missing, or the block created nothing at the yielded path.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with atomic_path(folder / "plot.txt") as tmp:
    ...     _ = tmp.write_text("drawn")
    >>> (folder / "plot.txt").read_text(), sorted(p.name for p in folder.iterdir())
    ('drawn', ['plot.txt'])
    >>> shutil.rmtree(folder)
    """
    target = Path(path)
    if _stream(target):
        # a device (/dev/null) or a named pipe: written through, as a shell's > does; a file
        # moved onto it would replace it (the device node, the pipe) with a plain file
        yield target
        return
    target = _followed(target)  # a symbolic link stays, and the file it names is replaced
    staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent))
    _STAGING.add(staging)
    try:
        tmp = staging / target.name
        yield tmp
        if tmp.is_file():
            _fsync_file(tmp)
            with contextlib.suppress(OSError):
                if target.is_file():
                    os.chmod(tmp, target.stat().st_mode & 0o7777)
        os.replace(tmp, target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        _STAGING.discard(staging)
    _fsync_directory(target.parent)


def _stream(path: Path) -> bool:
    """Whether `path` names a character device or a named pipe (a link followed): outputs
    written through, never replaced."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return False
    return stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)


def _special(path: Path) -> str | None:
    """What `path` is when it is neither a file, a folder, a character device nor a named pipe
    (``"a block device"``, ``"a socket"``): no output may go there."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode) or stat.S_ISCHR(mode) or stat.S_ISFIFO(mode):
        return None
    return "a block device" if stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "a special file"


def _followed(path: Path) -> Path:
    """`path`, or the path a symbolic link there names (the link is kept, its file replaced)."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


_STAGING: set[Path] = set()
"""The staging folders of :func:`atomic_path` blocks that have not ended yet."""


def abandon_staging() -> None:
    """Remove the staging folders of the outputs being written, which will never be finished.

    For a program that must end on the spot (:func:`os._exit`, a second Ctrl-C), where the
    blocks' own clean-up will not run: the outputs stay as they were, and nothing is left
    beside them.
    """
    for staging in list(_STAGING):
        shutil.rmtree(staging, ignore_errors=True)
        _STAGING.discard(staging)


def _fsync_file(path: Path) -> None:
    """Flush a written file's data to disk (it may have been written by another process)."""
    # Windows flushes only through a handle open for writing; POSIX through any.
    access = os.O_RDWR | getattr(os, "O_BINARY", 0) if os.name == "nt" else os.O_RDONLY
    fd = os.open(path, access)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_directory(directory: Path) -> None:
    """Make the rename durable (POSIX); harmless where directories cannot be opened."""
    if os.name != "posix":
        return
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        with contextlib.suppress(OSError):
            os.fsync(fd)
    finally:
        os.close(fd)


MAX_FILE_BYTES = 256 * 2**20
"""Most bytes an input file may have: 256 MiB (a trace of the 10×10 example's 218 s run is 7 MB)."""


def read_bytes(
    path: str | os.PathLike[str], error: type[CosmopInputError], kind: str, limit: int | None = None
) -> bytes:
    """Read an input file, at most `limit` bytes; every failure raises ``error`` naming the file.

    At most ``limit + 1`` bytes are read, so an endless stream (``/dev/zero``) or a file past
    the bound is refused after that much, not read into memory whole.  Pipes and devices are
    read like files (``cosmop validate <(generate)`` works).

    Parameters
    ----------
    path : path-like
    error : type of CosmopInputError
        The error to raise (e.g. ``ScenarioError``), constructed as ``error(message, file=...)``.
    kind : str
        What the file should be (``"a scenario file"``), for the messages.
    limit : int, optional
        The most bytes the file may have (default :data:`MAX_FILE_BYTES`).
    """
    file = os.fspath(path)
    limit = MAX_FILE_BYTES if limit is None else limit
    try:
        with open(path, "rb") as handle:
            raw = handle.read(limit + 1)
    except FileNotFoundError:
        raise error("file not found", file=file) from None
    except IsADirectoryError:
        raise error(f"is a directory, expected {kind}", file=file) from None
    except PermissionError:
        raise error("permission denied: cannot read the file", file=file) from None
    except OSError as err:
        raise error(f"cannot read the file: {err.strerror or err}", file=file) from None
    if len(raw) > limit:
        raise error(f"more than {limit:,} bytes; expected {kind} of at most that size", file=file)
    return raw


def read_text(path: str | os.PathLike[str], error: type[CosmopInputError], kind: str) -> str:
    """Read a UTF-8 input file (within :data:`MAX_FILE_BYTES`, :func:`read_bytes`); every
    failure raises ``error`` naming the file.

    Parameters
    ----------
    path : path-like
    error : type of CosmopInputError
        The error to raise (e.g. ``ScenarioError``), constructed as ``error(message, file=...)``.
    kind : str
        What the file should be (``"a scenario file"``), for the messages.

    Returns
    -------
    str
        The text, without a UTF-8 byte-order mark.
    """
    raw = read_bytes(path, error, kind)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        message = f"expected UTF-8 text, found an invalid byte at offset {err.start}"
        raise error(message, file=os.fspath(path)) from None


def compact_json(value: Any, width: int = 100, level: int = 0) -> str:
    """JSON indented by two spaces, with every value that fits in `width` columns on one line.

    A plan file read by people keeps a step with few objects on one line, and still shows
    its structure where a line would be too long.

    Parameters
    ----------
    value : Any
        A JSON value (dicts, lists, strings, numbers, booleans, None).
    width : int, optional
        The widest line, in characters, that a value is kept on.
    level : int, optional
        The indentation level `value` starts at.

    Returns
    -------
    str
        The JSON text, with no final newline.
    """
    flat = json.dumps(value, ensure_ascii=False, separators=(", ", ": "))
    if not isinstance(value, dict | list) or not value or len(flat) + 2 * level <= width:
        return flat
    pad, end = "  " * (level + 1), "  " * level
    if isinstance(value, dict):
        items = [
            f"{pad}{json.dumps(key, ensure_ascii=False)}: {compact_json(item, width, level + 1)}"
            for key, item in value.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + end + "}"
    items = [pad + compact_json(item, width, level + 1) for item in value]
    return "[\n" + ",\n".join(items) + "\n" + end + "]"
