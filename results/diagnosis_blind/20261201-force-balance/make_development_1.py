from drives.synth import synth_command
for scen, seed, eff in [("null", 951, ()), ("null", 952, ("leaf_friction.force=1000",)),
                        ("second", 953, ()), ("second", 954, ("leaf_friction.force=1000",)),
                        ("null", 955, ("leaf_friction.force=3000",)), ("second", 956, ("leaf_friction.force=3000",)),
                        ("null", 957, ("payload.mass=8000",)), ("second", 958, ("payload.mass=8000",))]:
    synth_command(scenario=scen, seed=seed, effects=eff, out=f"/work/ff74/{scen}-{seed}", force=True)
    print(scen, seed, eff, flush=True)
