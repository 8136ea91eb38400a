"""CLTLB(D) formulas: an immutable abstract syntax tree.

The logic is the paper's CLTLB(:math:`\\mathcal{D}`) (section "Counter Linear Temporal Logic Over
Constraint System", after Bersani et al.) over the constraint system of linear (in)equalities on
integer and real variables.

Syntax
------
Variables are declared by name and sort (``"int"``, ``"real"`` or ``"bool"``). An *arithmetic
temporal term* (a.t.t.) is a variable shifted in time, :math:`\\bigcirc^{o} x` for an integer
offset :math:`o` (:math:`\\bigcirc x` is ``x.next()``, :math:`\\bigcirc^{-1} x` is ``x.prev()``);
in the tree it is :class:`Shifted`. Terms combine linearly, with rational coefficients, into a
:class:`LinExpr`; :class:`Max` and :class:`Min` of two linear expressions are terms too (the
paper's :math:`\\max`, :math:`\\min`, encoded with ``ite``). Formulas are

.. math::

    \\phi ::= \\top \\mid \\bot \\mid \\bigcirc^{o} p \\mid \\textstyle\\sum_i c_i\\,t_i \\;\\#\\; c_0
        \\mid \\neg\\phi \\mid \\bigwedge\\Phi \\mid \\bigvee\\Phi \\mid \\phi\\to\\phi
        \\mid \\phi\\leftrightarrow\\phi \\mid \\bigcirc\\phi \\mid \\bigcirc^{-1}\\phi
        \\mid \\phi\\,\\mathbf{U}\\,\\phi \\mid \\phi\\,\\mathbf{S}\\,\\phi \\mid \\Diamond\\phi
        \\mid \\Box\\phi \\mid \\mathit{Last}[\\phi]

with :math:`p` a Boolean variable and :math:`\\# \\in \\{\\le, <, \\ge, >, =\\}`. A comparison is
always stored normalised as :class:`Compare` ``(sum c_i * t_i, op, c0)``: every constant is moved
to the right, equal terms are merged, zero coefficients dropped and the terms sorted, so that
``x + y`` and ``y + x`` build equal atoms.

Semantics
---------
A trace :math:`\\rho` of length :math:`K \\ge 0` assigns a value to every variable at each
instant :math:`k \\in \\{0, \\dots, K\\}`. The paper's Definition "Semantics" leaves the
boundaries implicit; here they are fixed as follows (:math:`\\rho, k \\models \\phi`):

* a term :math:`x` shifted by :math:`o` denotes :math:`x(k+o)` at instant :math:`k`. An atom
  (comparison or shifted Boolean variable) that mentions an instant outside :math:`[0, K]` is
  *false* (strong reading: :math:`\\bigcirc x > 0` is false at :math:`K`, and so is
  :math:`\\bigcirc x \\le 0`; their negations are true). The rule applies to the normalised atom,
  so terms that cancel out (``x.next() - x.next()``) mention nothing. Consequently the atom
  :math:`\\bigcirc^{o} p` is equivalent to :math:`o` nested :class:`Next` (or :class:`Prev`) around
  :math:`p`;
* :math:`\\bigcirc\\phi` holds at :math:`k` iff :math:`k < K` and :math:`\\phi` holds at
  :math:`k+1` (strong next: false at :math:`K`); :math:`\\bigcirc^{-1}\\phi` iff :math:`k > 0` and
  :math:`\\phi` holds at :math:`k-1` (false at 0);
* :math:`\\phi\\,\\mathbf{U}\\,\\psi` iff :math:`\\exists i \\in [k, K]`: :math:`\\psi` at :math:`i`
  and :math:`\\phi` at every :math:`j \\in [k, i)`;
* :math:`\\phi\\,\\mathbf{S}\\,\\psi` iff :math:`\\exists i \\in [0, k]`: :math:`\\psi` at :math:`i`
  and :math:`\\phi` at every :math:`j \\in (i, k]`;
* :math:`\\Diamond\\phi \\equiv \\top\\,\\mathbf{U}\\,\\phi` (some :math:`i \\in [k, K]`),
  :math:`\\Box\\phi \\equiv \\neg\\Diamond\\neg\\phi` (every :math:`i \\in [k, K]`);
* :math:`\\mathit{Last}[\\phi]` holds (at any :math:`k`) iff :math:`\\phi` holds at :math:`K`. This
  is the paper's stated meaning and its encoding :math:`\\Psi[K]`; its abbreviation
  :math:`\\Diamond(\\neg\\bigcirc\\top) \\wedge \\phi` would instead evaluate :math:`\\phi` at
  :math:`k`;
* an empty conjunction is true, an empty disjunction false;
* a formula holds on :math:`\\rho` iff it holds at instant 0.

Arithmetic is exact: integers and :class:`~fractions.Fraction`. A ``float`` (coefficient or
trace value) is read as the shortest decimal that round-trips, i.e. the number as typed
(``0.1`` is :math:`1/10`).

Equality and hashing
--------------------
Nodes are frozen dataclasses with *structural* ``==`` and a cached hash, so formulas can be
dictionary keys and memo tables are cheap. The price is that ``a == b`` compares trees and
returns a ``bool``; it does not build an equality atom. Write ``a.eq(b)`` (or :func:`eq`, or
``a.ne(b)``) for :math:`a = b`; on Boolean atoms ``eq`` builds :class:`Iff`. Mistakes are caught
loudly: a Python ``bool`` where a formula is expected raises :class:`TypeError`, and so does
taking the truth value of a node (``0 <= x <= 5`` raises; write ``x.between(0, 5)``).

Operators: ``~ & | >>`` build :class:`Not`, conjunctions, disjunctions and :class:`Implies`;
``+ - * /`` (by constants) and ``<= < >= >`` build expressions and atoms. Python binds ``&``
tighter than comparisons, so parenthesise: ``(x <= 3) & p``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, fields
from fractions import Fraction
from functools import cached_property
from itertools import combinations
from typing import TYPE_CHECKING, Any, Literal, TypeAlias, TypeVar, cast, overload

__all__ = [
    "FALSE",
    "OPS",
    "SORTS",
    "TRUE",
    "Always",
    "And",
    "BoolConst",
    "Compare",
    "Eventually",
    "Expr",
    "Formula",
    "Iff",
    "Implies",
    "Last",
    "LinExpr",
    "Max",
    "Min",
    "Next",
    "Node",
    "Not",
    "Or",
    "Prev",
    "Shifted",
    "Signature",
    "Since",
    "Sort",
    "Until",
    "Value",
    "Var",
    "as_expr",
    "as_formula",
    "bools",
    "conj",
    "disj",
    "eq",
    "exactly_one",
    "ints",
    "maximum",
    "minimum",
    "ne",
    "normalize_value",
    "reals",
    "subformulas",
    "sum_of",
    "to_fraction",
]

Sort: TypeAlias = Literal["int", "real", "bool"]
Value: TypeAlias = bool | int | Fraction

#: The variable sorts.
SORTS: tuple[str, ...] = ("int", "real", "bool")
#: The comparison operators of :class:`Compare`.
OPS: tuple[str, ...] = ("<=", "<", ">=", ">", "==")

_BOOL_HINT = (
    "`a == b` on formulas and expressions compares trees and returns a bool; "
    "build an equality atom with a.eq(b) or eq(a, b), and use TRUE/FALSE for constants"
)


# --------------------------------------------------------------------------------------------
# numbers and values


def _is_bool(value: object) -> bool:
    if isinstance(value, bool):
        return True
    dtype = getattr(value, "dtype", None)
    return dtype is not None and getattr(dtype, "kind", None) == "b" and getattr(value, "shape", None) == ()


def to_fraction(value: object) -> Fraction:
    """Exact rational value of a number.

    Parameters
    ----------
    value : int, Fraction, float or numpy scalar
        A ``float`` is read as the shortest decimal that round-trips (``0.1`` gives
        :math:`1/10`); ``nan`` and infinities are rejected.

    Returns
    -------
    Fraction

    Raises
    ------
    TypeError
        For non-numbers, including ``bool``.
    ValueError
        For non-finite floats.
    """
    kind = type(value)
    if kind is Fraction:  # the common case in formulas, first: immutable, so itself
        return cast(Fraction, value)
    if kind is int:
        return Fraction(cast(int, value))
    if _is_bool(value):
        raise TypeError(f"expected a number, got the bool {value!r}")
    if isinstance(value, numbers.Integral):
        return Fraction(int(value))
    if isinstance(value, numbers.Rational):
        return Fraction(int(value.numerator), int(value.denominator))
    if isinstance(value, numbers.Real):
        as_float = float(value)
        if not math.isfinite(as_float):
            raise ValueError(f"expected a finite number, got {value!r}")
        return Fraction(repr(as_float))
    raise TypeError(f"expected a number, got {type(value).__name__} {value!r}")


def normalize_value(sort: str, value: object) -> Value:
    """Check a trace value against a sort and return it in canonical form.

    Parameters
    ----------
    sort : {"int", "real", "bool"}
    value : object
        ``bool`` (or a numpy bool) for ``"bool"``; an integer for ``"int"``; any finite number
        but a bool for ``"real"``.

    Returns
    -------
    bool, int or Fraction
        ``bool`` for ``"bool"``, ``int`` for ``"int"`` and :class:`~fractions.Fraction` for
        ``"real"`` (floats read as by :func:`to_fraction`).

    Raises
    ------
    TypeError
        If the value does not fit the sort.
    """
    if sort == "bool":
        if _is_bool(value):
            return bool(value)
        raise TypeError(f"a bool variable needs a bool value, got {type(value).__name__} {value!r}")
    if sort == "int":
        if isinstance(value, numbers.Integral) and not _is_bool(value):
            return int(value)
        raise TypeError(f"an int variable needs an integer value, got {type(value).__name__} {value!r}")
    if sort == "real":
        return to_fraction(value)
    raise ValueError(f"unknown sort {sort!r}; expected one of {SORTS}")


# --------------------------------------------------------------------------------------------
# the node machinery


_Class = TypeVar("_Class", bound=type)


@overload
def _node(cls: _Class, /) -> _Class: ...


@overload
def _node(cls: None = None, /, *, init: bool = True) -> Callable[[_Class], _Class]: ...


def _node(cls: _Class | None = None, /, *, init: bool = True) -> _Class | Callable[[_Class], _Class]:
    """Make ``cls`` a frozen dataclass with structural ``==`` and a cached structural hash.

    The type checker does not see the generated ``__init__``: each node class declares the
    signature it accepts under ``TYPE_CHECKING`` (the dataclass keeps generating the real one).
    """

    def wrap(klass: _Class) -> _Class:
        klass = cast(_Class, dataclass(frozen=True, init=init)(klass))
        names = tuple(f.name for f in fields(klass))
        tag = klass.__name__

        def __hash__(self: Any) -> int:
            cached: int | None = self.__dict__.get("_hash")
            if cached is None:
                cached = hash((tag, *[getattr(self, name) for name in names]))
                object.__setattr__(self, "_hash", cached)
            return cached

        klass.__hash__ = __hash__  # type: ignore[assignment]  # the class object's hash slot, set once
        return klass

    return wrap if cls is None else wrap(cls)


class Node:
    """Base of every tree node: immutable, hashable, compared structurally.

    The truth value of a node is undefined (``bool(node)`` raises :class:`TypeError`), which
    turns the silent mistakes ``0 <= x <= 5`` and ``if x == y`` into errors.
    """

    __slots__ = ()

    def __bool__(self) -> bool:
        raise TypeError(
            f"the truth value of a {type(self).__name__} is undefined; chained comparisons such as "
            "`0 <= x <= 5` are not supported (write x.between(0, 5)), and `and`/`or`/`not` must be "
            "written `&`/`|`/`~`"
        )

    def __getstate__(self) -> dict[str, Any]:
        # The cached hash depends on the process's string-hash seed: never pickle it.
        state = dict(self.__dict__)
        state.pop("_hash", None)
        return state


# --------------------------------------------------------------------------------------------
# arithmetic expressions


def _scalar(value: object) -> Fraction | None:
    """The constant value of ``value`` if it is a number or a constant expression, else None."""
    if isinstance(value, Node):
        if isinstance(value, LinExpr) and not value.terms:
            return value.const
        return None
    try:
        return to_fraction(value)
    except TypeError:
        return None


class Expr(Node):
    """Mixin of the arithmetic expressions: operator overloading and temporal shifts.

    ``+``, ``-`` and multiplication or division by constants build :class:`LinExpr`;
    ``<=, <, >=, >`` build :class:`Compare` atoms; :meth:`eq` and :meth:`ne` build
    :math:`=` and :math:`\\neq`.
    """

    __slots__ = ()

    # -- structure ----------------------------------------------------------------------------
    def next(self, k: int = 1) -> Expr:
        """The expression :math:`k` instants later, :math:`\\bigcirc^{k} e` (every term shifted).

        Parameters
        ----------
        k : int
            Instants ahead (negative: back).
        """
        raise NotImplementedError

    def prev(self, k: int = 1) -> Expr:
        """The expression :math:`k` instants earlier, :math:`\\bigcirc^{-k} e`.

        Parameters
        ----------
        k : int
            Instants back (negative: ahead).
        """
        return self.next(-_offset(k))

    @property
    def offsets(self) -> frozenset[int]:
        """The time offsets of the terms the expression mentions."""
        raise NotImplementedError

    # -- arithmetic ---------------------------------------------------------------------------
    def __add__(self, other: object) -> LinExpr:
        return _combined(self, other, 1)

    def __radd__(self, other: object) -> LinExpr:
        return _combined(other, self, 1)

    def __sub__(self, other: object) -> LinExpr:
        return _combined(self, other, -1)

    def __rsub__(self, other: object) -> LinExpr:
        return _combined(other, self, -1)

    def __mul__(self, other: object) -> LinExpr:
        mine, theirs = _scalar(self), _scalar(other)
        if theirs is not None:
            return _scale(as_expr(self), theirs)
        if mine is not None and isinstance(other, Expr):
            return _scale(as_expr(other), mine)
        if isinstance(other, Expr):
            raise TypeError("the product of two non-constant expressions is not linear")
        return NotImplemented

    def __rmul__(self, other: object) -> LinExpr:
        return self.__mul__(other)

    def __truediv__(self, other: object) -> LinExpr:
        divisor = _scalar(other)
        if divisor is None:
            if isinstance(other, Expr):
                raise TypeError("division by a non-constant expression is not linear")
            return NotImplemented
        if divisor == 0:
            raise ZeroDivisionError("division of an expression by zero")
        return _scale(as_expr(self), 1 / divisor)

    def __neg__(self) -> LinExpr:
        return _scale(as_expr(self), Fraction(-1))

    def __pos__(self) -> LinExpr:
        return as_expr(self)

    # -- atoms --------------------------------------------------------------------------------
    def __le__(self, other: object) -> Compare:
        return _compare(self, "<=", other)

    def __lt__(self, other: object) -> Compare:
        return _compare(self, "<", other)

    def __ge__(self, other: object) -> Compare:
        return _compare(self, ">=", other)

    def __gt__(self, other: object) -> Compare:
        return _compare(self, ">", other)

    def eq(self, other: object) -> Formula:
        """The atom :math:`\\mathit{self} = \\mathit{other}` (see :func:`eq`).

        Parameters
        ----------
        other : expression, variable or number
            The right-hand side.
        """
        return eq(self, other)

    def ne(self, other: object) -> Formula:
        """The formula :math:`\\mathit{self} \\neq \\mathit{other}` (see :func:`ne`).

        Parameters
        ----------
        other : expression, variable or number
            The right-hand side.
        """
        return ne(self, other)

    def between(self, low: object, high: object) -> And:
        """The formula :math:`\\mathit{low} \\le \\mathit{self} \\le \\mathit{high}`.

        Parameters
        ----------
        low, high : expression, variable or number
            The bounds, both included.
        """
        return And(_compare(self, ">=", low), _compare(self, "<=", high))


def _offset(k: object) -> int:
    if isinstance(k, bool) or not isinstance(k, numbers.Integral):
        raise TypeError(f"a time offset is an integer, got {k!r}")
    return int(k)


def _term_key(term: Shifted | Max | Min) -> tuple[int, str, int]:
    if isinstance(term, Shifted):
        return (0, term.var.name, term.offset)
    return (1, repr(term), 0)


@_node
class LinExpr(Expr):
    """A linear expression :math:`\\sum_i c_i t_i + c_0`.

    Parameters
    ----------
    terms : tuple of (term, coefficient)
        Terms are numeric :class:`Shifted` variables, :class:`Max` or :class:`Min`;
        coefficients are rationals. Stored canonically: merged, without zeros, sorted.
    const : Fraction
        The constant :math:`c_0`.

    Notes
    -----
    Usually built with operators (``2 * x.next() - x + 3``) or :func:`sum_of`.
    """

    terms: tuple[tuple[Shifted | Max | Min, Fraction], ...] = ()
    const: Fraction = Fraction(0)

    if TYPE_CHECKING:

        def __init__(
            self, terms: Iterable[tuple[Shifted | Max | Min, object]] = (), const: object = Fraction(0)
        ) -> None: ...

    def __post_init__(self) -> None:
        merged: dict[Shifted | Max | Min, Fraction] = {}
        for term, coefficient in self.terms:
            if isinstance(term, Shifted):
                if term.sort == "bool":
                    raise TypeError(f"the bool variable {term.var.name!r} is not an arithmetic term")
            elif not isinstance(term, (Max, Min)):
                raise TypeError(f"not an arithmetic term: {term!r}")
            c = to_fraction(coefficient)
            known = merged.get(term)
            merged[term] = c if known is None else known + c
        canonical = [(t, c) for t, c in merged.items() if c]
        if len(canonical) > 1:
            canonical.sort(key=lambda tc: _term_key(tc[0]))
        object.__setattr__(self, "terms", tuple(canonical))
        object.__setattr__(self, "const", to_fraction(self.const))

    @classmethod
    def _canonical(cls, terms: tuple[tuple[Shifted | Max | Min, Fraction], ...], const: Fraction) -> LinExpr:
        """An expression from terms already in canonical form (merged, non-zero, sorted):
        no normalisation, for the operations that keep the form (scaling, dropping the constant)."""
        out = object.__new__(cls)
        object.__setattr__(out, "terms", terms)
        object.__setattr__(out, "const", const)
        return out

    def next(self, k: int = 1) -> LinExpr:
        """The expression :math:`k` instants later (every term shifted).

        Parameters
        ----------
        k : int
            Instants ahead (negative: back).
        """
        k = _offset(k)
        return LinExpr(tuple((t.next(k), c) for t, c in self.terms), self.const)

    @cached_property
    def offsets(self) -> frozenset[int]:
        return frozenset().union(*(t.offsets for t, _ in self.terms))

    @property
    def is_constant(self) -> bool:
        """True when the expression has no terms."""
        return not self.terms

    def __str__(self) -> str:
        parts: list[str] = []
        for term, coefficient in self.terms:
            sign = "-" if coefficient < 0 else "+"
            magnitude = abs(coefficient)
            text = str(term) if magnitude == 1 else f"{_fmt_number(magnitude)}*{term}"
            parts.append(f"{sign} {text}")
        if self.const != 0 or not parts:
            parts.append(f"{'-' if self.const < 0 else '+'} {_fmt_number(abs(self.const))}")
        text = " ".join(parts)
        return text[2:] if text.startswith("+ ") else "-" + text[2:]


def _fmt_number(value: Fraction) -> str:
    return str(value.numerator) if value.denominator == 1 else f"{value.numerator}/{value.denominator}"


def as_expr(value: object) -> LinExpr:
    """Coerce a number, numeric variable, term or expression to a :class:`LinExpr`.

    Parameters
    ----------
    value : object
        A number (read as by :func:`to_fraction`), numeric :class:`Var`, term or expression.

    Raises
    ------
    TypeError
        For Boolean variables, formulas and non-numbers.
    """
    if isinstance(value, LinExpr):
        return value
    if isinstance(value, (Var, Shifted)):
        if value.sort == "bool":
            name = value.name if isinstance(value, Var) else value.var.name
            raise TypeError(f"the bool variable {name!r} is not an arithmetic term")
        term = value if isinstance(value, Shifted) else Shifted(value, 0)
        return LinExpr(((term, Fraction(1)),))
    if isinstance(value, (Max, Min)):
        return LinExpr(((value, Fraction(1)),))
    if isinstance(value, Formula):
        raise TypeError(f"a formula is not an arithmetic expression: {value}")
    if _is_bool(value):
        raise TypeError(f"expected an arithmetic expression, got the bool {value!r}; {_BOOL_HINT}")
    return LinExpr((), to_fraction(value))


def _combine(left: object, right: object, sign: int) -> LinExpr | None:
    """``left + sign * right`` as a :class:`LinExpr`, or ``None`` for foreign operands."""
    for operand in (left, right):
        if not isinstance(operand, (Node, numbers.Number)) and not _is_bool(operand):
            return None
    a, b = as_expr(left), as_expr(right)
    terms = a.terms + tuple((t, sign * c) for t, c in b.terms)
    return LinExpr(terms, a.const + sign * b.const)


def _scale(expr: LinExpr, factor: Fraction) -> LinExpr:
    if factor == 1:
        return expr
    if not factor:
        return LinExpr((), Fraction(0))
    return LinExpr._canonical(tuple((t, c * factor) for t, c in expr.terms), expr.const * factor)


def sum_of(items: Iterable[object]) -> LinExpr:
    """The sum of numbers and expressions, built in one pass (linear time, unlike ``sum``).

    Parameters
    ----------
    items : iterable of object
        Numbers, numeric variables, terms or expressions.
    """
    terms: list[tuple[Shifted | Max | Min, Fraction]] = []
    const = Fraction(0)
    for item in items:
        expr = as_expr(item)
        terms.extend(expr.terms)
        const += expr.const
    return LinExpr(tuple(terms), const)


@_node
class Max(Expr):
    """The term :math:`\\max(a, b)` of two linear expressions (encoded with ``ite``).

    Attributes
    ----------
    left, right : LinExpr
        :math:`a` and :math:`b`.
    """

    left: LinExpr
    right: LinExpr

    if TYPE_CHECKING:

        def __init__(self, left: object, right: object) -> None: ...

    def __post_init__(self) -> None:
        object.__setattr__(self, "left", as_expr(self.left))
        object.__setattr__(self, "right", as_expr(self.right))

    def next(self, k: int = 1) -> Max:
        """The term :math:`k` instants later (both operands shifted).

        Parameters
        ----------
        k : int
            Instants ahead (negative: back).
        """
        return Max(self.left.next(k), self.right.next(k))

    @cached_property
    def offsets(self) -> frozenset[int]:
        return self.left.offsets | self.right.offsets

    def __str__(self) -> str:
        return f"max({self.left}, {self.right})"


@_node
class Min(Expr):
    """The term :math:`\\min(a, b)` of two linear expressions (encoded with ``ite``).

    Attributes
    ----------
    left, right : LinExpr
        :math:`a` and :math:`b`.
    """

    left: LinExpr
    right: LinExpr

    if TYPE_CHECKING:

        def __init__(self, left: object, right: object) -> None: ...

    def __post_init__(self) -> None:
        object.__setattr__(self, "left", as_expr(self.left))
        object.__setattr__(self, "right", as_expr(self.right))

    def next(self, k: int = 1) -> Min:
        """The term :math:`k` instants later (both operands shifted).

        Parameters
        ----------
        k : int
            Instants ahead (negative: back).
        """
        return Min(self.left.next(k), self.right.next(k))

    @cached_property
    def offsets(self) -> frozenset[int]:
        return self.left.offsets | self.right.offsets

    def __str__(self) -> str:
        return f"min({self.left}, {self.right})"


def maximum(first: object, *rest: object) -> LinExpr:
    """:math:`\\max` of one or more expressions, as nested binary :class:`Max` terms.

    Parameters
    ----------
    first, rest : object
        The expressions (numbers, numeric variables, terms), at least one.
    """
    result = as_expr(first)
    for item in rest:
        result = as_expr(Max(result, item))
    return result


def minimum(first: object, *rest: object) -> LinExpr:
    """:math:`\\min` of one or more expressions, as nested binary :class:`Min` terms.

    Parameters
    ----------
    first, rest : object
        The expressions (numbers, numeric variables, terms), at least one.
    """
    result = as_expr(first)
    for item in rest:
        result = as_expr(Min(result, item))
    return result


# --------------------------------------------------------------------------------------------
# formulas


class Formula(Node):
    """Mixin of the formulas: the connectives as operators and the tree's children.

    ``~f`` is :class:`Not`, ``f & g`` and ``f | g`` are :func:`conj` and :func:`disj` (which
    flatten and drop neutral constants), ``f >> g`` is :class:`Implies`.
    """

    __slots__ = ()

    @property
    def children(self) -> tuple[Formula, ...]:
        """The immediate sub-formulas (atoms and constants have none)."""
        return ()

    def __and__(self, other: object) -> Formula:
        return conj((self, other))

    def __rand__(self, other: object) -> Formula:
        return conj((other, self))

    def __or__(self, other: object) -> Formula:
        return disj((self, other))

    def __ror__(self, other: object) -> Formula:
        return disj((other, self))

    def __invert__(self) -> Not:
        return Not(self)

    def __rshift__(self, other: object) -> Implies:
        return Implies(self, other)

    def __rrshift__(self, other: object) -> Implies:
        return Implies(other, self)


def as_formula(value: object) -> Formula:
    """Coerce a Boolean variable (or shifted Boolean variable) or a formula to a :class:`Formula`.

    A Boolean :class:`Var` ``p`` becomes the atom ``Shifted(p, 0)``.

    Parameters
    ----------
    value : object
        A Boolean :class:`Var` or :class:`Shifted`, or a formula.

    Raises
    ------
    TypeError
        For numeric variables, expressions, Python bools (a likely ``a == b`` mistake) and
        anything else.
    """
    if isinstance(value, (Var, Shifted)):
        if value.sort != "bool":
            name = value.name if isinstance(value, Var) else value.var.name
            raise TypeError(f"the {value.sort} variable {name!r} is not a formula; compare it with a number")
        return value if isinstance(value, Shifted) else Shifted(value, 0)
    if isinstance(value, Formula):
        return value
    if _is_bool(value):
        raise TypeError(f"expected a formula, got the bool {value!r}; {_BOOL_HINT}")
    raise TypeError(f"expected a formula, got {type(value).__name__} {value!r}")


@_node
class Var(Formula, Expr):
    """A variable declared by name and sort.

    Parameters
    ----------
    name : str
        Non-empty; unique within a :class:`Signature`.
    sort : {"int", "real", "bool"}
        Domain :math:`\\mathbb{Z}`, :math:`\\mathbb{R}` or :math:`\\mathbb{B}`.

    Notes
    -----
    A numeric variable is an arithmetic term (``x + 1``), a Boolean one is an atomic formula
    (``p & q``). ``x.next(k)`` and ``x.prev(k)`` give the arithmetic temporal terms
    :math:`\\bigcirc^{k} x` and :math:`\\bigcirc^{-k} x` as :class:`Shifted`.
    """

    name: str
    sort: str

    if TYPE_CHECKING:

        def __init__(self, name: str, sort: str) -> None: ...

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a variable name is a non-empty string, got {self.name!r}")
        if self.sort not in SORTS:
            raise ValueError(
                f"unknown sort {self.sort!r} for variable {self.name!r}; expected one of {SORTS}"
            )

    def next(self, k: int = 1) -> Shifted:
        """The term :math:`\\bigcirc^{k} x`.

        Parameters
        ----------
        k : int
            Instants ahead (negative: back).
        """
        return Shifted(self, _offset(k))

    def prev(self, k: int = 1) -> Shifted:
        """The term :math:`\\bigcirc^{-k} x`.

        Parameters
        ----------
        k : int
            Instants back (negative: ahead).
        """
        return Shifted(self, -_offset(k))

    @property
    def offsets(self) -> frozenset[int]:
        return frozenset((0,))

    def __str__(self) -> str:
        return self.name


@_node
class Shifted(Formula, Expr):
    """The arithmetic temporal term :math:`\\bigcirc^{o} x`: variable ``var`` at ``k + offset``.

    For a Boolean variable it is an atomic formula, for a numeric one an arithmetic term.

    Attributes
    ----------
    var : Var
        The variable :math:`x`.
    offset : int
        :math:`o`, instants ahead (negative: back).
    """

    var: Var
    offset: int = 0

    if TYPE_CHECKING:

        def __init__(self, var: Var, offset: int = 0) -> None: ...

    def __post_init__(self) -> None:
        if not isinstance(self.var, Var):
            raise TypeError(f"Shifted needs a Var, got {self.var!r}")
        object.__setattr__(self, "offset", _offset(self.offset))

    @property
    def sort(self) -> str:
        """The sort of the shifted variable."""
        return self.var.sort

    def next(self, k: int = 1) -> Shifted:
        """The same variable :math:`k` instants later.

        Parameters
        ----------
        k : int
            Instants ahead (negative: back).
        """
        return Shifted(self.var, self.offset + _offset(k))

    def prev(self, k: int = 1) -> Shifted:
        """The same variable :math:`k` instants earlier.

        Parameters
        ----------
        k : int
            Instants back (negative: ahead).
        """
        return Shifted(self.var, self.offset - _offset(k))

    @property
    def offsets(self) -> frozenset[int]:
        return frozenset((self.offset,))

    def __str__(self) -> str:
        if self.offset == 0:
            return self.var.name
        return f"{self.var.name}[{self.offset:+d}]"


@_node
class BoolConst(Formula):
    """The constant :data:`TRUE` or :data:`FALSE`.

    Attributes
    ----------
    value : bool
        Which of the two.
    """

    value: bool

    if TYPE_CHECKING:

        def __init__(self, value: bool) -> None: ...

    def __post_init__(self) -> None:
        if not isinstance(self.value, bool):
            raise TypeError(f"BoolConst holds a bool, got {self.value!r}")

    def __str__(self) -> str:
        return "true" if self.value else "false"


#: The formula :math:`\top`.
TRUE = BoolConst(True)
#: The formula :math:`\bot`.
FALSE = BoolConst(False)


@_node
class Compare(Formula):
    """The atom :math:`\\sum_i c_i t_i \\;\\#\\; c_0`.

    Parameters
    ----------
    expr : LinExpr
        The left-hand side; a constant part is moved to ``const`` on construction.
    op : {"<=", "<", ">=", ">", "=="}
    const : Fraction
        The right-hand side :math:`c_0`.

    Notes
    -----
    Usually built with ``<=`` etc. on expressions, :meth:`Expr.eq` or :func:`eq`.
    """

    expr: LinExpr
    op: str
    const: Fraction = Fraction(0)

    if TYPE_CHECKING:

        def __init__(self, expr: object, op: str, const: object = Fraction(0)) -> None: ...

    def __post_init__(self) -> None:
        expr = as_expr(self.expr)
        if self.op not in OPS:
            raise ValueError(f"unknown comparison {self.op!r}; expected one of {OPS}")
        const = to_fraction(self.const)
        if expr.const:  # move the constant to the right-hand side
            const -= expr.const
            expr = LinExpr._canonical(expr.terms, Fraction(0))
        object.__setattr__(self, "expr", expr)
        object.__setattr__(self, "const", const)

    @property
    def offsets(self) -> frozenset[int]:
        """The time offsets mentioned by the atom."""
        return self.expr.offsets

    def __str__(self) -> str:
        const = _fmt_number(abs(self.const))
        return f"{self.expr} {self.op} {'-' if self.const < 0 else ''}{const}"


def _combined(left: object, right: object, sign: int) -> LinExpr:
    """:func:`_combine` for the arithmetic operators: ``NotImplemented`` for foreign operands, so
    that Python tries the other operand's method."""
    result = _combine(left, right, sign)
    return result if result is not None else NotImplemented


def _compare(left: object, op: str, right: object) -> Compare:
    difference = _combine(left, right, -1)
    if difference is None:
        raise TypeError(f"cannot compare {left!r} with {right!r}")
    return Compare(difference, op, 0)


def _is_boolean(value: object) -> bool:
    if isinstance(value, (Var, Shifted)):
        return value.sort == "bool"
    return isinstance(value, Formula)


def eq(left: object, right: object) -> Formula:
    """The equality :math:`\\mathit{left} = \\mathit{right}`.

    For arithmetic operands a :class:`Compare` ``==`` atom; when either operand is Boolean (a
    Boolean variable or any formula) the equivalence :class:`Iff`, so ``p.next().eq(p)`` says
    that ``p`` keeps its value.

    Parameters
    ----------
    left, right : object
        Expressions, numbers, Boolean variables or formulas.
    """
    if _is_boolean(left) or _is_boolean(right):
        return Iff(left, right)
    return _compare(left, "==", right)


def ne(left: object, right: object) -> Not:
    """The disequality :math:`\\neg(\\mathit{left} = \\mathit{right})` (see :func:`eq`).

    Parameters
    ----------
    left, right : object
        Expressions, numbers, Boolean variables or formulas.
    """
    return Not(eq(left, right))


@_node
class _Unary(Formula):
    """A connective of one operand.

    Attributes
    ----------
    arg : Formula
        The operand :math:`\\phi`.
    """

    arg: Formula

    if TYPE_CHECKING:

        def __init__(self, arg: object) -> None: ...

    def __post_init__(self) -> None:
        object.__setattr__(self, "arg", as_formula(self.arg))

    @property
    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)

    def __str__(self) -> str:
        return f"{self._symbol} {_fmt_operand(self.arg)}"

    _symbol = "?"


@_node
class _Binary(Formula):
    """A connective of two operands.

    Attributes
    ----------
    left, right : Formula
        The operands :math:`\\phi` and :math:`\\psi`.
    """

    left: Formula
    right: Formula

    if TYPE_CHECKING:

        def __init__(self, left: object, right: object) -> None: ...

    def __post_init__(self) -> None:
        object.__setattr__(self, "left", as_formula(self.left))
        object.__setattr__(self, "right", as_formula(self.right))

    @property
    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)

    def __str__(self) -> str:
        return f"({_fmt_operand(self.left)} {self._symbol} {_fmt_operand(self.right)})"

    _symbol = "?"


def _fmt_operand(formula: Formula) -> str:
    text = str(formula)
    if isinstance(formula, Compare) or (isinstance(formula, (And, Or)) and not formula.args):
        return f"({text})"
    return text


@_node
class Not(_Unary):
    """:math:`\\neg\\phi`."""

    _symbol = "~"

    def __str__(self) -> str:
        return f"~{_fmt_operand(self.arg)}"


@_node
class Next(_Unary):
    """:math:`\\bigcirc\\phi`: :math:`k < K` and :math:`\\phi` at :math:`k+1` (strong next)."""

    _symbol = "X"


@_node
class Prev(_Unary):
    """:math:`\\bigcirc^{-1}\\phi`: :math:`k > 0` and :math:`\\phi` at :math:`k-1`."""

    _symbol = "Y"


@_node
class Eventually(_Unary):
    """:math:`\\Diamond\\phi \\equiv \\top\\,\\mathbf{U}\\,\\phi`: :math:`\\phi` at some instant of
    :math:`[k, K]`."""

    _symbol = "F"


@_node
class Always(_Unary):
    """:math:`\\Box\\phi \\equiv \\neg\\Diamond\\neg\\phi`: :math:`\\phi` at every :math:`i \\in [k, K]`."""

    _symbol = "G"


@_node
class Last(_Unary):
    """:math:`\\mathit{Last}[\\phi]`: :math:`\\phi` holds at the last instant :math:`K` (read from
    any :math:`k`)."""

    _symbol = "Last"


@_node
class Implies(_Binary):
    """:math:`\\phi \\to \\psi`."""

    _symbol = "->"


@_node
class Iff(_Binary):
    """:math:`\\phi \\leftrightarrow \\psi`."""

    _symbol = "<->"


@_node
class Until(_Binary):
    """:math:`\\phi\\,\\mathbf{U}\\,\\psi`: some :math:`i \\in [k, K]` has :math:`\\psi`, and
    :math:`\\phi` holds on :math:`[k, i)`."""

    _symbol = "U"


@_node
class Since(_Binary):
    """:math:`\\phi\\,\\mathbf{S}\\,\\psi`: some :math:`i \\in [0, k]` has :math:`\\psi`, and
    :math:`\\phi` holds on :math:`(i, k]`."""

    _symbol = "S"


@_node(init=False)
class _NAry(Formula):
    """A connective of any number of operands.

    Attributes
    ----------
    args : tuple of Formula
        The operands :math:`\\phi_i`, in order.
    """

    args: tuple[Formula, ...]

    def __init__(self, *args: object) -> None:
        object.__setattr__(self, "args", tuple(as_formula(a) for a in args))

    @property
    def children(self) -> tuple[Formula, ...]:
        return self.args

    def __str__(self) -> str:
        if not self.args:
            return self._empty
        if len(self.args) == 1:
            return f"{self._word}({self.args[0]})"
        return "(" + f" {self._symbol} ".join(_fmt_operand(a) for a in self.args) + ")"

    _symbol = "?"
    _word = "?"
    _empty = "?"


@_node(init=False)
class And(_NAry):
    """:math:`\\bigwedge_i \\phi_i` (true when empty). ``And(*fs)`` builds exactly the node given."""

    _symbol = "&"
    _word = "and"
    _empty = "and()"


@_node(init=False)
class Or(_NAry):
    """:math:`\\bigvee_i \\phi_i` (false when empty). ``Or(*fs)`` builds exactly the node given."""

    _symbol = "|"
    _word = "or"
    _empty = "or()"


def conj(formulas: Iterable[object]) -> Formula:
    """The conjunction of ``formulas``: nested :class:`And` flattened, :data:`TRUE` dropped.

    Returns :data:`FALSE` if an argument is :data:`FALSE`, :data:`TRUE` if nothing remains, the
    single remaining formula alone, else an :class:`And`.

    Parameters
    ----------
    formulas : iterable of object
        Formulas or Boolean variables.
    """
    items: list[Formula] = []
    for item in formulas:
        f = as_formula(item)
        if isinstance(f, And):
            items.extend(f.args)
        elif f == FALSE:
            return FALSE
        elif f != TRUE:
            items.append(f)
    if FALSE in items:
        return FALSE
    if not items:
        return TRUE
    return items[0] if len(items) == 1 else And(*items)


def disj(formulas: Iterable[object]) -> Formula:
    """The disjunction of ``formulas``: nested :class:`Or` flattened, :data:`FALSE` dropped.

    Returns :data:`TRUE` if an argument is :data:`TRUE`, :data:`FALSE` if nothing remains, the
    single remaining formula alone, else an :class:`Or`.

    Parameters
    ----------
    formulas : iterable of object
        Formulas or Boolean variables.
    """
    items: list[Formula] = []
    for item in formulas:
        f = as_formula(item)
        if isinstance(f, Or):
            items.extend(f.args)
        elif f == TRUE:
            return TRUE
        elif f != FALSE:
            items.append(f)
    if TRUE in items:
        return TRUE
    if not items:
        return FALSE
    return items[0] if len(items) == 1 else Or(*items)


def exactly_one(formulas: Iterable[object]) -> Formula:
    """:math:`\\bigvee_i \\phi_i \\wedge \\bigwedge_{i<j} \\neg(\\phi_i \\wedge \\phi_j)` (pairwise;
    :data:`FALSE` when empty).

    Parameters
    ----------
    formulas : iterable of object
        Formulas or Boolean variables.
    """
    items = [as_formula(f) for f in formulas]
    at_least = disj(items)
    at_most = [Not(And(a, b)) for a, b in combinations(items, 2)]
    return conj([at_least, *at_most])


# --------------------------------------------------------------------------------------------
# traversal and signatures


def subformulas(formula: object) -> list[Formula]:
    """The distinct sub-formulas of ``formula`` (itself included) in post-order.

    Every formula appears after its children; structurally equal sub-formulas appear once.
    Iterative, so deep formulas do not hit the recursion limit.

    Parameters
    ----------
    formula : object
        A formula or Boolean variable.
    """
    root = as_formula(formula)
    order: list[Formula] = []
    seen: set[Formula] = set()
    stack: list[tuple[Formula, bool]] = [(root, False)]
    while stack:
        node, expanded = stack.pop()
        if expanded:
            order.append(node)
            continue
        if node in seen:
            continue
        seen.add(node)
        stack.append((node, True))
        stack.extend((child, False) for child in reversed(node.children) if child not in seen)
    return order


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}
"""Each node class's field names: :func:`dataclasses.fields` is slow to call once per node."""


def _field_names(kind: type) -> tuple[str, ...]:
    names = _FIELD_NAMES.get(kind)
    if names is None:
        names = _FIELD_NAMES[kind] = tuple(f.name for f in fields(kind))
    return names


def _iter_vars(obj: object) -> Iterator[Var]:
    """Variables of a node tree in left-to-right pre-order (with repetitions)."""
    stack: list[object] = [obj]
    seen: set[int] = set()
    while stack:
        item = stack.pop()
        if isinstance(item, Var):
            yield item
        elif isinstance(item, Node):
            if id(item) in seen:
                continue
            seen.add(id(item))
            stack.extend(reversed([getattr(item, name) for name in _field_names(type(item))]))
        elif isinstance(item, tuple):
            stack.extend(reversed(item))


class Signature(Mapping[str, str]):
    """An ordered, immutable mapping from variable name to sort.

    Parameters
    ----------
    items : mapping or iterable, optional
        ``{name: sort}``, or an iterable of :class:`Var` and ``(name, sort)`` pairs. A name
        may repeat only with the same sort.

    Raises
    ------
    ValueError
        If a name is declared with two sorts, or a sort is unknown.

    Examples
    --------
    >>> x, p = Var("x", "int"), Var("p", "bool")
    >>> Signature([x, p])
    Signature({'x': 'int', 'p': 'bool'})
    >>> Signature.of(x.next() >= 1, p)["x"]
    'int'
    """

    __slots__ = ("_sorts",)

    def __init__(self, items: Mapping[str, str] | Iterable[Var | tuple[str, str]] = ()) -> None:
        pairs = items.items() if isinstance(items, Mapping) else items
        sorts: dict[str, str] = {}
        for item in pairs:
            var = item if isinstance(item, Var) else Var(*item)
            known = sorts.setdefault(var.name, var.sort)
            if known != var.sort:
                raise ValueError(f"variable {var.name!r} is declared both {known} and {var.sort}")
        self._sorts = sorts

    @classmethod
    def of(cls, *objects: object) -> Signature:
        """The variables of formulas, expressions, variables or signatures, in order of appearance.

        Parameters
        ----------
        *objects : object
            Formulas, expressions, variables or signatures.
        """
        found: list[Var] = []
        for obj in objects:
            if isinstance(obj, Signature):
                found.extend(obj.vars)
            else:
                found.extend(_iter_vars(obj))
        return cls(found)

    @property
    def vars(self) -> tuple[Var, ...]:
        """The declared variables, in order."""
        return tuple(Var(name, sort) for name, sort in self._sorts.items())

    def var(self, name: str) -> Var:
        """The variable called ``name``.

        Parameters
        ----------
        name : str
            A declared variable's name.
        """
        return Var(name, self[name])

    def __or__(self, other: object) -> Signature:
        if not isinstance(other, Signature):
            return NotImplemented
        return Signature([*self.vars, *other.vars])

    def __getitem__(self, name: str) -> str:
        return self._sorts[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._sorts)

    def __len__(self) -> int:
        return len(self._sorts)

    def __hash__(self) -> int:
        return hash(frozenset(self._sorts.items()))

    def __repr__(self) -> str:
        return f"Signature({self._sorts!r})"


def _declare(sort: str, names: str) -> tuple[Var, ...]:
    return tuple(Var(name, sort) for name in names.split())


def ints(names: str) -> tuple[Var, ...]:
    """Integer variables from whitespace-separated names: ``i, j = ints("i j")``.

    Parameters
    ----------
    names : str
        Variable names separated by whitespace.
    """
    return _declare("int", names)


def reals(names: str) -> tuple[Var, ...]:
    """Real variables from whitespace-separated names: ``(x,) = reals("x")``.

    Parameters
    ----------
    names : str
        Variable names separated by whitespace.
    """
    return _declare("real", names)


def bools(names: str) -> tuple[Var, ...]:
    """Boolean variables from whitespace-separated names: ``p, q = bools("p q")``.

    Parameters
    ----------
    names : str
        Variable names separated by whitespace.
    """
    return _declare("bool", names)
