"""Synchronous products kept as their components, and their projection without the product.

A mission written in tasks form is the synchronous product :math:`\\|_j T_j` of one sequence
per robot: 4^N states for N robots of three events each.  Everything the top-down layer needs
from it is a natural projection, and projections of products can be computed component-wise:

**Lemma** (projection distributes over a product when shared events are kept).  If
:math:`\\Sigma_1 \\cap \\Sigma_2 \\subseteq \\Sigma'` then
:math:`P_{\\Sigma'}(L_1 \\| L_2) = P_{\\Sigma'}(L_1) \\| P_{\\Sigma'}(L_2)`.

:func:`project_composition` therefore composes the components one at a time and, after each
step, hides (projects away) every event that neither the target alphabet nor any component
still to come uses, then minimises.  Components that share no event with the rest (directly
or through others) form separate clusters and are projected on their own.  The result is
exact; the largest automaton built depends on how far events reach across components, not on
their number.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from cosmop.automata._index import explore
from cosmop.automata.dfa import DFA
from cosmop.automata.operations import extend_alphabet, is_empty, minimize, parallel, project


@dataclass
class SizeLog:
    """Running record of the automata an algorithm built, for its statistics.

    Attributes
    ----------
    largest : int
        Most states of any automaton observed.
    built : int
        Number of automata observed.
    """

    largest: int = 0
    built: int = 0

    def observe(self, dfa: DFA) -> DFA:
        """Record ``dfa`` and return it unchanged.

        Parameters
        ----------
        dfa : DFA
            An automaton just built.
        """
        self.largest = max(self.largest, dfa.n_states)
        self.built += 1
        return dfa


@dataclass(frozen=True)
class Composition:
    """The synchronous product :math:`\\|_j G_j` of ``components``, not built.

    Parameters
    ----------
    components : tuple of DFA
        At least one automaton.
    """

    components: tuple[DFA, ...]
    _alphabet: tuple[str, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        components = tuple(self.components)
        if not components:
            raise ValueError("a composition needs at least one component")
        object.__setattr__(self, "components", components)
        object.__setattr__(self, "_alphabet", tuple(sorted({e for c in components for e in c.alphabet})))

    @property
    def alphabet(self) -> tuple[str, ...]:
        """:math:`\\bigcup_j \\Sigma_j`, sorted."""
        return self._alphabet

    def build(self, log: SizeLog | None = None) -> DFA:
        """The product as one DFA (its size is the product of the components' sizes).

        Parameters
        ----------
        log : SizeLog, optional
            Records the product's size.
        """
        result = parallel(*self.components)
        return log.observe(result) if log else result

    def project(self, events: Iterable[str], log: SizeLog | None = None) -> DFA:
        """:math:`P_{\\Sigma'}(\\|_j L_m(G_j))` without building the product.

        Parameters
        ----------
        events : iterable of str
            The target alphabet :math:`\\Sigma'`.
        log : SizeLog, optional
            Records every intermediate automaton.
        """
        return project_composition(self.components, events, log=log)


def clusters(components: Sequence[DFA]) -> list[list[int]]:
    """Groups of components connected by shared events (union-find), in index order.

    Parameters
    ----------
    components : sequence of DFA
        The automata; two share a cluster when they share an event.
    """
    parent = list(range(len(components)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner: dict[str, int] = {}
    for i, comp in enumerate(components):
        for event in comp.alphabet:
            j = owner.setdefault(event, i)
            parent[find(i)] = find(j)
    groups: dict[int, list[int]] = {}
    for i in range(len(components)):
        groups.setdefault(find(i), []).append(i)
    return list(groups.values())


def _order(components: Sequence[DFA], members: list[int], target: set[str]) -> list[int]:
    """Greedy composition order: start where the target is, then follow shared events."""
    remaining = list(members)
    first = max(remaining, key=lambda i: (len(target & set(components[i].alphabet)), -i))
    order, alphabet = [first], set(components[first].alphabet)
    remaining.remove(first)
    while remaining:
        nxt = max(remaining, key=lambda i: (len(alphabet & set(components[i].alphabet)), -i))
        order.append(nxt)
        alphabet |= set(components[nxt].alphabet)
        remaining.remove(nxt)
    return order


def project_composition(
    components: Sequence[DFA], events: Iterable[str], *, log: SizeLog | None = None, minimal: bool = True
) -> DFA:
    """Natural projection of a synchronous product, computed compositionally.

    Parameters
    ----------
    components : sequence of DFA
        The factors :math:`G_j` of :math:`\\|_j G_j`.
    events : iterable of str
        The target alphabet :math:`\\Sigma'`.
    log : SizeLog, optional
        Records every intermediate automaton (to report the largest one built).
    minimal : bool
        Minimise every intermediate automaton (the default).  With ``False`` only the results
        of a projection are minimised (a subset construction is rarely minimal): the language
        is the same, and a caller that only searches the result, such as an inclusion check,
        saves the minimisations of components taken as they are.

    Returns
    -------
    DFA
        A DFA of :math:`P_{\\Sigma'}(\\|_j L_m(G_j))` over :math:`\\Sigma'`, minimal unless
        `minimal` is false.

    Notes
    -----
    Exact by the lemma in the module docstring: at step ``k`` the accumulated automaton is
    projected onto :math:`\\Sigma' \\cup \\bigcup_{l > k} \\Sigma_l`, which contains every
    event it shares with the components still to come.  If one cluster's marked language is
    empty, so is the product's, and the result is the empty language.
    """
    target = set(events)
    observe = log.observe if log else (lambda d: d)
    parts: list[DFA] = []
    for members in clusters(components):
        touches = any(target & set(components[i].alphabet) for i in members)
        if not touches and all(components[i].marked[components[i].initial] for i in members):
            continue  # contributes {ε}: the empty word is in every factor, so the cluster is not empty
        order = _order(components, members, target)
        acc: DFA | None = None
        for k, i in enumerate(order):
            later = {e for j in order[k + 1 :] for e in components[j].alphabet}
            acc = components[i] if acc is None else observe(parallel(acc, components[i]))
            keep = (target | later) & set(acc.alphabet)
            projected = keep != set(acc.alphabet)
            if projected:
                acc = observe(project(acc, keep))
            if minimal or projected:
                acc = observe(minimize(acc))
        assert acc is not None
        if is_empty(acc):
            return DFA.empty(target)
        if set(acc.alphabet) & target:
            parts.append(acc)
    if not parts:
        none = np.full((1, len(target)), -1, dtype=np.int32)
        return DFA(tuple(sorted(target)), none, 0, np.ones(1, dtype=bool))
    result = observe(parallel(*parts)) if len(parts) > 1 else parts[0]
    return extend_alphabet(result, target)


def shortest_word(dfa: DFA) -> tuple[str, ...] | None:
    """A shortest word of :math:`L_m(G)` (``None`` if the language is empty).

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    """
    delta = dfa.delta.astype(np.int64)
    ex = explore(dfa.initial, lambda codes: delta[codes], dfa.n_events, stop=lambda codes: dfa.marked[codes])
    if ex.stopped_at < 0:
        return None
    return tuple(dfa.alphabet[j] for j in ex.word_to(ex.stopped_at))


def lift_word(
    components: Sequence[DFA], word: Sequence[str], alphabet: Iterable[str]
) -> tuple[str, ...] | None:
    """A word ``t`` of :math:`L_m(\\|_j G_j)` with :math:`P_{\\Sigma'}(t) =` ``word``.

    Turns a counterexample found on a projection back into a word of the whole product.
    The components that share events with :math:`\\Sigma'` (directly or through others) are
    composed with the one-word automaton of ``word`` placed first, so the product never
    grows beyond the words that project onto ``word``; every other cluster contributes one
    of its shortest marked words, appended at the end.

    Returns ``None`` when no word of the product projects onto ``word``.

    Parameters
    ----------
    components : sequence of DFA
        The factors :math:`G_j`.
    word : sequence of str
        A word over :math:`\\Sigma'`.
    alphabet : iterable of str
        :math:`\\Sigma'`, the alphabet `word` was projected onto.
    """
    # events of the target that no component knows never occur in the product
    known = set(alphabet) & {e for c in components for e in c.alphabet}
    if not set(word) <= known:
        return None
    pinned = DFA.from_word(tuple(word), known, closed=False)
    groups = clusters([pinned, *components])
    head: tuple[str, ...] = ()
    tail: list[str] = []
    for members in groups:
        w = shortest_word(parallel(*[pinned if i == 0 else components[i - 1] for i in members]))
        if w is None:
            return None
        if 0 in members:
            head = w
        else:
            tail.extend(w)
    return (*head, *tail)
