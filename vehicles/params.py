"""Vehicle parameters: TOML files in ``vehicles/params/`` loaded into frozen dataclasses.

What it is for: the one description of a vehicle that the model builder, the
modal analysis, the virtual test drive and the inverse fit share.  Variants are
made with :func:`dataclasses.replace` (``replace(vp, frame=replace(vp.frame,
segments=6))``) and can be written back with :func:`save_vehicle`.

What it is not: the model (see :mod:`vehicles.builder`) or the effects
(:mod:`vehicles.effects`).  Every field of every table is required: a file with
an unknown or a missing field is refused with :class:`eroad.errors.EroadInputError`
naming the field and the file.  Units are SI and listed in each field's
``metadata["unit"]``; ``docs/vehicles.md`` lists every value with its source.

Coordinates (ISO 8855): x forward with x = 0 at the first axle (rear axles have
negative x), y to the left, z up from the road surface.
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from eroad.errors import EroadInputError

#: folder of the built-in vehicle files
PARAMS_DIR = Path(__file__).with_name("params")


def _f(unit: str, doc: str):
    """Field with unit and one-line description (used for docs and checks)."""
    return field(metadata={"unit": unit, "doc": doc})


@dataclass(frozen=True)
class MassItem:
    """A part of the sprung mass, modelled as a homogeneous box fixed to the frame.

    For a flexible frame each item is cut into the frame segments it spans
    (mass proportional to the overlap along x), so that a very stiff flexible
    frame carries exactly the mass and inertia of the rigid one.
    """

    name: str = _f("-", "label")
    mass: float = _f("kg", "mass")
    x_front: float = _f("m", "front end of the box along x")
    x_rear: float = _f("m", "rear end of the box along x (<= x_front; equal for a point-like item)")
    y: float = _f("m", "lateral position of the centre of gravity")
    z: float = _f("m", "height of the centre of gravity above the road")
    width: float = _f("m", "box extent along y (for the inertia)")
    height: float = _f("m", "box extent along z (for the inertia)")
    payload: bool = _f("-", "true for the item the `payload` effect changes (load, or kingpin load)")


@dataclass(frozen=True)
class Axle:
    """One rigid axle with its suspension (one vertical spring-damper per side) and tyres."""

    x: float = _f("m", "axle position along x (0 for the first axle, negative behind it)")
    steered: bool = _f("-", "steered axle (descriptive; the vertical model does not steer)")
    unsprung_mass: float = _f("kg", "axle, wheels, tyres, brakes, hubs and half the springs")
    roll_inertia: float = _f("kg m^2", "axle moment of inertia about x through its centre")
    pitch_inertia: float = _f("kg m^2", "axle moment of inertia about y")
    yaw_inertia: float = _f("kg m^2", "axle moment of inertia about z")
    tyres_per_side: int = _f("-", "1 (single) or 2 (dual tyres)")
    track: float = _f("m", "lateral distance between the left and right wheel (or dual pair) centres")
    dual_spacing: float = _f("m", "centre distance of the two tyres of a dual pair (ignored for singles)")
    tyre_radius: float = _f("m", "loaded tyre radius = axle centre height")
    tyre_stiffness: float = _f("N/m", "vertical stiffness of one tyre")
    tyre_damping: float = _f("N s/m", "vertical damping of one tyre")
    tyre_lateral_stiffness: float = _f("N/m", "lateral stiffness of one tyre at the contact")
    tyre_contact_length: float = _f("m", "length of the contact patch (mean over axles: default of "
                                          "`tyre_enveloping`)")
    spring_type: str = _f("-", "'leaf' or 'air' (leaf springs carry inter-leaf friction)")
    spring_track: float = _f("m", "lateral distance between the left and right spring seats")
    seat_height: float = _f("m", "height of the spring seats (spring-damper attachment, roll centre)")
    spring_stiffness: float = _f("N/m", "vertical suspension stiffness per side")
    damping: float = _f("N s/m", "vertical suspension damping per side (mean of compression and rebound)")
    guide_longitudinal_stiffness: float = _f("N/m", "longitudinal stiffness axle-frame per side")
    guide_lateral_stiffness: float = _f("N/m", "lateral stiffness axle-frame per side")
    windup_stiffness: float = _f("N m/rad", "axle pitch (wind-up) stiffness relative to the frame")


@dataclass(frozen=True)
class Frame:
    """Ladder frame: rigid, or rigid segments joined by rotational spring-dampers."""

    x_front: float = _f("m", "front end of the frame")
    x_rear: float = _f("m", "rear end of the frame")
    z: float = _f("m", "height of the frame's elastic axis (joint points)")
    segments: int = _f("-", "default number of rigid segments of the flexible frame (>= 2)")
    bending_stiffness: float = _f("N m^2", "effective vertical bending stiffness EI (frame with subframe)")
    torsion_stiffness: float = _f("N m^2/rad", "effective torsional stiffness GJ of the frame")
    lateral_bending_stiffness: float = _f("N m^2", "bending stiffness about z (both rails)")
    joint_translational_stiffness: float = _f("N/m", "stiffness of the joints in translation (quasi-rigid)")
    damping_ratio: float = _f("-", "structural damping ratio of the frame modes")
    target_torsion_hz: float = _f("Hz", "first frame torsion mode the stiffness was tuned to")
    target_bending_hz: float = _f("Hz", "first frame vertical bending mode the stiffness was tuned to")


@dataclass(frozen=True)
class DCDC:
    """DCDC converter + pantograph block on elastic mounts on the frame (tractor)."""

    mass: float = _f("kg", "mass of converter, pantograph and brackets")
    x: float = _f("m", "centre of the block along x")
    y: float = _f("m", "centre of the block along y")
    z_base: float = _f("m", "height of the mounting plane (top of the frame rails)")
    length: float = _f("m", "block extent along x")
    width: float = _f("m", "block extent along y")
    height: float = _f("m", "block extent along z (top face = z_base + height)")
    cog_height: float = _f("m", "centre of gravity above the mounting plane")
    mount_x_spacing: float = _f("m", "distance between front and rear mounts")
    mount_y_spacing: float = _f("m", "distance between left and right mounts")
    mount_vertical_stiffness: float = _f("N/m", "vertical stiffness of one of the four mounts")
    mount_lateral_stiffness: float = _f("N/m", "lateral stiffness of one mount")
    mount_longitudinal_stiffness: float = _f("N/m", "longitudinal stiffness of one mount")
    mount_stiffness_factor: float = _f("-", "scale of all mount stiffnesses (study knob, 1 nominal)")
    mount_damping_ratio: float = _f("-", "damping ratio of the mount modes")
    point_x: float = _f("m", "half distance of the characteristic top points along x")
    point_y: float = _f("m", "half distance of the characteristic top points along y")


@dataclass(frozen=True)
class Solver:
    """Default numerical settings (chosen by the accuracy benchmark)."""

    dt: float = _f("s", "default time step")
    spectral_radius: float = _f("-", "generalized-alpha spectral radius at infinity")


@dataclass(frozen=True)
class VehicleParams:
    """A complete vehicle.  ``source`` is the file it was read from (not a TOML field)."""

    id: str = _f("-", "identifier (the file stem for built-ins)")
    name: str = _f("-", "human-readable name")
    description: str = _f("-", "what the vehicle is and its layout")
    axles: tuple = _f("-", "tuple of Axle, front to rear")
    sprung: tuple = _f("-", "tuple of MassItem fixed to the frame")
    frame: Frame = _f("-", "frame")
    solver: Solver = _f("-", "solver defaults")
    dcdc: DCDC | None = _f("-", "DCDC block or None")
    source: str = field(default="", compare=False, metadata={"unit": "-", "doc": "file read"})

    # ---- derived quantities -------------------------------------------------
    @property
    def n_axles(self) -> int:
        return len(self.axles)

    @property
    def sprung_mass(self) -> float:
        """Sprung mass [kg] without the DCDC block."""
        return float(sum(m.mass for m in self.sprung))

    @property
    def total_mass(self) -> float:
        """Total mass [kg] including axles and the DCDC block."""
        dc = self.dcdc.mass if self.dcdc is not None else 0.0
        return self.sprung_mass + float(sum(a.unsprung_mass for a in self.axles)) + dc

    @property
    def wheelbase_extent(self) -> float:
        """Distance first to last axle [m]."""
        return self.axles[0].x - self.axles[-1].x


# --------------------------------------------------------------------------- loading
#: TOML table name -> (dataclass, is array of tables)
_TABLES = {"vehicle": None, "frame": Frame, "solver": Solver, "dcdc": DCDC,
           "axle": Axle, "mass": MassItem}
_VEHICLE_KEYS = ("id", "name", "description")


def _fields(cls) -> dict:
    return {f.name: f for f in dataclasses.fields(cls)}


def _coerce(value, ftype, where: str, src: str):
    """Check one TOML value against a field type; return the converted value."""
    if isinstance(ftype, str):  # postponed annotations
        ftype = {"float": float, "int": int, "str": str, "bool": bool}.get(ftype, ftype)
    if ftype is bool:
        if not isinstance(value, bool):
            raise EroadInputError(f"{src}: field '{where}' must be true or false, got {value!r}")
        return value
    if ftype is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise EroadInputError(f"{src}: field '{where}' must be an integer, got {value!r}")
        return value
    if ftype is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise EroadInputError(f"{src}: field '{where}' must be a finite number, got {value!r}")
        return float(value)
    if ftype is str:
        if not isinstance(value, str):
            raise EroadInputError(f"{src}: field '{where}' must be a string, got {value!r}")
        return value
    raise TypeError(f"unsupported field type {ftype!r}")  # pragma: no cover


def _build(cls, table: dict, name: str, src: str):
    if not isinstance(table, dict):
        raise EroadInputError(f"{src}: '{name}' must be a table")
    flds = _fields(cls)
    for key in table:
        if key not in flds:
            raise EroadInputError(f"{src}: unknown field '{name}.{key}'")
    kw = {}
    for fname, f in flds.items():
        if fname not in table:
            raise EroadInputError(f"{src}: missing field '{name}.{fname}'")
        kw[fname] = _coerce(table[fname], f.type, f"{name}.{fname}", src)
    return cls(**kw)


def parse_vehicle(doc: dict, src: str) -> VehicleParams:
    """Build :class:`VehicleParams` from a parsed TOML document.

    Parameters
    ----------
    doc : dict
        The TOML document.
    src : str
        File name used in error messages.

    Raises
    ------
    EroadInputError
        Unknown or missing table or field, wrong type, or an implausible value.
    """
    for key in doc:
        if key not in _TABLES:
            raise EroadInputError(f"{src}: unknown table or field '{key}'")
    for key in ("vehicle", "frame", "solver", "axle", "mass"):
        if key not in doc:
            raise EroadInputError(f"{src}: missing table '{key}'")
    veh = doc["vehicle"]
    if not isinstance(veh, dict):
        raise EroadInputError(f"{src}: 'vehicle' must be a table")
    for key in veh:
        if key not in _VEHICLE_KEYS:
            raise EroadInputError(f"{src}: unknown field 'vehicle.{key}'")
    for key in _VEHICLE_KEYS:
        if key not in veh:
            raise EroadInputError(f"{src}: missing field 'vehicle.{key}'")
        _coerce(veh[key], str, f"vehicle.{key}", src)
    if not isinstance(doc["axle"], list) or not isinstance(doc["mass"], list):
        raise EroadInputError(f"{src}: 'axle' and 'mass' must be arrays of tables ([[axle]], [[mass]])")
    axles = tuple(_build(Axle, t, f"axle[{i}]", src) for i, t in enumerate(doc["axle"]))
    sprung = tuple(_build(MassItem, t, f"mass[{i}]", src) for i, t in enumerate(doc["mass"]))
    frame = _build(Frame, doc["frame"], "frame", src)
    solver = _build(Solver, doc["solver"], "solver", src)
    dcdc = _build(DCDC, doc["dcdc"], "dcdc", src) if "dcdc" in doc else None
    vp = VehicleParams(id=veh["id"], name=veh["name"], description=veh["description"],
                       axles=axles, sprung=sprung, frame=frame, solver=solver, dcdc=dcdc,
                       source=src)
    validate_vehicle(vp)
    return vp


def validate_vehicle(vp: VehicleParams) -> None:
    """Check physical plausibility; raise :class:`EroadInputError` naming the field.

    Parameters
    ----------
    vp : VehicleParams
    """
    src = vp.source or vp.id

    def bad(where, msg):
        raise EroadInputError(f"{src}: field '{where}' {msg}")

    if not vp.axles:
        bad("axle", "needs at least one [[axle]]")
    if len(vp.axles) < 2:
        bad("axle", "needs at least two axles")
    for i, a in enumerate(vp.axles):
        w = f"axle[{i}]"
        for name in ("unsprung_mass", "roll_inertia", "pitch_inertia", "yaw_inertia", "track",
                     "tyre_radius", "tyre_stiffness", "tyre_lateral_stiffness",
                     "windup_stiffness", "spring_track", "spring_stiffness",
                     "guide_longitudinal_stiffness", "guide_lateral_stiffness", "seat_height"):
            if not getattr(a, name) > 0:
                bad(f"{w}.{name}", f"must be positive, got {getattr(a, name)!r}")
        for name in ("tyre_damping", "damping", "tyre_contact_length"):
            if getattr(a, name) < 0:
                bad(f"{w}.{name}", "must not be negative")
        if a.tyres_per_side not in (1, 2):
            bad(f"{w}.tyres_per_side", f"must be 1 or 2, got {a.tyres_per_side}")
        if a.tyres_per_side == 2 and not 0 < a.dual_spacing < a.track:
            bad(f"{w}.dual_spacing", "must be positive and below the track for dual tyres")
        if a.spring_type not in ("leaf", "air"):
            bad(f"{w}.spring_type", f"must be 'leaf' or 'air', got {a.spring_type!r}")
        if i > 0 and not a.x < vp.axles[i - 1].x:
            bad(f"{w}.x", "must be behind (smaller than) the previous axle's x")
        if not vp.frame.x_rear < a.x < vp.frame.x_front:
            bad(f"{w}.x", f"= {a.x} lies outside the frame [{vp.frame.x_rear}, {vp.frame.x_front}]")
    if not vp.sprung:
        bad("mass", "needs at least one [[mass]] item")
    for i, m in enumerate(vp.sprung):
        w = f"mass[{i}]"
        if not m.mass > 0:
            bad(f"{w}.mass", "must be positive")
        if m.x_rear > m.x_front:
            bad(f"{w}.x_rear", "must not be in front of x_front")
        if not (vp.frame.x_rear <= m.x_rear and m.x_front <= vp.frame.x_front):
            bad(f"{w}.x_front", "item must lie within the frame's x range")
        if m.width < 0 or m.height < 0:
            bad(f"{w}.width", "box dimensions must not be negative")
    if sum(m.payload for m in vp.sprung) > 1:
        bad("mass.payload", "at most one item may be the payload")
    fr = vp.frame
    if not fr.x_front > fr.x_rear:
        bad("frame.x_front", "must be in front of frame.x_rear")
    if fr.segments < 2:
        bad("frame.segments", "must be >= 2")
    for name in ("bending_stiffness", "torsion_stiffness", "lateral_bending_stiffness",
                 "joint_translational_stiffness", "target_torsion_hz", "target_bending_hz"):
        if not getattr(fr, name) > 0:
            bad(f"frame.{name}", "must be positive")
    if not 0 <= fr.damping_ratio < 1:
        bad("frame.damping_ratio", "must be in [0, 1)")
    if not vp.solver.dt > 0:
        bad("solver.dt", "must be positive")
    if not 0 <= vp.solver.spectral_radius <= 1:
        bad("solver.spectral_radius", "must be in [0, 1]")
    d = vp.dcdc
    if d is not None:
        for name in ("mass", "length", "width", "height", "cog_height", "mount_x_spacing",
                     "mount_y_spacing", "mount_vertical_stiffness", "mount_lateral_stiffness",
                     "mount_longitudinal_stiffness", "mount_stiffness_factor", "point_x", "point_y"):
            if not getattr(d, name) > 0:
                bad(f"dcdc.{name}", "must be positive")
        if not fr.x_rear < d.x < fr.x_front:
            bad("dcdc.x", "block must sit on the frame")
        if not 0 <= d.mount_damping_ratio < 1:
            bad("dcdc.mount_damping_ratio", "must be in [0, 1)")
        if d.point_x > d.length / 2 or d.point_y > d.width / 2:
            bad("dcdc.point_x", "characteristic points must lie on the top face")


def builtin_ids() -> tuple[str, ...]:
    """Ids of the built-in vehicles (stems of ``vehicles/params/*.toml``)."""
    return tuple(sorted(p.stem for p in PARAMS_DIR.glob("*.toml")))


def vehicle_path(vehicle) -> Path:
    """Resolve a built-in id or a file path to an existing TOML file.

    Raises
    ------
    EroadInputError
        Neither a built-in id nor an existing file.
    """
    s = str(vehicle)
    p = Path(s)
    if s in builtin_ids():
        return PARAMS_DIR / f"{s}.toml"
    if p.suffix.lower() == ".toml" or p.exists() or "/" in s or "\\" in s:
        if not p.is_file():
            raise EroadInputError(f"{p}: no such vehicle file")
        return p
    raise EroadInputError(f"unknown vehicle '{s}': not a built-in id ({', '.join(builtin_ids())}) "
                          "and not a .toml file")


def load_vehicle(vehicle) -> VehicleParams:
    """Load a vehicle by built-in id or from a TOML file.

    Parameters
    ----------
    vehicle : str or Path or VehicleParams
        ``"dump_truck_8x4"``, ``"e_tractor"``, a path to a ``.toml`` file, or an
        already loaded :class:`VehicleParams` (returned unchanged).

    Returns
    -------
    VehicleParams

    Raises
    ------
    EroadInputError
        Missing file, unreadable TOML, unknown or missing field (named with the file).
    """
    if isinstance(vehicle, VehicleParams):
        return vehicle
    path = vehicle_path(vehicle)
    try:
        with open(path, "rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise EroadInputError(f"{path}: not valid TOML ({exc})") from None
    except OSError as exc:
        raise EroadInputError(f"{path}: cannot read ({exc.strerror})") from None
    return parse_vehicle(doc, str(path))


def vehicle_to_dict(vp: VehicleParams) -> dict:
    """The TOML document of a vehicle (inverse of :func:`parse_vehicle`)."""
    doc = {"vehicle": {"id": vp.id, "name": vp.name, "description": vp.description},
           "frame": dataclasses.asdict(vp.frame), "solver": dataclasses.asdict(vp.solver)}
    if vp.dcdc is not None:
        doc["dcdc"] = dataclasses.asdict(vp.dcdc)
    doc["axle"] = [dataclasses.asdict(a) for a in vp.axles]
    doc["mass"] = [dataclasses.asdict(m) for m in vp.sprung]
    return doc


def save_vehicle(vp: VehicleParams, path) -> Path:
    """Write a vehicle as TOML (readable again by :func:`load_vehicle`).

    Parameters
    ----------
    vp : VehicleParams
    path : str or Path
        Target file; written to a temporary file and renamed into place.

    Returns
    -------
    Path
    """
    import os

    import tomli_w

    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        with open(tmp, "wb") as fh:
            tomli_w.dump(vehicle_to_dict(vp), fh)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def field_table() -> list[dict]:
    """Every parameter field with unit and description (for docs and tests).

    Returns
    -------
    list of dict
        ``{"table", "field", "unit", "doc"}`` for each field of each table.
    """
    rows = []
    for table, cls in (("vehicle", None), ("axle", Axle), ("mass", MassItem), ("frame", Frame),
                       ("solver", Solver), ("dcdc", DCDC)):
        if cls is None:
            for name in _VEHICLE_KEYS:
                f = _fields(VehicleParams)[name]
                rows.append({"table": table, "field": name, **f.metadata})
            continue
        for f in dataclasses.fields(cls):
            rows.append({"table": table, "field": f.name, **f.metadata})
    return rows

