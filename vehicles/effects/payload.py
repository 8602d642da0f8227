"""Effect ``payload``: payload mass and centre-of-gravity offset."""
from __future__ import annotations

from dataclasses import replace

from eroad.errors import EroadInputError
from vehicles.effects.base import Effect, Parameter


class Payload(Effect):
    """Changes the mass and position of the vehicle's payload item."""

    name = "payload"
    description = (
        "Payload error: the payload item (load of the dump truck, kingpin load of the tractor) "
        "gets 'mass' more kilograms and its centre of gravity moves by (dx, dy).  The static "
        "sag changes - the outputs stay zeroed on the nominal vehicle, so the mean suspension "
        "displacement shifts (more compression with more load) - body bounce and pitch "
        "frequencies drop with more mass, and dy makes left and right differ.")
    parameters = (
        Parameter("mass", "kg", 2000.0, (-50000.0, 50000.0), "change of the payload mass"),
        Parameter("dx", "m", 0.0, (-3.0, 3.0), "shift of the payload along x (forward +)"),
        Parameter("dy", "m", 0.0, (-1.0, 1.0), "shift of the payload along y (left +)"),
    )
    primary = "mass"
    order = 5

    def configure(self, ctx, p):
        vp = ctx.vp
        items = list(vp.sprung)
        idx = [i for i, m in enumerate(items) if m.payload]
        if not idx:
            raise EroadInputError(f"effect payload: vehicle {vp.id} has no payload item")
        it = items[idx[0]]
        m = it.mass + p["mass"]
        if m <= 0:
            raise EroadInputError(f"effect payload: mass change {p['mass']:g} kg leaves "
                                  f"{m:g} kg of payload (nominal {it.mass:g} kg)")
        fr = vp.frame
        dx = min(max(p["dx"], fr.x_rear - it.x_rear), fr.x_front - it.x_front)
        items[idx[0]] = replace(it, mass=m, x_front=it.x_front + dx, x_rear=it.x_rear + dx,
                                y=it.y + p["dy"])
        ctx.vp = replace(vp, sprung=tuple(items))
        ctx.notes["payload_mass_kg"] = m
        if dx != p["dx"]:
            ctx.notes["payload_dx_clipped_m"] = dx
