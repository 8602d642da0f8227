import sys, time, numpy as np
from roadlib.surface import RoadSurface
from studies.pantograph_contact import contact_drive
road = RoadSurface.load(sys.argv[1])
for fr in (0.0, 20.0):
    for dt in (1e-3, 5e-4, 2.5e-4):
        w0 = time.perf_counter()
        o = contact_drive(road, speed_kmh=80, frame_friction=fr, dt=dt, compare_static=False)
        s = o["stats"]
        print(f"friction {fr:g} N dt {dt:g}: sd {s['sd']:.3f} mean {s['mean']:.3f} loss {s['loss_percent']:.3f} % min {s['actual_min']:.2f} max {s['actual_max']:.2f}  ({time.perf_counter()-w0:.0f} s)", flush=True)
