"""Effect ``leaf_friction``: Coulomb friction between the leaves of leaf springs."""
from __future__ import annotations

from vehicles.effects.base import Effect, Parameter


class LeafFriction(Effect):
    """Smoothed Coulomb friction in parallel with each leaf spring."""

    name = "leaf_friction"
    description = (
        "Inter-leaf Coulomb friction of leaf springs (axles with spring_type 'leaf'), a force "
        "F tanh(v / v0) against the compression velocity v in parallel with spring and damper. "
        "On smooth roads and at small amplitudes it locks the suspension, so the body follows "
        "the axles: body accelerations rise around 4-10 Hz (above body bounce, around axle "
        "hop) and suspension travel drops; at large amplitudes it acts as extra damping.")
    parameters = (
        Parameter("force", "N", 2000.0, (0.0, 20000.0),
                  "friction force of one leaf spring (per axle side)"),
        Parameter("velocity", "m/s", 0.01, (1.0e-3, 0.1),
                  "smoothing velocity v0 (76 % of the force at v = v0)"),
    )
    primary = "force"
    nonlinear = True

    def suspension_terms(self, susp, p, ctx):
        if susp.spring_type != "leaf" or p["force"] == 0.0:
            return []
        import exudyn

        esym = exudyn.symbolic
        F, v0 = p["force"], p["velocity"]
        return [lambda u, v: F * esym.tanh(v * (1.0 / v0))]
