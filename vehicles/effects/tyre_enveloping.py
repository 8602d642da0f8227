"""Effect ``tyre_enveloping``: the tyre footprint averages short road irregularities."""
from __future__ import annotations

from vehicles.effects.base import Effect, Parameter


class TyreEnveloping(Effect):
    """Moving average of the road along x over the contact length."""

    name = "tyre_enveloping"
    description = (
        "Tyre enveloping: the road under each tyre is averaged over the footprint length "
        "(moving average along x, roadlib's footprint filter), a spatial low-pass whose first "
        "zero is at the wavelength equal to the length.  Cuts the excitation above about "
        "v / (2 length) Hz: mainly axle accelerations above the axle-hop band.")
    parameters = (
        Parameter("length", "m", 0.0, (0.0, 1.0),
                  "footprint (contact) length, rounded to an odd number of road grid steps; "
                  "0: the mean tyre_contact_length of the vehicle's axles"),
    )
    primary = "length"
    order = 20

    def road(self, road, p, ctx):
        length = p["length"] or float(sum(a.tyre_contact_length for a in ctx.vp.axles)
                                      / len(ctx.vp.axles))
        out = road.footprint_filtered(length)
        ctx.notes["tyre_enveloping_length_m"] = float(out.meta.get("footprint_length", p["length"]))
        return out
