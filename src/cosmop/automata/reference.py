"""Adapter to libFAUDES, the reference discrete-event-systems library (optional dependency).

This module lets the test-suite and the benchmarks cross-check :mod:`cosmop.automata`
against libFAUDES' Python binding (``import faudes``).  It works on *plain data* so that
it does not depend on our own DFA class:

.. code-block:: python

    PlainDFA = tuple[list[str], int, int, list[int], list[tuple[int, str, int]]]
    #          (alphabet, n_states, initial, marked, transitions (src, event, dst))

with states numbered ``0 .. n_states - 1``.  :func:`to_faudes` turns such a tuple into a
``faudes.Generator`` and :func:`from_faudes` turns a deterministic generator back into a
canonical tuple.  The operations (:func:`parallel`, :func:`project`,
:func:`language_inclusion`, :func:`language_equality`, :func:`minimal_states`) accept
either a generator or a :data:`PlainDFA` tuple.

``faudes`` is imported lazily, the first time a function needs it; without it, the module
still imports and every such function raises :class:`ImportError`.

Notes on libFAUDES (2.34) behaviour that this adapter relies on or hides
-------------------------------------------------------------------------
* **Event names.**  libFAUDES accepts any non-empty name made of printable ASCII
  characters except the space, ``"`` and ``#``; parentheses and commas are fine, so
  names such as ``pick(R1,O1)`` or ``drop(R1,O1,W1)`` are passed through unchanged.
  Other characters (whitespace, ``"``, ``#``, control and non-ASCII characters) are
  percent-encoded by :func:`encode_event` (UTF-8 bytes as ``%XX``, with ``%`` itself
  encoded as ``%25``), and :func:`from_faudes` decodes them again with
  :func:`decode_event`.  The encoding is a pure function of the name, so no side table
  has to travel with the generators.  Event names live in a process-wide libFAUDES
  symbol table, shared by all generators.
* **Printing.**  With the default verbosity, libFAUDES writes a ``FAUDES_EXCEPTION: ...``
  line to the C-level standard output before every exception it raises, and the Python
  module prints a warning at import when matplotlib or pillow is missing.  The adapter
  imports ``faudes`` with Python's stdout redirected and runs each call at verbosity 0
  (restoring the previous level afterwards).  libFAUDES errors are re-raised as
  :class:`FaudesError`.
* **State names.**  ``faudes.Parallel`` names product states ``"1|2"`` by default; the
  generators built here have state names disabled, which saves time and memory.
* **Project** determinises (subset construction from the initial state), so its result
  holds the *accessible* part only, is deterministic, and represents both the generated
  language ``P(L(G))`` and the marked language ``P(Lm(G))``; it need not be trim.  Its
  alphabet is the *intersection* of the requested events with the generator's
  alphabet: requested events unknown to the generator are dropped.
* **LanguageInclusion / LanguageEquality** compare *marked* languages only (generated
  languages and alphabets are ignored) and require deterministic arguments (libFAUDES
  raises otherwise); the adapter determinises non-deterministic arguments first.
* **StateMin** requires a deterministic generator and keeps blocking states;
  :func:`minimal_states` therefore trims before minimising.
"""

from __future__ import annotations

import contextlib
import functools
import io
import numbers
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, TypeAlias, cast

import numpy as np

from cosmop.automata.dfa import DFA

if TYPE_CHECKING:  # pragma: no cover - typing only
    import faudes

__all__ = [
    "FaudesError",
    "GeneratorLike",
    "PlainDFA",
    "decode_event",
    "encode_event",
    "from_faudes",
    "is_available",
    "language_equality",
    "language_inclusion",
    "minimal_states",
    "parallel",
    "project",
    "to_faudes",
]

PlainDFA: TypeAlias = tuple[list[str], int, int, list[int], list[tuple[int, str, int]]]
"""``(alphabet, n_states, initial, marked, transitions)`` with states ``0 .. n_states - 1``.

An automaton without states (empty generated language) is ``(alphabet, 0, 0, [], [])``:
the initial index ``0`` is then a placeholder and must not be used.
"""

GeneratorLike: TypeAlias = "faudes.Generator | PlainDFA"
"""A ``faudes.Generator`` or a :data:`PlainDFA` tuple (converted with :func:`to_faudes`)."""

_INSTALL_HINT = (
    "libFAUDES' Python binding (module 'faudes') is required for cosmop.automata.reference; "
    "install it with `pip install cosmop[test]` (or `pip install faudes`)."
)


class FaudesError(RuntimeError):
    """An error reported by libFAUDES (its message starts with ``libFAUDES Exception``)."""


# ----------------------------------------------------------------------------- loading


@functools.cache
def _load() -> ModuleType:
    """Import ``faudes`` once, silencing what it prints at import time.

    Returns
    -------
    module
        The ``faudes`` module.

    Raises
    ------
    ImportError
        If the binding is not installed, with a hint on how to install it.
    """
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            import faudes
    except ImportError as exc:
        raise ImportError(_INSTALL_HINT) from exc
    return cast(ModuleType, faudes)


def is_available() -> bool:
    """Tell whether the ``faudes`` binding can be imported.

    Returns
    -------
    bool
        ``True`` when :mod:`faudes` imports.
    """
    try:
        _load()
    except ImportError:
        return False
    return True


@contextlib.contextmanager
def _quiet(fd: ModuleType) -> Iterator[None]:
    """Run libFAUDES at verbosity 0 and turn its exceptions into :class:`FaudesError`."""
    previous = fd.Verbosity()
    fd.Verbosity(0)
    try:
        yield
    except Exception as exc:
        if str(exc).startswith("libFAUDES"):
            raise FaudesError(str(exc)) from exc
        raise
    finally:
        fd.Verbosity(previous)


# ------------------------------------------------------------------------- event names

_ESCAPE = "%"


def _is_safe_char(ch: str) -> bool:
    """Tell whether libFAUDES accepts ``ch`` in a symbol and it needs no escaping."""
    return "!" <= ch <= "~" and ch not in '"#' and ch != _ESCAPE


def encode_event(name: str) -> str:
    """Map an event name to a symbol that libFAUDES accepts.

    Names made only of printable ASCII characters other than space, ``"``, ``#`` and
    ``%`` are returned unchanged; every other character is replaced by the ``%XX``
    encoding of its UTF-8 bytes.

    Parameters
    ----------
    name : str
        A non-empty event name, e.g. ``"pick(R1,O1)"``.

    Returns
    -------
    str
        The libFAUDES symbol.

    Raises
    ------
    ValueError
        If ``name`` is empty (libFAUDES has no empty symbol).
    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"event names must be non-empty strings, got {name!r}")
    if all(_is_safe_char(ch) for ch in name):
        return name
    parts: list[str] = []
    for ch in name:
        if _is_safe_char(ch):
            parts.append(ch)
        else:
            parts.extend(f"%{byte:02X}" for byte in ch.encode("utf-8"))
    return "".join(parts)


def decode_event(symbol: str) -> str:
    """Invert :func:`encode_event`.

    Parameters
    ----------
    symbol : str
        A libFAUDES event symbol.

    Returns
    -------
    str
        The original event name.  Symbols without ``%`` are returned unchanged, and a
        ``%`` not followed by two hexadecimal digits is kept literally.
    """
    if _ESCAPE not in symbol:
        return symbol
    out = bytearray()
    i = 0
    while i < len(symbol):
        ch = symbol[i]
        if ch == _ESCAPE and _is_hex(symbol[i + 1 : i + 3]):
            out.append(int(symbol[i + 1 : i + 3], 16))
            i += 3
        else:
            out.extend(ch.encode("utf-8"))
            i += 1
    try:
        return out.decode("utf-8")
    except UnicodeDecodeError:  # not produced by encode_event: keep the symbol as it is
        return symbol


def _is_hex(text: str) -> bool:
    return len(text) == 2 and all(c in "0123456789abcdefABCDEF" for c in text)


# -------------------------------------------------------------------------- conversion


def _new_generator(fd: ModuleType, name: str = "cosmop") -> faudes.Generator:
    gen = fd.Generator()
    gen.StateNamesEnabled(False)
    gen.Name(name)
    return gen


def to_faudes(
    alphabet: Iterable[str],
    n_states: int,
    initial: int,
    marked: Iterable[int],
    transitions: Iterable[tuple[int, str, int]],
    *,
    name: str = "cosmop",
) -> faudes.Generator:
    """Build a deterministic ``faudes.Generator`` from plain data.

    State ``i`` becomes libFAUDES state index ``i + 1`` (libFAUDES indices start at 1);
    event names are encoded with :func:`encode_event`.

    Parameters
    ----------
    alphabet : iterable of str
        The event names (duplicates are ignored).  Every transition event must be in it.
    n_states : int
        Number of states; ``0`` gives the empty generator (then ``initial`` is ignored and
        ``marked`` and ``transitions`` must be empty).
    initial : int
        Index of the initial state.
    marked : iterable of int
        Indices of the marked (accepting) states.
    transitions : iterable of (int, str, int)
        Transitions ``(src, event, dst)``; at most one destination per ``(src, event)``.
    name : str, optional
        Name given to the generator.

    Returns
    -------
    faudes.Generator
        The generator, with state names disabled.

    Raises
    ------
    ValueError
        On an out-of-range state, an event outside the alphabet, an empty event name or a
        non-deterministic transition relation.
    ImportError
        If ``faudes`` is not installed.
    """
    fd = _load()
    plain = _checked(alphabet, n_states, initial, marked, transitions)
    return _generator(fd, plain, name)


@dataclass(frozen=True)
class _Checked:
    """Plain DFA data checked for :func:`to_faudes`, states as ``int``.

    Attributes
    ----------
    symbols : dict of str to str
        Each event name's libFAUDES symbol (:func:`encode_event`), in alphabet order.
    n_states : int
    initial : int
        Unchecked (and unused) when ``n_states`` is 0.
    marked : list of int
    delta : dict of (int, str) to int
        The transitions ``(src, event) -> dst``, in the order given.
    """

    symbols: dict[str, str]
    n_states: int
    initial: int
    marked: list[int]
    delta: dict[tuple[int, str], int]


def _state_index(q: object) -> object:
    """`q` as an ``int`` if it is an integer, else unchanged (and rejected when checked)."""
    # numpy integers are state indices too; booleans and floats are not
    return int(q) if isinstance(q, numbers.Integral) and not isinstance(q, bool) else q


def _check_state(q: object, n_states: int, what: str) -> int:
    """`q`, after raising :class:`ValueError` unless it is a state index in ``0 .. n_states - 1``."""
    if not isinstance(q, int) or not 0 <= q < n_states:
        raise ValueError(f"{what} {q!r} is not a state index in 0..{n_states - 1}")
    return q


def _checked(
    alphabet: Iterable[str],
    n_states: object,
    initial: object,
    marked: Iterable[object],
    transitions: Iterable[tuple[object, str, object]],
) -> _Checked:
    """Check the arguments of :func:`to_faudes` and index the transitions by ``(src, event)``.

    Raises
    ------
    ValueError
        As :func:`to_faudes` documents: the state count, then the initial and the marked
        states, the event names, and the transitions in order.
    """
    alphabet = list(alphabet)
    marked = [_state_index(q) for q in marked]
    transitions = [(_state_index(src), ev, _state_index(dst)) for src, ev, dst in transitions]
    n_states, initial = _state_index(n_states), _state_index(initial)
    if not isinstance(n_states, int) or n_states < 0:
        raise ValueError(f"n_states must be a non-negative int, got {n_states!r}")
    if n_states > 0:
        _check_state(initial, n_states, "initial state")
    states = [_check_state(q, n_states, "marked state") for q in marked]
    symbols = {ev: encode_event(ev) for ev in alphabet}
    delta: dict[tuple[int, str], int] = {}
    for src, ev, dst in transitions:
        source = _check_state(src, n_states, "transition source")
        target = _check_state(dst, n_states, "transition target")
        if ev not in symbols:
            raise ValueError(f"transition event {ev!r} is not in the alphabet")
        if delta.setdefault((source, ev), target) != target:
            raise ValueError(f"non-deterministic transitions from state {src} on {ev!r}")
    # `initial` is checked above unless there are no states (then it is unused)
    return _Checked(symbols, n_states, cast(int, initial), states, delta)


def _generator(fd: ModuleType, plain: _Checked, name: str) -> faudes.Generator:
    """A libFAUDES generator for checked data: state ``i`` is libFAUDES state ``i + 1``."""
    gen = _new_generator(fd, name)
    with _quiet(fd):
        event_index = {ev: gen.InsEvent(sym) for ev, sym in plain.symbols.items()}
        for q in range(plain.n_states):
            gen.InsState(q + 1)
        if plain.n_states > 0:
            gen.SetInitState(plain.initial + 1)
        for q in plain.marked:
            gen.SetMarkedState(q + 1)
        for (src, ev), dst in plain.delta.items():
            gen.SetTransition(src + 1, event_index[ev], dst + 1)
    return gen


def from_faudes(gen: faudes.Generator) -> PlainDFA:
    """Convert a deterministic ``faudes.Generator`` to a canonical :data:`PlainDFA`.

    States are renumbered breadth-first from the initial state (which becomes state 0),
    exploring successors in the order of the sorted event names; states that are not
    reachable follow, in libFAUDES index order.  The alphabet, the marked states and the
    transitions are sorted.  Hence two generators that differ only in state indices give
    the same tuple (on their accessible part).

    Parameters
    ----------
    gen : faudes.Generator
        A deterministic generator (at most one initial state).

    Returns
    -------
    PlainDFA
        ``(alphabet, n_states, initial, marked, transitions)``.  A generator without
        states, or without an initial state (both have empty languages), gives
        ``(alphabet, 0, 0, [], [])``.

    Raises
    ------
    ValueError
        If ``gen`` is not deterministic (use ``faudes.Deterministic`` first).
    """
    fd = _load()
    with _quiet(fd):
        if not fd.IsDeterministic(gen):
            raise ValueError("from_faudes needs a deterministic generator (apply faudes.Deterministic)")
        event_name = {ev: decode_event(gen.EventName(ev)) for ev in gen.Alphabet()}
        alphabet = sorted(event_name.values())
        inits = list(gen.InitStates())
        if not inits:
            return alphabet, 0, 0, [], []
        succ: dict[int, list[tuple[str, int]]] = {}
        for t in gen.TransRel():
            succ.setdefault(t.X1, []).append((event_name[t.Ev], t.X2))
        states = list(gen.States())
        marked_idx = list(gen.MarkedStates())

    number: dict[int, int] = {inits[0]: 0}
    queue = deque([inits[0]])
    while queue:
        q = queue.popleft()
        for _, dst in sorted(succ.get(q, ())):
            if dst not in number:
                number[dst] = len(number)
                queue.append(dst)
    for q in states:
        if q not in number:
            number[q] = len(number)
    transitions = sorted((number[src], ev, number[dst]) for src, edges in succ.items() for ev, dst in edges)
    marked = sorted(number[q] for q in marked_idx)
    return alphabet, len(number), 0, marked, transitions


def _as_generator(fd: ModuleType, g: GeneratorLike) -> faudes.Generator:
    """Return ``g`` itself if it is a generator, else convert the PlainDFA tuple."""
    if isinstance(g, tuple):
        return to_faudes(*g)
    if not isinstance(g, fd.Generator):
        raise TypeError(f"expected a faudes.Generator or a PlainDFA tuple, got {type(g).__name__}")
    return g


def _deterministic(fd: ModuleType, gen: faudes.Generator) -> faudes.Generator:
    """Return ``gen`` if deterministic, else a determinised copy (same languages)."""
    if fd.IsDeterministic(gen):
        return gen
    res = _new_generator(fd, gen.Name())
    fd.Deterministic(gen, res)
    return res


# -------------------------------------------------------------------------- operations


def parallel(g1: GeneratorLike, g2: GeneratorLike) -> faudes.Generator:
    """Synchronous (parallel) composition, ``faudes.Parallel``.

    Shared events synchronise, private events interleave; the result's alphabet is the
    union of both alphabets and only its accessible part is built.

    Parameters
    ----------
    g1, g2 : faudes.Generator or PlainDFA
        The operands (alphabets may differ).

    Returns
    -------
    faudes.Generator
        The product generator (state names disabled).
    """
    fd = _load()
    a, b = _as_generator(fd, g1), _as_generator(fd, g2)
    res = _new_generator(fd, "parallel")
    with _quiet(fd):
        fd.Parallel(a, b, res)
    return res


def project(g: GeneratorLike, events: Iterable[str]) -> faudes.Generator:
    """Natural projection with determinisation, ``faudes.Project``.

    Parameters
    ----------
    g : faudes.Generator or PlainDFA
        The generator to project.
    events : iterable of str
        The events to keep.

    Returns
    -------
    faudes.Generator
        A deterministic generator, accessible part only, of both ``P(L(g))`` and
        ``P(Lm(g))``.  Its alphabet is ``set(events)`` intersected with the alphabet of
        ``g`` (libFAUDES drops requested events that ``g`` does not know).  Projecting a
        generator without states gives a generator without states.
    """
    fd = _load()
    gen = _as_generator(fd, g)
    sigma = fd.EventSet()
    for ev in events:
        sigma.Insert(encode_event(ev))
    res = _new_generator(fd, "project")
    with _quiet(fd):
        fd.Project(gen, sigma, res)
    return res


def language_inclusion(g1: GeneratorLike, g2: GeneratorLike) -> bool:
    """Decide ``Lm(g1) ⊆ Lm(g2)`` with ``faudes.LanguageInclusion``.

    Only marked languages are compared (a string that is generated but not marked does
    not count), and alphabets are ignored.  Non-deterministic operands are determinised
    first, since libFAUDES rejects them.

    Parameters
    ----------
    g1, g2 : faudes.Generator or PlainDFA
        The operands.

    Returns
    -------
    bool
        Whether the marked language of ``g1`` is included in that of ``g2``.
    """
    fd = _load()
    a, b = _as_generator(fd, g1), _as_generator(fd, g2)
    with _quiet(fd):
        return bool(fd.LanguageInclusion(_deterministic(fd, a), _deterministic(fd, b)))


def language_equality(g1: GeneratorLike, g2: GeneratorLike) -> bool:
    """Decide ``Lm(g1) == Lm(g2)`` with ``faudes.LanguageEquality``.

    Same conventions as :func:`language_inclusion`.

    Parameters
    ----------
    g1, g2 : faudes.Generator or PlainDFA
        The operands.

    Returns
    -------
    bool
        Whether both marked languages are equal.
    """
    fd = _load()
    a, b = _as_generator(fd, g1), _as_generator(fd, g2)
    with _quiet(fd):
        return bool(fd.LanguageEquality(_deterministic(fd, a), _deterministic(fd, b)))


def minimal_states(g: GeneratorLike) -> int:
    """Number of states of the minimal trim deterministic generator of ``Lm(g)``.

    Computed as determinise (if needed), ``faudes.Trim``, then ``faudes.StateMin``.  This
    is the size of the minimal DFA of the marked language *without* a dead (sink) state;
    it is ``0`` for the empty marked language.

    Parameters
    ----------
    g : faudes.Generator or PlainDFA
        The generator (left unchanged).

    Returns
    -------
    int
        The state count.
    """
    fd = _load()
    gen = _as_generator(fd, g)
    with _quiet(fd):
        work = _new_generator(fd, "trim")
        if fd.IsDeterministic(gen):
            work.Assign(gen)
        else:
            fd.Deterministic(gen, work)
        fd.Trim(work)
        res = _new_generator(fd, "statemin")
        fd.StateMin(work, res)
        return int(res.Size())


def dfa_to_faudes(dfa: DFA) -> faudes.Generator:
    """A :class:`cosmop.automata.DFA` as a libFAUDES generator (same marked language).

    Parameters
    ----------
    dfa : DFA
        The automaton to convert.
    """
    rows, cols = np.nonzero(dfa.delta >= 0)
    transitions = [(int(q), dfa.alphabet[j], int(dfa.delta[q, j])) for q, j in zip(rows, cols, strict=True)]
    return to_faudes(dfa.alphabet, dfa.n_states, dfa.initial, np.flatnonzero(dfa.marked), transitions)


def faudes_to_dfa(gen: faudes.Generator) -> DFA:
    """A deterministic libFAUDES generator as a :class:`cosmop.automata.DFA`.

    A generator without states (libFAUDES's empty language) becomes :meth:`DFA.empty`.

    Parameters
    ----------
    gen : faudes.Generator
        Deterministic.
    """
    alphabet, n, initial, marked, transitions = from_faudes(gen)
    if n == 0:
        return DFA.empty(alphabet)
    col = {e: j for j, e in enumerate(alphabet)}
    delta = np.full((n, len(alphabet)), -1, dtype=np.int32)
    for src, ev, dst in transitions:
        delta[src, col[ev]] = dst
    mask = np.zeros(n, dtype=bool)
    mask[list(marked)] = True
    return DFA(tuple(alphabet), delta, initial, mask)
