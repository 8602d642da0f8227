"""Effect ``bump_stop``: elastic stops that limit the compression travel."""
from __future__ import annotations

import math

from vehicles.effects.base import Effect, Parameter


class BumpStop(Effect):
    """A stiff spring that engages after a free compression travel."""

    name = "bump_stop"
    description = (
        "Bump stops: after a free compression travel 'gap' from static equilibrium a stiff "
        "spring engages (a softplus of width 'smoothing').  Inactive on smooth roads; on rough "
        "roads it clips the compression peaks of the suspension displacement and produces "
        "impacts: body accelerations get heavier tails (higher kurtosis and peaks) and more "
        "high-frequency content.")
    parameters = (
        Parameter("gap", "m", 0.04, (0.0, 0.3),
                  "free compression travel from static equilibrium"),
        Parameter("stiffness", "N/m", 2.0e6, (1.0e4, 5.0e7), "contact stiffness"),
        Parameter("smoothing", "m", 0.002, (1.0e-4, 0.02),
                  "width of the smooth transition (softplus scale)"),
    )
    primary = "gap"
    nonlinear = True

    def suspension_terms(self, susp, p, ctx):
        import exudyn

        esym = exudyn.symbolic
        g, k, s = p["gap"], p["stiffness"], p["smoothing"]
        # k s softplus((u - g) / s): k (u - g) beyond the gap, exponentially small
        # before it (k s e^(-g/s) at static equilibrium, subtracted to keep statics exact)
        f0 = k * s * math.log1p(math.exp(-g / s))

        def term(u, v):
            x = (u - g) * (1.0 / s)
            return k * s * (esym.max(x, 0.0) + esym.log(1.0 + esym.exp(-esym.abs(x)))) - f0
        return [term]

    def suspension_elements(self, susp, p, ctx):
        return [("softplus", (float(p["stiffness"]), float(p["gap"]), float(p["smoothing"])))]
