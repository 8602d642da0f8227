"""Paired change between two roots: segments that became / stopped being within 20 % at 1 cycle/m,
and with the class right (python paired.py ROOT_BEFORE ROOT_AFTER)."""
import math
import sys

from g1cmp import load


def main(before, after):
    a, b = load(before), load(after)
    k = sorted(set(a) & set(b))
    ok = {r: {x: (abs(d[x][0]) <= math.log(1.2), d[x][4]) for x in k} for r, d in (("a", a), ("b", b))}
    for j, name in ((0, 'G1'), (1, 'class')):
        up = sum((not ok["a"][x][j]) and ok["b"][x][j] for x in k)
        dn = sum(ok["a"][x][j] and not ok["b"][x][j] for x in k)
        print(f'{name}: n {len(k)}  gained {up}  lost {dn}')


if __name__ == '__main__':
    main(sys.argv[1], sys.argv[2])
