"""rtrace's BRDF evaluation rate on this machine: the anchor that the
brtf-model `eval/*` benchmarks are compared with.

One rtrace process per run traces N eye rays at the oracle scene
(shared/oracle/rtrace_oracle.py, one polygon under a distant source);
each eye ray gives one BRDF value (eye ray + shadow ray). The time is the
whole process (start-up, octree load, pipes), best of --runs.

    .venv/bin/python crates/model/benches/rtrace_rate.py [--n 1000000] [--runs 3]
"""
import argparse
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', '..', '..', '..', 'shared', 'oracle'))
import rtrace_oracle as ro  # noqa: E402

# The materials of crates/model/benches/main.rs.
MATERIALS = {
    'plastic': [0.5, 0.4, 0.3, 0.05, 0.1],
    'metal': [0.9, 0.8, 0.7, 0.9, 0.1],
    'trans': [0.8, 0.8, 0.8, 0.05, 0.1, 0.5, 0.5],
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--n', type=int, default=1_000_000)
    ap.add_argument('--runs', type=int, default=3)
    ap.add_argument('--types', nargs='+', default=['metal'])
    a = ap.parse_args()
    rng = random.Random(1)
    outs = []
    for _ in range(a.n):
        # Views over both hemispheres, away from the grazing plane.
        t = rng.uniform(0.5, 179.5)
        if abs(t - 90.0) < 0.5:
            t += 1.0
        outs.append((0, ro.sph2vec(t, rng.uniform(0.0, 360.0))))
    for name in a.types:
        m = ro.Material(name, MATERIALS[name])
        best = math.inf
        with ro.RtraceRunner([m], 30.0, 0.0) as rr:
            for _ in range(a.runs):
                rr.radiance(outs)
                best = min(best, rr.last_rtrace_seconds)
        print('%s: %d evaluations in %.3f s (best of %d): %.3f M/s'
              % (name, a.n, best, a.runs, a.n / best / 1e6))


if __name__ == '__main__':
    main()
