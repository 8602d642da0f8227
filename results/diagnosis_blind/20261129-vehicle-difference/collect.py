"""Copy a bench_diagnosis work folder's results into a results folder: blind.json, bench.log,
caseNNN-summary.json and caseNNN-report.md (from caseNNN-run/)."""
import shutil, sys
from pathlib import Path
src, dst, log = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
dst.mkdir(parents=True, exist_ok=True)
shutil.copy(src / "blind.json", dst / "blind.json")
shutil.copy(log, dst / "bench.log")
for run in sorted(src.glob("case*-run")):
    k = run.name[:7]
    for f, g in (("summary.json", "summary.json"), ("report.md", "report.md")):
        if (run / f).exists():
            shutil.copy(run / f, dst / f"{k}-{g}")
            if f.endswith(".json"):   # compact, as the committed sets
                import json; p = dst / f"{k}-{g}"; d = json.load(open(p))
                d["localization"] = [r for r in d.get("localization", []) if r.get("significant")]   # the flagged cells only
                json.dump(d, open(p, "w"), separators=(",", ":"))
print(dst, len(list(dst.glob("case*-summary.json"))))
