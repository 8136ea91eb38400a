"""Operations on DFAs: trim, products, natural projection, inclusion, minimisation.

All operations are on marked languages :math:`L_m` and return new :class:`DFA` objects.
Product-like constructions share one breadth-first explorer
(:func:`cosmop.automata._index.explore`), so each of them is a successor function on arrays
of integer-coded state pairs.

Definitions follow Section II-A of the paper:

* natural projection :math:`P: \\Sigma^* \\to \\Sigma'^*` erases the events outside
  :math:`\\Sigma'`; on automata it is the subset construction over the
  :math:`(\\Sigma \\setminus \\Sigma')`-closure;
* the synchronous product :math:`\\|_i L_i = \\bigcap_i P_i^{-1}(L_i)`: shared events
  synchronise, private events interleave.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator, Sequence

import numpy as np
from numpy.typing import ArrayLike

from cosmop.automata._index import coreachable, explore, fresh_states, reachable
from cosmop.automata.dfa import DFA

# ---------------------------------------------------------------------------------------------
# alphabets and sub-automata
# ---------------------------------------------------------------------------------------------


def _columns(dfa: DFA, alphabet: Sequence[str], missing: str) -> np.ndarray:
    """``dfa.delta`` re-indexed to ``alphabet``.

    Events of ``alphabet`` that the DFA does not know are ``missing='block'`` (undefined) or
    ``missing='loop'`` (self-loops everywhere, as in an inverse projection).
    """
    if tuple(alphabet) == dfa.alphabet:
        return dfa.delta
    index = dfa.event_index()
    out = np.empty((dfa.n_states, len(alphabet)), dtype=np.int32)
    loops = np.arange(dfa.n_states, dtype=np.int32)
    for j, event in enumerate(alphabet):
        k = index.get(event)
        if k is not None:
            out[:, j] = dfa.delta[:, k]
        else:
            out[:, j] = loops if missing == "loop" else -1
    return out


def extend_alphabet(dfa: DFA, events: Iterable[str]) -> DFA:
    """The same language over :math:`\\Sigma \\cup E`: the new events never occur.

    Parameters
    ----------
    dfa : DFA
        The automaton.
    events : iterable of str
        The events :math:`E` to add.
    """
    alphabet = tuple(sorted(set(dfa.alphabet) | set(events)))
    return DFA(alphabet, _columns(dfa, alphabet, "block"), dfa.initial, dfa.marked, dfa.state_names)


def inverse_project(dfa: DFA, alphabet: Iterable[str]) -> DFA:
    """Inverse projection :math:`P^{-1}(L) \\subseteq \\Sigma_{big}^*`.

    Parameters
    ----------
    dfa : DFA
        Recognises :math:`L` over :math:`\\Sigma`.
    alphabet : iterable of str
        The larger alphabet; the union with :math:`\\Sigma` is used.

    Returns
    -------
    DFA
        Self-loops on every event outside :math:`\\Sigma`, at every state.
    """
    events = tuple(sorted(set(dfa.alphabet) | set(alphabet)))
    return DFA(events, _columns(dfa, events, "loop"), dfa.initial, dfa.marked, dfa.state_names)


def restrict(dfa: DFA, keep: np.ndarray) -> DFA:
    """Sub-automaton on the states where ``keep`` holds (must include the initial state).

    Parameters
    ----------
    dfa : DFA
        The automaton.
    keep : ndarray of bool, shape (n,)
        Which states to keep.
    """
    keep = np.asarray(keep, dtype=bool)
    if not keep[dfa.initial]:
        raise ValueError("restrict must keep the initial state")
    new_id = np.cumsum(keep, dtype=np.int64) - 1
    new_id[~keep] = -1
    sub = dfa.delta[keep]
    delta = np.where(sub >= 0, new_id[np.maximum(sub, 0)], -1).astype(np.int32)
    names = None
    if dfa.state_names is not None:
        names = tuple(n for n, k in zip(dfa.state_names, keep, strict=True) if k)
    return DFA(dfa.alphabet, delta, int(new_id[dfa.initial]), dfa.marked[keep], names)


def _known_accessible(dfa: DFA) -> DFA:
    """Note on `dfa` that every state is reachable (the construction guarantees it), so that
    :func:`accessible` and :func:`is_empty` need no search; returns `dfa`."""
    object.__setattr__(dfa, "_accessible", True)
    return dfa


def _is_known_accessible(dfa: DFA) -> bool:
    return getattr(dfa, "_accessible", False)


def with_marked(dfa: DFA, marked: ArrayLike) -> DFA:
    """The same automaton with the states `marked` (boolean, one per state) marked.

    Parameters
    ----------
    dfa : DFA
        The automaton.
    marked : array_like of bool, shape (n,)
        Whether each state is marked.

    Examples
    --------
    >>> with_marked(DFA.from_word(("a", "b")), [False, True, False]).accepts(("a",))
    True
    """
    out = DFA(dfa.alphabet, dfa.delta, dfa.initial, np.asarray(marked, dtype=bool), dfa.state_names)
    return _known_accessible(out) if _is_known_accessible(dfa) else out


def accessible(dfa: DFA) -> DFA:
    """Restriction to the states reachable from :math:`q_0` (same generated language).

    Parameters
    ----------
    dfa : DFA
        The automaton.
    """
    if _is_known_accessible(dfa):
        return dfa
    keep = reachable(dfa.delta, np.array([dfa.initial]))
    return _known_accessible(dfa if keep.all() else restrict(dfa, keep))


def coaccessible_mask(dfa: DFA) -> np.ndarray:
    """States from which a marked state can be reached.

    Parameters
    ----------
    dfa : DFA
        The automaton.
    """
    return coreachable(dfa.delta, np.flatnonzero(dfa.marked))


def trim(dfa: DFA) -> DFA:
    """Accessible and co-accessible part: same marked language, no blocking states.

    The empty marked language trims to :meth:`DFA.empty` over the same alphabet.

    Parameters
    ----------
    dfa : DFA
        The automaton.
    """
    dfa = accessible(dfa)
    if dfa.marked.all():  # prefix-closed: every accessible state is co-accessible
        return dfa
    keep = coaccessible_mask(dfa)
    if not keep[dfa.initial]:
        return DFA.empty(dfa.alphabet)
    # a path to a state that can reach a marked one runs through such states only
    return dfa if keep.all() else _known_accessible(restrict(dfa, keep))


def is_empty(dfa: DFA) -> bool:
    """Whether :math:`L_m(G) = \\emptyset`.

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    """
    if _is_known_accessible(dfa):
        return not dfa.marked.any()
    return not reachable(dfa.delta, np.array([dfa.initial]))[dfa.marked].any()


def prefix_closure(dfa: DFA) -> DFA:
    """:math:`\\overline{L_m(G)}`: trim, then mark every state.

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    """
    t = trim(dfa)
    if is_empty(t):
        return t
    return with_marked(t, np.ones(t.n_states, dtype=bool))


def complete(dfa: DFA, alphabet: Iterable[str] | None = None) -> DFA:
    """Same marked language over :math:`\\Sigma \\cup` ``alphabet`` with a total transition function.

    A non-marked sink state (the last state) absorbs every undefined transition.

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    alphabet : iterable of str, optional
        Extra events.
    """
    events = tuple(sorted(set(dfa.alphabet) | set(alphabet or ())))
    table = _columns(dfa, events, "block")
    sink = dfa.n_states
    table = np.vstack([np.where(table >= 0, table, sink), np.full((1, len(events)), sink, dtype=np.int32)])
    return DFA(events, table, dfa.initial, np.append(dfa.marked, False))


def complement(dfa: DFA, alphabet: Iterable[str] | None = None) -> DFA:
    """:math:`\\Sigma^* \\setminus L_m(G)` over :math:`\\Sigma \\cup` ``alphabet``.

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    alphabet : iterable of str, optional
        Extra events.
    """
    c = complete(dfa, alphabet)
    return with_marked(c, ~c.marked)


# ---------------------------------------------------------------------------------------------
# products
# ---------------------------------------------------------------------------------------------


_DENSE_LIMIT = 1 << 26  # table entries (256 MB of int32) up to which products are built densely


def _pair(a: DFA, b: DFA, *, synchronous: bool, a_accessible: bool = False) -> DFA:
    """Product of two DFAs over :math:`\\Sigma_a \\cup \\Sigma_b`.

    ``synchronous=True``: the synchronous product (an event outside one alphabet leaves that
    component where it is).  ``False``: the intersection of the languages as subsets of
    :math:`(\\Sigma_a \\cup \\Sigma_b)^*` (an event outside one alphabet is blocked).
    Only accessible pairs are built; a pair is marked when both components are.
    `a_accessible` says that every state of ``a`` is known to be accessible.
    """
    alphabet = tuple(sorted(set(a.alphabet) | set(b.alphabet)))
    missing = "loop" if synchronous else "block"
    da, db = _columns(a, alphabet, missing), _columns(b, alphabet, missing)
    nb = b.n_states
    if a.n_states * nb * max(len(alphabet), 1) <= _DENSE_LIMIT:
        # Small pair space: fill the whole table at once, then keep the accessible part.
        marked = (a.marked[:, None] & b.marked[None, :]).ravel()
        whole = DFA(alphabet, _pair_table(da, db), a.initial * nb + b.initial, marked)
        # No shared event: a pair (p, q) is reached by a word to p followed by a word to q,
        # so when both sides are accessible every pair is, and the search can be skipped.
        interleaved = synchronous and not set(a.alphabet) & set(b.alphabet)
        if interleaved and (a_accessible or _all_accessible(a)) and _all_accessible(b):
            return _known_accessible(whole)
        return accessible(whole)
    da, db = da.astype(np.int64), db.astype(np.int64)

    def successors(codes: np.ndarray) -> np.ndarray:
        ta = da[codes // nb]
        tb = db[codes % nb]
        return np.where((ta >= 0) & (tb >= 0), ta * nb + tb, -1)

    ex = explore(a.initial * nb + b.initial, successors, len(alphabet))
    marked = a.marked[ex.codes // nb] & b.marked[ex.codes % nb]
    return _known_accessible(DFA(alphabet, ex.delta, 0, marked))  # explored from the start


def _pair_table(da: np.ndarray, db: np.ndarray) -> np.ndarray:
    """Every pair's row: ``ta * nb + tb`` where both move, else ``-1`` (``int32``, pair
    ``(p, q)`` at row ``p * nb + q``), built as one ``(na, nb, m)`` block (rows contiguous)."""
    (na, m), nb = da.shape, db.shape[0]
    ta, tb = da, db  # int32: a dense table has fewer than 2**26 entries, codes fit
    table = np.empty((na, nb, m), dtype=np.int32)
    np.multiply(ta[:, None, :], np.int32(nb), out=table)
    table += tb[None, :, :]
    np.putmask(table, (ta < 0)[:, None, :] | (tb < 0)[None, :, :], np.int32(-1))
    return table.reshape(na * nb, m)


def _all_accessible(dfa: DFA) -> bool:
    return _is_known_accessible(dfa) or bool(reachable(dfa.delta, np.array([dfa.initial])).all())


def parallel(*dfas: DFA) -> DFA:
    """Synchronous (parallel) product :math:`G_1 \\| G_2 \\| \\cdots`.

    :math:`L_m(G_1 \\| G_2) = P_1^{-1}(L_m(G_1)) \\cap P_2^{-1}(L_m(G_2))` over
    :math:`\\Sigma_1 \\cup \\Sigma_2` (the paper's Definition of the synchronous product).
    Components are folded left to right; only accessible states are built.

    Parameters
    ----------
    *dfas : DFA
        The components, at least one.
    """
    return _fold(dfas, synchronous=True)


def product(*dfas: DFA) -> DFA:
    """Product (intersection) :math:`L_m(G_1) \\cap L_m(G_2) \\cap \\cdots`.

    Languages are sets of words over the union of the alphabets, so an event that one
    component does not know is blocked.  With equal alphabets this equals :func:`parallel`.

    Parameters
    ----------
    *dfas : DFA
        The components, at least one.
    """
    return _fold(dfas, synchronous=False)


def _fold(dfas: Sequence[DFA], *, synchronous: bool) -> DFA:
    """Left fold of :func:`_pair` over at least one DFA."""
    if not dfas:
        raise ValueError("a product needs at least one DFA")
    result = dfas[0]
    for k, other in enumerate(dfas[1:]):  # every product after the first is accessible
        result = _pair(result, other, synchronous=synchronous, a_accessible=k > 0)
    return result


# ---------------------------------------------------------------------------------------------
# natural projection
# ---------------------------------------------------------------------------------------------


def project(dfa: DFA, events: Iterable[str]) -> DFA:
    """Natural projection :math:`P_{\\Sigma'}(L_m(G))` as a DFA over :math:`\\Sigma'`.

    Subset construction over the unobservable closure: a state of the result is the set of
    states of ``dfa`` reachable by words whose projection is the same; it is marked when it
    contains a marked state.  Events of :math:`\\Sigma'` that ``dfa`` does not know are kept
    in the alphabet (they never occur).

    Parameters
    ----------
    dfa : DFA
    events : iterable of str
        The observable alphabet :math:`\\Sigma'`.

    Returns
    -------
    DFA
        Deterministic, accessible (not minimised).  The worst case is exponential in the
        number of states (subset construction); for missions it is usually far smaller.
    """
    target = tuple(sorted(set(events)))
    index = dfa.event_index()
    observable = [(j, index[e]) for j, e in enumerate(target) if e in index]
    hidden = [k for k, e in enumerate(dfa.alphabet) if e not in set(target)]
    if not hidden:
        return DFA(target, _columns(dfa, target, "block"), dfa.initial, dfa.marked, dfa.state_names)
    shown = np.array([col for _, col in observable], dtype=np.intp)
    n = dfa.n_states
    # one more entry, always seen: ``seen[-1]`` is it, so "no move" (-1) is never fresh
    seen = np.zeros(n + 1, dtype=bool)
    seen[n] = True
    scratch = np.zeros(n + 1, dtype=bool)

    def closure(states: np.ndarray) -> np.ndarray:
        """The sorted set of states reachable from `states` by hidden events."""
        parts = [fresh_states(states, seen, scratch)]
        frontier = parts[0]
        while frontier.size:
            # whole rows, observable columns blanked: cheaper than a hidden-column copy of delta
            nxt = dfa.delta[frontier]
            nxt[:, shown] = -1
            frontier = fresh_states(nxt.ravel(), seen, scratch)
            parts.append(frontier)
        size = sum(p.size for p in parts)
        # a large set is read off the mask (linear in the states), a small one sorted
        result = np.flatnonzero(seen[:n]) if 16 * size > n else np.sort(np.concatenate(parts))
        seen[result] = False
        return result.astype(np.int32)

    start = closure(np.array([dfa.initial], dtype=np.int32))
    subsets: list[np.ndarray] = [start]
    ids: dict[bytes, int] = {start.tobytes(): 0}
    rows: list[list[int]] = []
    k = 0
    while k < len(subsets):
        current = subsets[k]
        row = [-1] * len(target)
        for j, col in observable:
            succ = dfa.delta[current, col]
            succ = succ[succ >= 0]
            if succ.size == 0:
                continue
            subset = closure(succ)  # the closure deduplicates
            key = subset.tobytes()
            sid = ids.get(key)
            if sid is None:
                sid = ids[key] = len(subsets)
                subsets.append(subset)
            row[j] = sid
        rows.append(row)
        k += 1
    marked = np.array([bool(dfa.marked[s].any()) for s in subsets])
    table = np.array(rows, dtype=np.int32).reshape(len(subsets), len(target))
    return _known_accessible(DFA(target, table, 0, marked))  # every subset was reached


# ---------------------------------------------------------------------------------------------
# inclusion and equivalence
# ---------------------------------------------------------------------------------------------


def inclusion_counterexample(a: DFA, b: DFA) -> tuple[str, ...] | None:
    """A shortest word of :math:`L_m(a) \\setminus L_m(b)`, or ``None`` if :math:`L_m(a) \\subseteq L_m(b)`.

    Languages are sets of words over the union of the alphabets.  Breadth-first search of
    ``a`` against the completion of ``b``; the first level holding a pair (marked in ``a``,
    not marked in ``b``) gives a shortest counterexample.  When a state of ``a`` meets a
    single state of ``b`` (the usual case) the search runs over ``a``'s states alone, first
    on ``a`` as given and, if that fails, on ``trim(a)``; else over the pairs.

    Parameters
    ----------
    a, b : DFA
        The two automata, compared by marked language.
    """
    alphabet = tuple(sorted(set(a.alphabet) | set(b.alphabet)))
    db = _columns(b, alphabet, "block")
    try:
        # ``a`` as it is first: the search meets only accessible states, and a state from
        # which no marked state is reachable is never marked, so it never ends the search;
        # trimming (a pass over every transition) is paid only when the fast path fails
        found = _inclusion_by_partner(a, b, _columns(a, alphabet, "block"), db)
    except _NotFunctional:
        a = trim(a)
        da = _columns(a, alphabet, "block")
        try:
            found = _inclusion_by_partner(a, b, da, db)
        except _NotFunctional:
            found = _inclusion_by_pairs(a, complete(b, alphabet), da)
    return None if found is None else tuple(alphabet[j] for j in found)


class _NotFunctional(Exception):
    """A state of ``a`` meets two states of ``b``: the partner fast path does not apply."""


def _inclusion_by_pairs(a: DFA, bc: DFA, da: np.ndarray) -> list[int] | None:
    """Breadth-first search of all accessible pairs against the completed ``bc``; event
    columns of a shortest counterexample, or ``None`` when included."""
    nb = bc.n_states
    db = bc.delta.astype(np.int64)
    da = da.astype(np.int64)

    def successors(codes: np.ndarray) -> np.ndarray:
        ta = da[codes // nb]
        tb = db[codes % nb]
        return np.where(ta >= 0, ta * nb + tb, -1)

    def bad(codes: np.ndarray) -> np.ndarray:
        found: np.ndarray = a.marked[codes // nb] & ~bc.marked[codes % nb]
        return found

    ex = explore(a.initial * nb + bc.initial, successors, da.shape[1], stop=bad)
    return None if ex.stopped_at < 0 else ex.word_to(ex.stopped_at)


def _inclusion_by_partner(a: DFA, b: DFA, da: np.ndarray, db: np.ndarray) -> list[int] | None:
    """Fast path when every accessible state of ``a`` meets exactly one state of ``b``.

    Then the pair graph is the graph of ``a`` and a breadth-first search over ``a``'s states
    with plain arrays (no hashing) decides inclusion.  ``b``'s undefined transitions lead to
    a virtual non-marked sink ``b.n_states``.  Raises :class:`_NotFunctional` as soon as one
    state of ``a`` is met with two different states of ``b``.
    """
    n, m = da.shape
    sink = b.n_states
    b_marked = np.append(b.marked, False)
    partner = np.full(n, -1, dtype=np.int64)
    parent = np.full(n, -1, dtype=np.int64)
    via = np.full(n, -1, dtype=np.int64)
    stamp = np.empty(n, dtype=np.int64)
    partner[a.initial] = b.initial

    def word_to(q: int) -> list[int]:
        out = []
        while q != a.initial:
            out.append(int(via[q]))
            q = int(parent[q])
        return out[::-1]

    if a.marked[a.initial] and not b_marked[b.initial]:
        return []
    frontier = np.array([a.initial], dtype=np.int64)
    while frontier.size:
        rows = da[frontier].ravel()
        where = np.flatnonzero(rows >= 0)
        ta = rows[where].astype(np.int64)
        pb = partner[frontier[where // m]]
        in_b = pb < sink
        tb = np.full(ta.size, sink, dtype=np.int64)
        tb[in_b] = db[pb[in_b], where[in_b] % m]
        tb[tb < 0] = sink
        known = partner[ta]
        if np.any((known >= 0) & (known != tb)):
            raise _NotFunctional
        fresh = np.flatnonzero(known < 0)
        ta, tb, where = ta[fresh], tb[fresh], where[fresh]
        # each entry's first occurrence of its state, without sorting: written backwards,
        # the earliest position is the one left in `stamp`
        positions = np.arange(ta.size)
        stamp[ta[::-1]] = positions[::-1]
        first = stamp[ta]
        if np.any(tb != tb[first]):
            raise _NotFunctional
        new = np.sort(ta[first == positions])
        at = stamp[new]
        partner[new] = tb[at]
        parent[new] = frontier[where[at] // m]
        via[new] = where[at] % m
        bad = np.flatnonzero(a.marked[new] & ~b_marked[partner[new]])
        if bad.size:
            return word_to(int(new[bad[0]]))
        frontier = new
    return None


def is_included(a: DFA, b: DFA) -> bool:
    """Whether :math:`L_m(a) \\subseteq L_m(b)`.

    Parameters
    ----------
    a, b : DFA
        The two automata, compared by marked language.
    """
    return inclusion_counterexample(a, b) is None


def equivalence_counterexample(a: DFA, b: DFA) -> tuple[str, ...] | None:
    """A shortest word in the symmetric difference of the marked languages, or ``None``.

    Parameters
    ----------
    a, b : DFA
        The two automata, compared by marked language.
    """
    words = [w for w in (inclusion_counterexample(a, b), inclusion_counterexample(b, a)) if w is not None]
    return min(words, key=len) if words else None


def equivalent(a: DFA, b: DFA) -> bool:
    """Whether :math:`L_m(a) = L_m(b)`.

    Parameters
    ----------
    a, b : DFA
        The two automata, compared by marked language.
    """
    return equivalence_counterexample(a, b) is None


def satisfaction_counterexample(model: DFA, spec: DFA) -> tuple[str, ...] | None:
    """A shortest word ``t`` of ``model`` with :math:`P_{\\Sigma_{spec}}(t) \\notin L_m(spec)`.

    This is :math:`M \\models K` of the paper: :math:`P(L_m(M)) \\subseteq L_m(K)`,
    equivalently :math:`L_m(M) \\subseteq P^{-1}(L_m(K))`; the counterexample is a word of the
    model, over its own alphabet.

    Parameters
    ----------
    model : DFA
        :math:`M`.
    spec : DFA
        :math:`K`, over an alphabet that may be smaller than the model's.
    """
    return inclusion_counterexample(model, inverse_project(spec, model.alphabet))


# ---------------------------------------------------------------------------------------------
# minimisation and enumeration
# ---------------------------------------------------------------------------------------------


def canonical(dfa: DFA) -> DFA:
    """Renumber the accessible states in breadth-first order (events in column order).

    Two minimal DFAs of the same language over the same alphabet have identical canonical
    tables.

    Parameters
    ----------
    dfa : DFA
        The automaton.
    """
    dfa = accessible(dfa)
    order = [dfa.initial]
    new_id = np.full(dfa.n_states, -1, dtype=np.int64)
    new_id[dfa.initial] = 0
    k = 0
    while k < len(order):
        for t in dfa.delta[order[k]]:
            if t >= 0 and new_id[t] < 0:
                new_id[t] = len(order)
                order.append(int(t))
        k += 1
    perm = np.array(order)
    sub = dfa.delta[perm]
    delta = np.where(sub >= 0, new_id[np.maximum(sub, 0)], -1).astype(np.int32)
    return _known_accessible(DFA(dfa.alphabet, delta, 0, dfa.marked[perm]))


def minimize(dfa: DFA) -> DFA:
    """Minimal DFA of :math:`L_m(G)` (trim, partial, canonical numbering).

    Moore's partition refinement, vectorised: a class is refined by the tuple (own class,
    class of each successor), with ``-1`` standing for the implicit dead state, until the
    number of classes is stable.

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    """
    t = trim(dfa)
    if is_empty(t):
        return DFA.empty(t.alphabet)
    classes = t.marked.astype(np.int64)
    count = int(classes.any()) + int(not classes.all())  # marked and unmarked: one or two classes
    while True:
        succ = np.where(t.delta >= 0, classes[np.maximum(t.delta, 0)], -1)
        signature = np.column_stack([classes, succ])
        _, classes = np.unique(signature, axis=0, return_inverse=True)
        classes = classes.ravel().astype(np.int64)
        new_count = int(classes.max()) + 1
        if new_count == count:
            break
        count = new_count
    reps = np.zeros(count, dtype=np.int64)
    reps[classes] = np.arange(t.n_states)
    sub = t.delta[reps]
    delta = np.where(sub >= 0, classes[np.maximum(sub, 0)], -1).astype(np.int32)
    return canonical(DFA(t.alphabet, delta, int(classes[t.initial]), t.marked[reps]))


def words(dfa: DFA, max_length: int, *, marked: bool = True) -> Iterator[tuple[str, ...]]:
    """Words of :math:`L_m(G)` (or :math:`L(G)` with ``marked=False``) up to ``max_length``.

    In breadth-first (length, then alphabet column) order.  Meant for tests and small
    automata: the number of words can be exponential in ``max_length``.

    Parameters
    ----------
    dfa : DFA
        The automaton :math:`G`.
    max_length : int
        The longest word listed.
    marked : bool, default True
        Whether to list the marked language or the generated one.
    """
    queue: deque[tuple[int, tuple[str, ...]]] = deque([(dfa.initial, ())])
    while queue:
        q, w = queue.popleft()
        if not marked or dfa.marked[q]:
            yield w
        if len(w) < max_length:
            for j, t in enumerate(dfa.delta[q]):
                if t >= 0:
                    queue.append((int(t), (*w, dfa.alphabet[j])))
