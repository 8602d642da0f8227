"""Issue 15's targets on a pool of saved blind sets, read as decision.txt fixes them:
python decide.py DIR [DIR ...]   (each DIR a bench_diagnosis output folder with blind.json)

Every summary is re-decided with the code's verdict rules (``diagnosis.blind.rescore``) as pool.py
does. Groups are truth models: our truck (family ``nominal`` or ``measured``) and the independent truck
(``second``),
each on ISO roads and on the measured road profile (scenario contains "measured"). Prints each count
with its Clopper-Pearson 95 % interval and, per criterion, whether the point estimate meets it."""
import json
import sys
from pathlib import Path

from scipy.stats import beta

from diagnosis.blind import rescore, wrong_name


def cp(k, n, a=0.05):
    lo = beta.ppf(a / 2, k, n - k + 1) if k > 0 else 0.0
    hi = beta.ppf(1 - a / 2, k + 1, n - k) if k < n else 1.0
    return lo, hi


def frac(k, n):
    if n == 0:
        return "0/0"
    lo, hi = cp(k, n)
    return f"{k}/{n} = {100 * k / n:.1f} % (95 % CI {100 * lo:.0f}-{100 * hi:.0f} %)"


def truth_model(r):
    """The benchmark labels our truck's drives over the measured profile family "measured" (the
    independent truck's keep "second"): both are told apart from ISO drives by their scenario."""
    return "second" if r.get("family") == "second" else "nominal"


def main(dirs):
    rows, times = [], []
    for d in dirs:
        rows += rescore(d)["results"]
        times += [r.get("diagnose_s") for r in json.loads((Path(d) / "blind.json").read_text())["results"]
                  if r.get("diagnose_s") is not None]

    def pick(family, road):
        return [r for r in rows if truth_model(r) == family
                and (road == "all" or ("measured" in r.get("scenario", "")) == (road == "measured"))]

    checks = []
    for family, label in (("nominal", "our truck"), ("second", "independent truck")):
        for road in ("iso", "measured", "all"):
            rs = pick(family, road)
            eff = [r for r in rs if r["effect"] != "none"]
            nul = [r for r in rs if r["effect"] == "none"]
            k1 = sum(r["correct"] for r in eff)
            kn = sum(r["correct"] for r in nul)
            right = [r for r in eff if r["correct"] and r.get("param_ratio") is not None]
            kv = sum(1 / 1.5 <= r["param_ratio"] <= 1.5 for r in right)
            wrong = sum(wrong_name(r, r["verdict"]) for r in rs)
            print(f"{label}, {road} roads: top-1 {frac(k1, len(eff))}; no effect none/unexplained "
                  f"{frac(kn, len(nul))}; values x1.5 {frac(kv, len(right))}; wrong names {wrong}")
            if eff and road != "measured":
                checks.append((f"top-1 >= 90 %, {label}, {road} roads", k1 / len(eff) >= 0.9))
            if nul:
                checks.append((f"none/unexplained >= 90 %, {label}, {road} roads", kn / len(nul) >= 0.9))
            if right and road == "iso":
                checks.append((f"values x1.5 >= 80 %, {label}, ISO roads", kv / len(right) >= 0.8))
    clear_wrong = sum(bool(r.get("confident_wrong")) for r in rows)
    checks.append((f"no clear wrong name ({clear_wrong})", clear_wrong == 0))
    checks.append((f"<= 120 s per diagnosis (max {max(times):.1f} s, mean {sum(times) / len(times):.1f} s, "
                   f"{len(times)} drives)", max(times) <= 120))
    print()
    for text, ok in checks:
        print(f"{'met   ' if ok else 'MISSED'} {text}")
    print("\nissue 15:", "every target met on the pool" if all(ok for _, ok in checks) else "not every target met")


if __name__ == "__main__":
    main(sys.argv[1:])
