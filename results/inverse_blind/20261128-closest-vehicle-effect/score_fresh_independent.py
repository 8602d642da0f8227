"""The fresh independent-truck closed loop (seeds 53-72, fresh-independent-53-72/; run before either
change of this folder, with main at bb8925d): scored per channel set as the loop fits it ('none':
linear/axles, 'unexplained': linear/axle3_acc), with the 'unexplained' drives' intervals carrying the
open term (stop 47) and the 'unexplained' term (today). Neither change alters a fit here: the
closest-effect rule fires on none of the 20 drives (verdicts.txt). Segments >= 3 s; --profile: the
measured-road drives' fitted segments against the profile. Run from the repository root."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
sys.path.insert(0, str(HERE.parent / '20261128-correct-on-ambiguous'))
from calibrate_uncertainty import accuracy, load  # noqa: E402
from compose_unexplained import cov  # noqa: E402


def main(root=HERE / 'fresh-independent-53-72', profile=False):
    rec = {json.loads(l)['seed']: json.loads(l) for l in (Path(root) / 'results.jsonl').read_text().splitlines()}
    rows = load(Path(root), profile=profile)
    verdict = {s: c['closed_loop']['verdict'] for s, c in rec.items()}
    for label, form in (('stop 47 (open term)', 'open'), ('today (unexplained term)', 'unexplained')):
        g = {'linear/axles': [r for r in rows if verdict[r['seed']] == 'none'],
             'linear/axle3_acc': [dict(r, model_form=form) for r in rows if verdict[r['seed']] == 'unexplained'],
             'linear': [r for r in rows if verdict[r['seed']] not in ('none', 'unexplained')]}
        a = accuracy(rows)
        print(f"{'profile ' if profile else ''}{label}: {len(rows)} segments; G(1 cycle/m) within 20 % "
              f"{100 * a['g1'][0]:.1f} %, class right {100 * a['class'][0]:.1f} %; 90 % intervals cover "
              f"{cov(g)} % (ln Gq(n0) / w / ln G(n_best))")


if __name__ == '__main__':
    main(profile='--profile' in sys.argv)
