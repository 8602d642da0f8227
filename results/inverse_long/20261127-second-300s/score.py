import json, math, sys
from drives.synth import read_truth
from roadlib.psd import class_of
tr=read_truth(sys.argv[1]); ts=tr['segments']
for run in sys.argv[2:]:
    s=json.load(open(run+'/summary.json'))
    ok=cl=n=0
    for t in ts:
        if t['t_end']-t['t_start']<3: continue
        ov=[max(0,min(t['t_end'],f['t_end'])-max(t['t_start'],f['t_start'])) for f in s['segments']]
        f=s['segments'][max(range(len(ov)),key=lambda i:ov[i])]
        g1t=t['Gq_n0']*10**(-t['w']); g1f=f['Gq_n0']*10**(-f['w'])
        n+=1; ok+= abs(math.log(g1f/g1t))<=math.log(1.2); cl+= class_of(t['Gq_n0'])==f['class']
    poor=sum(1 for f in s['segments'] if f.get('fit_quality',{}).get('status')=='poor')
    print(run, 'K', len(s['segments']), 'truth segments >=3 s', n, 'G(1) within 20%', ok, 'class right', cl, 'poor', poor, 'wall %.0f s'%s['timing']['total_s'])
