"""The robot: its size and limits (:class:`Robot`), footprint and moving state (:class:`State`)."""

from trajopt.robot._footprint import (
    Footprint,
    FootprintCertificate,
    certify_footprint,
    polygons_clearance,
)
from trajopt.robot._robot import Robot, avoidance_width
from trajopt.robot._state import State

__all__ = [
    "Footprint",
    "FootprintCertificate",
    "Robot",
    "State",
    "avoidance_width",
    "certify_footprint",
    "polygons_clearance",
]
