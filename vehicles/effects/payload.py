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
        "frequencies drop with more mass, and dy makes left and right differ.  The mass change is "
        "limited per vehicle to [-P, +P] (P: nominal payload; -P is the empty vehicle) and dy "
        "to +-0.3 m, a load heaped against one side wall (every static tyre load of the "
        "built-in vehicles stays above 60 % of nominal, none near lifting off).")
    parameters = (
        Parameter("mass", "kg", 2000.0, (-50000.0, 50000.0),
                  "change of the payload mass; on a vehicle limited to [-P, +P] with P its "
                  "nominal payload (from empty to 100 % overload)"),
        Parameter("dx", "m", 0.0, (-3.0, 3.0), "shift of the payload along x (forward +; "
                  "clipped so that the payload stays on the frame)"),
        Parameter("dy", "m", 0.0, (-0.3, 0.3), "shift of the payload along y (left +)"),
    )
    primary = "mass"
    order = 5
    #: largest payload change as a fraction of the nominal payload: +100 % (overloading to
    #: twice the rated load, the order of overload reported for coal-haul tippers; the dump
    #: truck's tyres then carry 37-39 kN statically, the tractor's 29-39 kN); -100 % is the
    #: empty vehicle (no payload item).  Beyond +100 % the linear suspension and tyres are
    #: used far outside their design loads.
    OVERLOAD = 1.0

    @staticmethod
    def _item(vp):
        idx = [i for i, m in enumerate(vp.sprung) if m.payload]
        if not idx:
            raise EroadInputError(f"effect payload: vehicle {vp.id} has no payload item")
        return idx[0], vp.sprung[idx[0]]

    def vehicle_ranges(self, vp):
        out = super().vehicle_ranges(vp)
        if any(m.payload for m in vp.sprung):
            _, it = self._item(vp)
            lo, hi = -it.mass, self.OVERLOAD * it.mass
            out["mass"] = (max(lo, out["mass"][0]), min(hi, out["mass"][1]),
                           f"nominal payload '{it.name}' {it.mass:g} kg: from empty to "
                           f"{100 * self.OVERLOAD:g} % overload")
        return out

    def configure(self, ctx, p):
        vp = ctx.vp
        i, it = self._item(vp)
        self.check_vehicle(ctx.reference_vp, p)
        items = list(vp.sprung)
        m = it.mass + p["mass"]
        fr = vp.frame
        dx = min(max(p["dx"], fr.x_rear - it.x_rear), fr.x_front - it.x_front)
        if m > 0:
            items[i] = replace(it, mass=m, x_front=it.x_front + dx, x_rear=it.x_rear + dx,
                               y=it.y + p["dy"])
        else:       # the empty vehicle (mass = -P): the payload item is gone
            m = 0.0
            del items[i]
        ctx.vp = replace(vp, sprung=tuple(items))
        ctx.notes["payload_mass_kg"] = m
        if dx != p["dx"]:
            ctx.notes["payload_dx_clipped_m"] = dx
