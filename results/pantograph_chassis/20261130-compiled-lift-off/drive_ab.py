"""One 30 s drive of the 8x4 truck on a class-D road with lift-off, the flag on and off, 4 times each
(stop 62; run from the repository root: python results/pantograph_chassis/20261130-compiled-lift-off/drive_ab.py)."""
import time, numpy as np
from roadlib.segments import RoadSegment, segmented_surface
from vehicles import linear_sim
from vehicles.simulate import simulate
road = segmented_surface([RoadSegment(Gq_n0=1024e-6, share=500.0, nmin=0.011, nmax=5)], 500.0, 3.0, 0.025, 0.1, seed=5)
T = {True: [], False: []}
for rep in range(4):
    for flag in (True, False):
        linear_sim.COMPILED_UNILATERAL = flag
        t = time.perf_counter()
        r = simulate("dump_truck_8x4", road, 12.0, 30.0, lift_off_expected=True, solver="linear")
        T[flag].append(time.perf_counter() - t)
print({k: [round(x, 3) for x in v] for k, v in T.items()}, "off steps", r.meta["tyre_off_steps"])
print("median ratio numpy/compiled:", np.median(T[False][1:]) / np.median(T[True][1:]))
