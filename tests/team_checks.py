"""Checks of a simulated run that every team example must pass (shared by the tests)."""

from __future__ import annotations

import numpy as np

from cosmop.missions.mission import GlobalMission


def assert_no_overlap(scenario, result, tolerance: float = 1e-6) -> None:
    """No two robots' squares ever overlap (touching allowed), at any recorded cycle."""
    pose = result.frames["pose"]  # (n, R, 3)
    half = np.array([scenario.scene.robots[r].size / 2.0 for r in result.robot_ids])
    n_robots = pose.shape[1]
    for i in range(n_robots):
        for j in range(i + 1, n_robots):
            gap = np.abs(pose[:, i, :2] - pose[:, j, :2]).max(axis=1) - (half[i] + half[j])
            worst = int(np.argmin(gap))
            assert gap[worst] >= -tolerance, (
                f"{result.robot_ids[i]} and {result.robot_ids[j]} overlap by {-gap[worst]:.1f} mm "
                f"at t = {result.frames['t'][worst]:.1f} s"
            )


def assert_complete_word(scenario, result) -> None:
    """The mission events the run realised form a complete word of the global mission."""
    word = result.executed_word()
    assert GlobalMission.from_scenario(scenario).is_complete_word(word), word
