"""Material.eval against real Radiance: live rtrace (the PyPI package
pyradiance's Radiance 6.0a binaries, driven by ../shared/oracle's
rtrace_oracle.py as the Rust tests do), and the oracle's rtrace tables."""

from __future__ import annotations

import csv
import math
import os
import sys

import numpy as np
import pytest

import brtf
from conftest import SHARED

ORACLE = SHARED / "oracle"
APEX_DEG = 0.01  # the oracle's source: a 0.01° disc
OMEGA = 2 * math.pi * (1 - math.cos(math.radians(APEX_DEG) / 2))
REL, ABS = 1e-5, 1e-9


def oracle_module(radiance_bin):
    if not (ORACLE / "rtrace_oracle.py").is_file():
        pytest.fail(f"{ORACLE}/rtrace_oracle.py is missing")
    os.environ["RADIANCE_BIN"] = str(radiance_bin)
    os.environ.setdefault("RAYPATH", f".:{radiance_bin.parent / 'lib'}")
    sys.path.insert(0, str(ORACLE))
    try:
        import rtrace_oracle
    finally:
        sys.path.remove(str(ORACLE))
    return rtrace_oracle


CASES = [
    ("plastic", [0.6, 0.5, 0.4, 0.05, 0.08], None),
    ("metal", [0.9, 0.8, 0.7, 0.9, 0.05], None),
    ("metal", [0.95, 0.64, 0.54, 0.9, 0.0], None),
    ("trans", [0.6, 0.7, 0.8, 0.04, 0.1, 0.5, 0.3], None),
    ("plastic2", [0.5, 0.5, 0.5, 0.05, 0.05, 0.2], [0.3, 1.0, 0.0]),
    ("metal2", [0.8, 0.6, 0.4, 0.8, 0.1, 0.03], [1.0, 0.0, 0.0]),
    ("trans2", [0.6, 0.6, 0.6, 0.03, 0.07, 0.15, 0.6, 0.4], [0.0, 1.0, 0.0]),
]
GRID = [(t, p) for t in (0.0, 15.0, 35.0, 60.0, 80.0, 120.0, 165.0) for p in (0.0, 90.0, 180.0, 250.0)]


@pytest.mark.parametrize("kind, args, orientation", CASES, ids=[f"{c[0]}-{i}" for i, c in enumerate(CASES)])
@pytest.mark.parametrize("incidence", [(0.0, 0.0), (30.0, 0.0), (55.0, 120.0)])
def test_eval_matches_live_rtrace(radiance_bin, kind, args, orientation, incidence):
    oracle = oracle_module(radiance_bin)
    spec = oracle.Material(kind, args, orientation or (1.0, 0.0, 0.0))
    want = np.array(oracle.brdf(spec, *incidence, GRID))
    material = brtf.Material(kind, args=args, orientation=orientation, fresnel_k="pyradiance", source_omega=OMEGA)
    theta, phi = np.array(GRID).T
    got = material.eval(*incidence, theta, phi)
    assert np.count_nonzero(want) > 0
    ok = (np.abs(got - want) <= ABS) | (np.abs(got - want) <= REL * np.abs(want))
    assert ok.all(), f"brtf {got[~ok]} vs rtrace {want[~ok]}"


@pytest.mark.parametrize("kind", ["plastic", "metal", "trans", "plastic2", "metal2", "trans2"])
def test_eval_matches_the_oracle_tables(kind):
    path = ORACLE / "ref" / f"{kind}.csv"
    if not path.is_file():
        pytest.fail(f"{path} is missing")
    groups: dict = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            groups.setdefault((r["args"], r["orient"]), []).append(r)
    rows = 0
    for (args, orient), records in groups.items():
        material = brtf.Material(
            kind,
            args=[float(a) for a in args.split()],
            orientation=[float(o) for o in orient.split()] if orient.strip() else None,
            fresnel_k="pyradiance",
            source_omega=OMEGA,
        )
        col = lambda k: np.array([float(r[k]) for r in records])  # noqa: E731
        got = material.eval(col("theta_in"), col("phi_in"), col("theta_out"), col("phi_out"))
        want = np.stack([col("brdf_r"), col("brdf_g"), col("brdf_b")], axis=-1)
        ok = (np.abs(got - want) <= ABS) | (np.abs(got - want) <= REL * np.abs(want))
        assert ok.all(), f"{kind} {args}: brtf {got[~ok][:5]} vs rtrace {want[~ok][:5]}"
        rows += len(records)
    assert rows > 5000
