"""Bounded encoding of CLTLB(D) formulas into Z3.

Standard bounded unrolling
--------------------------
For a horizon :math:`K`, every variable :math:`x` of a :class:`~cosmop.logic.Signature` becomes
:math:`K+1` Z3 constants :math:`x[0], \\dots, x[K]` (``Int``, ``Real`` or ``Bool``), named
``f"{prefix}{name}@{k}"`` (the paper's arrays :math:`q_r.x[k]`). A formula :math:`\\phi` at
instant :math:`k` becomes a quantifier-free Z3 formula :math:`[\\![\\phi]\\!]_k` over them, such
that for every trace :math:`\\rho` of length :math:`K`

.. math::

    \\rho, k \\models \\phi \\iff [\\![\\phi]\\!]_k \\text{ is true under } x[i] := \\rho(i)(x),

with the semantics of :mod:`cosmop.logic.formulas`. Atoms translate directly (an a.t.t.
:math:`\\bigcirc^{o} x` at :math:`k` is :math:`x[k+o]`; an atom reaching outside :math:`[0, K]` is
``False``; ``max``/``min`` are ``If(a > b, a, b)``/``If(a < b, a, b)`` as in the paper), the
Boolean connectives map to Z3's, :math:`[\\![\\bigcirc\\phi]\\!]_k = [\\![\\phi]\\!]_{k+1}` for
:math:`k < K` and ``False`` at :math:`K` (symmetrically for :math:`\\bigcirc^{-1}`),
:math:`[\\![\\mathit{Last}[\\phi]]\\!]_k = [\\![\\phi]\\!]_K`, and the until, since, eventually and
always operators follow their recurrences

.. math::

    u[k] &= g[k] \\vee (f[k] \\wedge u[k+1]), & u[K] &= g[K]
        && (u = f\\,\\mathbf{U}\\,g;\\ \\Diamond f = \\top\\,\\mathbf{U}\\,f),\\\\
    a[k] &= f[k] \\wedge a[k+1], & a[K] &= f[K] && (a = \\Box f),\\\\
    s[k] &= g[k] \\vee (f[k] \\wedge s[k-1]), & s[0] &= g[0] && (s = f\\,\\mathbf{S}\\,g).

Each distinct sub-formula is encoded once per instant (memo on ``(node, k)``; structurally
equal sub-formulas share), and the result is a DAG of Z3 terms with no auxiliary variables,
:math:`O(|\\phi| \\cdot K)` in size. Light constant folding keeps out-of-range atoms from
cluttering it.

Comparison with the paper's encoding. The paper ("Encoding to SMT solver") encodes an
existential choice of instant with an integer index :math:`j \\in \\mathcal{N}_\\rho`, e.g.
:math:`\\psi_1\\,\\mathbf{U}\\,\\psi_2 \\Leftrightarrow \\bigwedge_k [(k < j \\to \\Psi_1[k]) \\wedge
(k = j \\to \\Psi_2[k])]`. On a finite trace, unfolding the recurrence gives
:math:`u[k] = \\bigvee_{i=k}^{K} (g[i] \\wedge \\bigwedge_{j=k}^{i-1} f[j])`, which is exactly
that existential over :math:`i` made explicit, so the two agree wherever the index encoding
applies. The recurrence needs no integer index variables, is an equivalence (so it is correct
under negation and inside other temporal operators, where one existential index shared by all
instants would not be), and shares work between instants.

Growing the horizon
-------------------
The fixed encoding depends on :math:`K` at the frontier: :math:`u[K] = g[K]`, ``Next`` and
atoms reading :math:`K+1` are ``False``, ``Last`` reads :math:`K`. Keeping those equations when
the horizon grows would be unsound (e.g. :math:`\\neg(f\\,\\mathbf{U}\\,g)` would be forced at
:math:`K` although :math:`g` may hold at :math:`K+1`). Past operators and atoms without positive
offsets do not depend on :math:`K`. :class:`IncrementalUnrolling` therefore encodes every
frontier-dependent item with a fresh Boolean :math:`d` whose boundary definition is guarded by
an "end" literal :math:`e_K` (":math:`K` is the last instant"), e.g.
:math:`e_K \\to (d \\leftrightarrow g[K])`. Growing to :math:`K+1` asserts :math:`\\neg e_K` and the
unguarded step definition :math:`d \\leftrightarrow g[K] \\vee (f[K] \\wedge u[K+1])`. The
constraints only accumulate, so one solver (with its learnt lemmas) serves every horizon: check
with the assumption :attr:`IncrementalUnrolling.end`.

Copies between instants
-----------------------
A specification is mostly transition constraints :math:`\\Box(\\bigcirc g \\rightarrow B)`
encoded at every instant, and walking a large :math:`B` in Python once per instant was most
of the encoder's time. A formula without future, since or ``Last`` operators that reads
instants :math:`k + lo .. k + hi` at :math:`k` is *time-invariant* away from the ends: when
:math:`0 \\le k + lo` and :math:`k + hi \\le K`, its encoding at :math:`k + d` is the one at
:math:`k` with every :math:`x[i]` renamed :math:`x[i + d]` (Z3's ``substitute``, one C call).
So each such formula is walked at one instant whose reads lie within the first horizon (an
encoding made then holds no literal of a frontier) and copied to the others.

At the frontier of a growing unrolling, :math:`\\bigcirc g` is false, so
:math:`\\bigcirc g \\rightarrow B` holds whatever :math:`B` is; and once the horizon grows,
:math:`B` at :math:`K` is its plain encoding if it reads no further than :math:`K + 1`. Such a
:math:`B` is therefore copied over the constants of instant :math:`K + 1` (made before they are
in the horizon, free until then) instead of walked with a frontier literal per atom: half the
constraints of a growing search, the same models projected on the instants :math:`0..K`.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import Any

import z3

from cosmop.logic._terms import Terms
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
    Signature,
    Since,
    Until,
    Value,
    Var,
    as_expr,
    as_formula,
    normalize_value,
)

__all__ = ["IncrementalUnrolling", "Unrolling"]

_COMPARE: dict[str, Callable[[Any, Any], Any]] = {
    "<=": operator.le,
    "<": operator.lt,
    ">=": operator.ge,
    ">": operator.gt,
    "==": operator.eq,
}


_COPYABLE = frozenset((Not, And, Or, Implies, Iff, Next, Prev))
"""Nodes whose encoding may be copied from another instant (see :meth:`_Encoding._shape`)."""

_COPY_MIN = 6
"""Nodes below which walking a formula costs less than copying it."""

_SIZE_CAP = 1 << 20


def _children(f: Formula) -> tuple[Formula, ...]:
    if isinstance(f, (And, Or)):
        return tuple(f.args)
    if isinstance(f, (Implies, Iff)):
        return (f.left, f.right)
    return (f.arg,)  # type: ignore[attr-defined]


def _check_horizon(K: object) -> int:
    if isinstance(K, bool) or not isinstance(K, int) or K < 0:
        raise ValueError(f"the horizon K is an integer >= 0, got {K!r}")
    return K


class _Encoding:
    """The Z3 variables of a signature over instants 0..K, and the shared encoding machinery."""

    def __init__(
        self,
        signature: Signature | Mapping[str, str],
        K: int,
        *,
        ctx: z3.Context | None,
        prefix: str,
        copies: bool = False,
    ) -> None:
        self._signature = signature if isinstance(signature, Signature) else Signature(signature)
        K = _check_horizon(K)
        if not isinstance(prefix, str):
            raise TypeError(f"prefix is a string, got {prefix!r}")
        self._ctx = ctx if ctx is not None else z3.main_ctx()
        self._prefix = prefix
        self._terms = Terms(self._ctx)
        self._true = z3.BoolVal(True, self._ctx)
        self._false = z3.BoolVal(False, self._ctx)
        self._grid: dict[str, list[Any]] = {name: [] for name in self._signature}
        self._K = -1
        self._grow(K)
        self._first = K  # the smallest horizon: encodings reading no further hold no frontier
        self._memo: dict[tuple[Formula, int], z3.BoolRef] = {}
        # one representative of each formula met, by identity: the specification builds the
        # same sub-formula many times, and a memo lookup of an equal copy compares whole trees
        self._canonical: dict[Formula, Formula] = {}
        # id -> (the formula, kept alive so that its id stays its own; its representative)
        self._seen: dict[int, tuple[Formula, Formula]] = {}
        self._integral: dict[LinExpr, bool] = {}
        self._scales: dict[Compare, int] = {}
        # time-invariant formulas: an encoding at one instant copied to another (module docs)
        self._shapes: dict[int, tuple[int, int, int] | None] = {}
        self._copies: dict[int, tuple[int, Any]] = {}
        self._moves: dict[tuple[int, int, int], tuple[int, Any, Any]] = {}
        self._copying = copies

    # -- the variables ------------------------------------------------------------------------
    @property
    def signature(self) -> Signature:
        """The unrolled variables and their sorts."""
        return self._signature

    @property
    def K(self) -> int:
        """The horizon: the last instant :math:`K` (instants are :math:`0, \\dots, K`)."""
        return self._K

    @property
    def ctx(self) -> z3.Context:
        """The Z3 context of every term built here."""
        return self._ctx

    @property
    def prefix(self) -> str:
        """The prefix of every Z3 constant name."""
        return self._prefix

    def _grow(self, K: int) -> None:
        self._columns(K)
        self._K = K

    def _columns(self, last: int) -> None:
        """Make the Z3 constants of instants up to `last` (beyond K too: see :meth:`_copy`)."""
        makers = {"int": z3.Int, "real": z3.Real, "bool": z3.Bool}
        for name, sort in self._signature.items():
            column = self._grid[name]
            for k in range(len(column), last + 1):
                column.append(makers[sort](f"{self._prefix}{name}@{k}", self._ctx))

    def __getitem__(self, key: tuple[str | Var, int]) -> Any:
        """The Z3 constant of a variable at an instant: ``unrolling["x", 3]`` is :math:`x[3]`.

        Raises
        ------
        KeyError
            If the variable is not in the signature (or a :class:`Var` has another sort).
        IndexError
            If the instant is outside :math:`[0, K]`.
        """
        name, k = key
        if isinstance(name, Var):
            return self._var(name, k)
        if name not in self._grid:
            raise KeyError(f"variable {name!r} is not in the signature")
        if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k <= self._K:
            raise IndexError(f"instant {k!r} is outside 0..{self._K}")
        return self._grid[name][k]

    def _var(self, var: Var, k: int) -> Any:
        sort = self._signature.get(var.name)
        if sort is None:
            raise KeyError(f"variable {var.name!r} is not in the signature {self._signature!r}")
        if sort != var.sort:
            raise KeyError(f"variable {var.name!r} is used as {var.sort} but declared {sort}")
        if not 0 <= k <= self._K:
            raise IndexError(f"instant {k} of variable {var.name!r} is outside 0..{self._K}")
        return self._grid[var.name][k]

    def _check_instant(self, k: object) -> int:
        if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k <= self._K:
            raise ValueError(f"instant {k!r} is outside 0..{self._K}")
        return k

    # -- traces -------------------------------------------------------------------------------
    def fix(self, trace: Sequence[Mapping[str, object]], *, start: int = 0) -> z3.BoolRef:
        """The constraint that the variables take a trace's values.

        Parameters
        ----------
        trace : sequence of mapping
            Values for instants ``start, start + 1, ...``; each mapping may give any subset of
            the signature's variables (the others stay free). Values as in
            :func:`cosmop.logic.evaluate`.
        start : int, default 0
            The instant of ``trace[0]``.

        Returns
        -------
        z3.BoolRef
            :math:`\\bigwedge_{i, x} x[\\mathit{start}+i] = \\mathit{trace}[i](x)`.
        """
        items = []
        for offset, state in enumerate(trace):
            k = start + offset
            for name, raw in state.items():
                variable = self[name, k]
                value = normalize_value(self._signature[name], raw)
                if isinstance(value, bool):
                    items.append(variable if value else z3.Not(variable))
                elif self._signature[name] == "int":
                    items.append(variable == z3.IntVal(value, self._ctx))
                else:
                    items.append(variable == z3.RealVal(value, self._ctx))
        return self._and(items)

    def trace(self, model: z3.ModelRef) -> list[dict[str, Value]]:
        """Read a model back as a trace :math:`\\rho(0), \\dots, \\rho(K)`.

        Variables the model leaves free get Z3's default completion. Values are ``bool``,
        ``int`` and :class:`~fractions.Fraction`, so the result can be fed to
        :func:`cosmop.logic.evaluate`.
        """
        states: list[dict[str, Value]] = []
        for k in range(self._K + 1):
            state: dict[str, Value] = {}
            for name, sort in self._signature.items():
                value = model.eval(self._grid[name][k], model_completion=True)
                if sort == "bool":
                    state[name] = z3.is_true(value)
                elif sort == "int":
                    state[name] = value.as_long()
                elif z3.is_rational_value(value):
                    state[name] = Fraction(value.numerator_as_long(), value.denominator_as_long())
                else:  # pragma: no cover - linear arithmetic has rational models
                    raise ValueError(f"{name}@{k} has the irrational value {value}")
            states.append(state)
        return states

    # -- arithmetic ---------------------------------------------------------------------------
    def term(self, expr: object, k: int = 0) -> z3.ArithRef:
        """The Z3 term of an arithmetic expression at instant ``k``.

        ``Int`` when the expression is integral (integer variables, coefficients and constant),
        else ``Real``. Useful for objectives and custom constraints.

        Raises
        ------
        ValueError
            If the expression reads an instant outside :math:`[0, K]`.
        """
        e = as_expr(expr)
        k = self._check_instant(k)
        if e.offsets and (k + min(e.offsets) < 0 or k + max(e.offsets) > self._K):
            raise ValueError(f"{e} at instant {k} reads outside 0..{self._K}")
        return self._arith(e, k, real=not self._is_integral(e))

    def _is_int_term(self, term: Shifted | Max | Min) -> bool:
        if isinstance(term, Shifted):
            return term.sort == "int"
        return self._is_integral(term.left) and self._is_integral(term.right)

    def _is_integral(self, expr: LinExpr) -> bool:
        known = self._integral.get(expr)
        if known is None:
            known = expr.const.denominator == 1 and all(
                c.denominator == 1 and self._is_int_term(t) for t, c in expr.terms
            )
            self._integral[expr] = known
        return known

    def _number(self, value: Fraction, real: bool) -> Any:
        return self._terms.number(value, real=real)

    def _arith(self, expr: LinExpr, k: int, *, real: bool, scale: int = 1) -> Any:
        """:math:`\\mathit{scale} \\cdot e` at ``k`` (Int arithmetic needs integral scaled coefficients)."""
        parts, terms = [], self._terms
        for term, coefficient in expr.terms:
            c = coefficient if scale == 1 else coefficient * scale
            parts.append(terms.scaled(c, self._term(term, k, real), real=real))
        if expr.const != 0 or not parts:
            parts.append(self._number(expr.const * scale, real))
        return parts[0] if len(parts) == 1 else self._terms.add(parts)

    def _term(self, term: Shifted | Max | Min, k: int, real: bool) -> Any:
        if isinstance(term, Shifted):
            variable = self._var(term.var, k + term.offset)
            return self._terms.to_real(variable) if real and term.sort == "int" else variable
        inner_real = real or not self._is_int_term(term)
        a = self._arith(term.left, k, real=inner_real)
        b = self._arith(term.right, k, real=inner_real)
        return self._terms.ite(self._terms.compare(">" if isinstance(term, Max) else "<", a, b), a, b)

    def _atom_expr(self, atom: Shifted | Compare, k: int) -> z3.BoolRef:
        """The atom at ``k``, all of whose instants are known to lie in [0, K]."""
        if isinstance(atom, Shifted):
            return self._var(atom.var, k + atom.offset)
        expr, op, const = atom.expr, atom.op, atom.const
        if not expr.terms:
            return self._true if _COMPARE[op](Fraction(0), const) else self._false
        scale = self._scales.get(atom)
        if scale is None:  # per atom, not per instant
            scale = self._scales[atom] = self._int_scale(atom)
        if scale:
            lhs = self._arith(expr, k, real=False, scale=scale)
            rhs = self._number(const * scale, False)
        else:
            lhs = self._arith(expr, k, real=True)
            rhs = self._number(const, True)
        return self._terms.compare(op, lhs, rhs)

    def _int_scale(self, atom: Compare) -> int:
        """The factor that clears `atom`'s denominators when it is pure integer arithmetic (a
        positive factor keeps its operator), else 0: it is compared over the reals."""
        if not all(self._is_int_term(t) for t, _ in atom.expr.terms):
            return 0
        return math.lcm(atom.const.denominator, *(c.denominator for _, c in atom.expr.terms))

    # -- Boolean structure with constant folding ----------------------------------------------
    # Every constant this class produces is one of the two objects `self._true`, `self._false`
    # (Z3 operators never fold), so identity tests suffice and cost nothing.
    def _and(self, args: Sequence[Any]) -> Any:
        true, false = self._true, self._false
        kept = []
        for a in args:
            if a is false:
                return false
            if a is not true:
                kept.append(a)
        if not kept:
            return true
        return kept[0] if len(kept) == 1 else self._terms.and_(kept)

    def _or(self, args: Sequence[Any]) -> Any:
        true, false = self._true, self._false
        kept = []
        for a in args:
            if a is true:
                return true
            if a is not false:
                kept.append(a)
        if not kept:
            return false
        return kept[0] if len(kept) == 1 else self._terms.or_(kept)

    def _not(self, a: Any) -> Any:
        if a is self._true:
            return self._false
        if a is self._false:
            return self._true
        return self._terms.not_(a)

    def _iff(self, a: Any, b: Any) -> Any:
        for x, y in ((a, b), (b, a)):
            if x is self._true:
                return y
            if x is self._false:
                return self._not(y)
        return self._terms.eq(a, b)

    # -- formulas -----------------------------------------------------------------------------
    def _canon(self, f: Formula) -> Formula:
        """The one representative of the formulas equal to `f`."""
        seen = self._seen.get(id(f))
        if seen is None:
            seen = self._seen[id(f)] = (f, self._canonical.setdefault(f, f))
        return seen[1]

    def _lit(self, f: Formula, k: int) -> Any:
        """:math:`[\\![f]\\!]_k`, memoised."""
        seen = self._seen.get(id(f))  # :meth:`_canon` written out: the encoder's hottest line
        if seen is None:
            seen = self._seen[id(f)] = (f, self._canonical.setdefault(f, f))
        f = seen[1]
        key = (f, k)
        known = self._memo.get(key)
        if known is not None:
            return known
        kind = type(f)
        copyable = self._copying and kind in _COPYABLE
        if copyable:
            result = self._copy(f, k, self._K)
            if result is not None:
                self._memo[key] = result
                return result
        if kind is BoolConst:
            result = self._true if f.value else self._false  # type: ignore[attr-defined]
        elif kind is Shifted or kind is Compare:
            result = self._atom(f, k)  # type: ignore[arg-type]
        elif kind is Not:
            result = self._not(self._lit(f.arg, k))  # type: ignore[attr-defined]
        elif kind is And:
            result = self._and([self._lit(a, k) for a in f.args])  # type: ignore[attr-defined]
        elif kind is Or:
            result = self._or([self._lit(a, k) for a in f.args])  # type: ignore[attr-defined]
        elif kind is Implies:
            result = self._implies(f, k)  # type: ignore[arg-type]
        elif kind is Iff:
            result = self._iff(self._lit(f.left, k), self._lit(f.right, k))  # type: ignore[attr-defined]
        elif kind is Prev:
            result = self._lit(f.arg, k - 1) if k > 0 else self._false  # type: ignore[attr-defined]
        elif kind is Since:
            result = self._since(f, k)  # type: ignore[arg-type]
        elif kind is Next:
            result = self._next(f, k)  # type: ignore[arg-type]
        elif kind is Until or kind is Eventually or kind is Always:
            result = self._future(f, k)
        elif kind is Last:
            result = self._last(f, k)  # type: ignore[arg-type]
        else:
            raise TypeError(f"not a formula node: {f!r}")
        self._memo[key] = result
        if copyable and id(f) not in self._copies:
            self._keep(f, k, result)
        return result

    def _implies(self, f: Implies, k: int) -> Any:
        return self._or([self._not(self._lit(f.left, k)), self._lit(f.right, k)])

    # -- copies between instants ------------------------------------------------------------
    def _shape(self, f: Formula) -> tuple[int, int, int] | None:
        """``(lo, hi, size)`` of a formula whose encoding is the same at every instant up to a
        shift of the instants, or None (it holds a future or since operator, or ``Last``).

        At instant ``k`` the encoding reads instants ``k + lo .. k + hi`` only (0 included), and
        when ``0 <= k + lo`` and ``k + hi <= K`` nothing is folded at the ends of the trace, so the
        encoding at ``k + d`` is the one at ``k`` with every ``x[i]`` replaced by ``x[i + d]``.
        `size` is the number of nodes, counted as a tree up to a cap.
        """
        known = self._shapes.get(id(f), False)
        if known is not False:
            return known  # type: ignore[return-value]
        kind = type(f)
        shape: tuple[int, int, int] | None
        if kind is BoolConst:
            shape = (0, 0, 1)
        elif kind is Shifted or kind is Compare:
            offsets = f.offsets or frozenset((0,))  # type: ignore[attr-defined]
            shape = (min(0, min(offsets)), max(0, max(offsets)), 1)
        elif kind in _COPYABLE:
            shapes = [self._shape(c) for c in _children(f)]
            children = [c for c in shapes if c is not None]
            if len(children) < len(shapes):
                shape = None
            else:
                lo = min([0, *(c[0] for c in children)])
                hi = max([0, *(c[1] for c in children)])
                size = min(_SIZE_CAP, 1 + sum(c[2] for c in children))
                if kind is Next:
                    lo, hi = min(lo + 1, 0), hi + 1
                elif kind is Prev:
                    lo, hi = lo - 1, max(hi - 1, 0)
                shape = (lo, hi, size)
        else:
            shape = None
        self._shapes[id(f)] = shape  # f is kept alive by the memo's representatives
        return shape

    def _keep(self, f: Formula, k: int, result: Any) -> None:
        """Keep `f`'s encoding at `k` to copy to other instants, when it is a plain shift of them.

        Only an instant whose reads lie within the first horizon is kept: an encoding made
        then holds no literal of a frontier (nothing it reads was ever past a frontier)."""
        shape = self._shape(f)
        if shape is not None and shape[2] >= _COPY_MIN and k + shape[0] >= 0 and k + shape[1] <= self._first:
            self._copies[id(f)] = (k, result)

    def _copy(self, f: Formula, k: int, last: int) -> Any:
        """`f` at `k` copied from its kept encoding (reads up to instant `last`), or None."""
        kept = self._copies.get(id(f))
        if kept is None:
            return None
        lo, hi, _ = self._shapes[id(f)]  # type: ignore[misc]
        if k + lo < 0 or k + hi > last:
            return None
        j, term = kept
        if term is self._true or term is self._false:
            return term
        key = (j + lo, j + hi, k - j)
        move = self._moves.get(key)
        if move is None:
            self._columns(k + hi)
            columns = self._grid.values()
            move = self._moves[key] = self._terms.renaming(
                [c[i] for c in columns for i in range(j + lo, j + hi + 1)],
                [c[i + k - j] for c in columns for i in range(j + lo, j + hi + 1)],
            )
        return self._terms.renamed(term, move)

    def _since(self, f: Since, k: int) -> Any:
        memo = self._memo
        i = k
        while i >= 0 and (f, i) not in memo:
            i -= 1
        for j in range(i + 1, k + 1):
            goal = self._lit(f.right, j)
            memo[(f, j)] = (
                goal if j == 0 else self._or([goal, self._and([self._lit(f.left, j), memo[(f, j - 1)]])])
            )
        return memo[(f, k)]

    def _step(self, f: Formula, k: int, after: Any) -> Any:
        """One step of the future recurrences at ``k``, given the value ``after`` at ``k + 1``."""
        if isinstance(f, Until):
            return self._or([self._lit(f.right, k), self._and([self._lit(f.left, k), after])])
        if isinstance(f, Eventually):
            return self._or([self._lit(f.arg, k), after])
        assert isinstance(f, Always)
        return self._and([self._lit(f.arg, k), after])

    def _beyond(self, f: Formula) -> Any:
        """The value of a future operator "after the end": false for U and F, true for G."""
        return self._true if isinstance(f, Always) else self._false

    def _atom(self, f: Shifted | Compare, k: int) -> Any:
        raise NotImplementedError

    def _next(self, f: Next, k: int) -> Any:
        raise NotImplementedError

    def _future(self, f: Formula, k: int) -> Any:
        raise NotImplementedError

    def _last(self, f: Last, k: int) -> Any:
        raise NotImplementedError


class Unrolling(_Encoding):
    """The bounded unrolling of a signature over instants :math:`0, \\dots, K`.

    Parameters
    ----------
    signature : Signature or mapping
        The variables (name to sort); see :meth:`cosmop.logic.Signature.of`.
    K : int
        The horizon, :math:`K \\ge 0`.
    ctx : z3.Context, optional
        The Z3 context (Z3's main context when omitted).
    prefix : str, default ""
        Prepended to every Z3 constant name, to unroll several systems side by side.
    copies : bool, default False
        Copy time-invariant formulas between instants instead of walking them at each one
        (module documentation): the same constraints, made faster, in another order, so the
        solver may return another of the models.

    Notes
    -----
    :meth:`encode` returns self-contained Z3 formulas (no auxiliary variables) valid for this
    horizon only; see the module documentation for the construction. Encodings of different
    formulas share their common sub-formulas. To search the smallest horizon with one solver,
    use :class:`IncrementalUnrolling`.

    Examples
    --------
    >>> import z3
    >>> from cosmop.logic import Signature, Until, ints
    >>> (x,) = ints("x")
    >>> spec = Until(x.next().eq(x + 1), x >= 3)
    >>> u = Unrolling(Signature.of(spec), K=4)
    >>> s = z3.Solver()
    >>> s.add(u.encode(spec), u.fix([{"x": 0}]))
    >>> s.check()
    sat
    >>> [state["x"] for state in u.trace(s.model())][:4]
    [0, 1, 2, 3]
    """

    def __init__(
        self,
        signature: Signature | Mapping[str, str],
        K: int,
        *,
        ctx: z3.Context | None = None,
        prefix: str = "",
        copies: bool = False,
    ) -> None:
        super().__init__(signature, K, ctx=ctx, prefix=prefix, copies=copies)

    def encode(self, formula: object, k: int = 0) -> z3.BoolRef:
        """:math:`[\\![\\phi]\\!]_k`: a Z3 formula true exactly on the traces where ``formula``
        holds at instant ``k``.

        Parameters
        ----------
        formula : Formula or bool Var
            Its variables must be in the signature (with the same sorts).
        k : int, default 0
            :math:`0 \\le k \\le K`.

        Returns
        -------
        z3.BoolRef
        """
        return self._lit(as_formula(formula), self._check_instant(k))

    def _atom(self, f: Shifted | Compare, k: int) -> Any:
        offsets = f.offsets
        if offsets and (k + min(offsets) < 0 or k + max(offsets) > self._K):
            return self._false
        return self._atom_expr(f, k)

    def _next(self, f: Next, k: int) -> Any:
        return self._lit(f.arg, k + 1) if k < self._K else self._false

    def _last(self, f: Last, k: int) -> Any:
        return self._lit(f.arg, self._K)

    def _future(self, f: Formula, k: int) -> Any:
        memo, K = self._memo, self._K
        i = k
        while i <= K and (f, i) not in memo:
            i += 1
        for j in range(i - 1, k - 1, -1):
            memo[(f, j)] = self._step(f, j, memo[(f, j + 1)] if j < K else self._beyond(f))
        return memo[(f, k)]


_ATOM, _NEXT, _FUTURE, _LAST = "atom", "next", "future", "last"


class IncrementalUnrolling(_Encoding):
    """An unrolling whose horizon grows, for searching the smallest :math:`K` with one solver.

    Parameters
    ----------
    signature : Signature or mapping
        The variables (name to sort).
    K : int, default 0
        The initial horizon.
    ctx : z3.Context, optional
        The Z3 context (Z3's main context when omitted).
    prefix : str, default ""
        Prepended to every Z3 constant name.
    copies : bool, default False
        Copy time-invariant formulas between instants, and at the frontier copy the effect
        of a transition over the next instant's constants instead of writing a literal for
        each of its atoms (module documentation): faster, with other constraints of the same
        meaning, so the solver may return another of the models.

    Notes
    -----
    Encodings are *definitional*: :meth:`encode` returns a literal standing for the formula at
    an instant together with the constraints defining it, and :meth:`extend` returns the
    constraints that move the horizon. Every constraint returned must be added to the solver,
    and the horizon must be chosen with the assumption :attr:`end`
    (``solver.check(u.end)``), never asserted: constraints of a frontier are guarded by its end
    literal, and growing the horizon asserts the old literal's negation. Under the assumption,
    the constraints added so far are equivalent (projected on the signature's variables) to the
    fixed-horizon encoding of :class:`Unrolling` for the current :math:`K`. Growing is
    irreversible: a smaller horizon cannot be checked again with the same solver.

    Examples
    --------
    >>> import z3
    >>> from cosmop.logic import TRUE, Always, Eventually, Next, Signature, ints
    >>> (x,) = ints("x")
    >>> spec = x.eq(0) & Always(Next(TRUE) >> (x.next() - x <= 1)) & Eventually(x >= 3)
    >>> u = IncrementalUnrolling(Signature.of(spec))
    >>> s = z3.Solver()
    >>> s.add(u.require(spec))
    >>> while s.check(u.end) != z3.sat:
    ...     s.add(u.extend())
    >>> u.K
    3
    """

    def __init__(
        self,
        signature: Signature | Mapping[str, str],
        K: int = 0,
        *,
        ctx: z3.Context | None = None,
        prefix: str = "",
        copies: bool = False,
    ) -> None:
        super().__init__(signature, K, ctx=ctx, prefix=prefix, copies=copies)
        self._end = self._new_end()
        self._pending: list[tuple[Any, ...]] = []
        self._last_values: dict[Formula, Any] = {}
        self._out: list[Any] = []

    @property
    def end(self) -> z3.BoolRef:
        """The literal ":math:`K` is the last instant", to pass as an assumption to ``check``."""
        return self._end

    def encode(self, formula: object, k: int = 0) -> tuple[z3.BoolRef, list[z3.BoolRef]]:
        """A literal for ``formula`` at instant ``k`` and the new constraints defining it.

        Parameters
        ----------
        formula : Formula or bool Var
        k : int, default 0
            :math:`0 \\le k \\le K`.

        Returns
        -------
        literal : z3.BoolRef
            Under the constraints and the assumption :attr:`end`, equivalent to
            :math:`[\\![\\phi]\\!]_k` for the current horizon, and for every later one.
        constraints : list of z3.BoolRef
            Definitions not returned before; add them all to the solver.
        """
        literal = self._lit(as_formula(formula), self._check_instant(k))
        return literal, self._drain()

    def require(self, formula: object, k: int = 0) -> list[z3.BoolRef]:
        """The constraints asserting that ``formula`` holds at instant ``k`` (definitions included).

        Parameters
        ----------
        formula : Formula or bool Var
            The formula to require.
        k : int, default 0
            :math:`0 \\le k \\le K`.
        """
        literal, constraints = self.encode(formula, k)
        constraints.append(literal)
        return constraints

    def extend(self, K: int | None = None) -> list[z3.BoolRef]:
        """Grow the horizon to ``K`` (default :math:`K+1`) and return the constraints to add.

        Parameters
        ----------
        K : int, optional
            The new last instant; at least the current one.

        Raises
        ------
        ValueError
            If ``K`` is smaller than the current horizon.
        """
        target = self._K + 1 if K is None else _check_horizon(K)
        if target < self._K:
            raise ValueError(f"the horizon only grows: {target} < {self._K}")
        while target > self._K:
            self._advance()
        return self._drain()

    # -- machinery ----------------------------------------------------------------------------
    def _drain(self) -> list[Any]:
        out, self._out = self._out, []
        return out

    def _fresh(self) -> Any:
        return z3.FreshBool(f"{self._prefix}aux", self._ctx)

    def _guarded(self, definition: Any) -> Any:
        """`definition` at the current frontier only: :math:`e_K \\rightarrow` `definition`."""
        return self._terms.implies(self._end, definition)

    def _new_end(self) -> Any:
        return z3.FreshBool(f"{self._prefix}end{self._K}_", self._ctx)

    def _advance(self) -> None:
        """Move the frontier from K to K + 1 and resolve the items that waited for it."""
        self._out.append(self._terms.not_(self._end))
        self._grow(self._K + 1)
        self._end = self._new_end()
        pending, self._pending = self._pending, []
        for item in pending:
            kind = item[0]
            if kind == _ATOM:
                _, atom, k, d = item
                if k + max(atom.offsets) <= self._K:
                    self._out.append(self._terms.eq(d, self._atom_expr(atom, k)))
                else:
                    self._out.append(self._guarded(self._terms.not_(d)))
                    self._pending.append(item)
            elif kind == _NEXT:
                _, f, k, d = item
                self._out.append(self._terms.eq(d, self._lit(f.arg, k + 1)))
            elif kind == _FUTURE:
                _, f, k, d = item
                self._out.append(self._terms.eq(d, self._step(f, k, self._lit(f, k + 1))))
            else:
                _, f, d = item
                self._out.append(self._guarded(self._terms.eq(d, self._lit(f.arg, self._K))))
                self._pending.append(item)

    def _atom(self, f: Shifted | Compare, k: int) -> Any:
        offsets = f.offsets
        if offsets and k + min(offsets) < 0:
            return self._false
        if not offsets or k + max(offsets) <= self._K:
            return self._atom_expr(f, k)
        d = self._fresh()
        self._out.append(self._guarded(self._terms.not_(d)))
        self._pending.append((_ATOM, f, k, d))
        return d

    def _implies(self, f: Implies, k: int) -> Any:
        if self._copying and k == self._K and type(f.left) is Next:
            # At the last instant X(g) is false, so X(g) -> B holds whatever B is; once the
            # horizon grows, B here is its plain encoding if it reads no further than K + 1.  So
            # B is copied over the constants of K + 1 (no literal of the frontier, no walk).
            left, effect = self._lit(f.left, k), self._canon(f.right)
            right = self._copy(effect, k, k + 1)
            if right is None and k > 0:  # walked at k - 1, where a formula met now is needed next
                self._lit(effect, k - 1)
                right = self._copy(effect, k, k + 1)
            if right is not None:
                return self._or([self._not(left), right])
        return super()._implies(f, k)

    def _next(self, f: Next, k: int) -> Any:
        if k < self._K:
            return self._lit(f.arg, k + 1)
        d = self._fresh()
        self._out.append(self._guarded(self._terms.not_(d)))
        self._pending.append((_NEXT, f, k, d))
        return d

    def _last(self, f: Last, k: int) -> Any:
        d = self._last_values.get(f)
        if d is None:
            d = self._fresh()
            self._last_values[f] = d
            self._out.append(self._guarded(self._terms.eq(d, self._lit(f.arg, self._K))))
            self._pending.append((_LAST, f, d))
        return d

    def _future(self, f: Formula, k: int) -> Any:
        memo, K = self._memo, self._K
        i = k
        while i <= K and (f, i) not in memo:
            i += 1
        for j in range(i - 1, k - 1, -1):
            if j == K:
                d = self._fresh()
                self._out.append(self._guarded(self._terms.eq(d, self._step(f, K, self._beyond(f)))))
                self._pending.append((_FUTURE, f, K, d))
                memo[(f, j)] = d
            else:
                memo[(f, j)] = self._step(f, j, memo[(f, j + 1)])
        return memo[(f, k)]
