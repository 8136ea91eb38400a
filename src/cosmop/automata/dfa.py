"""The deterministic finite automaton type.

A DFA is the paper's 5-tuple :math:`G = (Q, \\Sigma, q_0, \\delta, Q_m)` (Section II-A) with a
*partial* transition function.  It is stored array-backed: states are ``0 .. n-1``, events
are the columns of an ``int32`` table ``delta`` of shape ``(n, |Σ|)`` whose entry ``-1``
means "undefined", and ``Q_m`` is a boolean mask.  A million states over thirty events take
120 MB.

Languages:

* the *generated* language :math:`L(G) = \\{s \\mid \\delta(q_0, s)\\text{ defined}\\}`;
* the *marked* language :math:`L_m(G) = \\{s \\in L(G) \\mid \\delta(q_0, s) \\in Q_m\\}`.

Every operation in :mod:`cosmop.automata.operations` is about marked languages; a mission is
prefix-closed (every state marked), so for missions the two coincide.  Events are plain
strings here; :mod:`cosmop.missions` maps them to and from mission events.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True, eq=False)
class DFA:
    """Deterministic finite automaton with a partial, array-backed transition function.

    Parameters
    ----------
    alphabet : tuple of str
        :math:`\\Sigma`; column ``j`` of ``delta`` is event ``alphabet[j]``.  Event names are
        unique.  Operations return alphabets in sorted order.
    delta : ndarray of int32, shape (n, len(alphabet))
        :math:`\\delta(q, \\sigma)` or ``-1`` where undefined.  Stored read-only.
    initial : int
        :math:`q_0`.  Every DFA has at least one state; the empty language is a single
        unmarked state without transitions.
    marked : ndarray of bool, shape (n,)
        Membership in :math:`Q_m`.  Stored read-only.
    state_names : tuple of str, optional
        Names for reading and writing; ``q0, q1, ...`` when omitted.

    Notes
    -----
    Instances are immutable and compared by identity; compare languages with
    :func:`cosmop.automata.equivalent`.
    """

    alphabet: tuple[str, ...]
    delta: np.ndarray
    initial: int
    marked: np.ndarray
    state_names: tuple[str, ...] | None = field(default=None)

    def __post_init__(self) -> None:
        delta = np.ascontiguousarray(self.delta, dtype=np.int32)
        marked = np.ascontiguousarray(self.marked, dtype=bool)
        alphabet = tuple(self.alphabet)
        n = delta.shape[0] if delta.ndim == 2 else -1
        if delta.ndim != 2 or delta.shape[1] != len(alphabet):
            raise ValueError(f"delta must have shape (n, {len(alphabet)}), got {delta.shape}")
        if n < 1:
            raise ValueError("a DFA has at least one state")
        if len(set(alphabet)) != len(alphabet):
            raise ValueError("alphabet has repeated events")
        if marked.shape != (n,):
            raise ValueError(f"marked must have shape ({n},), got {marked.shape}")
        if not 0 <= self.initial < n:
            raise ValueError(f"initial state {self.initial} out of range 0..{n - 1}")
        if delta.size and (delta.min() < -1 or delta.max() >= n):
            raise ValueError("delta refers to a state out of range")
        if self.state_names is not None:
            if len(self.state_names) != n:
                raise ValueError("state_names must name every state")
            if len(set(self.state_names)) != n:
                raise ValueError("state_names must be distinct")
        delta.flags.writeable = False
        marked.flags.writeable = False
        object.__setattr__(self, "delta", delta)
        object.__setattr__(self, "marked", marked)
        object.__setattr__(self, "alphabet", alphabet)
        object.__setattr__(self, "initial", int(self.initial))

    # -- size -------------------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        """Number of states :math:`|Q|`."""
        return int(self.delta.shape[0])

    @property
    def n_events(self) -> int:
        """Number of events :math:`|\\Sigma|`."""
        return len(self.alphabet)

    @property
    def n_transitions(self) -> int:
        """Number of defined transitions."""
        return int(np.count_nonzero(self.delta >= 0))

    def event_index(self) -> dict[str, int]:
        """Column of each event."""
        return {e: j for j, e in enumerate(self.alphabet)}

    def name_of(self, state: int) -> str:
        """Name of ``state`` (``q<i>`` when the DFA carries no names).

        Parameters
        ----------
        state : int
            A state's index.
        """
        return self.state_names[state] if self.state_names is not None else f"q{state}"

    def __repr__(self) -> str:
        return f"DFA(states={self.n_states}, events={self.n_events}, transitions={self.n_transitions})"

    # -- words ------------------------------------------------------------------------------
    def run(self, word: Iterable[str]) -> int:
        """State reached by ``word`` from :math:`q_0` (``-1`` if it leaves the generated language).

        Events outside the alphabet are undefined, so they also give ``-1``.

        Parameters
        ----------
        word : iterable of str
            A sequence of events.
        """
        index = self.event_index()
        q = self.initial
        for event in word:
            j = index.get(event)
            if j is None:
                return -1
            q = int(self.delta[q, j])
            if q < 0:
                return -1
        return q

    def generates(self, word: Iterable[str]) -> bool:
        """Whether ``word`` is in the generated language :math:`L(G)`.

        Parameters
        ----------
        word : iterable of str
            A sequence of events.
        """
        return self.run(word) >= 0

    def accepts(self, word: Iterable[str]) -> bool:
        """Whether ``word`` is in the marked language :math:`L_m(G)`.

        Parameters
        ----------
        word : iterable of str
            A sequence of events.
        """
        q = self.run(word)
        return q >= 0 and bool(self.marked[q])

    def is_prefix_closed_marking(self) -> bool:
        """Whether every state is marked (then :math:`L_m(G) = L(G)` is prefix-closed)."""
        return bool(self.marked.all())

    # -- construction -----------------------------------------------------------------------
    @classmethod
    def from_transitions(
        cls,
        initial: str,
        transitions: Iterable[tuple[str, str, str]],
        *,
        marked: Iterable[str] | None = None,
        states: Sequence[str] | None = None,
        alphabet: Iterable[str] | None = None,
    ) -> DFA:
        """Build a DFA from named states and transitions ``(source, event, target)``.

        Parameters
        ----------
        initial : str
            Name of :math:`q_0`.
        transitions : iterable of (str, str, str)
            Must be deterministic: at most one target per (source, event).
        marked : iterable of str, optional
            :math:`Q_m`; every state when omitted (a prefix-closed mission).
        states : sequence of str, optional
            State order; otherwise the initial state first, then in order of appearance.
        alphabet : iterable of str, optional
            Extra events (columns without transitions); the alphabet is sorted.

        Raises
        ------
        ValueError
            On nondeterminism or a marked state that does not exist.
        """
        transitions = [(s, e, t) for s, e, t in transitions]
        order: dict[str, int] = {}
        for name in [*(states or []), initial, *[x for s, _, t in transitions for x in (s, t)]]:
            order.setdefault(name, len(order))
        events = sorted({e for _, e, _ in transitions} | set(alphabet or ()))
        col = {e: j for j, e in enumerate(events)}
        delta = np.full((len(order), len(events)), -1, dtype=np.int32)
        for s, e, t in transitions:
            q, j = order[s], col[e]
            if delta[q, j] >= 0 and delta[q, j] != order[t]:
                raise ValueError(f"nondeterministic: state {s!r} has two transitions on {e!r}")
            delta[q, j] = order[t]
        mask = np.ones(len(order), dtype=bool)
        if marked is not None:
            mask[:] = False
            for name in marked:
                if name not in order:
                    raise ValueError(f"marked state {name!r} is not a state")
                mask[order[name]] = True
        return cls(tuple(events), delta, order[initial], mask, tuple(order))

    @classmethod
    def from_words(cls, words: Iterable[Sequence[str]]) -> DFA:
        """The prefix tree of finitely many words: its marked language is exactly `words`.

        Parameters
        ----------
        words : iterable of sequence of str
            The words, each a sequence of events.

        Examples
        --------
        >>> d = DFA.from_words([("a", "b"), ("a", "c")])
        >>> d.n_states, d.accepts(("a", "c")), d.accepts(("a",))
        (4, True, False)
        """
        names: dict[tuple[str, ...], str] = {(): "q0"}
        transitions, marked = [], []
        for word in words:
            word = tuple(word)
            for i in range(len(word)):
                prefix = word[: i + 1]
                if prefix not in names:
                    names[prefix] = f"q{len(names)}"
                    transitions.append((names[word[:i]], word[i], names[prefix]))
            marked.append(names[word])
        return cls.from_transitions("q0", transitions, marked=marked, states=list(names.values()))

    @classmethod
    def from_word(
        cls, word: Sequence[str], alphabet: Iterable[str] | None = None, *, closed: bool = True
    ) -> DFA:
        """The linear DFA of one word: it generates :math:`\\overline{w}` and marks ``w``.

        This is the paper's :math:`\\mathcal{DFA}(t)` used in membership queries.  With
        ``closed=True`` every prefix is marked, so the marked language is
        :math:`\\overline{w}`.

        Parameters
        ----------
        word : sequence of str
            The word :math:`w`.
        alphabet : iterable of str, optional
            Extra events (columns without transitions); the alphabet is sorted.
        closed : bool, default True
            Whether every prefix is marked, or only ``w`` itself.
        """
        events = sorted(set(word) | set(alphabet or ()))
        col = {e: j for j, e in enumerate(events)}
        delta = np.full((len(word) + 1, len(events)), -1, dtype=np.int32)
        for i, e in enumerate(word):
            delta[i, col[e]] = i + 1
        marked = np.ones(len(word) + 1, dtype=bool) if closed else np.arange(len(word) + 1) == len(word)
        return cls(tuple(events), delta, 0, marked)

    @classmethod
    def universal(cls, alphabet: Iterable[str]) -> DFA:
        """One marked state with a self-loop on every event: :math:`\\Sigma^*`.

        Parameters
        ----------
        alphabet : iterable of str
            :math:`\\Sigma`.
        """
        events = tuple(sorted(set(alphabet)))
        return cls(events, np.zeros((1, len(events)), dtype=np.int32), 0, np.ones(1, dtype=bool))

    @classmethod
    def empty(cls, alphabet: Iterable[str] = ()) -> DFA:
        """The empty language: one unmarked state, no transitions.

        Parameters
        ----------
        alphabet : iterable of str, optional
            :math:`\\Sigma` (events without transitions).
        """
        events = tuple(sorted(set(alphabet)))
        return cls(events, np.full((1, len(events)), -1, dtype=np.int32), 0, np.zeros(1, dtype=bool))

    # -- serialisation ----------------------------------------------------------------------
    def transitions(self) -> list[tuple[str, str, str]]:
        """All transitions as named ``(source, event, target)`` triples, in table order."""
        rows, cols = np.nonzero(self.delta >= 0)
        return [
            (self.name_of(int(q)), self.alphabet[int(j)], self.name_of(int(self.delta[q, j])))
            for q, j in zip(rows, cols, strict=True)
        ]

    def to_dict(self, *, with_alphabet: bool = False) -> dict[str, Any]:
        """The DFA form of the scenario file: ``initial``, ``transitions`` (+ ``states``, ``marked``).

        ``marked`` is omitted when every state is marked (a prefix-closed mission), ``states``
        when every state appears on a transition or is initial.  ``with_alphabet`` adds the
        sorted ``alphabet`` (events without transitions are otherwise lost).

        Parameters
        ----------
        with_alphabet : bool, default False
            Whether to add the ``alphabet`` entry.
        """
        data: dict[str, Any] = {
            "initial": self.name_of(self.initial),
            "transitions": [list(t) for t in self.transitions()],
        }
        on_edges = set(np.flatnonzero((self.delta >= 0).any(axis=1))) | set(
            self.delta[self.delta >= 0].tolist()
        )
        if len(on_edges | {self.initial}) < self.n_states:
            data["states"] = [self.name_of(q) for q in range(self.n_states)]
        if not self.marked.all():
            data["marked"] = [self.name_of(int(q)) for q in np.flatnonzero(self.marked)]
        if with_alphabet:
            data["alphabet"] = list(self.alphabet)
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DFA:
        """Inverse of :meth:`to_dict` (also reads a scenario's ``mission.dfa`` block).

        Parameters
        ----------
        data : mapping
            ``initial`` and optionally ``transitions``, ``marked``, ``states``, ``alphabet``.
        """
        return cls.from_transitions(
            data["initial"],
            [tuple(t) for t in data.get("transitions", ())],
            marked=data.get("marked"),
            states=data.get("states"),
            alphabet=data.get("alphabet"),
        )

    def to_dot(self, name: str = "G") -> str:
        """Graphviz DOT text: marked states are double circles, parallel edges are merged.

        Parameters
        ----------
        name : str, default "G"
            The graph's name.
        """

        def quote(text: str) -> str:
            return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'

        lines = [f"digraph {quote(name)} {{", "  rankdir=LR;", '  __start [shape=point, label=""];']
        for q in range(self.n_states):
            shape = "doublecircle" if self.marked[q] else "circle"
            lines.append(f"  {quote(self.name_of(q))} [shape={shape}];")
        lines.append(f"  __start -> {quote(self.name_of(self.initial))};")
        edges: dict[tuple[int, int], list[str]] = {}
        rows, cols = np.nonzero(self.delta >= 0)
        for row, j in zip(rows, cols, strict=True):
            edges.setdefault((int(row), int(self.delta[row, j])), []).append(self.alphabet[int(j)])
        for (q, t), labels in edges.items():
            lines.append(
                f"  {quote(self.name_of(q))} -> {quote(self.name_of(t))} [label={quote(', '.join(labels))}];"
            )
        lines.append("}")
        return "\n".join(lines) + "\n"
