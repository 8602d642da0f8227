"""The effect library: registry, parsing of ``NAME=VALUE`` switches, resolution.

Every module in this package except ``base`` defines one subclass of
:class:`vehicles.effects.base.Effect`; the registry imports the modules and collects
them, so adding an effect is adding one file.

>>> from vehicles.effects import EFFECTS, parse_effects
>>> sorted(EFFECTS)[:3]
['bump_stop', 'damper_asymmetry', 'frame_flex']
>>> parse_effects(["leaf_friction=3000", "bump_stop.gap=0.04"])
{'leaf_friction': {'force': 3000.0}, 'bump_stop': {'gap': 0.04}}
"""
from __future__ import annotations

import importlib
import inspect
import pkgutil

from eroad.errors import EroadInputError
from vehicles.effects.base import Effect, EffectContext, Parameter


def _discover() -> dict:
    found = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.name.startswith("_") or info.name == "base":
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if issubclass(cls, Effect) and cls is not Effect and cls.__module__ == module.__name__ \
                    and cls.name:
                if cls.name in found:
                    raise RuntimeError(f"effect name {cls.name!r} defined twice")
                found[cls.name] = cls()
    return dict(sorted(found.items()))


#: effect name -> Effect instance
EFFECTS: dict = _discover()


def any_nonlinear(effects) -> bool:
    """True if any of ``effects`` (names, or a ``{name: params}`` dict) is a library effect
    that makes the model nonlinear (``Effect.nonlinear``); names outside the library (the
    diagnosis's ``speed_scale``) do not count."""
    return any(EFFECTS[n].nonlinear for n in effects or () if n in EFFECTS)


def suspension_terms_of(effects: dict, ctx):
    """The ``suspension_terms`` hook of :func:`vehicles.builder.build_model` for the resolved
    ``effects`` ({name: params}): a function of one suspension that collects every effect's
    extra terms there, or None where no effect adds any (the builder's plain suspension)."""
    if not any(type(EFFECTS[n]).suspension_terms is not Effect.suspension_terms for n in effects):
        return None

    def terms_of(susp):
        out = []
        for n, p in effects.items():
            out += list(EFFECTS[n].suspension_terms(susp, p, ctx) or [])
        return out
    return terms_of


def get_effect(name: str) -> Effect:
    """The effect called ``name`` (EroadInputError naming the known ones otherwise)."""
    try:
        return EFFECTS[name]
    except KeyError:
        raise EroadInputError(f"unknown effect {name!r}; known: {', '.join(EFFECTS)}") from None


def parse_effects(items) -> dict:
    """Parse ``NAME``, ``NAME=VALUE`` and ``NAME.PARAM=VALUE`` strings.

    Parameters
    ----------
    items : iterable of str

    Returns
    -------
    dict
        ``{effect name: {parameter: value}}`` (values as floats; ``NAME`` alone
        switches the effect on with its defaults).

    Raises
    ------
    EroadInputError
        Unknown effect or parameter, or a value that is not a number.
    """
    out: dict = {}
    for item in items or ():
        text = str(item).strip()
        key, sep, value = text.partition("=")
        key = key.strip()
        name, dot, param = key.partition(".")
        eff = get_effect(name)
        entry = out.setdefault(name, {})
        if not sep:
            if dot:
                raise EroadInputError(f"--effect {text!r}: give a value, e.g. {key}=...")
            continue
        pname = param if dot else eff.primary
        eff.parameter(pname)
        try:
            entry[pname] = float(value)
        except ValueError:
            raise EroadInputError(f"--effect {text!r}: {value.strip()!r} is not a number") from None
    return out


def resolve_effects(effects) -> dict:
    """Full, validated parameters of the switched-on effects.

    Parameters
    ----------
    effects : dict or list or None
        ``{name: value | {param: value} | None}`` or a list of ``NAME=VALUE`` strings.

    Returns
    -------
    dict
        ``{name: {param: value for every parameter}}`` in application order.
    """
    if effects is None:
        return {}
    if isinstance(effects, (list, tuple)):
        effects = parse_effects(effects)
    if not isinstance(effects, dict):
        raise EroadInputError(f"effects must be a dict or a list of NAME=VALUE, got {type(effects).__name__}")
    resolved = {name: get_effect(name).resolve(values) for name, values in effects.items()}
    return dict(sorted(resolved.items(), key=lambda kv: (EFFECTS[kv[0]].order, kv[0])))


__all__ = ["EFFECTS", "Effect", "EffectContext", "Parameter", "get_effect", "parse_effects",
           "resolve_effects", "suspension_terms_of"]
