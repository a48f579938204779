"""How the robot's base moves, chosen once as a value: the :class:`Drive` protocol and its records.

:class:`Differential` (turns in place), :class:`Omni` (turns its body while it drives) and
:class:`Ackermann` (a car: a turning radius, cusps) are frozen, validated records that own
their fields and answer what the stages ask of a drive (:class:`Drive`): the speed-cap
terms the timing receives (:class:`SpeedTerms`, :func:`speed_cap`), the steering it caps,
the fields of its samples, its label, and the plan and re-plan it composes from the shared
stages. ``Robot(drive="ackermann", min_turning_radius=...)`` and the other strings stay
accepted as shorthands (:func:`as_drive`).
"""

from trajopt.drive._protocol import Drive, SpeedTerms, Steering, speed_cap
from trajopt.drive._records import (
    CAR_FIELDS,
    DRIVES,
    Ackermann,
    Differential,
    Omni,
    as_drive,
)

__all__ = [
    "CAR_FIELDS",
    "DRIVES",
    "Ackermann",
    "Differential",
    "Drive",
    "Omni",
    "SpeedTerms",
    "Steering",
    "as_drive",
    "speed_cap",
]
