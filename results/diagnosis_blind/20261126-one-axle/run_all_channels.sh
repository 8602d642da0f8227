#!/bin/bash
source /work/venv/bin/activate
while pgrep -f "run.sh" > /dev/null; do sleep 5; done
for d in full-*; do
  name=${d#full-}
  start=$(date +%s)
  eroad diagnose $d --out diag-full-$name --quiet > /dev/null 2>&1
  echo "$name rc=$? $(( $(date +%s) - start )) s: $(python3 -c "import json;s=json.load(open('diag-full-$name/summary.json'));print(s['verdict'], s.get('verdict_confidence'))" 2>&1)"
done
