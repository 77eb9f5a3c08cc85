"""The Python package against the `brtf` command line: the same library
calls must give the same numbers."""

from __future__ import annotations

import csv
import io
import json

import numpy as np
import pytest

import brtf
from conftest import run_cli

MATERIALS = {
    "plastic": ("void plastic p\n0\n0\n5 0.6 0.5 0.4 0.05 0.08\n", {}),
    "metal": ("void metal m\n0\n0\n5 0.9 0.8 0.7 0.9 0.05\n", {}),
    "trans": ("void trans t\n0\n0\n7 0.6 0.7 0.8 0.04 0.1 0.5 0.3\n", {}),
    "plastic2": ("void plastic2 p2\n4 0.3 1 0 .\n0\n6 0.5 0.5 0.5 0.05 0.05 0.2\n", {}),
    "metal2": ("void metal2 m2\n4 1 0 0 .\n0\n6 0.8 0.6 0.4 0.8 0.1 0.03\n", {}),
    "trans2": ("void trans2 t2\n4 0 1 0 .\n0\n8 0.6 0.6 0.6 0.03 0.07 0.15 0.6 0.4\n", {}),
    # The other formula sets and options of `brtf eval`.
    "metal-ward1992": ("void metal m\n0\n0\n5 0.9 0.8 0.7 0.9 0.05\n", {"variant": "ward1992"}),
    "plastic-manual2004": ("void plastic p\n0\n0\n5 0.6 0.5 0.4 0.05 0.08\n", {"variant": "manual2004"}),
    "plastic-rough0-omega": (
        "void plastic p\n0\n0\n5 0.6 0.5 0.4 0.05 0\n",
        {"fresnel_k": "pyradiance", "source_omega": 1e-4},
    ),
}


def directions(seed: int, n: int = 400):
    rng = np.random.default_rng(seed)
    theta = np.concatenate([rng.uniform(0, 180, n), [0.0, 30.0, 45.0, 89.9, 135.0]])
    phi = np.concatenate([rng.uniform(-180, 360, n), [0.0, 180.0, 180.0, 0.0, 180.0]])
    return theta, phi


def cli_eval(cli, rad_path, theta_in, phi_in, theta, phi, options):
    args = ["eval", "--material", rad_path, "--theta-in", theta_in, "--phi-in", phi_in]
    if "variant" in options:
        args += ["--variant", options["variant"]]
    if "fresnel_k" in options:
        args += ["--fresnel-k", options["fresnel_k"]]
    if "source_omega" in options:
        args += ["--source-omega", repr(options["source_omega"])]
    stdin = "".join(f"{float(t)!r},{float(p)!r}\n" for t, p in zip(theta, phi))
    rows = list(csv.DictReader(io.StringIO(run_cli(cli, *args, stdin=stdin))))
    return np.array([[float(r["r"]), float(r["g"]), float(r["b"])] for r in rows])


@pytest.mark.parametrize("label", sorted(MATERIALS))
@pytest.mark.parametrize("incidence", [(0.0, 0.0), (30.0, 0.0), (60.0, 200.0), (150.0, 45.0)])
def test_eval_equals_brtf_eval(cli, tmp_path, label, incidence):
    text, options = MATERIALS[label]
    rad = tmp_path / "m.rad"
    rad.write_text(text)
    theta, phi = directions(hash((label, incidence)) % 2**32)
    want = cli_eval(cli, rad, *incidence, theta, phi, options)
    material = brtf.Material.from_rad(rad, **options)
    got = material.eval(incidence[0], incidence[1], theta, phi)
    assert got.shape == (len(theta), 3)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    # Per-row incidences (the other code path) give the same numbers.
    rows = material.eval(np.full(len(theta), incidence[0]), incidence[1], theta, phi)
    np.testing.assert_allclose(rows, want, rtol=1e-12, atol=0)


def test_albedo_equals_brtf_albedo(cli, tmp_path):
    text, _ = MATERIALS["trans"]
    rad = tmp_path / "t.rad"
    rad.write_text(text)
    thetas = [0.0, 20.0, 45.0, 70.0, 160.0]
    out = run_cli(cli, "albedo", "--material", rad, "--theta-in", ",".join(map(str, thetas)))
    rows = list(csv.DictReader(io.StringIO(out)))
    a = brtf.Material.from_rad(rad).albedo(thetas)
    assert a.rho.shape == (5, 3) and a.tau.shape == (5, 3)
    for i, row in enumerate(rows):
        for c, ch in enumerate("rgb"):
            # The CLI prints 7 decimals.
            assert abs(a.rho[i, c] - float(row[f"rho_{ch}"])) <= 5e-8
            assert abs(a.tau[i, c] - float(row[f"tau_{ch}"])) <= 5e-8


def reports(fit_json: dict):
    return fit_json["incidences"] + [fit_json["global"]]


def assert_same_parameters(py_json: dict, cli_json: dict):
    py_reports, cli_reports = reports(py_json), reports(cli_json)
    assert len(py_reports) == len(cli_reports)
    worst = 0.0
    for a, b in zip(py_reports, cli_reports):
        assert a["theta_in"] == b["theta_in"]
        for pa, pb in zip(a["params"], b["params"]):
            assert pa["name"] == pb["name"]
            rel = abs(pa["value"] - pb["value"]) / max(abs(pb["value"]), 1e-300)
            worst = max(worst, rel)
            assert rel <= 1e-9, f"{a['source']} {pa['name']}: {pa['value']} vs {pb['value']}"
        assert a["cost"] == pytest.approx(b["cost"], rel=1e-9)
        assert a["material_args"] == pytest.approx(b["material_args"], rel=1e-9)
    print(f"worst relative parameter difference: {worst:.3e}")
    return worst


def test_fit_equals_brtf_fit_on_alu_ggx(cli, tmp_path, alu):
    run_cli(cli, "fit", *alu, "--model", "metal", "--out", tmp_path / "cli", "--no-plots", "--no-export")
    cli_json = json.loads((tmp_path / "cli" / "fit.json").read_text())
    fit = brtf.fit([str(p) for p in alu], model="metal")
    assert_same_parameters(fit.to_dict(), cli_json)
    assert fit.name == cli_json["name"] == "alu-ggx"
    # The θ_in table as fit.json stores it.
    table = fit.table(np.array(cli_json["table"]["theta_in"]))
    for i, name in enumerate(brtf.Material("metal", rgb=0.5).param_names):
        np.testing.assert_allclose(table[name], [row[i] for row in cli_json["table"]["args"]], rtol=1e-12)


@pytest.mark.parametrize(
    "options, flags",
    [
        ({"gray": True}, ["--gray"]),
        ({"gray": True, "residual": "relative", "loss": "huber"}, ["--gray", "--residual", "relative", "--loss", "huber"]),
        # The file's frame, and a turn given in degrees, as on the command line.
        ({"gray": True, "phi_offset": 0}, ["--gray", "--phi-offset", "0"]),
        ({"gray": True, "phi_offset": -2.5}, ["--gray", "--phi-offset", "-2.5"]),
        # The holder's shadow: its band (True) and the shadows found.
        ({"gray": True, "mask_holder": True}, ["--gray", "--mask-holder"]),
        ({"gray": True, "mask_holder": "auto"}, ["--gray", "--mask-holder", "auto"]),
    ],
)
def test_fit_equals_brtf_fit_on_golden_paper(cli, tmp_path, golden_paper, options, flags):
    out = tmp_path / "cli"
    run_cli(cli, "fit", golden_paper, "--model", "metal", *flags, "--out", out, "--no-plots", "--no-export")
    cli_json = json.loads((out / "fit.json").read_text())
    # A Measurement read from the file fits as the file does.
    fit = brtf.fit(brtf.read(golden_paper), model="metal", **options)
    assert_same_parameters(fit.to_dict(), cli_json)
    assert fit.name == cli_json["name"] == "Golden_glossy_paper"
    py_inc, cli_inc = fit.incidences[0], cli_json["incidences"][0]
    assert py_inc.n_points == cli_inc["n_points"]
    assert py_inc.termination == brtf.Fit.load(out).incidences[0].termination
    turn = cli_json["provenance"]["inputs"][0].get("phi_turn_deg", 0.0)
    assert turn == options.get("phi_offset", pytest.approx(3.44, abs=0.02))
    for p in cli_inc["params"]:
        if p["stderr"] is not None:
            assert py_inc.stderr[p["name"]] == pytest.approx(p["stderr"], rel=1e-6)


def test_save_writes_the_folder_brtf_fit_writes(cli, tmp_path, alu):
    run_cli(cli, "fit", *alu, "--model", "metal", "--out", tmp_path / "cli")
    fit = brtf.fit(alu, model="metal")
    written = fit.save(tmp_path / "py")
    cli_files = sorted(p.relative_to(tmp_path / "cli").as_posix() for p in (tmp_path / "cli").rglob("*") if p.is_file())
    py_files = sorted(p.relative_to(tmp_path / "py").as_posix() for p in (tmp_path / "py").rglob("*") if p.is_file())
    assert py_files == cli_files
    assert sorted(str(tmp_path / "py" / f) for f in py_files) == sorted(written)
    # The Radiance exports are the same text, but for the comment lines
    # (time and command line).
    def body(path):
        lines = path.read_text().splitlines()
        skip = ("Command:", " created ")
        return [line for line in lines if not line.startswith("#") and not any(s in line for s in skip)]

    for name in ("alu-ggx.rad", "alu-ggx-theta.rad", "alu-ggx-theta.cal"):
        assert body(tmp_path / "py" / name) == body(tmp_path / "cli" / name)
    # The rest is the same bytes: params.csv, every plot, the preview scene.
    same = [f for f in cli_files if f.startswith("plots/") or f in ("params.csv", "residuals.csv", "alu-ggx-preview.rad")]
    assert len(same) > 20
    for name in same:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # fit.json: the same fit, but for the provenance and the run times.
    def fit_json(folder):
        fit = json.loads((folder / "fit.json").read_text())
        del fit["provenance"]["created"], fit["provenance"]["command_line"]
        for report in fit["incidences"] + [fit["global"]]:
            del report["elapsed_ms"]
        fit["outputs"] = [o for o in fit["outputs"] if o["path"] in same]
        return fit

    assert fit_json(tmp_path / "py") == fit_json(tmp_path / "cli")
    # And `brtf export` reads the Python-written folder.
    run_cli(cli, "export", tmp_path / "py", "--out", tmp_path / "re")
    assert body(tmp_path / "re" / "alu-ggx.rad") == body(tmp_path / "py" / "alu-ggx.rad")
