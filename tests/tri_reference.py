#!/usr/bin/env python3
"""tri_reference.py -- the point-to-triangle kernel against exact rational arithmetic.

usage: tri_reference.py TRI_CASES [--cases N] [--seed S]

Draws N seeded cases from the families below, runs the kernel on them through
the filter program TRI_CASES (tests/internal/tri_cases.c: fast path with its
exact fallback, then the exact path alone), and checks every distance against
a reference computed here with Python integers, which are exact, by a route
of its own: the closest point is a corner, a point inside an edge (the
parameter of the orthogonal projection, strictly between 0 and 1) or the
projection onto the plane when its barycentric coordinates, from the 2x2
normal equations of the Gram matrix, are all non-negative; the squared
distance is the least of those candidates, a ratio of integers; and its
square root is rounded to the nearest double, ties to even, from an integer
square root with a sticky bit. It also checks that the plain-double bounds
hd__tri_bounds gives contain the exact squared distance, as rationals. Every double is an integer over a power of
two, so scaling all twelve coordinates by their common denominator makes
every quantity an integer.

The families: uniform, points near the face, an edge or a corner (offsets
from 2^-50 to 1), slivers, needles, exactly collinear corners, coincident
corners, a repeated corner, integer lattices, one scale from 1e-300 to 1e150
per case, coordinates of mixed scales within a case, and distances placed on
and next to the midpoint between two doubles (Pythagorean triples with a
54-bit odd hypotenuse). It prints how often the exact path decided in each
family, and "N passed, M failed" last.
"""
import argparse
import math
import random
import struct
import subprocess
import sys
from math import isqrt

FAMILIES = ["uniform", "near face", "near edge", "near corner", "sliver", "needle",
            "collinear", "coincident", "repeated corner", "lattice", "one scale",
            "mixed scales", "midpoint"]


# ---- the reference -----------------------------------------------------------

def as_integers(values):
    """The values as integers over one power-of-two denominator."""
    ratios = [v.as_integer_ratio() for v in values]
    den = max(d for _, d in ratios)
    return [n * (den // d) for n, d in ratios], den


def sub(u, v):
    return (u[0] - v[0], u[1] - v[1], u[2] - v[2])


def dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def least(cands):
    """The least of fractions given as (numerator, denominator > 0)."""
    bn, bd = cands[0]
    for n, d in cands[1:]:
        if n * bd < bn * d:
            bn, bd = n, d
    return bn, bd


def squared_distance(p, a, b, c):
    """Exact squared distance from p to the closed triangle abc, as (num, den)."""
    cands = [(dot(sub(p, v), sub(p, v)), 1) for v in (a, b, c)]
    for x, y in ((a, b), (b, c), (c, a)):
        xy, xp = sub(y, x), sub(p, x)
        den, num = dot(xy, xy), dot(xp, xy)
        if den > 0 and 0 < num < den:
            cands.append((dot(xp, xp) * den - num * num, den))
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    g11, g12, g22 = dot(ab, ab), dot(ab, ac), dot(ac, ac)
    det = g11 * g22 - g12 * g12
    if det > 0:
        r1, r2 = dot(ab, ap), dot(ac, ap)
        s = g22 * r1 - g12 * r2
        t = g11 * r2 - g12 * r1
        if s >= 0 and t >= 0 and s + t <= det:
            q = tuple(det * ap[i] - s * ab[i] - t * ac[i] for i in range(3))
            cands.append((dot(q, q), det * det))
    return least(cands)


def round_to_double(s, sticky, exp):
    """The double nearest (s + f) 2^exp, f = 0 if not sticky else in (0, 1)."""
    if s == 0:
        return 0.0
    top = s.bit_length() - 1 + exp                  # the value lies in [2^top, 2^(top+1))
    g = max(top - 52, -1074)                        # the last bit a double keeps there
    shift = g - exp
    assert shift >= 2
    q, rem = s >> shift, s & ((1 << shift) - 1)
    half = 1 << (shift - 1)
    if rem > half or (rem == half and sticky) or (rem == half and not sticky and q & 1):
        q += 1
    return math.ldexp(q, g)


def reference(case):
    """The correctly rounded distance and the exact squared distance (num, den)."""
    ints, den = as_integers(case)
    p, a, b, c = (tuple(ints[i:i + 3]) for i in range(0, 12, 3))
    num, d = squared_distance(p, a, b, c)
    qden = d * den * den                            # t^2 = num / qden
    if num == 0:
        return 0.0, (num, qden)
    k = max(0, 70 - (num.bit_length() - qden.bit_length()) // 2)
    x = num << (2 * k)
    s = isqrt(x // qden)
    return round_to_double(s, s * s * qden != x, -k), (num, qden)


def within(lo2, hi2, sq):
    """lo2 <= num / den <= hi2, exactly (hi2 may be infinite)."""
    num, den = sq
    lo_n, lo_d = lo2.as_integer_ratio()
    if lo_n * den > num * lo_d:
        return False
    if math.isinf(hi2):
        return True
    hi_n, hi_d = hi2.as_integer_ratio()
    return num * hi_d <= hi_n * den


# ---- the cases ---------------------------------------------------------------

def unit3(r):
    return [r.uniform(-1, 1) for _ in range(3)]


def axpy(x, s, y):
    return [x[i] + s * y[i] for i in range(3)]


def midpoint_case(r):
    while True:
        # u = v + d with 2 u v just below 2^53 and u^2 + v^2 = 2 u v + d^2 above it
        d = r.randrange(1 << 20, 1 << 24)
        delta = r.randrange(1, d * d)
        v = (isqrt(d * d + 2 * ((1 << 53) - delta)) - d) // 2
        u = v + d
        hyp = u * u + v * v
        if hyp >> 53 == 1 and hyp & 1 and not (2 * u * v) >> 53 and not (u * u - v * v) >> 53:
            break
    dx, dy = float(u * u - v * v), float(2 * u * v)
    nudge = r.choice((-1, 0, 1))
    if nudge:
        dy = math.nextafter(dy, math.inf if nudge > 0 else 0)
    sc = math.ldexp(1, r.randrange(-100, 100))
    a = [0.0, 0.0, 0.0]
    b = [-1 * sc, -2 * sc, -3 * sc]
    c = [-2 * sc, -1 * sc, -5 * sc]
    p = [math.ldexp(dx, -40) * sc, math.ldexp(dy, -40) * sc, 0.0]
    return p, a, b, c


def make_case(r, fam):
    a, b, c, p = unit3(r), unit3(r), unit3(r), unit3(r)
    e1, e2 = [b[i] - a[i] for i in range(3)], [c[i] - a[i] for i in range(3)]
    n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
    h = math.ldexp(1, -r.randrange(50))
    s = r.random()
    t = r.random() * (1 - s)
    name = FAMILIES[fam]
    if name == "near face":
        p = axpy(axpy(axpy(a, s, e1), t, e2), h * (r.random() - 0.5), n)
    elif name == "near edge":
        p = axpy(axpy(axpy(a, s, e1), h * (r.random() - 0.5), n), h * (r.random() - 0.5), e2)
    elif name == "near corner":
        p = [b[i] + h * (r.random() - 0.5) for i in range(3)]
    elif name == "sliver":
        c = axpy(axpy(a, 0.5, e1), math.ldexp(h, -10), n)
    elif name == "needle":
        b = [a[i] + math.ldexp(h, -10) * (r.random() - 0.5) for i in range(3)]
    elif name == "collinear":
        a = [math.floor(x * 64) for x in a]
        b = [math.floor(x * 64) for x in b]
        c = [2.0 * b[i] - a[i] for i in range(3)]
        a, b = [float(x) for x in a], [float(x) for x in b]
    elif name == "coincident":
        b, c = list(a), list(a)
    elif name == "repeated corner":
        c = list(a)
    elif name == "lattice":
        a, b, c, p = ([float(math.floor(x * 3)) for x in v] for v in (a, b, c, p))
    elif name == "one scale":
        k = 10.0 ** r.randrange(-300, 151)
        a, b, c, p = ([x * k for x in v] for v in (a, b, c, p))
    elif name == "mixed scales":
        a = [math.ldexp(x, r.randrange(-60, 60)) for x in a]
        p = [math.ldexp(x, r.randrange(-60, 60)) for x in p]
    elif name == "midpoint":
        p, a, b, c = midpoint_case(r)
    return [float(x) for x in p + a + b + c]


# ---- the run -----------------------------------------------------------------

def run_filter(prog, cases, exact):
    data = b"".join(struct.pack("<12d", *cs) for cs in cases)
    out = subprocess.run([prog] + (["--exact"] if exact else []), input=data,
                         stdout=subprocess.PIPE, check=True).stdout
    if len(out) != 25 * len(cases):
        sys.exit("tri_cases wrote %d bytes for %d cases" % (len(out), len(cases)))
    return [struct.unpack_from("<dBdd", out, 25 * i) for i in range(len(cases))]


def check_chunk(args, r, first, count, per, tally):
    """Cases first .. first + count - 1: drawn, run both ways, checked."""
    fams = [(first + i) % len(FAMILIES) for i in range(count)]
    cases = [make_case(r, f) for f in fams]
    fast = run_filter(args.prog, cases, False)
    exact = run_filter(args.prog, cases, True)
    for i, (cs, f, (d_fast, flag, lo2, hi2), (d_exact, flag2, _, _)) in enumerate(
            zip(cases, fams, fast, exact)):
        want, sq = reference(cs)
        per[FAMILIES[f]][0] += 1
        per[FAMILIES[f]][1] += flag == 1
        bounded = within(lo2, hi2, sq)
        if flag != 2 and flag2 != 2 and d_fast == want and d_exact == want and bounded:
            tally[0] += 1
            continue
        tally[1] += 1
        if tally[1] <= 10:
            print("FAIL case %d (seed %d, family %s): want %r, fast path %r, exact path %r, "
                  "bounds [%r, %r] %s; case %s"
                  % (first + i, args.seed, FAMILIES[f], want, d_fast, d_exact, lo2, hi2,
                     "hold" if bounded else "do not hold", [x.hex() for x in cs]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("prog")
    ap.add_argument("--cases", type=int, default=1000000)
    ap.add_argument("--seed", type=int, default=20261201)
    args = ap.parse_args()
    r = random.Random(args.seed)
    per = {name: [0, 0] for name in FAMILIES}
    tally = [0, 0]
    for first in range(0, args.cases, 50000):
        check_chunk(args, r, first, min(50000, args.cases - first), per, tally)
    for name in FAMILIES:
        n, e = per[name]
        print("  %-16s %7d cases, exact path decided %6.2f %%" % (name, n, 100.0 * e / max(n, 1)))
    print("%d passed, %d failed" % (tally[0], tally[1]))
    return 1 if tally[1] else 0


if __name__ == "__main__":
    sys.exit(main())
