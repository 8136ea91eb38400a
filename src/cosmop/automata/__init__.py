"""Array-backed deterministic finite automata for the top-down mission layer.

:class:`DFA` is the paper's :math:`(Q, \\Sigma, q_0, \\delta, Q_m)` with a partial ``int32``
transition table; the functions implement the operations of Section II-A on marked languages:
trim, product and synchronous product, natural projection and its inverse, inclusion and
equivalence with shortest counterexamples, minimisation and prefix-closure.
:func:`project_composition` projects a synchronous product without building it.
"""

from cosmop.automata.composition import Composition, project_composition
from cosmop.automata.dfa import DFA
from cosmop.automata.operations import (
    accessible,
    canonical,
    complement,
    complete,
    equivalence_counterexample,
    equivalent,
    extend_alphabet,
    inclusion_counterexample,
    inverse_project,
    is_empty,
    is_included,
    minimize,
    parallel,
    prefix_closure,
    product,
    project,
    restrict,
    satisfaction_counterexample,
    trim,
    with_marked,
    words,
)

__all__ = [
    "DFA",
    "Composition",
    "accessible",
    "canonical",
    "complement",
    "complete",
    "equivalence_counterexample",
    "equivalent",
    "extend_alphabet",
    "inclusion_counterexample",
    "inverse_project",
    "is_empty",
    "is_included",
    "minimize",
    "parallel",
    "prefix_closure",
    "product",
    "project",
    "project_composition",
    "restrict",
    "satisfaction_counterexample",
    "trim",
    "with_marked",
    "words",
]
