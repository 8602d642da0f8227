"""Pooled counts over saved blind sets, each summary re-decided with the code's verdict rules
(``diagnosis.blind.rescore``) and scored as the benchmark scores (``diagnosis.blind.score``):
python pool.py DIR [DIR ...]

Per family (nominal, second, with "/measured" for drives over the measured road profile): library
effects named right, the same on drives whose truth passes the benchmark's noise gate (the truth's
own effect at its true value improves the held-out gap by more than ``Z_PAIRED`` sd of its paired
noise: the score's "detectable"), no-effect drives answered none/unexplained, wrong names and clear
wrong names."""
import sys

from diagnosis.blind import rescore, score, wrong_name


def main(dirs):
    groups = {}
    for d in dirs:
        for r in rescore(d)["results"]:
            key = r.get("family", "nominal") + ("/measured" if "measured" in r.get("scenario", "") else "")
            groups.setdefault(key, []).append(r)
    for key, rs in sorted(groups.items()):
        sc = score(rs)
        eff = [r for r in rs if r["effect"] != "none"]
        nul = [r for r in rs if r["effect"] == "none"]
        det = round(sc["detectable_top1_accuracy"] * sc["n_detectable"]) if sc["n_detectable"] else 0
        print(f"{key}: library effects right {sum(r['correct'] for r in eff)}/{len(eff)}, of those the "
              f"truth shows {det}/{sc['n_detectable']}, no effect none/unexplained "
              f"{sum(r['correct'] for r in nul)}/{len(nul)}, wrong names {sum(wrong_name(r, r['verdict']) for r in rs)}, "
              f"clear wrong {sc['confident_wrong']}")


if __name__ == "__main__":
    main(sys.argv[1:])
