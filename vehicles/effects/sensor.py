"""Effect ``sensor``: sensor dynamics (low-pass) and noise on the measurement channels."""
from __future__ import annotations

import numpy as np

from vehicles.effects.base import Effect, Parameter

#: spawn key of the sensor-noise stream: SeedSequence(seed, spawn_key=SENSOR_SPAWN_KEY)
SENSOR_SPAWN_KEY = (0x5E45,)
#: channel prefixes the sensors measure
MEASURED = ("susp_disp_", "axle_acc_", "body_acc_")


class Sensor(Effect):
    """Second-order Butterworth low-pass and white noise, seeded."""

    name = "sensor"
    description = (
        "Sensor dynamics and noise on the measurement channels (susp_disp, axle_acc, "
        "body_acc; not speed or the DCDC points): a causal 2nd-order Butterworth low-pass "
        "with -3 dB at 'cutoff' (attenuates and delays the band above it) and white Gaussian "
        "noise (a floor in the PSD, seeded from the run's seed with spawn key "
        "SENSOR_SPAWN_KEY, one stream per channel in channel order).")
    parameters = (
        Parameter("cutoff", "Hz", 40.0, (1.0, 1000.0),
                  "-3 dB frequency of the low-pass (no filter at or above fs/2)"),
        Parameter("acc_noise", "m/s^2", 0.05, (0.0, 5.0), "noise std of acceleration channels"),
        Parameter("disp_noise", "m", 2.0e-4, (0.0, 0.01), "noise std of displacement channels"),
    )
    primary = "cutoff"
    order = 80

    def outputs(self, time, channels, p, ctx):
        from scipy import signal

        fs = ctx.fs_out
        names = [n for n in channels if n.startswith(MEASURED)]
        filt = p["cutoff"] < 0.5 * fs * 0.999
        if filt:
            b, a = signal.butter(2, p["cutoff"], fs=fs)
            zi = signal.lfilter_zi(b, a)
        else:
            ctx.notes["sensor"] = f"cutoff {p['cutoff']:g} Hz >= fs/2: no low-pass"
        streams = np.random.SeedSequence(ctx.seed, spawn_key=SENSOR_SPAWN_KEY).spawn(len(names))
        for name, ss in zip(names, streams):
            x = channels[name]
            if filt:
                x, _ = signal.lfilter(b, a, x, zi=zi * x[0])
            std = p["disp_noise"] if name.startswith("susp_disp_") else p["acc_noise"]
            if std > 0:
                x = x + std * np.random.default_rng(ss).standard_normal(x.size)
            channels[name] = x
