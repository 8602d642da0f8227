"""Effect ``leaf_friction``: Coulomb friction between the leaves of leaf springs."""
from __future__ import annotations

from vehicles.effects.base import Effect, Parameter

#: largest friction force per leaf spring [N].  Inter-leaf Coulomb friction of multi-leaf
#: truck springs is usually quoted at roughly 5-20 % of the static spring load, more for
#: dry or corroded many-leaf packs (e.g. Fancher et al. 1980, SAE 800905; Cebon 1999,
#: Handbook of Vehicle-Road Interaction; order of magnitude, not re-derived here).  The
#: built-in vehicles' leaf springs carry 23-42 kN statically per side, so 12 kN is 28-52 %
#: of it: above the worst quoted values with a margin, and the diagnosis's search range
#: (diagnosis.pipeline.SEARCH) ends there.  The simulator itself copes further (16.4 kN
#: runs with one step halving), so the limit is physical, not numerical.
FORCE_MAX = 12000.0
#: smallest smoothing velocity [m/s].  While stuck, F tanh(v / v0) acts as a damper F / v0:
#: at 12 kN and 5 mm/s that is 2.4e6 N s/m, 200 times the axle dampers, so the spring is
#: locked (creep below v0) as Coulomb friction would lock it.  Smaller v0 only stiffens
#: Newton's problem: the slope F / v0 outweighs the axle's inertia m / (gamma dt) and the
#: iterations jump between stick and slip.  Measured (benchmarks/effect_ranges.py and
#: tests/test_effect_ranges.py): 12 kN with v0 = 5 mm/s needs at most two of the
#: simulator's three step halvings (vehicles.simulate.MAX_DT_HALVINGS) on class B to E
#: roads (both vehicles); 1 mm/s failed even at a quarter of the step.
VELOCITY_MIN = 0.005


class LeafFriction(Effect):
    """Smoothed Coulomb friction in parallel with each leaf spring."""

    name = "leaf_friction"
    description = (
        "Inter-leaf Coulomb friction of leaf springs (axles with spring_type 'leaf'), a force "
        "F tanh(v / v0) against the compression velocity v in parallel with spring and damper. "
        "On smooth roads and at small amplitudes it locks the suspension, so the body follows "
        "the axles: body accelerations rise around 4-10 Hz (above body bounce, around axle "
        "hop) and suspension travel drops; at large amplitudes it acts as extra damping.  "
        "Force up to 12 kN (28-52 % of the built-in vehicles' static leaf-spring loads, above "
        "the 5-20 % usually quoted for multi-leaf springs), v0 from 5 mm/s (stiffer "
        "regularisation adds nothing physical and stops Newton from converging).")
    parameters = (
        Parameter("force", "N", 2000.0, (0.0, FORCE_MAX),
                  "friction force of one leaf spring (per axle side)"),
        Parameter("velocity", "m/s", 0.01, (VELOCITY_MIN, 0.1),
                  "smoothing velocity v0 (76 % of the force at v = v0)"),
    )
    primary = "force"
    nonlinear = True

    def suspension_terms(self, susp, p, ctx):
        # the force of suspension_elements, as Exudyn's symbolic user function
        import exudyn

        esym = exudyn.symbolic
        return [(lambda u, v, F=F, v0=v0: F * esym.tanh(v * (1.0 / v0)))
                for _kind, (F, v0) in self.suspension_elements(susp, p, ctx)]

    def suspension_elements(self, susp, p, ctx):
        if susp.spring_type != "leaf" or p["force"] == 0.0:
            return []
        return [("tanh_force", (float(p["force"]), float(p["velocity"])))]
