#!/usr/bin/env python3
"""The peer brtf's fitter is measured against: the `metal` fit a researcher
would write with scipy.optimize.least_squares (bounded trust-region, vectorised
numpy model and analytic Jacobian), on the same 120 000-point data and with the
same residuals as brtf's default (relative with a floor, solid-angle weights).

Reads target/fit-bench-metal.csv (written by `cargo bench -p brtf-fit`),
prints the median time of several runs and the cost 1/2 sum r^2.
Run through scripts/bench-fit.sh, which measures brtf in the same run.
"""
import sys
import time

import numpy as np
from scipy.optimize import least_squares

FTINY = 1e-6


def load(path):
    d = np.loadtxt(path, delimiter=",", skiprows=1)
    theta_in, phi_in = np.radians(d[0, 0]), np.radians(d[0, 1])
    light = np.array([np.sin(theta_in) * np.cos(phi_in), np.sin(theta_in) * np.sin(phi_in), np.cos(theta_in)])
    return light, d[:, 2:5], d[:, 5], d[:, 6]


def setup(light, views, y, w):
    positive = np.sort(y[y > 0])
    floor = max(0.1 * positive[len(positive) // 10], 1e-12)
    sw = np.sqrt(w / w.mean())
    k = sw / np.sqrt(y * y + floor * floor)
    h = views + light
    hn = h[:, 2]
    hh = np.einsum("ij,ij->i", h, h)
    tan2 = (hh - hn * hn) / (hn * hn)
    norm = hh / (np.pi * hn ** 4)
    return k, tan2, norm


def model(p, tan2, norm):
    c, rs, a = p
    a2 = a * a
    d = norm * np.exp(-tan2 / a2) / a2
    d = np.where(d > FTINY, d, 0.0)
    return c * (1 - rs) / np.pi + c * rs * d, d


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "target/fit-bench-metal.csv"
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    light, views, y, w = load(path)
    k, tan2, norm = setup(light, views, y, w)

    def residuals(p):
        return k * (model(p, tan2, norm)[0] - y)

    def jacobian(p):
        c, rs, a = p
        m, d = model(p, tan2, norm)
        dd_da = np.where(d > 0, d * (tan2 / (a * a) - 1) * 2 / a, 0.0)
        return np.column_stack([
            k * ((1 - rs) / np.pi + rs * d),
            k * (-c / np.pi + c * d),
            k * c * rs * dd_da,
        ])

    times, result = [], None
    for _ in range(runs):
        t0 = time.perf_counter()
        result = least_squares(residuals, [0.5, 0.5, 0.1], jac=jacobian,
                               bounds=([0, 0, 0.002], [1, 1, 1]), method="trf",
                               ftol=1e-12, xtol=1e-12, gtol=1e-14)
        times.append(time.perf_counter() - t0)
    c, rs, a = result.x
    if len(sys.argv) > 3:
        import json
        with open(sys.argv[3]) as f:
            brtf_ms = json.load(f)["median"]["point_estimate"] / 1e6
        print(f"brtf (criterion median): {brtf_ms:.1f} ms; scipy median {1e3 * np.median(times):.1f} ms; "
              f"ratio {1e3 * np.median(times) / brtf_ms:.1f}x")
    print(f"scipy least_squares (trf, analytic jacobian): median {1e3 * np.median(times):.1f} ms "
          f"over {runs} runs; colour {c:.5f} spec {rs:.5f} rough {a:.5f} cost {result.cost:.6e} "
          f"nfev {result.nfev}")


if __name__ == "__main__":
    main()
