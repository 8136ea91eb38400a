"""Tests of ``cosmop.logic``: CLTLB(D) formulas, finite-trace evaluation and the Z3 encodings.

The property tests compare three independent readings of random formulas on random traces: a
brute-force transcription of the paper's Definition "Semantics" (quantifiers over instants,
no memo), :func:`evaluate` (fixpoint columns) and the satisfiability of the Z3 encodings with
every variable fixed to the trace. Every solver is seeded and resource-limited.
"""

from __future__ import annotations

import copy
import operator
import pickle
import time
from fractions import Fraction

import pytest
import z3
from hypothesis import given, settings
from hypothesis import strategies as st

from cosmop.logic import (
    FALSE,
    OPS,
    TRUE,
    Always,
    And,
    BoolConst,
    Compare,
    Eventually,
    Iff,
    Implies,
    IncrementalUnrolling,
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
    Unrolling,
    Until,
    Var,
    bools,
    conj,
    disj,
    eq,
    evaluate,
    evaluate_all,
    exactly_one,
    failing,
    ints,
    maximum,
    minimum,
    ne,
    reals,
    subformulas,
    sum_of,
)

CTX = z3.Context()
RLIMIT = 5_000_000

i, j = ints("i j")
(r,) = reals("r")
p, q = bools("p q")
SIG = Signature([i, j, r, p, q])


def solver() -> z3.Solver:
    s = z3.Solver(ctx=CTX)
    s.set("random_seed", 0)
    s.set("rlimit", RLIMIT)
    return s


def is_sat(*constraints: z3.BoolRef) -> bool:
    s = solver()
    s.add(*constraints)
    result = s.check()
    assert result != z3.unknown, s.reason_unknown()
    return result == z3.sat


def states(**columns: list) -> list[dict]:
    """A trace from per-variable columns of equal length: ``states(x=[0, 1], p=[True, False])``."""
    lengths = {len(v) for v in columns.values()}
    assert len(lengths) == 1
    return [{name: values[k] for name, values in columns.items()} for k in range(lengths.pop())]


# --------------------------------------------------------------------------------------------
# reference semantics: the paper's Definition, transcribed literally

_CMP = {"<=": operator.le, "<": operator.lt, ">=": operator.ge, ">": operator.gt, "==": operator.eq}


def reference(formula, trace, k: int) -> bool:
    K = len(trace) - 1
    memo: dict = {}

    def value(term, k):
        if isinstance(term, Shifted):
            return Fraction(trace[k + term.offset][term.var.name])
        pick = max if isinstance(term, Max) else min
        return pick(linear(term.left, k), linear(term.right, k))

    def linear(expr, k):
        return expr.const + sum((c * value(t, k) for t, c in expr.terms), Fraction(0))

    def in_range(offsets, k):
        return all(0 <= k + o <= K for o in offsets)

    def holds(f, k):
        key = (f, k)
        if key not in memo:
            memo[key] = compute(f, k)
        return memo[key]

    def compute(f, k):
        match f:
            case BoolConst(value=v):
                return v
            case Shifted(var=v, offset=o):
                return in_range({o}, k) and trace[k + o][v.name]
            case Compare(expr=e, op=op, const=c):
                return in_range(e.offsets, k) and _CMP[op](linear(e, k), c)
            case Not(arg=a):
                return not holds(a, k)
            case And(args=args):
                return all(holds(a, k) for a in args)
            case Or(args=args):
                return any(holds(a, k) for a in args)
            case Implies(left=a, right=b):
                return (not holds(a, k)) or holds(b, k)
            case Iff(left=a, right=b):
                return holds(a, k) == holds(b, k)
            case Next(arg=a):
                return k + 1 <= K and holds(a, k + 1)
            case Prev(arg=a):
                return k - 1 >= 0 and holds(a, k - 1)
            case Until(left=a, right=b):
                return any(holds(b, n) and all(holds(a, m) for m in range(k, n)) for n in range(k, K + 1))
            case Since(left=a, right=b):
                return any(
                    holds(b, n) and all(holds(a, m) for m in range(n + 1, k + 1)) for n in range(0, k + 1)
                )
            case Eventually(arg=a):
                return holds(Until(TRUE, a), k)
            case Always(arg=a):
                return not holds(Eventually(Not(a)), k)
            case Last(arg=a):
                return holds(a, K)
        raise AssertionError(f"unknown node {f!r}")

    return holds(formula, k)


# --------------------------------------------------------------------------------------------
# formulas


def test_comparison_is_normalised():
    atom = 2 * i.next() - i + 3 <= 5
    assert isinstance(atom, Compare)
    assert atom.op == "<="
    assert atom.expr.terms == ((Shifted(i, 0), Fraction(-1)), (Shifted(i, 1), Fraction(2)))
    assert atom.expr.const == 0
    assert atom.const == 2
    assert (i + j <= 1) == (j + i <= 1)
    assert hash(i + j <= 1) == hash(j + i <= 1)
    assert len({i + j <= 1, j + i <= 1, 1 >= i + j}) == 1  # noqa: SIM300 - `1 >= e` becomes `e <= 1`
    assert (-i - j >= -1) != (i + j <= 1)  # no sign normalisation: the operator is kept
    assert (i - i + 1 <= 2).expr.terms == ()
    assert Compare(i + 3, ">", 1) == (i > -2)
    assert (3 <= i) == (i >= 3)  # noqa: SIM300 - reflected comparison


def test_shifts_compose():
    assert i.next() == Shifted(i, 1)
    assert i.prev() == Shifted(i, -1)
    assert i.next().prev() == Shifted(i, 0)
    assert i.next(2) == i.next().next()
    assert i.prev(2) == i.next(-2)
    assert (i + 2 * j).next() == i.next() + 2 * j.next()
    assert Max(i, j).next() == Max(i.next(), j.next())
    assert (i + j).offsets == {0} and (i.next() - j.prev()).offsets == {1, -1}
    with pytest.raises(TypeError):
        i.next(1.5)


def test_coefficients_are_exact():
    assert (0.1 * r).terms == ((Shifted(r, 0), Fraction(1, 10)),)
    assert (r / 4).terms == ((Shifted(r, 0), Fraction(1, 4)),)
    assert (Fraction(2, 3) * r + 0.5).const == Fraction(1, 2)
    assert sum_of([i, j, i, 1, 2.5]) == 2 * i + j + Fraction(7, 2)
    with pytest.raises(TypeError, match="not linear"):
        i * j
    with pytest.raises(TypeError, match="not linear"):
        i / j
    with pytest.raises(ZeroDivisionError):
        i / 0
    with pytest.raises(ValueError):
        r * float("nan")


def test_equality_api():
    atom = i.next().eq(i)
    assert isinstance(atom, Compare) and atom.op == "==" and atom.const == 0
    assert eq(i, 3) == Compare(i, "==", 3)
    assert i.ne(3) == Not(i.eq(3)) == ne(i, 3)
    assert p.next().eq(p) == Iff(p.next(), p)
    assert isinstance(i.next() == i, bool)  # `==` stays structural, hence hashable nodes
    with pytest.raises(TypeError, match=r"a\.eq\(b\)"):
        And(i == 3)
    with pytest.raises(TypeError, match="between"):
        0 <= i <= 5  # noqa: B015 - the chained comparison itself must raise
    with pytest.raises(TypeError):
        bool(p)
    assert evaluate(i.between(0, 5), [{"i": 5}]) and not evaluate(i.between(0, 5), [{"i": 6}])


def test_sorts_are_checked():
    with pytest.raises(TypeError, match="bool variable"):
        p + 1
    with pytest.raises(TypeError, match="not a formula"):
        i & p
    with pytest.raises(TypeError):
        Until(i, p)
    with pytest.raises(ValueError):
        Var("x", "float")
    with pytest.raises(ValueError):
        Var("", "int")
    with pytest.raises(TypeError):
        Next(3)


def test_connectives_and_helpers():
    assert ~p == Not(Shifted(p, 0))
    assert p >> q == Implies(p, q)
    assert (p & q & (i > 0)) == And(p, q, i > 0)
    assert (p | (q | p.next())) == Or(p, q, p.next())
    assert (p & TRUE) == Shifted(p, 0)
    assert (p & FALSE) == FALSE and (p | TRUE) == TRUE
    assert conj([]) == TRUE and disj([]) == FALSE
    assert And() != TRUE and evaluate(And(), [{}]) and not evaluate(Or(), [{}])
    assert exactly_one([]) == FALSE
    a, b, c = bools("a b c")
    one = exactly_one([a, b, c])
    for bits in range(8):
        values = {"a": bool(bits & 1), "b": bool(bits & 2), "c": bool(bits & 4)}
        assert evaluate(one, [values]) == (sum(values.values()) == 1)


def test_max_min_terms():
    e = Max(i, j.next()) - Min(r, 1) + 1
    assert isinstance(e, LinExpr) and len(e.terms) == 2
    assert maximum(i, j, 3) == Max(Max(i, j), 3) + 0
    assert minimum(i) == i + 0
    trace = states(i=[1, 0], j=[5, 2], r=[Fraction(1, 2), 7])
    assert evaluate(e.eq(Fraction(5, 2)), trace)  # max(1, 2) - min(1/2, 1) + 1
    assert not evaluate(e.eq(Fraction(5, 2)), trace, 1)  # reads j at 2: out of range


def test_signature():
    sig = Signature.of(Until(p, i.next() > r), q, i)
    assert list(sig.items()) == [("p", "bool"), ("i", "int"), ("r", "real"), ("q", "bool")]
    assert sig.var("r") == r and sig.vars[0] == p
    assert Signature({"i": "int"}) | Signature([j]) == Signature([i, j])
    assert hash(Signature([i, j])) == hash(Signature([j, i]))
    with pytest.raises(ValueError, match="declared both"):
        Signature.of(Var("i", "int") > 0, Var("i", "bool"))


def test_nodes_are_hashable_and_picklable():
    f = Always(Until(p, (i.next() - 2 * r >= Fraction(1, 3)) & ~Last(q)) | Since(p, Prev(q)))
    hash(f)
    g = pickle.loads(pickle.dumps(f))
    assert g == f and hash(g) == hash(f)
    assert "_hash" not in pickle.loads(pickle.dumps(f)).__dict__
    assert len(subformulas(And(p, p, Not(p)))) == 3
    order = subformulas(f)
    assert order[-1] == f
    assert all(order.index(c) < order.index(n) for n in order for c in n.children)


def test_str():
    assert str(2 * i.next() - i + 3 <= 5) == "-i + 2*i[+1] <= 2"
    assert str(Always(p >> Eventually(q))) == "G (p -> F q)"
    assert str((i > 0) & Until(p, q)) == "((i > 0) & (p U q))"
    assert str(Max(i, r / 2)) == "max(i, 1/2*r)"


# --------------------------------------------------------------------------------------------
# evaluation on hand-made traces


def test_strong_atoms_at_the_boundaries():
    trace = states(i=[1, 2, 3])
    up = i.next() > i
    assert evaluate_all(up, trace) == [True, True, False]
    assert evaluate_all(~up, trace) == [False, False, True]
    assert evaluate_all(i.next() <= i, trace) == [False, False, False]
    assert evaluate_all(i.prev() < i, trace) == [False, True, True]
    assert evaluate_all((i.next() - i.prev()).eq(2), trace) == [False, True, False]
    assert evaluate_all((i.next() - i.next()).eq(0), trace) == [True, True, True]  # normalised away
    assert evaluate_all(p.next(), states(p=[True, True])) == [True, False]
    assert evaluate_all(p.prev(), states(p=[True, True])) == [False, True]


def test_next_and_prev():
    trace = states(p=[False, True, False])
    assert evaluate_all(Next(p), trace) == [True, False, False]
    assert evaluate_all(Prev(p), trace) == [False, False, True]
    assert evaluate_all(Next(TRUE), trace) == [True, True, False]
    assert evaluate_all(~Next(TRUE), trace) == [False, False, True]  # "last instant"
    assert evaluate_all(Prev(TRUE), trace) == [False, True, True]
    single = [{"p": True}]  # K = 0
    assert evaluate(p, single)
    assert not evaluate(Next(TRUE), single) and not evaluate(Prev(TRUE), single)
    assert evaluate(~Next(p), single) and evaluate(~Prev(p), single)


def test_until():
    def until(ps, qs):
        return evaluate_all(Until(p, q), states(p=ps, q=qs))

    assert until([True, True, False], [False, False, True]) == [True, True, True]
    assert until([True, False, False], [False, False, True]) == [False, False, True]
    assert until([False, False, False], [True, False, False]) == [True, False, False]
    assert until([True, True, True], [False, False, False]) == [False, False, False]
    assert until([True], [False]) == [False]
    assert until([False], [True]) == [True]
    assert evaluate(Until(FALSE, p), [{"p": True}, {"p": False}])


def test_since():
    def since(ps, qs):
        return evaluate_all(Since(p, q), states(p=ps, q=qs))

    assert since([False, True, True], [True, False, False]) == [True, True, True]
    assert since([False, True, False], [True, False, False]) == [True, True, False]
    assert since([False, False, False], [False, False, True]) == [False, False, True]
    assert since([True, True], [False, False]) == [False, False]
    assert since([False], [True]) == [True]


def test_eventually_always_last():
    trace = states(p=[True, False, True, True])
    assert evaluate_all(Eventually(~p), trace) == [True, True, False, False]
    assert evaluate_all(Always(p), trace) == [False, False, True, True]
    assert evaluate_all(Last(~p), trace) == [False] * 4
    assert evaluate_all(Last(Prev(~p)), states(p=[True, False, True])) == [True] * 3
    assert evaluate(Always(p), [{"p": True}]) and not evaluate(Eventually(FALSE), [{}])
    assert evaluate(Always(TRUE), [{}]) and evaluate(Eventually(Last(TRUE)), [{}, {}])
    assert evaluate_all(Always(Next(TRUE)), trace) == [False] * 4  # strong next fails at K
    assert evaluate_all(Always(Next(TRUE) >> p.next()), trace) == [False, True, True, True]


def test_boolean_connectives_and_comparisons():
    trace = states(p=[True, True, False, False], q=[True, False, True, False])
    assert evaluate_all(p & q, trace) == [True, False, False, False]
    assert evaluate_all(p | q, trace) == [True, True, True, False]
    assert evaluate_all(p >> q, trace) == [True, False, True, True]
    assert evaluate_all(Iff(p, q), trace) == [True, False, False, True]
    assert evaluate_all(~p, trace) == [False, False, True, True]
    values = states(i=[1, 2], r=[0.1, Fraction(3, 2)])
    assert evaluate_all((10 * r).eq(i), values) == [True, False]  # 0.1 is read as 1/10
    assert evaluate_all((r * 2 - i).eq(1), values) == [False, True]
    for op, expected in zip(
        OPS, ([True, False], [False, False], [True, True], [False, True], [True, False]), strict=True
    ):
        assert evaluate_all(Compare(i, op, 1), values) == expected, op


def test_evaluate_rejects_bad_input():
    with pytest.raises(ValueError, match="at least one instant"):
        evaluate(p, [])
    with pytest.raises(ValueError, match="outside"):
        evaluate(p, [{"p": True}], 1)
    with pytest.raises(KeyError, match="'q'"):
        evaluate(q, [{"p": True}])
    with pytest.raises(TypeError, match="integer"):
        evaluate(i > 0, [{"i": 1.5}])
    with pytest.raises(TypeError, match="bool"):
        evaluate(p, [{"p": 1}])
    with pytest.raises(TypeError, match="bool"):
        evaluate(r > 0, [{"r": True}])
    with pytest.raises(TypeError):
        evaluate(p, {"p": True})


def test_deep_trace():
    K = 20_000
    trace = [{"i": k, "p": k % 2 == 0} for k in range(K + 1)]
    counting = Always(Next(TRUE) >> i.next().eq(i + 1))
    started = time.perf_counter()
    assert evaluate(counting & Until(i.next() > i, i >= K) & Last(p), trace)
    assert evaluate(Since(TRUE, i.eq(0)), trace, K)
    assert evaluate_all(Eventually(Always(p | p.next())), trace)[0]
    assert time.perf_counter() - started < 5


# --------------------------------------------------------------------------------------------
# the fixed-horizon encoding


def test_unrolling_variables():
    u = Unrolling(SIG, 2, ctx=CTX, prefix="R1.")
    assert u.K == 2 and u.signature is SIG and u.ctx is CTX and u.prefix == "R1."
    assert str(u["i", 2]) == "R1.i@2" and u["i", 2].sort() == z3.IntSort(CTX)
    assert u["r", 0].sort() == z3.RealSort(CTX) and u["p", 1].sort() == z3.BoolSort(CTX)
    assert u[p, 1].eq(u["p", 1])
    with pytest.raises(IndexError):
        u["i", 3]
    with pytest.raises(KeyError):
        u["x", 0]
    with pytest.raises(KeyError, match="declared int"):
        u[Var("i", "real"), 0]
    with pytest.raises(KeyError, match="not in the signature"):
        u.encode(Var("x", "int") > 0)
    with pytest.raises(ValueError):
        u.encode(p, 3)
    with pytest.raises(ValueError):
        Unrolling(SIG, -1)


def test_encoding_of_atoms():
    u = Unrolling(SIG, 2, ctx=CTX)
    assert z3.is_false(u.encode(i.next() > 0, 2)) and z3.is_false(u.encode(p.prev(), 0))
    assert z3.is_true(u.encode(Not(i.prev() > 0), 0))
    assert z3.is_true(u.encode(i - i <= 1))
    half = u.encode(i / 2 + j / 3 <= Fraction(1, 6))  # integral: scaled to 3i + 2j <= 1 in Int
    assert "to_real" not in half.sexpr() and "3" in half.sexpr()
    mixed = u.encode(i + r <= 1)
    assert "to_real" in mixed.sexpr()
    assert "ite" in u.encode(Max(i, j) >= 1).sexpr()
    assert u.term(i + 2 * j.next(), 1).sort() == z3.IntSort(CTX)
    assert u.term(i + r, 0).sort() == z3.RealSort(CTX)
    with pytest.raises(ValueError, match="reads outside"):
        u.term(i.next(), 2)


def test_unrolling_solves_and_reads_back():
    spec = (
        i.eq(0)
        & Always(Next(TRUE) >> ((i.next() - i).between(0, 2) & r.next().eq(r + Fraction(1, 2))))
        & Until(~p, Last(p) & (i >= 5))
        & Eventually(Max(i, r) >= 3)
    )
    for K in range(6):
        u = Unrolling(Signature.of(spec), K, ctx=CTX)
        s = solver()
        s.add(u.encode(spec))
        result = s.check()
        assert result == (z3.sat if K >= 3 else z3.unsat), K
        if result == z3.sat:
            trace = u.trace(s.model())
            assert len(trace) == K + 1 and trace[0]["i"] == 0
            assert all(isinstance(state["r"], Fraction) for state in trace)
            assert evaluate(spec, trace) and reference(spec, trace, 0)
            assert is_sat(u.fix(trace), u.encode(spec))


def test_fix_partial_and_errors():
    u = Unrolling(SIG, 2, ctx=CTX)
    assert is_sat(u.fix([{"i": 3}], start=1), u.encode(Next(i.eq(3))))
    assert not is_sat(u.fix([{"i": 3}], start=1), u.encode(Next(i.eq(4))))
    assert z3.is_true(u.fix([]))
    with pytest.raises(IndexError):
        u.fix([{"i": 0}] * 4)
    with pytest.raises(KeyError):
        u.fix([{"x": 0}])
    with pytest.raises(TypeError):
        u.fix([{"i": 0.5}])


def test_shared_subformulas_are_encoded_once():
    u = Unrolling(SIG, 3, ctx=CTX)
    body = Until(p, q)
    first = u.encode(Always(body))
    memo_size = len(u._memo)
    second = u.encode(Eventually(Until(p, q)))
    assert len(u._memo) == memo_size + 4  # only the four Eventually entries are new
    assert first.sort() == second.sort() == z3.BoolSort(CTX)


def test_an_equal_copy_of_a_formula_is_looked_up_by_its_first_representative():
    # the specification builds the same sub-formula again and again: the memo keeps the first
    # one met and finds copies by identity after one comparison, not one per instant
    u = Unrolling(SIG, 3, ctx=CTX)
    first = Always(Until(p, q) | (i >= 2))
    copy = Always(Until(p, q) | (i >= 2))
    assert copy == first and copy is not first
    a = u.encode(first)
    memo_size = len(u._memo)
    b = u.encode(copy)
    assert len(u._memo) == memo_size and a.eq(b)
    assert all(key[0] is first for key in u._memo if key[0] == first)
    assert all(key[0] is first.arg for key in u._memo if key[0] == copy.arg)


# --------------------------------------------------------------------------------------------
# the incremental encoding


def test_incremental_finds_the_smallest_horizon():
    spec = (
        i.eq(0)
        & Always(Next(TRUE) >> (i.next() - i).between(0, 1))
        & Until(i < 2, i.eq(2) & Next(i.eq(3)))
        & Last(p)
    )
    u = IncrementalUnrolling(Signature.of(spec), ctx=CTX)
    s = solver()
    s.add(u.require(spec))
    while s.check(u.end) != z3.sat:
        assert u.K < 10
        s.add(u.extend())
    assert u.K == 3
    trace = u.trace(s.model())
    assert [state["i"] for state in trace] == [0, 1, 2, 3] and evaluate(spec, trace)
    for K in range(4):  # agrees with the fixed-horizon encoding at every horizon
        fixed = Unrolling(Signature.of(spec), K, ctx=CTX)
        assert is_sat(fixed.encode(spec)) == (K == 3)


def test_incremental_encode_after_extension():
    u = IncrementalUnrolling(SIG, 0, ctx=CTX)
    s = solver()
    s.add(u.extend(2))
    assert u.K == 2
    s.add(u.require(Eventually(i.next().eq(7)), 1))
    s.add(u.fix(states(i=[0, 0, 0])))
    assert s.check(u.end) == z3.unsat
    s.add(u.extend())
    s.add(u.fix([{"i": 7}], start=3))
    assert s.check(u.end) == z3.sat
    assert u.extend(3) == []
    with pytest.raises(ValueError, match="only grows"):
        u.extend(1)


# --------------------------------------------------------------------------------------------
# property tests: evaluate == reference == Z3

SHIFTS = st.sampled_from([-1, 0, 1])
COEFFICIENTS = st.sampled_from([1, -1, 2, -2, Fraction(1, 2), Fraction(-3, 2)])
CONSTANTS = st.sampled_from([-2, -1, 0, 1, 2, Fraction(1, 2), Fraction(-5, 2)])
numeric_terms = st.builds(lambda v, o: v.next(o), st.sampled_from([i, j, r]), SHIFTS)
plain = st.lists(st.tuples(COEFFICIENTS, numeric_terms), min_size=1, max_size=3).map(
    lambda items: sum_of(c * t for c, t in items)
)
terms = st.one_of(
    plain,
    plain,
    plain,
    st.builds(Max, plain, plain | CONSTANTS),
    st.builds(Min, plain, plain | CONSTANTS),
)
expressions = st.lists(st.tuples(COEFFICIENTS, terms), min_size=1, max_size=2).map(
    lambda items: sum_of(c * t for c, t in items)
)
atoms = st.one_of(
    st.sampled_from([TRUE, FALSE]),
    st.builds(lambda v, o: v.next(o), st.sampled_from([p, q]), SHIFTS),
    st.builds(Compare, expressions, st.sampled_from(OPS), CONSTANTS),
)
UNARY = [Not, Next, Prev, Eventually, Always, Last]
BINARY = [Implies, Iff, Until, Since]


@st.composite
def formulas(draw, depth: int = 4, unary=tuple(UNARY), binary=tuple(BINARY)):
    """Random formulas with at most ``depth`` nested operators (of `unary`, `binary`, and and
    or) above the atoms."""
    if depth == 0 or draw(st.integers(0, 3)) == 0:
        return draw(atoms)
    shape = draw(st.sampled_from(["unary", "binary", "n-ary"]))
    below = formulas(depth - 1, unary, binary)
    if shape == "unary":
        return draw(st.sampled_from(unary))(draw(below))
    if shape == "binary":
        return draw(st.sampled_from(binary))(draw(below), draw(below))
    args = draw(st.lists(below, max_size=3))
    return draw(st.sampled_from([And, Or]))(*args)


HALVES = [Fraction(n, 2) for n in range(-4, 5)]


@st.composite
def traces(draw) -> list[dict]:
    K = draw(st.integers(0, 4))
    small = st.integers(-2, 2)
    return [
        {
            "i": draw(small),
            "j": draw(small),
            "r": draw(st.sampled_from(HALVES)),
            "p": draw(st.booleans()),
            "q": draw(st.booleans()),
        }
        for _ in range(K + 1)
    ]


@settings(max_examples=400, deadline=None)
@given(formula=formulas(), trace=traces())
def test_encoding_agrees_with_evaluation(formula, trace):
    K = len(trace) - 1
    column = evaluate_all(formula, trace)
    assert column == [reference(formula, trace, k) for k in range(K + 1)]
    u = Unrolling(SIG, K, ctx=CTX)
    s = solver()
    s.add(u.fix(trace))
    for k in range(K + 1):
        encoded = u.encode(formula, k)
        for goal, want in ((encoded, column[k]), (z3.Not(encoded), not column[k])):
            s.push()
            s.add(goal)
            result = s.check()
            s.pop()
            assert result != z3.unknown, s.reason_unknown()
            assert (result == z3.sat) == want, (k, str(formula))


@settings(max_examples=300, deadline=None)
@given(many=st.lists(formulas(depth=3), min_size=1, max_size=4), trace=traces())
def test_failing_agrees_with_evaluation_with_equal_formulas_that_are_other_objects(many, trace):
    # one evaluation shares the columns of sub-formulas by structure and by object: copies
    # (equal, not the same objects) and the originals, in any order, get the same answers
    mixed = [f for original in many for f in (original, copy.deepcopy(original))]
    expected = [i for i, f in enumerate(mixed) if not reference(f, trace, 0)]
    assert failing(mixed, trace) == expected
    assert failing(mixed[::-1], trace) == [len(mixed) - 1 - i for i in reversed(expected)]
    # bare variables are made formulas for the call (short-lived objects): each its own answer,
    # as one evaluation each gives
    bare = [p, p.next(), q, p, ~q]
    assert failing(bare, trace) == [i for i, f in enumerate(bare) if not evaluate(f, trace)]


@settings(max_examples=400, deadline=None)
@given(formula=formulas(), trace=traces(), start=st.integers(0, 4))
def test_incremental_encoding_agrees_at_every_horizon(formula, trace, start):
    K = len(trace) - 1
    K0 = min(start, K)
    u = IncrementalUnrolling(SIG, K0, ctx=CTX)
    s = solver()
    literal, definitions = u.encode(formula)
    s.add(definitions)
    s.add(u.fix(trace[: K0 + 1]))
    for horizon in range(K0, K + 1):
        if horizon > K0:
            s.add(u.extend())
            s.add(u.fix([trace[horizon]], start=horizon))
        expected = evaluate(formula, trace[: horizon + 1])
        for goal, want in ((literal, expected), (z3.Not(literal), not expected)):
            s.push()
            s.add(goal)
            result = s.check(u.end)
            s.pop()
            assert result != z3.unknown, s.reason_unknown()
            assert (result == z3.sat) == want, (horizon, str(formula))


def symbolic_reference(u, formula, k: int) -> z3.BoolRef:
    """The paper's Definition over the variables of ``u`` (horizon ``u.K``), quantifiers expanded.

    Independent of the encoder: no recurrences, all arithmetic in Real, atoms straight from the
    normalised tree. Equivalence with :meth:`Unrolling.encode` is then one validity check that
    covers every trace of that horizon at once.
    """
    K = u.K
    memo: dict = {}

    def linear(expr, k):
        parts = [z3.RealVal(c, CTX) * term(t, k) for t, c in expr.terms]
        return z3.Sum([*parts, z3.RealVal(expr.const, CTX)])

    def term(t, k):
        if isinstance(t, Shifted):
            v = u[t.var.name, k + t.offset]
            return z3.ToReal(v) if t.var.sort == "int" else v
        a, b = linear(t.left, k), linear(t.right, k)
        return z3.If(a >= b, a, b) if isinstance(t, Max) else z3.If(a <= b, a, b)

    def in_range(offsets, k):
        return all(0 <= k + o <= K for o in offsets)

    def at(f, k):
        key = (f, k)
        if key not in memo:
            memo[key] = build(f, k)
        return memo[key]

    def build(f, k):
        false = z3.BoolVal(False, CTX)
        match f:
            case BoolConst(value=v):
                return z3.BoolVal(v, CTX)
            case Shifted(var=v, offset=o):
                return u[v.name, k + o] if in_range({o}, k) else false
            case Compare(expr=e, op=op, const=c):
                return _CMP[op](linear(e, k), z3.RealVal(c, CTX)) if in_range(e.offsets, k) else false
            case Not(arg=a):
                return z3.Not(at(a, k))
            case And(args=args):
                return z3.And([at(a, k) for a in args] + [z3.BoolVal(True, CTX)])
            case Or(args=args):
                return z3.Or([at(a, k) for a in args] + [false])
            case Implies(left=a, right=b):
                return z3.Implies(at(a, k), at(b, k))
            case Iff(left=a, right=b):
                return at(a, k) == at(b, k)
            case Next(arg=a):
                return at(a, k + 1) if k < K else false
            case Prev(arg=a):
                return at(a, k - 1) if k > 0 else false
            case Until(left=a, right=b):
                return z3.Or(
                    [z3.And([at(b, n), *[at(a, m) for m in range(k, n)]]) for n in range(k, K + 1)] + [false]
                )
            case Since(left=a, right=b):
                return z3.Or(
                    [z3.And([at(b, n), *[at(a, m) for m in range(n + 1, k + 1)]]) for n in range(k + 1)]
                    + [false]
                )
            case Eventually(arg=a):
                return at(Until(TRUE, a), k)
            case Always(arg=a):
                return z3.Not(at(Eventually(Not(a)), k))
            case Last(arg=a):
                return at(a, K)
        raise AssertionError(f"unknown node {f!r}")

    return at(formula, k)


def assert_valid(s: z3.Solver, claim: z3.BoolRef, *assumptions: z3.BoolRef, note: object = "") -> None:
    s.push()
    s.add(z3.Not(claim))
    result = s.check(*assumptions)
    s.pop()
    assert result != z3.unknown, s.reason_unknown()
    assert result == z3.unsat, (note, s.model() if result == z3.sat else None)


@settings(max_examples=400, deadline=None)
@given(formula=formulas(), K=st.integers(0, 4))
def test_encoding_is_equivalent_to_the_definition(formula, K):
    u = Unrolling(SIG, K, ctx=CTX)
    s = solver()
    for k in range(K + 1):
        assert_valid(s, u.encode(formula, k) == symbolic_reference(u, formula, k), note=(k, str(formula)))


@settings(max_examples=200, deadline=None)
@given(formula=formulas(), K0=st.integers(0, 2), K=st.integers(0, 4), k=st.integers(0, 2))
def test_incremental_encoding_is_equivalent_to_the_definition(formula, K0, K, k):
    k = min(k, K0)
    u = IncrementalUnrolling(SIG, K0, ctx=CTX)
    s = solver()
    literal, definitions = u.encode(formula, k)
    s.add(definitions)
    for horizon in range(K0, max(K0, K) + 1):
        if horizon > K0:
            s.add(u.extend())
        assert s.check(u.end) == z3.sat  # the definitions are consistent
        assert_valid(s, literal == symbolic_reference(u, formula, k), u.end, note=(horizon, str(formula)))


def test_incremental_with_longer_shifts():
    formulas_ = [
        i.next(2) > i,
        Always(Next(Next(TRUE)) >> (i.next(2) - i.prev(2)).eq(r.next())),
        Until(p.next(3), q.prev(2) | Last(i.next(2) >= 0)),
        Eventually(Next(Next(p)) & (Max(i.next(2), j) <= r)),
    ]
    for formula in formulas_:
        for k in (0, 1):
            u = IncrementalUnrolling(SIG, 1, ctx=CTX)
            s = solver()
            literal, definitions = u.encode(formula, k)
            s.add(definitions)
            for _ in range(5):
                assert_valid(s, literal == symbolic_reference(u, formula, k), u.end, note=(u.K, str(formula)))
                s.add(u.extend())


def steady_formulas(depth: int = 3):
    """Random formulas without future, since or Last operators: the time-invariant ones."""
    return formulas(depth, (Not, Next, Prev), (Implies, Iff))


@st.composite
def transition_formulas(draw):
    """A specification's shape: transition constraints, and whatever else, conjoined."""
    steps = [
        Always(Implies(Next(draw(steady_formulas(1))), draw(steady_formulas())))
        for _ in range(draw(st.integers(1, 3)))
    ]
    return conj([*steps, draw(st.sampled_from([TRUE, draw(formulas(2)), draw(steady_formulas())]))])


class _CopyingEverything:
    """Copy every formula between instants, however small (the encoder copies only large ones)."""

    def __enter__(self) -> None:
        import cosmop.logic.encode as encode

        self._module, self._saved = encode, encode._COPY_MIN
        encode._COPY_MIN = 1

    def __exit__(self, *exc: object) -> None:
        self._module._COPY_MIN = self._saved


@settings(max_examples=300, deadline=None)
@given(formula=st.one_of(transition_formulas(), formulas()), K=st.integers(0, 4))
def test_copies_between_instants_are_the_definition(formula, K):
    with _CopyingEverything():
        u = Unrolling(SIG, K, ctx=CTX, copies=True)
        s = solver()
        for k in range(K + 1):
            assert_valid(s, u.encode(formula, k) == symbolic_reference(u, formula, k), note=(k, str(formula)))


@settings(max_examples=300, deadline=None)
@given(formula=st.one_of(transition_formulas(), formulas()), K0=st.integers(0, 3), k=st.integers(0, 3))
def test_copies_at_a_growing_frontier_are_the_definition(formula, K0, k):
    k = min(k, K0)
    with _CopyingEverything():
        u = IncrementalUnrolling(SIG, K0, ctx=CTX, copies=True)
        s = solver()
        literal, definitions = u.encode(formula, k)
        s.add(definitions)
        for horizon in range(K0, K0 + 4):
            if horizon > K0:
                s.add(u.extend())
                # formulas met only now are copied from instants of an older horizon
                more, definitions = u.encode(formula, horizon - 1)
                s.add(definitions)
                assert_valid(s, more == symbolic_reference(u, formula, horizon - 1), u.end, note=str(formula))
            assert s.check(u.end) == z3.sat  # the definitions are consistent
            assert_valid(s, literal == symbolic_reference(u, formula, k), u.end, note=(horizon, str(formula)))


@pytest.mark.parametrize("copies", [True, False])
def test_a_transition_grows_the_horizon_without_a_literal_per_atom(copies):
    # Growing the horizon by one instant adds the transition at the old frontier and at the new
    # one; with copies the effect B is copied (no walk, no frontier literal for each of its ten
    # atoms), without them each atom gets its literal: the same meaning either way
    effect = conj((i.next() - i <= c) | (j.next() >= c) for c in range(5))
    spec = Always(Implies(Next(p), effect))
    u = IncrementalUnrolling(SIG, 2, ctx=CTX, copies=copies)
    s = solver()
    s.add(u.require(spec))
    for _ in range(3):
        added = u.extend()
        assert (len(added) <= 6) == copies, [str(c) for c in added]
        s.add(added)
        assert_valid(s, u.encode(spec)[0] == symbolic_reference(u, spec, 0), u.end)
