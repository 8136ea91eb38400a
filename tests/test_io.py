"""Helpers of :mod:`cosmop.io` that the commands' tests do not reach on their own."""

from __future__ import annotations

import gc

import pytest

from cosmop.io import collector_paused


def test_the_collector_is_paused_and_restored_as_it_was():
    assert gc.isenabled()
    with collector_paused():
        assert not gc.isenabled()
    assert gc.isenabled()
    with pytest.raises(RuntimeError), collector_paused():
        raise RuntimeError("a failure while building")
    assert gc.isenabled()  # restored after a failure too
    gc.disable()
    try:
        with collector_paused():
            pass
        assert not gc.isenabled()  # a caller's choice is kept
    finally:
        gc.enable()


def test_the_collector_is_paused_while_a_decorated_function_runs():
    seen = []

    @collector_paused()
    def work(n):
        seen.append(gc.isenabled())
        return n + 1

    assert work(1) == 2 and work(2) == 3  # each call pauses it anew
    assert seen == [False, False]
    assert gc.isenabled()
