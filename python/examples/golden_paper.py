"""Fit Radiance's metal to a real pgII scan, plot the in-plane cut, export.

    python python/examples/golden_paper.py [--data golden_paper.txt] [--out DIR]

This is the worked example of docs/python.md; scripts/test.sh runs it.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt
import numpy as np

import brtf

here = Path(__file__).resolve()
parser = argparse.ArgumentParser()
parser.add_argument(
    "--data",
    type=Path,
    default=here.parents[3] / "shared/data/rgl-epfl-pgII-raw/golden_paper.txt",
)
parser.add_argument("--out", type=Path, default=Path("golden_paper-python"))
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

# 1. Read the scan: 127 039 samples of raw detector current (µA).
scan = brtf.read(args.data)
print(scan)
print("sample:", scan.header["sample_name"], "| lamp:", scan.header["lamp"])

# 2. Fit a grey metal, as `brtf fit golden_paper.txt --model metal --gray`.
fit = brtf.fit([scan], model="metal", gray=True)
result = fit.incidences[0]
print(result)
for name, value in result.params.items():
    error = result.stderr[name]  # None: fixed, or at a bound
    print(f"  {name:5} = {value:.4f}" + (f" ± {error:.1e}" if error is not None else ""))
# Raw data: `scale` is the instrument's unknown factor, fitted freely.

# 3. The in-plane cut: samples within 1° of the plane of incidence, with
#    θ_out signed (negative on the side of the light), data against model.
#    The data are raw current ∝ BSDF · cos θ_out, the model is the BSDF:
#    model in data units = scale · BSDF · cos θ_out.
phi = scan.phi
in_plane = (np.abs(phi - 180.0) < 1.0) | (np.minimum(phi, 360.0 - phi) < 1.0)
in_plane &= scan.theta < 85.0
theta = scan.theta[in_plane]
signed = np.where(np.abs(phi[in_plane] - 180.0) < 1.0, theta, -theta)
order = np.argsort(signed)
bsdf = result.material.eval(scan.theta_in, scan.phi_in, theta, phi[in_plane])[:, 0]
model = result.scale * bsdf * np.cos(np.radians(theta))

fig, ax = plt.subplots(figsize=(7, 4.5))
ax.semilogy(signed[order], scan.value[in_plane, 0][order], ".", ms=3, label="golden_paper.txt (pgII)")
ax.semilogy(signed[order], model[order], "-", lw=1.5, label=f"metal fit, rough {result.params['rough']:.3f}")
ax.axvline(scan.theta_in, color="grey", lw=0.5)
ax.set_xlabel("θ_out in the plane of incidence (degrees; < 0: towards the light)")
ax.set_ylabel(f"detector signal [{scan.unit}]")
ax.set_ylim(bottom=max(1e-4, np.nanmin(scan.value[in_plane, 0][scan.value[in_plane, 0] > 0])))
ax.legend()
fig.tight_layout()
figure = args.out / "golden_paper-cut.png"
fig.savefig(figure, dpi=120)
print("wrote", figure)

# The peak of the model must sit where the data's does (the mirror direction).
peak_data = signed[np.nanargmax(scan.value[in_plane, 0])]
peak_model = signed[np.argmax(model)]
assert abs(peak_data - peak_model) < 2.0, (peak_data, peak_model)

# 4. Export: the static Radiance material (a free-scale fit gets no preview scene), as
#    `brtf export`; `fit.save(folder)` would write the whole `brtf fit` folder.
for path in fit.export(args.out / "export"):
    print("wrote", path)
print(brtf.Material.from_rad(args.out / "export" / "Golden_glossy_paper.rad").to_rad())
