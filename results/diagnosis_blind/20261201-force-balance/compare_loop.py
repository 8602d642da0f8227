"""Test 1 of decision.txt: the closed loop with the force balance's friction against the control arm.

    python compare_loop.py CONTROL_ROOT TREATMENT_ROOT     # --root folders of benchmarks/bench_inverse.py

Segments >= 3 s, scored as bench_inverse scores them (results.jsonl); the force each treatment run used
(summary.json closed_loop) against the `random` truth, 2000 N per spring.
"""
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "inverse_blind" / "20261201-exact-tyre-lines"))
from compare import rows, score  # noqa: E402

TRUTH_N = 2000.0


def forces(root):
    out = {}
    for s in sorted(Path(root).glob("run-*/summary.json")):
        cl = json.loads(s.read_text()).get("closed_loop") or {}
        fb = cl.get("force_balance") or {}
        used = (cl.get("effects") or {}).get("leaf_friction", {}).get("force")
        out[int(s.parent.name.split("-")[1])] = (cl.get("verdict"), used, fb.get("force_N"), fb.get("detected"),
                                                  fb.get("available"), cl.get("reason", ""))
    return out


def main(rc, rt):
    a, b = rows(rc), rows(rt)
    keys = [k for k in sorted(set(a) & set(b)) if abs(a[k]["duration_s"] - b[k]["duration_s"]) < 1e-6]
    print(f"control {len(a)} segments >= 3 s, treatment {len(b)}, shared {len(keys)}")
    sa, sb = score(a), score(b)
    for name, s in (("control", sa), ("treatment", sb)):
        print(f"  {name}: G(1) within 20 % {round(s['g1_within20'] * s['n'])}/{s['n']} ({100 * s['g1_within20']:.1f} %), "
              f"class {round(s['class_right'] * s['n'])} ({100 * s['class_right']:.1f} %), cover "
              + " / ".join(f"{100 * c:.1f}" for c in s["cover"])
              + f" %, ln G(1) error mean {s['g1_mean_signed']:+.3f} sd {s['g1_sd']:.3f}")
    ok = True
    g_a = sum(abs(a[k]["lnG_1cpm_err"]) <= math.log(1.2) for k in keys)
    g_b = sum(abs(b[k]["lnG_1cpm_err"]) <= math.log(1.2) for k in keys)
    ok_a = g_b >= g_a
    print(f"a. G(1) within 20 % on shared segments: {g_a} -> {g_b}: {'holds' if ok_a else 'FAILS'}")
    c_a = sum(a[k]["class_fit"] == a[k]["class_true"] for k in keys)
    c_b = sum(b[k]["class_fit"] == b[k]["class_true"] for k in keys)
    ok_b = c_b >= c_a - 1
    print(f"b. class right: {c_a} -> {c_b}: {'holds' if ok_b else 'FAILS'}")
    ok_c = True
    for q, ca, cb in zip(("ln Gq(n0)", "w", "ln G(n_best)"), sa["cover"], sb["cover"]):
        out_a, out_b = max(0.0, 0.85 - ca, ca - 0.95), max(0.0, 0.85 - cb, cb - 0.95)
        good = out_b == 0.0 or out_b <= out_a + 0.03
        ok_c &= good
        print(f"c. coverage {q}: {100 * ca:.1f} -> {100 * cb:.1f} %: {'holds' if good else 'FAILS'}")
    fo, fc = forces(rt), forces(rc)
    rep = [(s, v) for s, v in fo.items() if v[1] is not None and v[2] is not None and v[3] and v[4]]
    within = sum(abs(math.log(v[1] / TRUTH_N)) <= math.log(1.2) for _, v in rep)
    ok_d = bool(rep) and within >= 0.9 * len(rep)
    print(f"d. force used within x1.2 of {TRUTH_N:.0f} N where the balance replaced it: {within}/{len(rep)}: "
          f"{'holds' if ok_d else 'FAILS'}")
    print("\n| seed | verdict | control force [N] | treatment force [N] | balance [N] |")
    print("|---|---|---|---|---|")
    for s in sorted(fo):
        c = fc.get(s, (None, None))[1]
        v = fo[s]
        print(f"| {s} | {v[0]} | {'-' if c is None else f'{c:.0f}'} | {'-' if v[1] is None else f'{v[1]:.0f}'} | "
              f"{'-' if v[2] is None else f'{v[2]:.0f}'} |")
    lc = [math.log(fc[s][1] / TRUTH_N) for s in fc if fc[s][1]]
    lt = [math.log(fo[s][1] / TRUTH_N) for s in fo if fo[s][1]]
    print(f"rms ln(force / truth): control {np.sqrt(np.mean(np.square(lc))):.3f} ({len(lc)} drives), "
          f"treatment {np.sqrt(np.mean(np.square(lt))):.3f} ({len(lt)})")
    ok &= ok_a and ok_b and ok_c and ok_d
    print("decision.txt test 1:", "every bar holds -> the rule stays on" if ok else "a bar fails -> the rule is off")


if __name__ == "__main__":
    main(*sys.argv[1:3])
