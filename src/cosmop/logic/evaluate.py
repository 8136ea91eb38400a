"""Exact evaluation of CLTLB(D) formulas on finite traces.

A trace :math:`\\rho` of length :math:`K` is a sequence of :math:`K+1` mappings from variable
name to value, :math:`\\rho(0), \\dots, \\rho(K)`. The semantics is the one stated in
:mod:`cosmop.logic.formulas` (the paper's Definition "Semantics" with strong next and previous,
out-of-range atoms false, :math:`\\mathit{Last}[\\phi]` read at :math:`K`); arithmetic is exact
(``int`` and :class:`~fractions.Fraction`).

The evaluator computes, for every distinct sub-formula, its truth value at all instants at once,
children before parents: :math:`O(|\\phi| \\cdot K)` work, with the temporal operators by their
fixpoint characterisations (for :math:`k < K`)

.. math::

    \\phi\\,\\mathbf{U}\\,\\psi\\,[k] = \\psi[k] \\vee (\\phi[k] \\wedge \\phi\\,\\mathbf{U}\\,\\psi\\,[k+1]),
    \\qquad \\phi\\,\\mathbf{U}\\,\\psi\\,[K] = \\psi[K],

and symmetrically for :math:`\\mathbf{S}` from instant 0. Neither the trace length nor the
formula depth is limited by Python's recursion limit.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction

from cosmop.logic.formulas import (
    Always,
    And,
    BoolConst,
    Compare,
    Eventually,
    Formula,
    Iff,
    Implies,
    Last,
    LinExpr,
    Max,
    Min,
    Next,
    Not,
    Or,
    Prev,
    Shifted,
    Since,
    Until,
    Var,
    as_formula,
    normalize_value,
)

__all__ = ["evaluate", "evaluate_all", "failing"]

Trace = Sequence[Mapping[str, object]]

_COMPARE: dict[str, Callable[[Fraction | int, Fraction | int], bool]] = {
    "<=": operator.le,
    "<": operator.lt,
    ">=": operator.ge,
    ">": operator.gt,
    "==": operator.eq,
}


def evaluate(formula: object, trace: Trace, k: int = 0) -> bool:
    """Whether ``formula`` holds on ``trace`` at instant ``k``: :math:`\\rho, k \\models \\phi`.

    Parameters
    ----------
    formula : Formula or bool Var
    trace : sequence of mapping
        :math:`\\rho(0), \\dots, \\rho(K)` with :math:`K \\ge 0`: each mapping gives a value to every
        variable the formula reads at that instant (``bool`` for bool variables, integers for
        int ones, ``int``/``Fraction``/``float`` for real ones; floats are read as typed, e.g.
        ``0.1`` is :math:`1/10`). Extra names are ignored.
    k : int, default 0
        The instant, :math:`0 \\le k \\le K`. A formula holds on a trace when it holds at 0.

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        If the trace is empty or ``k`` is outside :math:`[0, K]`.
    KeyError
        If a needed value is missing.
    TypeError
        If a value does not fit its variable's sort.

    Examples
    --------
    >>> from cosmop.logic import ints, Eventually
    >>> (x,) = ints("x")
    >>> evaluate(Eventually(x.next().eq(x + 1)), [{"x": 0}, {"x": 5}, {"x": 6}])
    True
    """
    values = evaluate_all(formula, trace)
    if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < len(values):
        raise ValueError(f"instant {k!r} is outside the trace's instants 0..{len(values) - 1}")
    return values[k]


def evaluate_all(formula: object, trace: Trace) -> list[bool]:
    """The truth value of ``formula`` at every instant of ``trace``.

    Parameters
    ----------
    formula : Formula or bool Var
    trace : sequence of mapping
        As for :func:`evaluate`.

    Returns
    -------
    list of bool
        Entry :math:`k` is :math:`\\rho, k \\models \\phi`, for :math:`k = 0, \\dots, K`.
    """
    root = as_formula(formula)
    return _Evaluator(trace).column(root)


def failing(formulas: Sequence[object], trace: Trace) -> list[int]:
    """The indices of the `formulas` that do not hold on `trace` (at instant 0).

    One evaluation shares the work of the sub-formulas the formulas have in common, so
    testing many constraints of one specification on a plan costs little more than one.

    Parameters
    ----------
    formulas : sequence of Formula or bool Var
        The formulas to test.
    trace : sequence of mapping
        As for :func:`evaluate`.

    Examples
    --------
    >>> from cosmop.logic import ints
    >>> (x,) = ints("x")
    >>> failing([x >= 0, x >= 2, x.next() > x], [{"x": 1}, {"x": 3}])
    [1]
    """
    evaluator = _Evaluator(trace)
    return [i for i, f in enumerate(formulas) if not evaluator.column(as_formula(f))[0]]


class _Evaluator:
    """Truth columns of sub-formulas on one trace, memoised by node: by object, then by structure."""

    def __init__(self, trace: Trace) -> None:
        if isinstance(trace, Mapping) or not isinstance(trace, Sequence):
            raise TypeError("a trace is a sequence of mappings (one per instant)")
        if len(trace) == 0:
            raise ValueError("a trace has at least one instant (K >= 0)")
        self.trace = trace
        self.K = len(trace) - 1
        self.columns: dict[Formula, list[bool]] = {}
        # the same by object (id -> (node, column)): a structural look-up of a node equal to one
        # computed but not the same object compares them deeply, so each object is looked up
        # structurally once (as the encoder's canonical formulas are)
        self.by_id: dict[int, tuple[Formula, list[bool]]] = {}
        self.values: dict[tuple[Var, int], bool | int | Fraction] = {}
        self.scaled: dict[Compare, tuple[tuple[tuple[Shifted | Max | Min, int], ...], int]] = {}

    # -- values -------------------------------------------------------------------------------
    def value(self, var: Var, i: int) -> bool | int | Fraction:
        key = (var, i)
        cached = self.values.get(key)
        if cached is None:
            state = self.trace[i]
            try:
                raw = state[var.name]
            except KeyError:
                raise KeyError(f"instant {i} of the trace has no value for variable {var.name!r}") from None
            try:
                cached = normalize_value(var.sort, raw)
            except TypeError as error:
                raise TypeError(f"variable {var.name!r} at instant {i}: {error}") from None
            self.values[key] = cached
        return cached

    def linear(self, expr: LinExpr, k: int) -> Fraction:
        return expr.const + self.weighted(expr.terms, k)

    def weighted(self, terms: Sequence[tuple[Shifted | Max | Min, Fraction | int]], k: int) -> Fraction | int:
        """:math:`\\sum_t c_t \\cdot t` at instant `k` (integers stay integers: :meth:`_integral`)."""
        total: Fraction | int = 0
        for term, coefficient in terms:
            if type(term) is Shifted:  # most terms: the value itself, without a call or a Fraction
                total += coefficient * self.value(term.var, k + term.offset)
            else:
                total += coefficient * self.term(term, k)
        return total

    def term(self, term: Shifted | Max | Min, k: int) -> Fraction:
        if isinstance(term, Shifted):
            return Fraction(self.value(term.var, k + term.offset))
        left, right = self.linear(term.left, k), self.linear(term.right, k)
        return max(left, right) if isinstance(term, Max) else min(left, right)

    def _integral(self, node: Compare) -> tuple[tuple[tuple[Shifted | Max | Min, int], ...], int]:
        """`node`'s coefficients and constant times the least common multiple of their
        denominators: the same comparison (the factor is positive) in integers, which Python
        adds far faster than fractions."""
        known = self.scaled.get(node)
        if known is None:
            terms = node.expr.terms
            scale = math.lcm(node.const.denominator, *(c.denominator for _, c in terms))
            known = tuple((t, int(c * scale)) for t, c in terms), int(node.const * scale)
            self.scaled[node] = known
        return known

    # -- formulas -----------------------------------------------------------------------------
    def column(self, root: Formula) -> list[bool]:
        """The truth column of `root`, computing only the sub-formulas not computed yet: a
        specification's parts share most of their nodes, and each is tested in turn."""
        columns, by_id = self.columns, self.by_id
        stack: list[tuple[Formula, bool]] = [(root, False)]
        while stack:  # post-order, iterative: deep formulas do not hit the recursion limit
            node, expanded = stack.pop()
            if expanded:
                if id(node) not in by_id:  # (an object met twice before it was computed)
                    column = columns[node] = self._compute(node)
                    by_id[id(node)] = (node, column)
            elif id(node) not in by_id:
                known = columns.get(node)
                if known is not None:
                    by_id[id(node)] = (node, known)
                    continue
                stack.append((node, True))
                stack.extend((child, False) for child in reversed(node.children) if id(child) not in by_id)
        return by_id[id(root)][1]

    def _in_range(self, offsets: frozenset[int]) -> range:
        """The instants k at which every k + o, o in offsets, lies in [0, K]."""
        if not offsets:
            return range(self.K + 1)
        return range(max(0, -min(offsets)), min(self.K, self.K - max(offsets)) + 1)

    def _compute(self, node: Formula) -> list[bool]:
        K, by_id = self.K, self.by_id
        n = K + 1
        kind = type(node)
        if kind is BoolConst:
            return [node.value] * n  # type: ignore[attr-defined]
        if kind is Shifted:
            assert isinstance(node, Shifted)
            out = [False] * n
            for k in self._in_range(node.offsets):
                out[k] = bool(self.value(node.var, k + node.offset))
            return out
        if kind is Compare:
            assert isinstance(node, Compare)
            test = _COMPARE[node.op]
            terms, const = self._integral(node)
            out = [False] * n
            for k in self._in_range(node.offsets):
                out[k] = test(self.weighted(terms, k), const)
            return out
        children = [by_id[id(c)][1] for c in node.children]
        if kind is Not:
            return [not v for v in children[0]]
        if kind is And:
            return [all(c[k] for c in children) for k in range(n)]
        if kind is Or:
            return [any(c[k] for c in children) for k in range(n)]
        if kind is Implies:
            a, b = children
            return [(not a[k]) or b[k] for k in range(n)]
        if kind is Iff:
            a, b = children
            return [a[k] == b[k] for k in range(n)]
        if kind is Next:
            (a,) = children
            return [k < K and a[k + 1] for k in range(n)]
        if kind is Prev:
            (a,) = children
            return [k > 0 and a[k - 1] for k in range(n)]
        if kind is Last:
            (a,) = children
            return [a[K]] * n
        if kind in (Until, Eventually, Always):
            if kind is Until:
                hold, goal = children
            else:
                hold, goal = [True] * n, children[0]
            out = [False] * n
            if kind is Always:
                # G f = ~F ~f, and F = true U.
                out[K] = goal[K]
                for k in range(K - 1, -1, -1):
                    out[k] = goal[k] and out[k + 1]
                return out
            out[K] = goal[K]
            for k in range(K - 1, -1, -1):
                out[k] = goal[k] or (hold[k] and out[k + 1])
            return out
        if kind is Since:
            hold, goal = children
            out = [False] * n
            out[0] = goal[0]
            for k in range(1, n):
                out[k] = goal[k] or (hold[k] and out[k - 1])
            return out
        raise TypeError(f"not a formula node: {node!r}")
