"""The named effect's value profiled on the inversion's own fit: the closed loop's second look.

What it is for: the diagnosis calibrates the effect it names on its own features with its own
cheap road fit; the closed loop (:mod:`diagnosis.closed_loop`) then inverts the drive with that
value. How far off the value may be, and what that costs the road, was measured on 20 fresh
friction drives (our truck with a leaf friction of 2000 N and a flexible frame; seeds 61-80,
results/inverse_blind/20261128-effect-profile/): the diagnosis's leaf-friction values ranged
1318-3065 N, and the same drives inverted with the true 2000 N put G(1 cycle/m) within 20 % in
many more segments than with the diagnosis's value (numbers in that folder's README). The
inversion's fit -- every segment's road fitted jointly with the effect's value held fixed --
uses far more of the drive than the diagnosis's calibration, and its objective was lowest near
the true value.

So the loop profiles the effect's primary parameter on that objective: the inversion is run
again at the value times and divided by :data:`STEP`; while the lowest objective sits at an end
of the values tried it steps on that way (at most :data:`MAX_STEPS` steps from the diagnosis's
value, so at most MAX_STEPS + 1 runs beyond the first; never outside the parameter's advertised
range); the run with the lowest objective is the loop's result. The segmentation and the fitted features do not depend on the vehicle model, so
the objectives of the runs compare like with like (checked: the runs' feature counts must agree).

What it is not: a calibration of the effect with its own uncertainty. The value is chosen on a
grid of ratio STEP (within a factor STEP**0.5 of the profile's minimum); the road intervals keep
the closed loop's model-form terms (inverse.uncertainty, 'diagnosed').

Effects profiled (:data:`PROFILED`): leaf friction's force, the one effect this was measured on.
Others are inverted at the diagnosis's value as before: a payload's mass is refined from the
static offset by the diagnosis already, a speed factor is calibrated to 1 % there (a step of 1.3
would be meaningless), and the rest (damper ratio, frame stiffness, bump-stop gap, sensor and
tyre terms) were not checked blind with a profile.
"""
from __future__ import annotations

import math
from typing import Callable

#: ratio between neighbouring values tried [-]: the diagnosis's leaf-friction grid steps by
#: about 1.17 and its values scattered over a factor 2.3 on the fresh friction drives; 1.3
#: reaches the scatter's ends in one or two steps and keeps a chosen value within a factor
#: 1.14 of the profile's minimum
STEP = 1.3
#: the farthest the profile goes from the diagnosis's value [steps of STEP]: two steps (a factor
#: 1.69) are about twice the diagnosis's scatter (rms 0.26 in ln of its leaf-friction values on the
#: fresh friction drives); a search let run to four steps ran away to 1000-1200 N on three of 17
#: drives (true 2000 N) and lost G(1) there
MAX_STEPS = 2


#: the effects whose value the loop profiles, and the parameter profiled
PROFILED = {"leaf_friction": "force"}


def profiled_parameter(effects: dict) -> tuple[str, str, float, tuple] | None:
    """``(effect, parameter, value, range)`` where the loop corrects with exactly one effect of
    :data:`PROFILED` at a positive value; None otherwise."""
    from vehicles.effects import EFFECTS

    if not effects or len(effects) != 1:
        return None
    (name, params), = effects.items()
    if name not in PROFILED:
        return None
    par = next(p for p in EFFECTS[name].parameters if p.name == PROFILED[name])
    value = float(params.get(par.name, par.default))
    if value <= 0.0:
        return None
    return name, par.name, value, tuple(float(x) for x in par.range)


def profile(objective_at: Callable[[float], float], value: float, bounds: tuple,
            step: float = STEP, max_steps: int = MAX_STEPS) -> dict:
    """Profile ``objective_at`` (the inversion's objective with the parameter at a value) around
    ``value``: its neighbours at ``value * step**(+-1)``, then further steps while the lowest
    objective is at an end of the values tried, within ``bounds`` and ``max_steps`` steps of
    ``value`` (at most ``max_steps + 2`` runs in all).

    Returns ``{"values": [...], "objectives": [...], "best": index}`` in the order evaluated
    (the first is ``value``)."""
    lo, hi = max(bounds[0], value / step ** max_steps), min(bounds[1], value * step ** max_steps)
    values, objs = [value], [objective_at(value)]

    def tried(v: float) -> bool:
        return any(abs(math.log(v / u)) < 1e-9 for u in values)

    def run(v: float) -> bool:
        v = min(max(v, lo), hi)
        if v <= 0.0 or tried(v):
            return False
        values.append(v)
        objs.append(objective_at(v))
        return True

    run(value / step)
    run(value * step)
    while True:
        best = min(range(len(values)), key=objs.__getitem__)
        v = values[best]
        if v == max(values):
            moved = run(v * step)
        elif v == min(values):
            moved = run(v / step)
        else:
            break
        if not moved:
            break
    return {"values": values, "objectives": objs, "best": min(range(len(values)), key=objs.__getitem__)}
