"""Plausibility of a vehicle file against heavy-truck engineering ranges (``eroad vehicle check``).

What it is for: a vehicle TOML that loads (the loader, :mod:`vehicles.params`, already
refuses missing fields, wrong types and non-positive stiffnesses or masses) can still be
physically wrong: a spring entered in kN/m instead of N/m is 1000x too soft and runs
without a word. This module computes what such a slip changes and compares it with
the ranges of real heavy trucks; it warns (exit 0) and never refuses.

What it computes, per axle (left and right are taken as equal: the sprung items lie on
the centre line or their lateral offsets are small; roll is not considered):

* **Static loads.** The sprung mass (the ``[[mass]]`` items at their box centres and the
  DCDC block at its ``x``) is a rigid beam in bounce z and pitch theta on one support per
  axle, the axle's two springs (2 k_s) in series with its tyres (2 n k_t):
  sum k_i (z + theta x_i) = W and sum k_i x_i (z + theta x_i) = W x_cg. The axle's
  spring load is k_i (z + theta x_i); the tyres carry it plus the unsprung weight.
  This is the rigid model's static equilibrium (``tests/test_vehicle_check.py`` compares
  it with the Exudyn static solution: within 1 %). g = 9.81 m/s^2, as in the model.
* **Static deflections.** Spring: load per side / k_s. Tyre: (load per side + unsprung
  weight per side) / (n k_t) for the n tyres of a side.
* **Quarter car per side.** Sprung mass m_s = spring load per side / g, unsprung m_u =
  half the axle's unsprung mass, spring k_s and damper c_s, tyres n k_t and n c_t. The
  undamped 2-DOF natural frequencies are the body bounce (lower) and the axle hop (upper)
  [Hz]; the damping ratio of each mode is phi^T C phi / (2 omega phi^T M phi) over its
  undamped mode shape phi (classical modal damping). The suspension damping ratio
  zeta_s = c_s / (2 sqrt(k_s m_s)) is the textbook quarter-car value the ranges refer to.

Ranges (heavy trucks, laden or unladen; engineering ranges, not limits of a standard):

* body bounce 1.0-3.0 Hz and axle hop 8-15 Hz: the frequencies that heavy-vehicle
  ride and road-loading studies report (Cebon, *Handbook of Vehicle-Road Interaction*,
  1999, ch. 4-5: sprung mass modes about 1.5-4 Hz, unsprung about 8-15 Hz; Gillespie,
  *Fundamentals of Vehicle Dynamics*, 1992, ch. 5: ride frequencies of trucks above those
  of cars, axle hop 10-12 Hz typical). We take 1-3 Hz for the quarter car (its sprung
  mass carries no pitch coupling), an engineering choice.
* suspension damping ratio 0.1-0.5 (air springs, or any axle with dampers), 0.05-0.5 for
  leaf springs: cars are tuned to 0.2-0.4 (Gillespie ch. 5); below 0.1 the body bounce
  rings, above 0.5 the ride is harsh (engineering range). Leaf-sprung tandem bogies often
  have no dampers at all and are damped by inter-leaf friction, whose equivalent viscous
  ratio is about 0.05-0.15 (the built-in tipper's bogie: 0.09, docs/vehicles.md; its
  Coulomb part is the ``leaf_friction`` effect), hence the lower bound 0.05 for them.
* static spring deflection 0.02-0.25 m: the deflection g / (2 pi f)^2 of a linear spring
  with its bounce frequency f between 3 and 1 Hz (the same physics as the bounce range,
  stated as a length a user can picture: leaf springs of laden trucks sag 5-15 cm).
* static tyre deflection 0.01-0.06 m: truck tyres have vertical stiffnesses of about
  0.8-1.2 MN/m and carry 20-40 kN each at their rated load (ETRTO/TRA load tables for
  315/80R22.5 and 12.00R20 tyres), a deflection of 2-5 cm; wider for margin.

The checks are per axle and independent of the model: they read parameters only.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import re
from pathlib import Path

import numpy as np

from eroad.errors import EroadInputError
from vehicles.params import (DCDC, Axle, Frame, MassItem, Solver, VehicleParams,
                             load_vehicle, vehicle_path)

#: gravity used by the model (vehicles.builder.GRAVITY) [m/s^2]
GRAVITY = 9.81

#: quantity -> (low, high, unit, label): the heavy-truck ranges (see the module docstring)
RANGES = {
    "body_bounce_hz": (1.0, 3.0, "Hz", "body bounce"),
    "axle_hop_hz": (8.0, 15.0, "Hz", "axle hop"),
    "suspension_damping_ratio": (0.1, 0.5, "-", "suspension damping ratio"),
    "suspension_damping_ratio_leaf": (0.05, 0.5, "-", "suspension damping ratio, leaf springs"),
    "spring_deflection_m": (0.02, 0.25, "m", "static spring deflection"),
    "tyre_deflection_m": (0.01, 0.06, "m", "static tyre deflection"),
}
#: where the ranges come from (printed with --json)
RANGE_SOURCES = ("engineering ranges for heavy trucks; frequencies as reported by Cebon, "
                 "Handbook of Vehicle-Road Interaction (1999) and Gillespie, Fundamentals of "
                 "Vehicle Dynamics (1992); see vehicles/check.py")
#: a value this far outside its range (factor) is called 'far' outside
FAR_FACTOR = 3.0


# --------------------------------------------------------------------------- statics and modes

def _beam_loads(vp: VehicleParams, k: np.ndarray) -> np.ndarray:
    """Support loads [N] of the rigid sprung mass on one support of stiffness k_i per axle."""
    items = [(it.mass, 0.5 * (it.x_front + it.x_rear)) for it in vp.sprung]
    if vp.dcdc is not None:
        items.append((vp.dcdc.mass, vp.dcdc.x))
    m = sum(mi for mi, _ in items)
    xcg = sum(mi * xi for mi, xi in items) / m
    w = m * GRAVITY
    x = np.array([a.x for a in vp.axles])
    a_mat = np.array([[k.sum(), (k * x).sum()], [(k * x).sum(), (k * x * x).sum()]])
    z, th = np.linalg.solve(a_mat, [w, w * xcg])
    return k * (z + th * x)


def static_axle_loads(vp: VehicleParams) -> np.ndarray:
    """Static spring load of each axle (both sides together) [N].

    Rigid sprung mass in bounce and pitch on one support per axle (springs in series
    with tyres). Negative: the axle would have to pull the body down (centre of gravity
    outside the axles).
    """
    ks = np.array([2.0 * a.spring_stiffness for a in vp.axles])
    kt = np.array([2.0 * a.tyres_per_side * a.tyre_stiffness for a in vp.axles])
    return _beam_loads(vp, ks * kt / (ks + kt))


def equal_share_loads(vp: VehicleParams) -> np.ndarray:
    """Each axle's share of the sprung weight were all axles equally stiff [N].

    The reference a spring is judged against: it depends on where the masses and axles
    are, not on the springs (with two axles it is the lever rule). The actual loads
    (:func:`static_axle_loads`) follow the springs: a spring 1000x too soft carries
    almost nothing, and its neighbours carry its share.
    """
    return _beam_loads(vp, np.ones(vp.n_axles))


def quarter_car(m_s: float, m_u: float, k_s: float, c_s: float, k_t: float, c_t: float) -> dict:
    """Undamped natural frequencies and modal damping ratios of a 2-DOF quarter car.

    Parameters
    ----------
    m_s, m_u : float
        Sprung and unsprung mass [kg] (m_s > 0).
    k_s, c_s : float
        Suspension stiffness [N/m] and damping [N s/m].
    k_t, c_t : float
        Tyre stiffness [N/m] and damping [N s/m].

    Returns
    -------
    dict
        body_bounce_hz, axle_hop_hz, body_damping_ratio, hop_damping_ratio (modal,
        over the undamped mode shapes), suspension_damping_ratio (c_s / 2 sqrt(k_s m_s)).
    """
    mm = np.diag([m_s, m_u])
    kk = np.array([[k_s, -k_s], [-k_s, k_s + k_t]])
    cc = np.array([[c_s, -c_s], [-c_s, c_s + c_t]])
    # symmetric form: M^-1/2 K M^-1/2
    s = np.diag(1.0 / np.sqrt([m_s, m_u]))
    w2, v = np.linalg.eigh(s @ kk @ s)
    phi = s @ v
    out = {}
    for key, j in (("body", 0), ("hop", 1)):
        om = math.sqrt(max(w2[j], 0.0))
        p = phi[:, j]
        zeta = float(p @ cc @ p / (2.0 * om * (p @ mm @ p))) if om > 0 else math.inf
        out[key] = (om / (2 * math.pi), zeta)
    return {"body_bounce_hz": out["body"][0], "axle_hop_hz": out["hop"][0],
            "body_damping_ratio": out["body"][1], "hop_damping_ratio": out["hop"][1],
            "suspension_damping_ratio": c_s / (2.0 * math.sqrt(k_s * m_s))}


def axle_table(vp: VehicleParams) -> list[dict]:
    """Per axle: loads, masses, deflections, frequencies and damping ratios (SI units)."""
    loads = static_axle_loads(vp)
    shares = equal_share_loads(vp)
    rows = []
    for i, (a, f, sh) in enumerate(zip(vp.axles, loads, shares)):
        f_side = f / 2.0
        m_s = f_side / GRAVITY
        m_u = a.unsprung_mass / 2.0
        kt = a.tyres_per_side * a.tyre_stiffness
        row = {
            "axle": i + 1, "x_m": a.x, "spring_type": a.spring_type,
            "tyres_per_side": a.tyres_per_side,
            "spring_load_kN": f / 1000.0,
            "equal_share_kN": sh / 1000.0,
            "axle_load_kN": (f + a.unsprung_mass * GRAVITY) / 1000.0,
            "sprung_mass_per_side_kg": m_s, "unsprung_mass_per_side_kg": m_u,
            "spring_stiffness_Npm": a.spring_stiffness, "damping_Nspm": a.damping,
            "tyre_stiffness_Npm": a.tyre_stiffness,
            "spring_deflection_m": f_side / a.spring_stiffness,
            "tyre_deflection_m": (f_side + m_u * GRAVITY) / kt,
        }
        if m_s > 0:
            row.update(quarter_car(m_s, m_u, a.spring_stiffness, a.damping, kt,
                                   a.tyres_per_side * a.tyre_damping))
        else:
            row.update({k: None for k in ("body_bounce_hz", "axle_hop_hz", "body_damping_ratio",
                                          "hop_damping_ratio", "suspension_damping_ratio")})
        rows.append(row)
    return rows


# --------------------------------------------------------------------------- warnings

def _fmt(v: float, unit: str) -> str:
    if unit == "m":
        return f"{v * 1000:.3g} mm" if abs(v) < 1 else f"{v:.3g} m"
    return f"{v:.3g}" + ("" if unit == "-" else f" {unit}")


def _outside(v: float, lo: float, hi: float) -> float:
    """1 inside [lo, hi]; else the factor by which v lies outside (> 1)."""
    if lo <= v <= hi:
        return 1.0
    return lo / v if v < lo else v / hi


def _warn(axle: int, quantity: str, value: float, message: str) -> dict:
    lo, hi, unit, _ = RANGES.get(quantity, (None, None, "", ""))
    return {"axle": axle, "quantity": quantity, "value": value,
            "range": None if lo is None else [lo, hi], "unit": unit, "message": message}


def check_vehicle(vp: VehicleParams) -> dict:
    """Every axle's statics and quarter-car modes, and the warnings against :data:`RANGES`.

    Parameters
    ----------
    vp : VehicleParams

    Returns
    -------
    dict
        vehicle, name, source, masses, axles (:func:`axle_table`), ranges, warnings (each
        with axle, quantity, value, range, unit and a one-line message naming the numbers
        and the parameter most likely wrong).
    """
    rows = axle_table(vp)
    warnings = []
    for r in rows:
        i = r["axle"]
        w = f"axle {i}"
        if r["spring_load_kN"] <= 0:
            warnings.append(_warn(i, "spring_load_kN", r["spring_load_kN"],
                                  f"{w}: static spring load {r['spring_load_kN']:.3g} kN: the axle "
                                  "carries no body weight (centre of gravity behind or ahead "
                                  "of the axles? check the [[mass]] x positions)"))
            continue
        m_s = r["sprung_mass_per_side_kg"]
        k = r["spring_stiffness_Npm"]
        # the spring, judged against the axle's equal-stiffness share of the body (the
        # actual load follows the springs: a far too soft spring sheds its load)
        m_sh = r["equal_share_kN"] * 1000.0 / 2.0 / GRAVITY
        spring_far = False
        if m_sh > 0:
            qc = quarter_car(m_sh, r["unsprung_mass_per_side_kg"], k, r["damping_Nspm"],
                             r["tyres_per_side"] * r["tyre_stiffness_Npm"], 0.0)
            lo, hi = RANGES["body_bounce_hz"][:2]
            f_b = qc["body_bounce_hz"]
            k_tyres = r["tyres_per_side"] * r["tyre_stiffness_Npm"]
            tyre_limits = f_b < lo and m_sh * (2 * math.pi * lo) ** 2 >= k_tyres
            if not lo <= f_b <= hi and not tyre_limits:   # (a too soft tyre: judged below)
                soft = f_b < lo
                # the spring that, in series with the tyres, gives the range's end
                k_e = m_sh * (2 * math.pi * (lo if soft else hi)) ** 2
                k_t = r["tyres_per_side"] * r["tyre_stiffness_Npm"]
                k_ref = k_e * k_t / (k_t - k_e) if k_e < k_t else math.inf
                factor = k_ref / k if soft else k / k_ref
                spring_far = factor >= FAR_FACTOR
                verdict = ("far too soft" if soft else "far too stiff") if spring_far else (
                    "soft" if soft else "stiff")
                slip = ""
                if factor >= 100:
                    slip = (" (a unit slip? kN/m or N/mm entered as N/m makes a spring 1000x "
                            "too soft)" if soft else " (a unit slip? N/m entered where kN/m "
                            "was meant makes a spring 1000x too stiff)")
                shed = ""
                if r["spring_load_kN"] < 0.5 * r["equal_share_kN"]:
                    shed = (f"; so it carries {r['spring_load_kN']:.3g} kN of its "
                            f"{r['equal_share_kN']:.3g} kN share and the other axles the rest")
                warnings.append(_warn(
                    i, "body_bounce_hz", f_b,
                    f"{w}: spring_stiffness = {k:.3g} N/m is {verdict}: "
                    f"{factor:.3g}x {'softer' if soft else 'stiffer'} than the {k_ref:.3g} N/m "
                    f"that gives {lo if soft else hi:g} Hz body bounce (heavy trucks {lo:g}-{hi:g} "
                    f"Hz) for this axle's share of the body ({m_sh:.0f} kg per side); with it "
                    f"the body bounces at {f_b:.3g} Hz and sags "
                    f"{_fmt(m_sh * GRAVITY / k, 'm')} under that share{slip}{shed}"))
        f_def = _outside(r["spring_deflection_m"], *RANGES["spring_deflection_m"][:2])
        if f_def > 1 and not spring_far:
            warnings.append(_warn(
                i, "spring_deflection_m", r["spring_deflection_m"],
                f"{w}: static spring deflection {_fmt(r['spring_deflection_m'], 'm')} under "
                f"{r['spring_load_kN'] / 2:.3g} kN per side is outside 20-250 mm (heavy trucks): "
                f"spring_stiffness = {k:.3g} N/m"))
        ratio = r["spring_load_kN"] / r["equal_share_kN"] if r["equal_share_kN"] > 0 else 1.0
        if not spring_far and not 0.5 <= ratio <= 2.0:
            warnings.append(_warn(
                i, "spring_load_kN", r["spring_load_kN"],
                f"{w}: carries {r['spring_load_kN']:.3g} kN on its springs, {ratio:.2g}x its "
                f"share with equally stiff axles ({r['equal_share_kN']:.3g} kN): its springs are "
                f"{'much stiffer' if ratio > 1 else 'much softer'} than the other axles' "
                "(or a spring or tyre is off; see the other warnings)"))
        # the tyre
        f_ty = _outside(r["tyre_deflection_m"], *RANGES["tyre_deflection_m"][:2])
        # with a spring far off, the tyre load and the hop follow from it: not repeated
        if f_ty > 1 and not (spring_far and f_ty < FAR_FACTOR):
            soft = r["tyre_deflection_m"] > RANGES["tyre_deflection_m"][1]
            verdict = ("far too soft" if soft else "far too stiff") if f_ty >= FAR_FACTOR else (
                "soft" if soft else "stiff")
            load = r["tyre_deflection_m"] * r["tyre_stiffness_Npm"] / 1000
            if f_ty >= FAR_FACTOR:
                msg = (f"{w}: tyre_stiffness = {r['tyre_stiffness_Npm']:.3g} N/m per tyre is "
                       f"{verdict}: static tyre deflection {_fmt(r['tyre_deflection_m'], 'm')} "
                       f"under {load:.3g} kN per tyre (heavy-truck tyres 10-60 mm; their "
                       "stiffness is about 0.8-1.2e6 N/m)")
            else:
                msg = (f"{w}: static tyre deflection {_fmt(r['tyre_deflection_m'], 'm')} under "
                       f"{load:.3g} kN per tyre is outside 10-60 mm (heavy trucks): "
                       f"tyre_stiffness = {r['tyre_stiffness_Npm']:.3g} N/m per tyre (truck "
                       "tyres about 0.8-1.2e6 N/m), or the load on this axle")
            warnings.append(_warn(i, "tyre_deflection_m", r["tyre_deflection_m"], msg))
        # the axle hop (tyre and unsprung mass)
        f_hop = _outside(r["axle_hop_hz"], *RANGES["axle_hop_hz"][:2])
        if f_hop > 1 and not spring_far:
            warnings.append(_warn(
                i, "axle_hop_hz", r["axle_hop_hz"],
                f"{w}: axle hop {r['axle_hop_hz']:.3g} Hz is outside 8-15 Hz (heavy trucks): "
                f"unsprung_mass = {2 * r['unsprung_mass_per_side_kg']:.4g} kg, tyre_stiffness "
                f"= {r['tyre_stiffness_Npm']:.3g} N/m x {r['tyres_per_side']} per side, spring "
                f"{k:.3g} N/m (the hop frequency rises with tyre and spring stiffness and falls "
                "with the axle's mass)"))
        # the damper
        z = r["suspension_damping_ratio"]
        zkey = "suspension_damping_ratio" + ("_leaf" if r["spring_type"] == "leaf" else "")
        z_lo, z_hi = RANGES[zkey][:2]
        f_z = _outside(z, z_lo, z_hi)
        if f_z > 1 and not spring_far:
            low = z < z_lo
            verdict = ("far too low" if low else "far too high") if f_z >= FAR_FACTOR else (
                "low" if low else "high")
            c_mid = 2 * 0.25 * math.sqrt(k * m_s)
            warnings.append(_warn(
                i, "suspension_damping_ratio", z,
                f"{w}: damping = {r['damping_Nspm']:.3g} N s/m per side gives a suspension "
                f"damping ratio of {z:.3g}, {verdict} (heavy trucks {z_lo:g}-{z_hi:g} with "
                f"{r['spring_type']} springs; 0.25 would be {c_mid:.3g} N s/m with this spring "
                "and load)"))
    total = vp.total_mass
    return {
        "vehicle": vp.id, "name": vp.name, "source": vp.source,
        "total_mass_kg": total,
        "sprung_mass_kg": total - sum(a.unsprung_mass for a in vp.axles),
        "gravity_mps2": GRAVITY,
        "axles": rows,
        "ranges": {k: {"low": lo, "high": hi, "unit": u, "what": lab}
                   for k, (lo, hi, u, lab) in RANGES.items()},
        "ranges_source": RANGE_SOURCES,
        "warnings": warnings,
    }


def format_check(rep: dict) -> str:
    """The human-readable report of :func:`check_vehicle`."""
    lines = [f"vehicle   {rep['name']} ({rep['vehicle']})" +
             (f", from {rep['source']}" if rep["source"] else ""),
             f"mass      total {rep['total_mass_kg']:.0f} kg, sprung {rep['sprung_mass_kg']:.0f} kg",
             "",
             "axle  axle load  sprung/side  spring defl.  tyre defl.  body bounce  axle hop  "
             "zeta_s  zeta_hop",
             "      [kN]       [kg]         [mm]          [mm]        [Hz]         [Hz]      "
             "[-]     [-]"]

    def num(v, f):
        return "-" if v is None else format(v, f)

    for r in rep["axles"]:
        lines.append(f"{r['axle']:<5d} {r['axle_load_kN']:<10.1f} "
                     f"{r['sprung_mass_per_side_kg']:<12.0f} "
                     f"{r['spring_deflection_m'] * 1000:<13.1f} {r['tyre_deflection_m'] * 1000:<11.1f} "
                     f"{num(r['body_bounce_hz'], '<12.2f')} {num(r['axle_hop_hz'], '<9.1f')} "
                     f"{num(r['suspension_damping_ratio'], '<7.2f')} "
                     f"{num(r['hop_damping_ratio'], '.2f')}")
    lines.append("")
    lines.append("ranges    body bounce 1-3 Hz, axle hop 8-15 Hz, zeta_s 0.1-0.5 (leaf springs "
                 "0.05-0.5), spring deflection 20-250 mm, tyre deflection 10-60 mm")
    lines.append("          (heavy trucks, engineering ranges; per side of each axle as a "
                 "quarter car; see vehicles/check.py)")
    for w in rep["warnings"]:
        lines.append(f"warning   {w['message']}")
    n = len(rep["warnings"])
    lines.append(f"result    {n} warning(s)" if n else
                 "result    no warnings: every axle within the heavy-truck ranges")
    return "\n".join(lines)


# --------------------------------------------------------------------------- the template

_CLASSES = {"vehicle": None, "frame": Frame, "solver": Solver, "dcdc": DCDC, "axle": Axle,
            "mass": MassItem}
_VEHICLE_DOCS = {"id": "identifier (shown in reports)", "name": "human-readable name",
                 "description": "what the vehicle is and its layout"}


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        for digits in range(1, 18):        # the shortest text that reads back exactly
            text = f"{v:.{digits}g}"
            if float(text) == v:
                break
        else:  # pragma: no cover
            text = repr(v)
        return text if any(c in text for c in ".einf") else text + ".0"
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    raise TypeError(f"cannot write {v!r}")  # pragma: no cover


def _table_lines(cls, values: dict) -> list[str]:
    rows = []
    for f in dataclasses.fields(cls):
        rows.append((f"{f.name} = {_toml_value(values[f.name])}",
                     f"[{f.metadata['unit']}] {f.metadata['doc']}"))
    width = max(len(a) for a, _ in rows)
    return [f"{a:<{width}}  # {b}" for a, b in rows]


def vehicle_template(source, new_id: str) -> str:
    """A commented TOML copy of a vehicle: every field with its unit and meaning.

    Parameters
    ----------
    source : str or Path
        Built-in id or vehicle file to copy.
    new_id : str
        The copy's ``id``.

    Returns
    -------
    str
        TOML text that :func:`vehicles.params.load_vehicle` reads back to the same
        vehicle (but for ``id``).
    """
    path = vehicle_path(source)
    vp = load_vehicle(path)
    orig = [ln for ln in path.read_text(encoding="utf-8").splitlines()
            if ln.startswith("#")]
    out = [
        f"# Vehicle parameters for eroad: a copy of '{vp.id}' made by `eroad vehicle new`.",
        "#",
        "# Edit the values (SI units; each field says its unit and meaning), then check them",
        "# against heavy-truck ranges (static deflections, natural frequencies, damping):",
        f"#     eroad vehicle check {new_id}.toml",
        "# and use the file wherever a vehicle is asked for, for example",
        f"#     eroad simulate --vehicle {new_id}.toml --road road.npz --speed 10 --duration 15 --out drive1",
        f"#     eroad data import logger.csv --map map.toml --out my-drive --vehicle {new_id}.toml",
        "# Every field is required; add or remove [[axle]] and [[mass]] blocks as your vehicle",
        "# has them (axles front to rear, x = 0 at the first axle, negative behind it).",
        "# docs/vehicles.md gives the source of each value of the built-in vehicles.",
    ]
    if orig:
        out += ["#", f"# The notes of {path.name}:"] + orig
    doc = {"id": new_id, "name": vp.name, "description": vp.description}
    out += ["", "[vehicle]"]
    for k, v in doc.items():
        out += [f"# {_VEHICLE_DOCS[k]}", f"{k} = {_toml_value(v)}"]
    out += ["", "[frame]"] + _table_lines(Frame, dataclasses.asdict(vp.frame))
    out += ["", "[solver]"] + _table_lines(Solver, dataclasses.asdict(vp.solver))
    if vp.dcdc is not None:
        out += ["", "[dcdc]"] + _table_lines(DCDC, dataclasses.asdict(vp.dcdc))
    for i, a in enumerate(vp.axles):
        out += ["", f"[[axle]]  # axle {i + 1}"] + _table_lines(Axle, dataclasses.asdict(a))
    for m in vp.sprung:
        out += ["", "[[mass]]"] + _table_lines(MassItem, dataclasses.asdict(m))
    return "\n".join(out) + "\n"


def new_vehicle_file(source, out) -> Path:
    """Write :func:`vehicle_template` of ``source`` to ``out``; refuse an existing file.

    Raises
    ------
    EroadInputError
        ``out`` exists, its folder does not, or it is not a ``.toml`` name.
    """
    out = Path(out)
    if out.suffix.lower() != ".toml":
        raise EroadInputError(f"{out}: the vehicle file name must end in .toml")
    if out.exists():
        raise EroadInputError(f"{out}: exists; refusing to overwrite it (choose another name)")
    if not out.parent.is_dir():
        raise EroadInputError(f"{out.parent}: no such folder for --out")
    new_id = re.sub(r"[^A-Za-z0-9_.-]", "_", out.stem) or "my_vehicle"
    text = vehicle_template(source, new_id)
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.link(tmp, out)            # fails if out appeared meanwhile: never overwrites
    except FileExistsError:
        raise EroadInputError(f"{out}: exists; refusing to overwrite it") from None
    finally:
        if tmp.exists():
            tmp.unlink()
    return out
