"""SimResult: the typed result of a vehicle simulation.

What it is for: carrying the sampled output channels with units and the run's
metadata from :func:`vehicles.simulate.simulate` to a DataFrame or to a dataset
folder in the measurement format (``../shared/docs/measurement-format.md``), so that
simulated and measured drives share one reader.

What it is not: plotting or analysis (those read saved results).
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: channel name prefix -> unit
UNITS = {"susp_disp": "m", "axle_acc": "m/s^2", "body_acc": "m/s^2", "dcdc_y": "m",
         "dcdc_z": "m", "speed": "m/s"}


def unit_of(name: str) -> str:
    """SI unit of a channel name (``susp_disp_3L`` -> ``m``)."""
    for prefix, unit in UNITS.items():
        if name == prefix or name.startswith(prefix + "_"):
            return unit
    raise KeyError(f"no unit known for channel {name!r}")


@dataclass
class SimResult:
    """Sampled outputs of one simulation.

    Attributes
    ----------
    time : ndarray (N,)
        Sample times [s], uniform, starting at 0.
    channels : dict of str -> ndarray (N,)
        ``susp_disp_<a><L|R>`` [m] (axle relative to the body above it, positive in
        compression, zero at static equilibrium on a flat road),
        ``axle_acc_<a><side>`` and ``body_acc_<a><side>`` [m/s^2] (vertical, up,
        gravity removed), ``dcdc_y_P<k>``, ``dcdc_z_P<k>`` [m] (tractor: lateral and
        vertical displacement of DCDC top point k from its static position) and
        ``speed`` [m/s] (the recorded speed signal).
    units : dict of str -> str
    meta : dict
        ``vehicle`` (id), ``chassis``, ``effects`` (resolved parameters), ``dt`` [s],
        ``fs_out`` [Hz], ``duration`` [s], ``steps``, ``wall_s`` [s], ``realtime_factor``
        (simulated seconds per wall-clock second), ``n_dof``, ``speed_mean`` [m/s],
        ``x_start`` [m], ``y_offset`` [m], ``tyre_lift_off_fraction`` (share of samples
        in which some tyre carries no force), ``tyre_pull_fraction`` (share in which a
        linear tyre would pull), ``tyres`` (``"unilateral"`` or ``"bilateral"``),
        ``tyre_contact_run`` (``"linear"`` or ``"unilateral"``: the run kept),
        ``tyre_off_steps``, ``seed``, versions.
    extra : dict of str -> ndarray
        Not dataset channels: ``dcdc_ref`` (N, 6) rigid-body motion of the DCDC block's
        top-face centre from static, columns ``Tx, Ty, Tz`` [m], ``Rx, Ry, Rz`` [rad]
        (small-angle rotation); ``dcdc_points`` (4, 3) the characteristic points'
        positions relative to the top-face centre [m] (vehicle axes);
        ``dcdc_ref_acc`` (N, 6) accelerations of the same [m/s^2, rad/s^2];
        ``dcdc_ref_vel`` (N, 3) angular velocity [rad/s];
        ``road_z`` (N, n_contacts) road height under each tyre [m] (as seen by the
        model, after the footprint filter); ``tyre_force`` (N, n_contacts) dynamic
        tyre force change [N] (of the one-sided tyre when the corrected run was kept);
        ``tyre_off`` (N,) bool: some tyre carries no force.
    vehicle : VehicleParams or None
        The (effect-modified) vehicle that was simulated.
    nominal_vehicle : VehicleParams or None
        The vehicle as given to ``simulate`` (before effects): the one a dataset
        names as its nominal vehicle.
    """

    time: np.ndarray
    channels: dict
    units: dict
    meta: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)
    vehicle: object = None
    nominal_vehicle: object = None

    @property
    def sample_rate_hz(self) -> float:
        return float(self.meta.get("fs_out", 1.0 / (self.time[1] - self.time[0])))

    def __getitem__(self, name: str) -> np.ndarray:
        return self.channels[name]

    @property
    def channel_names(self) -> list:
        return list(self.channels)

    def to_dataframe(self):
        """DataFrame with ``time`` [s] first, then every channel (``speed`` last).

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        cols = {"time": self.time}
        names = [n for n in self.channels if n != "speed"]
        if "speed" in self.channels:
            names.append("speed")
        for n in names:
            cols[n] = self.channels[n]
        return pd.DataFrame(cols)

    def save_dataset(self, folder, name: str | None = None, vehicle=None, *,
                     overwrite: bool = False, description: str | None = None,
                     add_files=None, start_time_s: float | None = None) -> Path:
        """Write the measurement-dataset folder (channels.csv, meta.toml).

        Parameters
        ----------
        folder : str or Path
            Target folder; refused if it exists and is not empty, unless ``overwrite``.
        name : str, optional
            Dataset name (default: the folder name).
        vehicle : str or Path, optional
            A built-in vehicle id (written to meta) or a vehicle TOML file (copied to
            ``vehicle.toml``).  Default: the nominal vehicle (as given to
            ``simulate``, before effects): its id if it equals the built-in vehicle,
            otherwise its parameters written to ``vehicle.toml``.
        overwrite : bool
        description : str, optional
        add_files : callable, optional
            ``f(tmp_folder)`` adding files (e.g. ``truth/``) inside the atomic write.
        start_time_s : float, optional
            Written as ``start_time_s``.

        Returns
        -------
        Path
            The dataset folder.
        """
        import tempfile

        from drives.format import write_drive

        from vehicles.params import builtin_ids, load_vehicle, save_vehicle

        vfile, vid, tmpdir = None, None, None
        if vehicle is not None:
            if str(vehicle) in builtin_ids():
                vid = str(vehicle)
            else:
                vfile = Path(vehicle)
        else:
            nom = self.nominal_vehicle
            if nom is not None and nom.id in builtin_ids() and nom == load_vehicle(nom.id):
                vid = nom.id
            elif nom is not None:   # a variant or a file: write its parameters
                tmpdir = tempfile.TemporaryDirectory()
                vfile = save_vehicle(nom, Path(tmpdir.name) / "vehicle.toml")
            else:
                vid = self.meta.get("vehicle")
        meta = {"name": name or Path(folder).name, "sample_rate_hz": self.sample_rate_hz}
        if vid is not None:
            meta["vehicle"] = str(vid)
        if "speed" not in self.channels:
            meta["speed_mps"] = float(self.meta.get("speed_mean", 0.0))
        meta["description"] = description or (
            f"eroad simulation: {self.meta.get('vehicle')} ({self.meta.get('chassis')} chassis), "
            f"effects {json.dumps(self.meta.get('effects', {}))}")
        if start_time_s is not None:
            meta["start_time_s"] = float(start_time_s)
        try:
            return write_drive(folder, self.to_dataframe(), meta, vehicle_file=vfile,
                               overwrite=overwrite, add_files=add_files)
        finally:
            if tmpdir is not None:
                tmpdir.cleanup()

    def summary(self) -> dict:
        """JSON-ready summary: timing, sizes and the RMS of every channel."""
        out = {k: v for k, v in self.meta.items() if isinstance(v, (int, float, str, bool, dict, list))}
        out["channels"] = {n: {"unit": self.units.get(n, ""), "rms": float(np.sqrt(np.mean(v ** 2))),
                               "mean": float(np.mean(v))} for n, v in self.channels.items()}
        return out
