#!/bin/bash
source /work/venv/bin/activate
set -u
cases="null:201: null:202: second:203: second:204: null:205:leaf_friction=3000 null:206:leaf_friction=3000 second:207:leaf_friction=3000 second:208:payload=3000"
for c in $cases; do
  fam=${c%%:*}; rest=${c#*:}; seed=${rest%%:*}; eff=${rest#*:}
  name=$fam-$seed${eff:+-$eff}
  if [ -n "$eff" ]; then eroad synth --scenario $fam --seed $seed --duration 30 --effect $eff --out full-$name > /dev/null 2>&1; else eroad synth --scenario $fam --seed $seed --duration 30 --out full-$name > /dev/null 2>&1; fi
  python - "$name" <<'PY'
import sys, shutil, pandas as pd, pathlib
name=sys.argv[1]; src=pathlib.Path(f"full-{name}"); dst=pathlib.Path(f"ax3-{name}")
if dst.exists(): shutil.rmtree(dst)
dst.mkdir(); shutil.copy(src/"meta.toml", dst/"meta.toml")
df=pd.read_csv(src/"channels.csv")
keep=["time"]+[c for c in df.columns if c.endswith(("3L","3R"))]+["speed"]
df[keep].to_csv(dst/"channels.csv", index=False, float_format="%.10g")
PY
  start=$(date +%s)
  eroad diagnose ax3-$name --out diag-ax3-$name --quiet > /dev/null 2>&1
  echo "$name rc=$? $(( $(date +%s) - start )) s: $(python3 -c "import json;s=json.load(open('diag-ax3-$name/summary.json'));print(s['verdict'], s.get('verdict_confidence'))" 2>&1)"
done
