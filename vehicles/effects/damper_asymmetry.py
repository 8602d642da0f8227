"""Effect ``damper_asymmetry``: different damping in rebound and compression."""
from __future__ import annotations

from vehicles.effects.base import Effect, Parameter


class DamperAsymmetry(Effect):
    """Rebound/compression damping ratio with the mean damping kept."""

    name = "damper_asymmetry"
    description = (
        "Asymmetric dampers: rebound damping 'ratio' times the compression damping, their "
        "mean equal to the nominal damping (smooth switch over 'velocity').  With stronger "
        "rebound the suspension is pulled down on rough roads (mean compression grows, "
        "'jacking down') and the displacement distribution becomes skewed.")
    parameters = (
        Parameter("ratio", "-", 3.0, (0.2, 8.0), "rebound / compression damping"),
        Parameter("velocity", "m/s", 0.02, (1.0e-3, 0.5), "smoothing velocity of the switch"),
    )
    primary = "ratio"
    nonlinear = True

    def suspension_terms(self, susp, p, ctx):
        # the force of suspension_elements, as Exudyn's symbolic user function
        import exudyn

        esym = exudyn.symbolic
        return [(lambda u, v, dc=dc, v0=v0: dc * esym.tanh(v * (1.0 / v0)) * v)
                for _kind, (dc, v0) in self.suspension_elements(susp, p, ctx)]

    def suspension_elements(self, susp, p, ctx):
        if susp.damping == 0.0 or p["ratio"] == 1.0:
            return []
        r, c = p["ratio"], susp.damping
        dc = c * (1.0 - r) / (1.0 + r)   # c_comp = c + dc, c_reb = c - dc (v > 0: compression)
        return [("tanh_damper", (dc, float(p["velocity"])))]
