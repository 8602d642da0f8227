"""Effect ``bump_stop``: elastic stops that limit the compression travel."""
from __future__ import annotations

from vehicles.effects.base import Effect, Parameter


class BumpStop(Effect):
    """A stiff spring that engages after a free compression travel."""

    name = "bump_stop"
    description = (
        "Bump stops: after a free compression travel 'gap' from static equilibrium a stiff "
        "spring engages (smoothed over 'smoothing').  Inactive on smooth roads; on rough "
        "roads it clips the compression peaks of the suspension displacement and produces "
        "impacts: body accelerations get heavier tails (higher kurtosis and peaks) and more "
        "high-frequency content.")
    parameters = (
        Parameter("gap", "m", 0.04, (0.005, 0.3),
                  "free compression travel from static equilibrium"),
        Parameter("stiffness", "N/m", 2.0e6, (1.0e4, 5.0e7), "contact stiffness"),
        Parameter("smoothing", "m", 0.002, (1.0e-4, 0.02), "width of the smooth transition"),
    )
    primary = "gap"
    nonlinear = True

    def suspension_terms(self, susp, p, ctx):
        import exudyn

        esym = exudyn.symbolic
        g, k, s = p["gap"], p["stiffness"], p["smoothing"]
        f0 = 0.5 * k * (-g + (g * g + s * s) ** 0.5)   # value at u = 0: keep statics exact

        def term(u, v):
            d = u - g
            return 0.5 * k * (d + esym.sqrt(d * d + s * s)) - f0
        return [term]
