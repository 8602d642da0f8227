"""Effect ``speed_scale``: the recorded speed differs from the true speed by a factor."""
from __future__ import annotations

from vehicles.effects.base import Effect, Parameter


class SpeedScale(Effect):
    """Scale error of the recorded speed signal."""

    name = "speed_scale"
    description = (
        "Speed-signal scale error (e.g. a wrong wheel radius in the odometer): the recorded "
        "'speed' channel is 'factor' times the true speed; the dynamics are unchanged, but "
        "whatever maps time to road distance with the recorded speed is off by the factor "
        "(wavelengths, spatial frequencies, road PSD level and segment lengths).")
    parameters = (
        Parameter("factor", "-", 1.02, (0.8, 1.25), "recorded speed / true speed"),
    )
    primary = "factor"
    order = 90

    def outputs(self, time, channels, p, ctx):
        if "speed" in channels:
            channels["speed"] = channels["speed"] * p["factor"]
