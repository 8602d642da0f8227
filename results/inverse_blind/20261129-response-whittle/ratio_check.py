"""Measured axle-3 acceleration periodogram over the linear model's expected one at the TRUE road parameters,
per frequency band, on the segments >= 3 s of null seed 101 (python ratio_check.py DATA_ROOT, from the
repository root; DATA_ROOT as made by response_whittle.py)."""
import sys, math, numpy as np
sys.path.insert(0,'.'); sys.path.insert(0,'results/inverse_blind/20261129-response-whittle')
from drives.format import read_drive
from drives.synth import read_truth
from vehicles.linear import linear_model
from scipy.signal.windows import tukey
lm=linear_model('dump_truck_8x4')
for seed in (101,):
    ds=f'{sys.argv[1]}/null-{seed}'; dr=read_drive(ds); tr=read_truth(ds)
    t=np.asarray(dr.time); v=np.asarray(dr.speed)
    for s in tr['segments']:
        if s['t_end']-s['t_start']<3: continue
        m=(t>=s['t_start'])&(t<s['t_end']); vs=v[m]
        win=tukey(m.sum(),0.2); f=np.fft.rfftfreq(m.sum(),1/200.); scale=1/(200*np.sum(win**2))
        H=lm.frf(f,['axle_acc_3L','axle_acc_3R'])
        P=np.zeros((2,f.size))
        for sp in np.quantile(vs,[1/6,.5,5/6]):
            S=lm.road_cross_spectrum({'Gq_n0':s['Gq_n0'],'w':s['w'],'nmin':s['nmin'],'nmax':s['nmax'],'lam':1.0},sp,f)
            P+=np.einsum('fod,fod->fo',H@S,H.conj()).real.T/3
        E=P+0.03**2/100
        for j,c in enumerate(['axle_acc_3L','axle_acc_3R']):
            x=dr.channels[c].to_numpy()[m]; x=x-x.mean(); I=2*scale*np.abs(np.fft.rfft(x*win))**2
            r=I/E[j]
            edges=[1.5,3,6,10,15,20,30,45,70,99]
            print(seed, round(s['t_end']-s['t_start'],1), c, 'v %.1f-%.1f'%(vs.min(),vs.max()), ' '.join('%g-%g:%.2f'%(edges[k],edges[k+1],np.mean(r[(f>=edges[k])&(f<edges[k+1])])) for k in range(len(edges)-1)))
