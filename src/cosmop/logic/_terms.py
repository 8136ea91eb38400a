"""Z3 terms built straight through Z3's C API, for the encoder's well-sorted terms.

Z3's Python operators (``z3.And``, ``+``, ``<=``, ...) coerce their arguments: they ask each
argument for its sort, merge the sorts, and wrap every intermediate in a Python object.  The
encoder of :mod:`cosmop.logic.encode` already knows every sort (it decides ``Int`` or
``Real`` per atom), so that work only costs time: it was about half of the time a robot's
synthesis spent building its formula.  :class:`Terms` makes the same terms with one C call
each (numerals cached), and returns the usual ``z3.BoolRef`` / ``z3.ArithRef`` objects, so a
solver, a model and Z3's own operators take them as any other term.

Every argument must already have the right sort (Boolean for the connectives, one arithmetic
sort on both sides of a comparison): nothing here converts.  Z3 still checks each call and
raises ``z3.Z3Exception`` on a sort error.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import z3
from z3 import z3core

_COMPARE = {
    "<=": z3core.Z3_mk_le,
    "<": z3core.Z3_mk_lt,
    ">=": z3core.Z3_mk_ge,
    ">": z3core.Z3_mk_gt,
    "==": z3core.Z3_mk_eq,
}


def _array(items: Sequence[Any]) -> Any:
    out = (z3.Ast * len(items))()
    for i, item in enumerate(items):
        out[i] = item.ast
    return out


class Terms:
    """Constructors of Z3 terms in one context, without Python-side sort coercion.

    Examples
    --------
    >>> import z3
    >>> t = Terms(z3.main_ctx())
    >>> x, y = z3.Ints("x y")
    >>> t.compare("<=", t.add([x, t.scaled(2, y, real=False)]), t.number(Fraction(3), real=False))
    x + 2*y <= 3
    """

    def __init__(self, ctx: z3.Context) -> None:
        self._ctx = ctx
        self._ref = ctx.ref()
        self._int = z3.IntSort(ctx).ast
        self._real = z3.RealSort(ctx).ast
        self._numbers: dict[tuple[Fraction, bool], z3.ArithRef] = {}

    def _bool(self, ast: Any) -> z3.BoolRef:
        return z3.BoolRef(ast, self._ctx)

    def _arith(self, ast: Any) -> z3.ArithRef:
        return z3.ArithRef(ast, self._ctx)

    def and_(self, args: Sequence[z3.BoolRef]) -> z3.BoolRef:
        """:math:`\\bigwedge` `args` (two or more)."""
        return self._bool(z3core.Z3_mk_and(self._ref, len(args), _array(args)))

    def or_(self, args: Sequence[z3.BoolRef]) -> z3.BoolRef:
        """:math:`\\bigvee` `args` (two or more)."""
        return self._bool(z3core.Z3_mk_or(self._ref, len(args), _array(args)))

    def not_(self, a: z3.BoolRef) -> z3.BoolRef:
        return self._bool(z3core.Z3_mk_not(self._ref, a.ast))

    def implies(self, a: z3.BoolRef, b: z3.BoolRef) -> z3.BoolRef:
        return self._bool(z3core.Z3_mk_implies(self._ref, a.ast, b.ast))

    def eq(self, a: z3.ExprRef, b: z3.ExprRef) -> z3.BoolRef:
        """:math:`a = b` (:math:`a \\leftrightarrow b` for Booleans)."""
        return self._bool(z3core.Z3_mk_eq(self._ref, a.ast, b.ast))

    def compare(self, op: str, a: z3.ArithRef, b: z3.ArithRef) -> z3.BoolRef:
        """``a op b`` for `op` in ``<=, <, >=, >, ==``; both sides of one sort."""
        return self._bool(_COMPARE[op](self._ref, a.ast, b.ast))

    def number(self, value: Fraction, *, real: bool) -> z3.ArithRef:
        """The numeral `value` (``Int`` unless `real`; an ``Int`` must be whole)."""
        key = (value, real)
        known = self._numbers.get(key)
        if known is None:
            text = f"{value.numerator}/{value.denominator}" if real else str(int(value))
            ast = z3core.Z3_mk_numeral(self._ref, text, self._real if real else self._int)
            known = self._numbers[key] = self._arith(ast)
        return known

    def add(self, args: Sequence[z3.ArithRef]) -> z3.ArithRef:
        """:math:`\\sum` `args` (two or more, one sort)."""
        return self._arith(z3core.Z3_mk_add(self._ref, len(args), _array(args)))

    def scaled(self, c: Fraction | int, a: z3.ArithRef, *, real: bool) -> z3.ArithRef:
        """:math:`c \\cdot a` (:math:`a` and :math:`-a` for ``c = ±1``)."""
        if c.denominator == 1 and c.numerator in (1, -1):  # cheaper than Fraction equality
            return a if c.numerator == 1 else self._arith(z3core.Z3_mk_unary_minus(self._ref, a.ast))
        factor = self.number(Fraction(c), real=real)
        return self._arith(z3core.Z3_mk_mul(self._ref, 2, _array([factor, a])))

    def to_real(self, a: z3.ArithRef) -> z3.ArithRef:
        return self._arith(z3core.Z3_mk_int2real(self._ref, a.ast))

    def ite(self, c: z3.BoolRef, a: z3.ArithRef, b: z3.ArithRef) -> z3.ArithRef:
        return self._arith(z3core.Z3_mk_ite(self._ref, c.ast, a.ast, b.ast))

    def renaming(self, sources: Sequence[z3.ExprRef], targets: Sequence[z3.ExprRef]) -> tuple[int, Any, Any]:
        """A renaming of constants, each of `sources` to the `targets` at its place, for :meth:`renamed`."""
        return len(sources), _array(sources), _array(targets)

    def renamed(self, term: z3.BoolRef, renaming: tuple[int, Any, Any]) -> z3.BoolRef:
        """`term` with the constants of `renaming` replaced at once (Z3's ``substitute``)."""
        n, sources, targets = renaming
        return self._bool(z3core.Z3_substitute(self._ref, term.ast, n, sources, targets))


def assert_all(solver: z3.Solver, terms: Sequence[z3.BoolRef]) -> None:
    """Assert Boolean `terms` in `solver`, as ``solver.add(terms)`` without its per-term cast."""
    ref, handle = solver.ctx.ref(), solver.solver
    for term in terms:
        z3core.Z3_solver_assert(ref, handle, term.ast)


__all__ = ["Terms", "assert_all"]
