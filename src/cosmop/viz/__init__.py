"""Plots of scenes and plans (matplotlib, the optional ``viz`` extra)."""

from cosmop.viz.plans import draw_plan, save_plan_png

__all__ = ["draw_plan", "save_plan_png"]
