from drives.synth import synth_command
for scen, seed, eff in [("null", 961, ("damper_asymmetry.ratio=3",)), ("null", 962, ("bump_stop.gap=0.01",)),
                        ("null", 963, ("sensor.cutoff=10",)), ("null", 964, ("tyre_enveloping.length=0.3",)),
                        ("null", 965, ("frame_flex.stiffness_factor=3",)), ("null", 966, ("speed_scale.factor=1.05",)),
                        ("null_measured", 967, ()), ("second_measured", 968, ()),
                        ("null", 969, ("leaf_friction.force=500",)), ("second", 970, ("leaf_friction.force=600",)),
                        ("null", 971, ("frame_flex.stiffness_factor=20",)), ("null", 972, ("sensor.cutoff=40",))]:
    synth_command(scenario=scen, seed=seed, effects=eff, out=f"/work/ff74/{scen}-{seed}", force=True)
    print(scen, seed, eff, flush=True)
