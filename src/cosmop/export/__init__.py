"""Exports of cosmop runs to the robotics ecosystem's formats: ROS 2 bags (the ``ros`` extra)."""

from cosmop.export.rosbag import BagSummary, ros_available, write_bag

__all__ = ["BagSummary", "ros_available", "write_bag"]
