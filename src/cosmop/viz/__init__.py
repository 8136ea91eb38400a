"""Plots of scenes and plans (matplotlib, the optional ``viz`` extra)."""

from cosmop.viz.plans import available, draw_plan, save_plan_png

__all__ = ["available", "draw_plan", "save_plan_png"]
