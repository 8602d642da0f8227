"""Base class of the effect switches and the context they act on.

What it is for: an effect is a physical or measurement phenomenon that the nominal
model leaves out and that a user can switch on with parameters (a candidate of the
sim-to-real gap diagnosis and a knob of the virtual test drive).  Each effect is one
file in ``vehicles/effects/`` defining one subclass of :class:`Effect`; the registry
(:mod:`vehicles.effects`) finds it by itself.

Hooks (all optional; called by :func:`vehicles.simulate.simulate` in this order):

1. :meth:`Effect.configure` - change the vehicle parameters or the chassis settings
   in the :class:`EffectContext` before the model is built;
2. :meth:`Effect.road` - change the road the tyres see;
3. :meth:`Effect.suspension_terms` - extra suspension force terms (symbolic, run in
   C++ by Exudyn) per axle side;
4. :meth:`Effect.outputs` - change the sampled output channels (sensor dynamics,
   recorded speed).

What it is not: the list of effects (``vehicles.effects.EFFECTS``) or the parsing of
``NAME=VALUE`` strings (:func:`vehicles.effects.parse_effects`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from eroad.errors import EroadInputError


@dataclass(frozen=True)
class Parameter:
    """One effect parameter.

    Attributes
    ----------
    name : str
    unit : str
        SI unit (``"-"`` for dimensionless).
    default : float
        Value used when the effect is switched on without this parameter.
    range : (float, float)
        Sensible range; values outside are refused.
    doc : str
        One line: what it is.
    """

    name: str
    unit: str
    default: float
    range: tuple
    doc: str

    def check(self, value, effect: str) -> float:
        """Validate and return ``value`` as float (EroadInputError outside the range)."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise EroadInputError(f"effect {effect}: parameter {self.name} must be a number, "
                                  f"got {value!r}") from None
        lo, hi = self.range
        if not math.isfinite(v) or not lo <= v <= hi:
            raise EroadInputError(f"effect {effect}: {self.name} = {value!r} {self.unit} is outside "
                                  f"the sensible range [{lo:g}, {hi:g}]")
        return v

    def to_dict(self) -> dict:
        return {"name": self.name, "unit": self.unit, "default": self.default,
                "range": list(self.range), "doc": self.doc}


@dataclass
class EffectContext:
    """What effects may read and change during one simulation.

    Attributes
    ----------
    vp : VehicleParams
        Vehicle to build (effects may replace it, e.g. payload).
    reference_vp : VehicleParams
        Nominal vehicle whose static equilibrium on a flat road is the zero of the
        outputs (the sensors were zeroed on the nominal vehicle).
    chassis : str
        ``"rigid"`` or ``"flexible"``.
    stiffness_factor : float
        Frame stiffness scale.
    frame_segments : int or None
    fs_out : float
        Output sample rate [Hz].
    dt : float
        Time step [s].
    seed : int
        Root seed of the run.
    notes : dict
        Effects record what they did (copied to ``SimResult.meta["effect_notes"]``).
    """

    vp: object
    reference_vp: object
    chassis: str
    stiffness_factor: float = 1.0
    frame_segments: int | None = None
    fs_out: float = 200.0
    dt: float = 0.005
    seed: int = 0
    notes: dict = field(default_factory=dict)


class Effect:
    """An effect switch.  Subclasses set the class attributes and override hooks.

    Attributes
    ----------
    name : str
        Identifier used in ``--effect NAME=VALUE``.
    description : str
        What it does physically and where in the spectrum it acts.
    parameters : tuple of Parameter
    primary : str
        The parameter that ``NAME=VALUE`` sets.
    nonlinear : bool
        True if the effect makes the equations nonlinear (Newton iterations needed).
    order : int
        Application order (lower first).
    """

    name: str = ""
    description: str = ""
    parameters: tuple = ()
    primary: str = ""
    nonlinear: bool = False
    order: int = 50

    # ------------------------------------------------------------------ parameters
    def parameter(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise EroadInputError(f"effect {self.name} has no parameter {name!r}; it has "
                              f"{', '.join(p.name for p in self.parameters)}")

    def resolve(self, values=None) -> dict:
        """Full parameter dict from a value for the primary parameter, a partial dict
        or None (defaults); every value checked against its range.

        Raises
        ------
        EroadInputError
            Unknown parameter or value outside its sensible range.
        """
        if values is None:
            values = {}
        elif not isinstance(values, dict):
            values = {self.primary: values}
        out = {}
        for k in values:
            self.parameter(k)
        for p in self.parameters:
            out[p.name] = p.check(values.get(p.name, p.default), self.name)
        return out

    def vehicle_ranges(self, vp) -> dict:
        """Allowed range of every parameter on vehicle ``vp``.

        The ``range`` of a :class:`Parameter` is the same for every vehicle; an effect
        whose physical limits depend on the vehicle (payload: the payload can not be
        taken below zero) narrows it here.

        Returns
        -------
        dict
            ``{name: (lo, hi, why)}``; ``why`` says where a vehicle-specific limit
            comes from ("" for the plain parameter range).
        """
        return {p.name: (float(p.range[0]), float(p.range[1]), "") for p in self.parameters}

    def check_vehicle(self, vp, p: dict) -> None:
        """Refuse values outside :meth:`vehicle_ranges` on vehicle ``vp``.

        Raises
        ------
        EroadInputError
            One line naming the value, the vehicle and its allowed range.
        """
        for name, (lo, hi, why) in self.vehicle_ranges(vp).items():
            v = p[name]
            if not lo <= v <= hi:
                unit = self.parameter(name).unit
                raise EroadInputError(
                    f"effect {self.name}: {name} = {v:g} {unit} is outside the range for vehicle "
                    f"{vp.id}: [{lo:g}, {hi:g}] {unit}" + (f" ({why})" if why else ""))

    @property
    def acts_on_vehicle(self) -> bool:
        """Whether the effect changes the vehicle itself and nothing else: it overrides
        :meth:`configure` or :meth:`suspension_terms` and neither :meth:`road` nor
        :meth:`outputs`. An effect on the road the tyres see (tyre enveloping) or on the
        recorded channels (a sensor low-pass, a speed scale) acts where the road model's own
        parameters (level, waviness, band edges) act too, so a fit can trade one for the
        other; one on the suspension or the masses cannot be mimicked by the road's
        spectrum alone (used by :func:`diagnosis.closed_loop.effects_from_diagnosis`)."""
        cls = type(self)
        def own(hook):
            return getattr(cls, hook) is not getattr(Effect, hook)
        return (own("configure") or own("suspension_terms")) and not (own("road") or own("outputs"))

    def to_dict(self) -> dict:
        """JSON description (``eroad effects --json``)."""
        return {"name": self.name, "description": self.description, "primary": self.primary,
                "nonlinear": self.nonlinear,
                "parameters": [p.to_dict() for p in self.parameters]}

    # ------------------------------------------------------------------ hooks
    def configure(self, ctx: EffectContext, p: dict) -> None:
        """Change vehicle parameters or chassis settings before the build."""

    def road(self, road, p: dict, ctx: EffectContext):
        """Return the road the tyres see (default: unchanged)."""
        return road

    def suspension_terms(self, susp, p: dict, ctx: EffectContext) -> list:
        """Extra suspension force terms for one axle side.

        Parameters
        ----------
        susp : vehicles.builder.Suspension
        p : dict
        ctx : EffectContext

        Returns
        -------
        list of callables ``term(u, v)``
            Force [N] pushing axle and frame apart as a function of the dynamic
            compression ``u`` [m] and compression velocity ``v`` [m/s]; built from
            ``exudyn.symbolic`` functions (``esym.tanh``, ``esym.sqrt``, ...) so that
            it runs in C++.
        """
        return []

    def suspension_elements(self, susp, p: dict, ctx: EffectContext) -> list | None:
        """The same forces as :meth:`suspension_terms`, as element kinds of
        :mod:`vehicles.suspension_forces` (``[(kind, params), ...]``), so that the linear
        integrator can step them (``simulate(solver="linear")``); None (the default): not
        expressible there, the drive runs in Exudyn."""
        return None

    def outputs(self, time, channels: dict, p: dict, ctx: EffectContext) -> None:
        """Change sampled channels in place (sensor effects)."""
