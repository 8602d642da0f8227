"""Effect ``frame_flex``: chassis flexibility (frame torsion and bending)."""
from __future__ import annotations

from eroad.errors import EroadInputError
from vehicles.effects.base import Effect, Parameter


class FrameFlex(Effect):
    """The frame as rigid segments joined by torsion and bending springs."""

    name = "frame_flex"
    description = (
        "Chassis flexibility: the frame becomes rigid segments joined by torsion (about x) "
        "and bending (about y) spring-dampers, tuned so that the first frame torsion and "
        "vertical bending modes sit at the vehicle's targets (5-15 Hz) times "
        "sqrt(stiffness_factor).  Adds response near those modes to body accelerations "
        "(left/right out of phase for torsion) and to the DCDC points; a very stiff frame "
        "reproduces the rigid chassis.")
    parameters = (
        Parameter("stiffness_factor", "-", 1.0, (0.05, 1.0e4),
                  "scale of the frame's torsion, bending and lateral bending stiffness"),
        Parameter("segments", "-", 0.0, (0.0, 16.0),
                  "number of frame segments (0: the vehicle's default)"),
    )
    primary = "stiffness_factor"
    order = 10

    def configure(self, ctx, p):
        ctx.chassis = "flexible"
        ctx.stiffness_factor = p["stiffness_factor"]
        n = p["segments"]
        if n:
            if n != int(n) or n < 2:
                raise EroadInputError(f"effect frame_flex: segments must be a whole number >= 2 "
                                      f"(or 0 for the default), got {n:g}")
            ctx.frame_segments = int(n)
