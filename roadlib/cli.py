"""``eroad road ...``: generate roads, estimate their PSD and IRI, plot them.

What this module is for: the command-line face of roadlib (argument parsing,
file reading and writing, summaries).  The computing lives in the other roadlib
modules; nothing here is needed to use roadlib from Python.

Subcommands
-----------
``generate``  ISO 8608 road (one class or explicit parameters, or segments) to
              ``FILE.npz`` / ``FILE.crg``, plus ``FILE.npz.summary.json`` beside it.
``psd``       Welch PSD + ISO fit of a road file or a two-column profile.
``iri``       IRI per segment of a two-column profile or a track of a road file.
``plot``      PNG of profile, surface map and PSD against the ISO classes.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
import tomllib
from pathlib import Path

import numpy as np

from eroad.argtypes import positive_float
from eroad.errors import EroadInputError
from roadlib.profiles import DEFAULT_TRACK_WIDTH_M, DEFAULT_WIDTH_M

SEGMENT_KEYS = {"class", "Gq_n0", "length", "w", "nmin", "nmax", "lambda"}


# ----------------------------------------------------------------------------- helpers
def _write_text_atomic(path: Path, text: str) -> None:
    from roadlib.surface import _new_file_mode

    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.chmod(tmp, _new_file_mode())   # mkstemp's 0600 would stay after the rename
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _refuse_existing(path: Path, force: bool) -> None:
    if path.exists() and not force:
        raise EroadInputError(f"{path} exists; refusing to overwrite it (use --force)")


def _parse_segment(text: str):
    from roadlib.segments import RoadSegment

    parts = text.split(":")
    if len(parts) != 2:
        raise EroadInputError(f"--segment {text!r}: expected CLASS:LENGTH, e.g. C:300")
    cls, length = parts
    try:
        length_m = float(length)
    except ValueError:
        raise EroadInputError(f"--segment {text!r}: length {length!r} is not a number of metres") from None
    if not (math.isfinite(length_m) and length_m > 0):
        raise EroadInputError(f"--segment {text!r}: length must be positive metres")
    return RoadSegment.from_class(cls, share=length_m), length_m


def read_segments_toml(path, defaults: dict):
    """Read ``[[segment]]`` tables (class or Gq_n0 [m^3], length [m], optional w,
    nmin, nmax [cycles/m], lambda) from a TOML file.

    Returns
    -------
    list of (RoadSegment, length [m])
    """
    from roadlib.segments import RoadSegment

    path = Path(path)
    if not path.is_file():
        raise EroadInputError(f"{path}: no such segments file")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise EroadInputError(f"{path}: not valid TOML ({exc})") from None
    extra = set(data) - {"segment"}
    if extra:
        raise EroadInputError(f"{path}: unknown key {sorted(extra)[0]!r} (expected [[segment]] tables)")
    tables = data.get("segment")
    if not isinstance(tables, list) or not tables:
        raise EroadInputError(f"{path}: no [[segment]] tables")
    out = []
    for i, t in enumerate(tables, 1):
        where = f"{path}, segment {i}"
        unknown = set(t) - SEGMENT_KEYS
        if unknown:
            raise EroadInputError(f"{where}: unknown key {sorted(unknown)[0]!r} "
                                  f"(allowed: {', '.join(sorted(SEGMENT_KEYS))})")
        if "length" not in t:
            raise EroadInputError(f"{where}: missing 'length' [m]")
        if ("class" in t) == ("Gq_n0" in t):
            raise EroadInputError(f"{where}: give exactly one of 'class' or 'Gq_n0' [m^3]")
        kw = dict(defaults)
        for key, name in (("w", "w"), ("nmin", "nmin"), ("nmax", "nmax"), ("lambda", "lam")):
            if key in t:
                kw[name] = t[key]
        for name, v in kw.items():
            if not isinstance(v, (int, float)) or isinstance(v, bool):
                raise EroadInputError(f"{where}: {name} must be a number, got {v!r}")
        length = t["length"]
        if not isinstance(length, (int, float)) or isinstance(length, bool) or not length > 0:
            raise EroadInputError(f"{where}: 'length' must be a positive number of metres, got {length!r}")
        try:
            if "class" in t:
                seg = RoadSegment.from_class(str(t["class"]), share=float(length), **kw)
            else:
                seg = RoadSegment(Gq_n0=float(t["Gq_n0"]), share=float(length), label=f"seg{i}", **kw)
        except EroadInputError as exc:
            raise EroadInputError(f"{where}: {exc}") from None
        except TypeError as exc:
            raise EroadInputError(f"{where}: {exc}") from None
        out.append((seg, float(length)))
    return out


def read_profile_text(path):
    """Two-column profile x [m], z [m]: whitespace- or comma-separated; '#' comments
    and a non-numeric header line are skipped.

    Returns
    -------
    x, z : ndarray
    """
    path = Path(path)
    if not path.is_file():
        raise EroadInputError(f"{path}: no such profile file")
    xs, zs = [], []
    try:
        lines = path.read_text().splitlines()
    except UnicodeDecodeError:
        raise EroadInputError(f"{path}: not a text profile (use .npz or .crg for road files)") from None
    for row, line in enumerate(lines, 1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        parts = [p for p in s.replace(",", " ").replace(";", " ").split() if p]
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            if not xs and row <= 3:  # a header line
                continue
            raise EroadInputError(f"{path}, row {row}: not numeric: {line.strip()[:60]!r}") from None
        if len(vals) != 2:
            raise EroadInputError(f"{path}, row {row}: expected 2 columns (x [m], z [m]), found {len(vals)}")
        if not all(math.isfinite(v) for v in vals):
            raise EroadInputError(f"{path}, row {row}: NaN or inf value")
        xs.append(vals[0])
        zs.append(vals[1])
    if len(xs) < 3:
        raise EroadInputError(f"{path}: fewer than 3 profile rows")
    x, z = np.array(xs), np.array(zs)
    d = np.diff(x)
    if np.any(d <= 0):
        bad = int(np.flatnonzero(d <= 0)[0])
        raise EroadInputError(f"{path}, column 1, row {bad + 2}: x must increase strictly")
    return x, z


def _load_track(path, track):
    """(x, z, dx, surface-or-None) from a road file or a profile text file."""
    from roadlib.surface import RoadSurface

    p = Path(path)
    if p.suffix.lower() in (".npz", ".crg"):
        s = RoadSurface.load(p)
        if track is None:
            if s.y.size > 1:
                raise EroadInputError(f"{p}: a surface of width {s.width:g} m; choose a track with --track Y [m]")
            track = float(s.y[0])
        if s.y.size > 1 and not (s.y[0] - 1e-9 <= track <= s.y[-1] + 1e-9):
            raise EroadInputError(f"--track {track:g} m is outside the road {s.y[0]:g}..{s.y[-1]:g} m of {p}")
        return s.x, s.track(track), s.dx, s
    x, z = read_profile_text(p)
    dx = float(np.median(np.diff(x)))
    if np.max(np.abs(np.diff(x) - dx)) > 1e-6 * dx + 1e-9:
        bad = int(np.argmax(np.abs(np.diff(x) - dx)))
        raise EroadInputError(f"{p}, column 1, row {bad + 2}: profile must be uniformly sampled (dx = {dx:g} m)")
    return x, z, dx, None


def _print(args, summary: dict, text: str) -> None:
    if getattr(args, "json", False):
        print(json.dumps(summary, indent=2))
    else:
        print(text)


# ----------------------------------------------------------------------------- commands
def _road_outputs(args) -> tuple[Path, Path]:
    """The road file ``--out`` (.npz or .crg, in an existing folder) and its summary beside
    it, both refused where they exist unless ``--force``."""
    out = Path(args.out)
    if out.suffix.lower() not in (".npz", ".crg"):
        raise EroadInputError(f"--out {out}: use a .npz or .crg file name")
    if not out.parent.exists():
        raise EroadInputError(f"--out {out}: folder {out.parent} does not exist")
    summary_path = out.with_name(out.name + ".summary.json")
    _refuse_existing(out, args.force)
    _refuse_existing(summary_path, args.force)
    return out, summary_path


def cmd_generate(args) -> int:
    from roadlib.metrics import default_band, fit_iso_psd, profile_psd
    from roadlib.psd import class_gd0
    from roadlib.segments import RoadSegment, segmented_surface
    from roadlib.synthesis import SpectralParams, synth_surface

    out, summary_path = _road_outputs(args)
    if args.seed < 0:
        raise EroadInputError(f"--seed must be a non-negative integer, got {args.seed}")
    spec = {"w": args.w, "nmin": args.nmin, "nmax": args.nmax, "lam": args.lam}
    n_sources = sum(bool(v) for v in (args.iso_class, args.gd0 is not None, args.segment, args.segments))
    if n_sources == 0:
        raise EroadInputError("give the road: --class C, --gd0 GQ_N0 [m^3], --segment CLASS:LENGTH or --segments FILE.toml")
    if n_sources > 1:
        raise EroadInputError("give only one of --class, --gd0, --segment (repeatable) or --segments")

    if args.segment or args.segments:
        if args.segment:
            pairs = []
            for t in args.segment:
                seg, ln = _parse_segment(t)
                pairs.append((RoadSegment(**{**seg.to_dict(), **spec, "share": seg.share}), ln))
        else:
            pairs = read_segments_toml(args.segments, spec)
        total = sum(ln for _, ln in pairs)
        if args.length is not None and abs(args.length - total) > 1e-9 * total:
            raise EroadInputError(f"--length {args.length:g} m differs from the sum of the segment lengths "
                                  f"{total:g} m; drop --length")
        surf = segmented_surface([s for s, _ in pairs], total, args.width, args.dx, args.dy, seed=args.seed)
        params = None
    else:
        length = 1000.0 if args.length is None else args.length
        if not (math.isfinite(length) and length > 0):
            raise EroadInputError(f"--length must be positive metres, got {length:g}")
        gd0 = class_gd0(args.iso_class) if args.iso_class else args.gd0
        params = SpectralParams(Gq_n0=gd0, dx=args.dx, dy=args.dy, **spec)
        surf = synth_surface(params, length, args.width, seed=args.seed)
    if not (math.isfinite(args.width) and args.width >= 0):
        raise EroadInputError(f"--width must be >= 0 m, got {args.width:g}")
    surf.meta["command"] = "eroad road generate"

    centre = float(surf.y[np.argmin(np.abs(surf.y))])
    try:
        est = profile_psd(surf.track(centre), surf.dx)
        lo, hi = default_band(est)
        fit = fit_iso_psd(est, band=(max(lo, args.nmin), min(hi, 0.97 * args.nmax))).to_dict()
        fit_text = (f"centre track Gd(n0) = {fit['Gd_n0']:.3e} m^3, w = {fit['w']:.2f}, "
                    f"class {fit['class']}")
    except EroadInputError as exc:  # road too short for a PSD estimate
        fit = {"error": str(exc)}
        fit_text = f"no PSD check ({exc})"
    surf.save(out, overwrite=True)
    summary = {
        "command": "road generate", "out": str(out), "seed": args.seed,
        "params": params.to_dict() if params else None,
        "segments": surf.meta.get("segments"), "junctions": surf.meta.get("junctions"),
        "surface": surf.summary(),
        "centre_track_psd": {"y": centre, **fit},
    }
    _write_text_atomic(summary_path, json.dumps(summary, indent=2) + "\n")
    _print(args, summary, f"wrote {out} ({surf.x.size} x {surf.y.size} grid, {surf.length:g} m x "
           f"{surf.width:g} m, z rms {1000 * np.std(surf.z):.2f} mm); {fit_text}; summary {summary_path}")
    return 0


def cmd_from_profile(args) -> int:
    from roadlib.metrics import surface_content_top
    from roadlib.profiles import surface_from_profiles

    out, summary_path = _road_outputs(args)
    left = read_profile_text(args.profile)
    right = read_profile_text(args.right) if args.right else None
    surf = surface_from_profiles(left, right, track_width=args.track_width, width=args.width,
                                 dx=args.dx, dy=args.dy,
                                 names=(str(args.profile), str(args.right)))
    surf.meta["command"] = "eroad road from-profile"
    surf.meta["profiles"] = [str(Path(args.profile).resolve())] + (
        [str(Path(args.right).resolve())] if args.right else [])
    n_top = surface_content_top(surf)
    surf.save(out, overwrite=True)
    summary = {"command": "road from-profile", "out": str(out), "profiles": surf.meta["profiles"],
               "surface": surf.summary(), "lateral": surf.meta["lateral"],
               "grades": surf.meta["grades"], "source_x_start_m": surf.meta["source_x_start_m"],
               "content_top_cpm": n_top,
               "no_roll_input": right is None}
    _write_text_atomic(summary_path, json.dumps(summary, indent=2) + "\n")
    grades = ", ".join(f"{100 * g:+.2f} %" for g in surf.meta["grades"])
    msg = (f"wrote {out} ({surf.x.size} x {surf.y.size} grid, {surf.length:g} m x {surf.width:g} m; "
           f"chainage {surf.meta['source_x_start_m']:g} m is x = 0; grade removed: {grades}); "
           f"{surf.meta['lateral']}; content up to {n_top:.2f} cycles/m (a vehicle at v m/s gets "
           f"no road input above {n_top:.2f} v Hz); summary {summary_path}")
    if right is None:
        msg += ("\nnote: one profile drives both wheel tracks alike, so the vehicle gets no roll "
                "input from the road; give the other wheel track with --right where it was measured")
    _print(args, summary, msg)
    return 0


def cmd_psd(args) -> int:
    from roadlib.metrics import default_band, fit_iso_psd, profile_psd
    from roadlib.surface import RoadSurface

    p = Path(args.file)
    if p.suffix.lower() in (".npz", ".crg") and args.track is None:
        s = RoadSurface.load(p)
        z, dx, meta = s.z, s.dx, s.meta
        what = f"{s.y.size} track(s)"
    else:
        _, z, dx, s = _load_track(p, args.track)
        meta = s.meta if s is not None else {}
        what = "1 track"
    est = profile_psd(z, dx, segment_length=args.segment_length)
    if args.band:
        band = tuple(args.band)
    else:
        band = default_band(est)
        pm = meta.get("params") if isinstance(meta, dict) else None
        if isinstance(pm, dict) and "nmin" in pm and "nmax" in pm:
            band = (max(band[0], float(pm["nmin"])), min(band[1], 0.97 * float(pm["nmax"])))
    fit = fit_iso_psd(est, band=band, w=2.0 if args.fixed_w else None)
    summary = {"file": str(p), "tracks": what, "dx": dx, "n_averages": est.n_averages, **fit.to_dict()}
    text = (f"{p}: Gd(n0) = {fit.Gd_n0:.4e} m^3 (+-{100 * fit.Gd_n0_rel_se:.1f} %), "
            f"w = {fit.w:.3f} (+-{fit.w_se:.3f}), class {fit.iso_class}, band {band[0]:.3g}-{band[1]:.3g} "
            f"cycles/m, {what}")
    if np.ndim(z) == 2 and np.shape(z)[1] > 1:
        # neighbouring tracks are nearly one profile at long wavelengths: the +- intervals
        # count them as the independent tracks they are worth (roadlib.tracks)
        from roadlib.tracks import effective_tracks, fit_weights

        m = np.shape(z)[1]
        free_w = not args.fixed_w
        n_gd = effective_tracks(z, dx, est.nperseg, band, weights=lambda n: fit_weights(n, free_w=free_w)[0])
        n_w = effective_tracks(z, dx, est.nperseg, band, weights=lambda n: fit_weights(n)[1]) if free_w else m
        summary.update(Gd_n0_rel_se=fit.Gd_n0_rel_se * math.sqrt(m / n_gd),
                       w_se=fit.w_se * math.sqrt(m / n_w),
                       effective_tracks={"Gd_n0": n_gd, "w": n_w},
                       centre_track=_centre_track_fit(s, band, args.fixed_w))
        c = summary["centre_track"]
        text = (f"{p}: Gd(n0) = {fit.Gd_n0:.4e} m^3 (+-{100 * summary['Gd_n0_rel_se']:.1f} %), "
                f"w = {fit.w:.3f} (+-{summary['w_se']:.3f}), class {fit.iso_class}, band "
                f"{band[0]:.3g}-{band[1]:.3g} cycles/m; the average of {m} tracks, worth about "
                f"{n_gd:.1f} independent ones for Gd(n0) (neighbouring tracks are nearly one profile "
                f"at long wavelengths).\nThe centre track alone (y = {c['y']:g} m; what `road plot` "
                f"and `road generate` report): Gd(n0) = {c['Gd_n0']:.4e} m^3 (+-{100 * c['Gd_n0_rel_se']:.1f} %)"
                f", w = {c['w']:.3f}")
    _print(args, summary, text)
    return 0


def _centre_track_fit(surf, band, fixed_w: bool) -> dict:
    """The ISO fit of the track nearest y = 0 [m] in ``band``, as ``road plot`` shows it."""
    from roadlib.metrics import fit_iso_psd, profile_psd

    y = float(surf.y[np.argmin(np.abs(surf.y))])
    fit = fit_iso_psd(profile_psd(surf.track(y), surf.dx), band=band, w=2.0 if fixed_w else None)
    return {"y": y, **fit.to_dict()}


def cmd_iri(args) -> int:
    from roadlib.iri import iri_segments

    x, z, dx, _ = _load_track(args.profile, args.track)
    segs = iri_segments(x, z, args.segment, start=args.start, partial=args.partial)
    rows = [s.to_dict() for s in segs]
    text = "\n".join(f"{r['start']:10.2f} {r['end']:10.2f}  IRI {r['iri']:.4f} m/km" for r in rows)
    _print(args, rows, text)
    return 0


def cmd_plot(args) -> int:
    from roadlib.plot import plot_road
    from roadlib.surface import RoadSurface

    p = Path(args.file)
    if p.suffix.lower() in (".npz", ".crg"):
        s = RoadSurface.load(p)
    else:
        x, z = read_profile_text(p)
        s = RoadSurface(x, [0.0], z[:, None], {"source": str(p)})
    out = Path(args.out) if args.out else p.with_suffix(".png")
    if out.suffix.lower() != ".png":
        raise EroadInputError(f"--out {out}: the plot is a PNG; use a .png file name")
    _refuse_existing(out, args.force)
    track = args.track if args.track is not None else float(s.y[np.argmin(np.abs(s.y))])
    if s.y.size > 1 and not (s.y[0] - 1e-9 <= track <= s.y[-1] + 1e-9):
        raise EroadInputError(f"--track {track:g} m is outside the road {s.y[0]:g}..{s.y[-1]:g} m")
    fit = plot_road(s, out, track=track)
    summary = {"file": str(p), "png": str(out), "track": track, **fit}
    _print(args, summary, f"wrote {out}: track y = {track:g} m, Gd(n0) = {fit['Gd_n0']:.4e} m^3, "
           f"w = {fit['w']:.3f}, class {fit['class']} (one track; `road psd` averages all the "
           "road's tracks unless --track)")
    return 0


# ----------------------------------------------------------------------------- parser


def _nonneg(text):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(v) and v >= 0):
        raise argparse.ArgumentTypeError(f"{text!r} must be >= 0")
    return v


def register(subparsers) -> None:
    """Add ``eroad road {generate,from-profile,psd,iri,plot}`` to the top-level subparsers."""
    road = subparsers.add_parser("road", help="ISO 8608 roads: generate, from a measured profile, PSD, IRI, plot",
                                 description="ISO 8608 road surfaces (roadlib).")
    sub = road.add_subparsers(dest="road_command", metavar="ACTION")

    def _road_help(args):
        road.print_help()
        return 2

    road.set_defaults(func=_road_help)

    g = sub.add_parser("generate", help="generate a road to .npz or .crg",
                       description="Generate an ISO 8608 road by harmonic superposition. Give one class, an "
                       "explicit level, or segments. Writes FILE and FILE.summary.json beside it.")
    src = g.add_argument_group("road spectrum (one of)")
    src.add_argument("--class", dest="iso_class", metavar="CLASS", help="ISO 8608 class A-H (geometric mean level)")
    src.add_argument("--gd0", type=positive_float, metavar="GQ_N0", help="Gd(n0) at n0 = 0.1 cycles/m [m^3], e.g. 256e-6")
    src.add_argument("--segment", action="append", metavar="CLASS:LENGTH",
                     help="a segment of class CLASS and LENGTH [m]; repeat in travel order")
    src.add_argument("--segments", metavar="FILE.toml",
                     help="[[segment]] tables: class or Gq_n0 [m^3], length [m], optional w, nmin, nmax, lambda")
    g.add_argument("--w", type=positive_float, default=2.0, help="waviness [-] (default 2)")
    g.add_argument("--nmin", type=positive_float, default=0.011, help="lowest spatial frequency [cycles/m] (0.011)")
    g.add_argument("--nmax", type=positive_float, default=2.83, help="highest spatial frequency [cycles/m] (2.83)")
    g.add_argument("--length", type=positive_float, default=None, help="road length [m] (default 1000; "
                   "with segments the sum of their lengths)")
    g.add_argument("--width", type=_nonneg, default=4.0, help="road width [m], centred on y = 0 (default 4; 0 = one track)")
    g.add_argument("--dx", type=positive_float, default=0.1, help="grid step along the road [m] (0.1)")
    g.add_argument("--dy", type=positive_float, default=0.1, help="grid step across the road [m] (0.1)")
    g.add_argument("--lambda", dest="lam", type=positive_float, default=1.0,
                   help="anisotropy factor [-] of the surface PSD (1 isotropic, > 1 more coherent across)")
    g.add_argument("--seed", type=int, default=0, help="root seed (default 0)")
    g.add_argument("--out", required=True, metavar="FILE", help="output road file, .npz or .crg")
    g.add_argument("--force", action="store_true", help="overwrite existing output files")
    g.add_argument("--json", action="store_true", help="print the summary as JSON")
    g.set_defaults(func=cmd_generate)

    fp = sub.add_parser("from-profile", help="a road file from measured wheel-track profiles",
                        description="Make a road surface (.npz or .crg) of a measured longitudinal "
                        "profile (two columns x [m], z [m], a uniform step), or of two: the left "
                        "and right wheel tracks. Each profile is detrended (its least-squares line, "
                        "the grade, removed and reported) and band-limited onto the road grid (no "
                        "content added above its Nyquist wavenumber); across the road the height is "
                        "linear between the two tracks and held beyond. One profile drives both "
                        "tracks alike (no roll input). Then: eroad simulate --road FILE. "
                        "docs/roadlib.md, 'Measured profiles'.")
    fp.add_argument("profile", help="the (left) wheel-track profile: x [m] z [m] text")
    fp.add_argument("--right", default=None, metavar="PROFILE",
                    help="the right wheel-track profile on the same chainage")
    fp.add_argument("--track-width", type=positive_float, default=DEFAULT_TRACK_WIDTH_M,
                    help=f"lateral distance between the two profiles [m] (default {DEFAULT_TRACK_WIDTH_M:g})")
    fp.add_argument("--width", type=positive_float, default=DEFAULT_WIDTH_M,
                    help=f"road width [m], centred on y = 0 (default {DEFAULT_WIDTH_M:g})")
    fp.add_argument("--dx", type=positive_float, default=0.05, help="grid step along the road [m] (0.05)")
    fp.add_argument("--dy", type=positive_float, default=0.05, help="grid step across the road [m] (0.05)")
    fp.add_argument("--out", required=True, metavar="FILE", help="output road file, .npz or .crg")
    fp.add_argument("--force", action="store_true", help="overwrite existing output files")
    fp.add_argument("--json", action="store_true", help="print the summary as JSON")
    fp.set_defaults(func=cmd_from_profile)

    p = sub.add_parser("psd", help="Welch PSD and ISO 8608 fit of a road or profile",
                       description="Estimate the displacement PSD (Welch, cycles/m) and fit Gd(n0) [m^3] and w "
                       "in linear space (Whittle likelihood); report the ISO class.")
    p.add_argument("file", help="road file (.npz/.crg; all tracks averaged unless --track) or x z profile text")
    p.add_argument("--track", type=float, default=None, help="use only the track at lateral position Y [m]")
    p.add_argument("--band", type=positive_float, nargs=2, metavar=("LOW", "HIGH"),
                   help="fit band [cycles/m] (default: ISO band within the data)")
    p.add_argument("--segment-length", type=positive_float, default=None, help="Welch segment length [m]")
    p.add_argument("--fixed-w", action="store_true", help="fix w = 2 (the ISO class definition)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_psd)

    i = sub.add_parser("iri", help="IRI per segment (golden quarter car, ASTM E1926)",
                       description="International Roughness Index per segment [m/km].")
    i.add_argument("profile", help="two-column x [m] z [m] text (space or comma separated), or .npz/.crg with --track")
    i.add_argument("--segment", type=positive_float, required=True, metavar="LENGTH", help="segment length [m]")
    i.add_argument("--track", type=float, default=None, help="lateral position Y [m] of the track in a road file")
    i.add_argument("--start", type=float, default=None, help="start of the first segment [m] (default first sample)")
    i.add_argument("--partial", action="store_true", help="also report the last incomplete segment")
    i.add_argument("--json", action="store_true", help="print a JSON list of {start, end, iri}")
    i.set_defaults(func=cmd_iri)

    pl = sub.add_parser("plot", help="PNG: profile, surface map, PSD against ISO classes",
                        description="Plot a road file or a profile (Agg, PNG).")
    pl.add_argument("file", help="road file (.npz/.crg) or x z profile text")
    pl.add_argument("--out", default=None, help="PNG file (default FILE with .png suffix)")
    pl.add_argument("--track", type=float, default=None, help="lateral position of the plotted track [m]")
    pl.add_argument("--force", action="store_true", help="overwrite an existing PNG")
    pl.add_argument("--json", action="store_true", help="print a JSON summary")
    pl.set_defaults(func=cmd_plot)
