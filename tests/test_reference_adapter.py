"""Tests of the libFAUDES adapter :mod:`cosmop.automata.reference` on small hand-made automata."""

from __future__ import annotations

import itertools
import subprocess
import sys
import textwrap

import pytest

faudes = pytest.importorskip("faudes")

from cosmop.automata import reference as ref  # noqa: E402


def sequence(events: list[str], *, all_marked: bool = True) -> ref.PlainDFA:
    """Plain DFA of the single word ``events`` (prefix-closed if ``all_marked``)."""
    n = len(events) + 1
    marked = list(range(n)) if all_marked else [n - 1]
    return list(events), n, 0, marked, [(i, ev, i + 1) for i, ev in enumerate(events)]


A = ["a1", "a2", "a3"]
B = ["b1", "b2", "b3"]
ROBOT1 = ["pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"]
ROBOT2 = ["pick(R2,O2)", "drop(R2,O2,W2)", "return(R2)"]


# ---------------------------------------------------------------------- event names


@pytest.mark.parametrize("name", ["a", "pick(R1,O1)", "drop(R1,O1,W1)", "away(O2,R1,R2)", "x<y>[z]{}|;:!"])
def test_project_event_names_pass_unchanged(name: str) -> None:
    assert ref.encode_event(name) == name
    assert ref.decode_event(name) == name


@pytest.mark.parametrize("name", ["a b", 'say "hi"', "#1", "50%", "é→", "tab\there", "%41"])
def test_unsafe_event_names_round_trip(name: str) -> None:
    symbol = ref.encode_event(name)
    assert symbol != name
    assert all("!" <= ch <= "~" and ch not in '"#' for ch in symbol)
    assert ref.decode_event(symbol) == name
    gen = ref.to_faudes([name], 2, 0, [1], [(0, name, 1)])
    assert gen.EventName(gen.EventIndex(symbol)) == symbol
    assert ref.from_faudes(gen) == ([name], 2, 0, [1], [(0, name, 1)])


def test_empty_event_name_rejected() -> None:
    with pytest.raises(ValueError):
        ref.encode_event("")


# ------------------------------------------------------------------------ round trips


def test_round_trip_sequence_with_robot_events() -> None:
    plain = sequence(ROBOT1)
    gen = ref.to_faudes(*plain)
    assert gen.Size() == 4
    assert gen.TransRelSize() == 3
    assert faudes.IsDeterministic(gen)
    assert ref.from_faudes(gen) == (sorted(ROBOT1), 4, 0, [0, 1, 2, 3], plain[4])


def test_from_faudes_renumbers_initial_first_and_is_canonical() -> None:
    # states listed in a scrambled order: initial state 2, chain 2 -a-> 0 -b-> 3, 1 unreachable
    plain = (["b", "a"], 4, 2, [3], [(2, "a", 0), (0, "b", 3)])
    alphabet, n, initial, marked, transitions = ref.from_faudes(ref.to_faudes(*plain))
    assert alphabet == ["a", "b"]
    assert (n, initial) == (4, 0)
    assert transitions == [(0, "a", 1), (1, "b", 2)]
    assert marked == [2]  # state 3 (unreachable) comes last, unmarked


def test_round_trip_is_fixed_point_on_product() -> None:
    first = ref.from_faudes(ref.parallel(sequence(A), sequence(B)))
    assert ref.from_faudes(ref.to_faudes(*first)) == first


def test_round_trip_keeps_unused_alphabet_events() -> None:
    plain = (["a", "b", "z"], 2, 0, [0, 1], [(0, "a", 1), (1, "b", 0)])
    assert ref.from_faudes(ref.to_faudes(*plain)) == plain


def test_empty_generator_round_trip() -> None:
    empty = ref.to_faudes(["a"], 0, 0, [], [])
    assert empty.Size() == 0
    assert ref.from_faudes(empty) == (["a"], 0, 0, [], [])
    assert ref.from_faudes(faudes.Generator()) == ([], 0, 0, [], [])


def test_from_faudes_rejects_nondeterministic() -> None:
    gen = faudes.Generator()
    gen.InsEvent("a")
    for q in (1, 2, 3):
        gen.InsState(q)
    gen.SetInitState(1)
    gen.SetTransition(1, gen.EventIndex("a"), 2)
    gen.SetTransition(1, gen.EventIndex("a"), 3)
    with pytest.raises(ValueError, match="deterministic"):
        ref.from_faudes(gen)


@pytest.mark.parametrize(
    "plain",
    [
        (["a"], 2, 2, [], []),  # initial out of range
        (["a"], 2, 0, [5], []),  # marked out of range
        (["a"], 2, 0, [], [(0, "b", 1)]),  # event outside the alphabet
        (["a"], 2, 0, [], [(0, "a", 1), (0, "a", 0)]),  # non-deterministic
        (["a"], -1, 0, [], []),
        ([""], 1, 0, [], []),
    ],
)
def test_to_faudes_validates(plain: ref.PlainDFA) -> None:
    with pytest.raises(ValueError):
        ref.to_faudes(*plain)


# ------------------------------------------------------------------------- operations


def test_shuffle_of_two_sequences_has_16_states() -> None:
    shuffle = ref.parallel(sequence(A), sequence(B))
    alphabet, n, _, marked, transitions = ref.from_faudes(shuffle)
    assert alphabet == sorted(A + B)
    assert n == 16
    assert len(marked) == 16
    assert len(transitions) == 2 * 3 * 4  # each of the 4 positions of one word, 3 moves of the other
    assert ref.minimal_states(shuffle) == 16


def test_parallel_synchronises_shared_events() -> None:
    # x a y  ||  z a : shared "a" must be taken together
    g1 = (["x", "a", "y"], 4, 0, [3], [(0, "x", 1), (1, "a", 2), (2, "y", 3)])
    g2 = (["z", "a"], 3, 0, [2], [(0, "z", 1), (1, "a", 2)])
    prod = ref.parallel(g1, g2)
    # words: {xz, zx} a y -> states: (0,0) (1,0) (0,1) (1,1) (2,2) (3,2)
    assert prod.Size() == 6
    expected = (
        ["a", "x", "y", "z"],
        6,
        0,
        [5],
        [(0, "x", 1), (0, "z", 2), (1, "z", 3), (2, "x", 3), (3, "a", 4), (4, "y", 5)],
    )
    assert ref.from_faudes(prod) == expected


def test_projection_of_shuffle_is_the_sequence() -> None:
    shuffle = ref.parallel(sequence(A), sequence(B))
    for word in (A, B):
        proj = ref.project(shuffle, word)
        assert faudes.IsDeterministic(proj)
        assert ref.from_faudes(proj) == sequence(word)
        assert ref.language_equality(proj, sequence(word))


def test_projection_of_robot_shuffle() -> None:
    mission = ref.parallel(sequence(ROBOT1), sequence(ROBOT2))
    assert mission.Size() == 16
    assert ref.from_faudes(ref.project(mission, ROBOT2)) == (sorted(ROBOT2), *sequence(ROBOT2)[1:])


def test_project_keeps_marked_language_and_reachable_part() -> None:
    # 0 -a-> 1 -b-> 2 (only 2 marked), 3 unreachable and marked
    g = (["a", "b"], 4, 0, [2, 3], [(0, "a", 1), (1, "b", 2)])
    proj = ref.project(g, ["b"])
    assert ref.from_faudes(proj) == (["b"], 2, 0, [1], [(0, "b", 1)])
    # erasing everything: the marked language {ab} projects to {eps}
    assert ref.from_faudes(ref.project(g, [])) == ([], 1, 0, [0], [])


def test_project_drops_events_unknown_to_the_generator() -> None:
    proj = ref.project(sequence(["a"]), ["a", "z"])
    assert ref.from_faudes(proj)[0] == ["a"]


def test_project_of_empty_generator_is_empty() -> None:
    proj = ref.project(ref.to_faudes(["a"], 0, 0, [], []), ["a"])
    assert proj.Size() == 0
    assert ref.from_faudes(proj) == (["a"], 0, 0, [], [])


def test_project_is_a_nfa_determinisation() -> None:
    # (a | b c) with b unobservable: projection onto {a, c} is (a | c), 3 states after minimisation
    g = (["a", "b", "c"], 4, 0, [1, 3], [(0, "a", 1), (0, "b", 2), (2, "c", 3)])
    proj = ref.project(g, ["a", "c"])
    assert faudes.IsDeterministic(proj)
    assert ref.language_equality(proj, (["a", "c"], 2, 0, [1], [(0, "a", 1), (0, "c", 1)]))
    assert ref.minimal_states(proj) == 2


def test_language_inclusion_true_and_false() -> None:
    shuffle = ref.parallel(sequence(A), sequence(B))
    prefix = sequence(A[:2])
    assert ref.language_inclusion(prefix, sequence(A))
    assert not ref.language_inclusion(sequence(A), prefix)
    assert ref.language_inclusion(sequence(A), shuffle)  # A's prefixes are shuffle words
    assert not ref.language_inclusion(shuffle, sequence(A))
    assert ref.language_equality(shuffle, ref.parallel(sequence(B), sequence(A)))
    assert not ref.language_equality(prefix, sequence(A))


def test_language_inclusion_compares_marked_languages_only() -> None:
    word = sequence(["a", "b"], all_marked=False)  # Lm = {ab}
    # extra unmarked branch c: larger generated language, same marked language
    bigger = (["a", "b", "c"], 4, 0, [2], [(0, "a", 1), (1, "b", 2), (0, "c", 3)])
    assert ref.language_equality(word, bigger)
    assert ref.language_inclusion(bigger, word)
    # a generator with nothing marked has the empty marked language
    nothing = (["a"], 2, 0, [], [(0, "a", 1)])
    assert ref.language_inclusion(nothing, word)
    assert not ref.language_inclusion(word, nothing)
    assert ref.minimal_states(nothing) == 0


def test_language_inclusion_accepts_nondeterministic_generators() -> None:
    gen = faudes.Generator()
    gen.InsEvent("a")
    for q in (1, 2):
        gen.InsState(q)
    gen.SetInitState(1)
    gen.SetMarkedState(2)
    gen.SetTransition(1, gen.EventIndex("a"), 1)
    gen.SetTransition(1, gen.EventIndex("a"), 2)  # a+ (non-deterministic)
    a_plus = (["a"], 2, 0, [1], [(0, "a", 1), (1, "a", 1)])
    assert ref.language_equality(gen, a_plus)
    assert ref.minimal_states(gen) == 2


def test_minimal_states_merges_equivalent_states() -> None:
    # (ab)* unrolled twice: 4 states, minimal 2
    unrolled = (["a", "b"], 4, 0, [0, 2], [(0, "a", 1), (1, "b", 2), (2, "a", 3), (3, "b", 0)])
    assert ref.minimal_states(unrolled) == 2
    # blocking state (d leads nowhere marked) is trimmed away
    blocking = (["a", "d"], 3, 0, [0, 1], [(0, "a", 1), (0, "d", 2)])
    assert ref.minimal_states(blocking) == 2


def test_operations_accept_generators_and_plain_tuples_alike() -> None:
    plain_a, plain_b = sequence(A), sequence(B)
    gen_a, gen_b = ref.to_faudes(*plain_a), ref.to_faudes(*plain_b)
    assert ref.from_faudes(ref.parallel(gen_a, plain_b)) == ref.from_faudes(ref.parallel(plain_a, gen_b))
    with pytest.raises(TypeError):
        ref.parallel(object(), gen_b)  # type: ignore[arg-type]


def test_separability_of_three_robot_mission() -> None:
    robots = [sequence([f"{ev}{i}" for ev in "pdr"]) for i in range(3)]
    mission = robots[0]
    for robot in robots[1:]:
        mission = ref.parallel(mission, robot)
    assert mission.Size() == 64
    projections = [ref.project(mission, robot[0]) for robot in robots]
    product = projections[0]
    for proj in projections[1:]:
        product = ref.parallel(product, proj)
    assert ref.language_inclusion(product, mission)
    assert ref.language_inclusion(mission, product)

    # a non-separable mission: robot 0 and robot 1 must not both pick (mutual exclusion)
    alphabet = ["p0", "p1"]
    one_of = (alphabet, 2, 0, [0, 1], [(0, "p0", 1), (0, "p1", 1)])
    p0, p1 = ref.project(one_of, ["p0"]), ref.project(one_of, ["p1"])
    assert not ref.language_inclusion(ref.parallel(p0, p1), one_of)


def test_all_words_of_small_shuffle_match_parallel() -> None:
    # brute force: the marked words of a||b are the interleavings of prefixes
    plain = ref.from_faudes(ref.parallel(sequence(["a", "b"]), sequence(["c"])))
    alphabet, _, init, marked, transitions = plain
    delta = {(s, e): d for s, e, d in transitions}

    def accepts(word: tuple[str, ...]) -> bool:
        q = init
        for ev in word:
            if (q, ev) not in delta:
                return False
            q = delta[(q, ev)]
        return q in marked

    for length in range(4):
        for word in itertools.product(alphabet, repeat=length):
            ab = [ev for ev in word if ev in "ab"]
            c = [ev for ev in word if ev == "c"]
            expected = ab == ["a", "b"][: len(ab)] and len(c) <= 1
            assert accepts(word) == expected, word


def test_two_initial_states_are_determinised() -> None:
    gen = faudes.Generator()
    gen.InsEvent("a")
    gen.InsState(1)
    gen.InsState(2)
    gen.SetInitState(1)
    gen.SetInitState(2)  # StateMin and LanguageInclusion reject this unless determinised
    gen.SetMarkedState(1)
    assert ref.minimal_states(gen) == 1
    assert ref.language_equality(gen, ([], 1, 0, [0], []))
    with pytest.raises(ValueError, match="deterministic"):
        ref.from_faudes(gen)


def test_faudes_errors_are_raised_quietly(capfd: pytest.CaptureFixture[str]) -> None:
    verbosity = faudes.Verbosity()
    gen = faudes.Generator()
    with pytest.raises(ref.FaudesError, match="not a valid symbol"), ref._quiet(faudes):
        gen.InsEvent("a b")
    assert faudes.Verbosity() == verbosity
    ref.minimal_states(ref.parallel(sequence(A), sequence(B)))
    assert "FAUDES" not in capfd.readouterr().out


def test_module_imports_and_explains_without_faudes() -> None:
    code = textwrap.dedent(
        """
        import sys
        sys.modules["faudes"] = None  # simulate a missing binding
        from cosmop.automata import reference as ref
        assert not ref.is_available()
        try:
            ref.to_faudes(["a"], 1, 0, [0], [])
        except ImportError as exc:
            assert "pip install cosmop[test]" in str(exc), exc
        else:
            raise AssertionError("no ImportError")
        """
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr
