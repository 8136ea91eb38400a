"""Plots of scenes and plans, and animations of simulation traces (matplotlib, the ``viz`` extra)."""

from cosmop.viz.animation import draw_frame, save_animation, video_available
from cosmop.viz.plans import available, draw_plan, save_plan_png

__all__ = ["available", "draw_frame", "draw_plan", "save_animation", "save_plan_png", "video_available"]
