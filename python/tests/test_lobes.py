"""Lobe sums and model="auto" from Python: a two-lobe fit of data/alu-ggx
is its lobes' weighted sum, carries E1, and saves the folder the CLI
writes; Materials of lobe sums and mixfunc trees; the candidates of auto."""

from __future__ import annotations

import json

import numpy as np
import pytest

import brtf
from conftest import run_cli

THETA_OUT = np.array([0.0, 10.0, 25.0, 30.0, 32.0, 45.0, 60.0, 85.0, 30.0, 50.0])
PHI_OUT = np.array([0.0, 180.0, 180.0, 180.0, 170.0, 90.0, 200.0, 180.0, 0.0, 300.0])


@pytest.fixture(scope="module")
def two_lobes(alu):
    return brtf.fit(alu, model="metal", lobes=2)


def weighted_sum(material, *incidence):
    return sum(w * lobe.eval(*incidence, THETA_OUT, PHI_OUT) for w, lobe in material.components)


def test_a_two_lobe_fit_is_the_weighted_sum_of_its_lobes(two_lobes):
    fit = two_lobes
    m = fit.material
    assert m.kind == "metal" and m.lobes == 2 and m.shape == "metal ×2 lobes"
    assert m.param_names == ["red", "green", "blue", "spec", "split1", "rough1", "rough2"]
    assert m.args == fit.global_fit.material_args and m.params == fit.global_fit.params
    weights = [w for w, _ in m.components]
    assert weights[0] == m.params["split1"] and sum(weights) == pytest.approx(1.0, abs=1e-15)
    for (_, lobe), rough in zip(m.components, ("rough1", "rough2")):
        assert lobe.lobes == 1 and lobe.kind == "metal"
        assert lobe.args == [m.params[n] for n in ("red", "green", "blue", "spec", rough)]
    for material in [m] + [inc.material for inc in fit.incidences]:
        for incidence in [(0.0, 0.0), (30.0, 0.0), (60.0, 45.0)]:
            got = material.eval(*incidence, THETA_OUT, PHI_OUT)
            assert got.shape == (len(THETA_OUT), 3) and np.all(got > 0)
            np.testing.assert_allclose(got, weighted_sum(material, *incidence), rtol=1e-14, atol=0)
        # Rows with their own incidences take the other path: the same numbers.
        rows = material.eval(np.full(len(THETA_OUT), 30.0), 0.0, THETA_OUT, PHI_OUT)
        np.testing.assert_allclose(rows, weighted_sum(material, 30.0, 0.0), rtol=1e-14, atol=0)
    # The hemispherical reflectance is the lobes' weighted too.
    a = m.albedo([0.0, 45.0])
    parts = [(w, lobe.albedo([0.0, 45.0])) for w, lobe in m.components]
    np.testing.assert_allclose(a.rho, sum(w * p.rho for w, p in parts), rtol=1e-12)
    assert 0.5 < a.rho[0, 0] < 1.0
    assert "lobes=2" in repr(m)


def test_the_two_lobe_fit_has_e1_and_its_table(two_lobes):
    fit = two_lobes
    assert fit.model == "metal" and fit.auto is None
    reports = fit.incidences + [fit.global_fit]
    for inc, entry in zip(reports, fit.to_dict()["incidences"] + [fit.to_dict()["global"]]):
        assert inc.e1 == entry["e1"] and 0.0 < inc.e1 < 0.2
        assert list(inc.params) == fit.material.param_names
        assert inc.material.args == inc.material_args
    # Two lobes describe alu-ggx far better than one (E1 ~ 10% against ~ 30%).
    one = brtf.fit(fit.incidences[2].source, model="metal")
    assert one.incidences[0].e1 > 2 * fit.incidences[2].e1
    table = fit.table([0.0, 30.0, 60.0])
    assert list(table) == fit.material.param_names
    for k, index in enumerate([0, 2, 4]):
        assert table["rough2"][k] == pytest.approx(fit.incidences[index].params["rough2"], rel=1e-12)
    at = fit.material_at(30.0)
    assert at.lobes == 2 and at.args == pytest.approx(fit.incidences[2].material_args, rel=1e-12)


def test_a_lobe_sum_round_trips_through_radiance_text():
    m = brtf.Material("metal", args=[0.9, 0.8, 0.7, 0.9, 0.3, 0.05, 0.2], lobes=2)
    text = m.to_rad("alu")
    assert text.count("void metal alu.") == 2 and "void mixfunc alu\n4 alu.1 alu.2 0.3 .\n" in text
    back = brtf.Material.from_rad(text)
    assert back.name == "alu" and back.args == m.args and back.shape == m.shape
    np.testing.assert_array_equal(back.eval(20, 0, THETA_OUT, PHI_OUT), m.eval(20, 0, THETA_OUT, PHI_OUT))
    # A fitted orientation is an argument, in degrees.
    o = brtf.Material("plastic2", args=[0.5, 0.5, 0.5, 0.05, 0.3, 0.1, 0.05, 0.2, 0.02, 30.0], lobes=2, oriented=True)
    assert o.param_names[-1] == "orient" and o.shape == "plastic2 ×2 lobes (orientation fitted)"
    assert o.orientation == pytest.approx([np.sqrt(0.75), 0.5, 0.0], abs=1e-15)
    fixed = brtf.Material.from_rad(o.to_rad("p"))
    np.testing.assert_allclose(fixed.eval(40, 10, THETA_OUT, PHI_OUT), o.eval(40, 10, THETA_OUT, PHI_OUT), rtol=1e-14)
    # Any constant mixfunc tree is a material, of no lobe-sum shape when
    # its primitives differ in type.
    tree = (
        "void plastic a\n0\n0\n5 .5 .4 .3 .05 .1\n"
        "void metal b\n0\n0\n5 .9 .9 .9 .9 .05\n"
        "void mixfunc ab\n4 a b .3 .\n0\n0\n"
    )
    mix = brtf.Material.from_rad(tree)
    assert mix.name == "ab" and mix.lobes == 2 and mix.args is None and mix.shape is None
    assert [round(w, 12) for w, _ in mix.components] == [0.3, 0.7]
    np.testing.assert_allclose(mix.eval(30, 0, THETA_OUT, PHI_OUT), weighted_sum(mix, 30, 0), rtol=1e-14)
    assert "mixture of 2" in repr(mix)


def test_lobe_sum_arguments_are_checked():
    with pytest.raises(brtf.ModelError, match=r"args=\[red, green, blue, spec, split1, rough1, rough2\]"):
        brtf.Material("metal", rgb=0.5, lobes=2)
    with pytest.raises(brtf.ModelError, match="split"):
        brtf.Material("metal", args=[0.9, 0.8, 0.7, 0.9, 1.3, 0.05, 0.2], lobes=2)
    with pytest.raises(brtf.ModelError, match="lobe 1: spec is 1.9"):
        brtf.Material("metal", args=[0.9, 0.8, 0.7, 1.9, 0.3, 0.05, 0.2], lobes=2)
    with pytest.raises(brtf.ModelError, match="1 to 3 lobes"):
        brtf.Material("metal", args=[0.9] * 9, lobes=4)
    with pytest.raises(brtf.ModelError, match="isotropic"):
        brtf.Material("metal", args=[0.9, 0.8, 0.7, 0.9, 0.05, 10.0], oriented=True)
    with pytest.raises(brtf.ModelError, match="one lobe"):
        brtf.Material("trans", args=[0.5] * 9, lobes=2)


def test_a_two_lobe_save_is_the_folder_brtf_fit_writes(cli, tmp_path, alu, two_lobes):
    run_cli(cli, "fit", *alu, "--model", "metal", "--lobes", "2", "--out", tmp_path / "cli")
    written = two_lobes.save(tmp_path / "py")

    def files(folder):
        return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())

    cli_files, py_files = files(tmp_path / "cli"), files(tmp_path / "py")
    assert py_files == cli_files and sorted(written) == sorted(str(tmp_path / "py" / f) for f in py_files)
    assert "plots/map-t30.svg" in cli_files and "plots/params.png" in cli_files
    same = [f for f in cli_files if f.startswith("plots/") or f in ("params.csv", "alu-ggx-preview.rad")]
    for name in same:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name

    def body(path):  # but for the comments (time and command line)
        skip = ("Command:", " created ")
        lines = path.read_text().splitlines()
        return [line for line in lines if not line.startswith("#") and not any(s in line for s in skip)]

    for name in ("alu-ggx.rad", "alu-ggx-theta.rad", "alu-ggx-theta.cal"):
        assert body(tmp_path / "py" / name) == body(tmp_path / "cli" / name), name
    assert "void mixfunc alu-ggx" in (tmp_path / "py" / "alu-ggx.rad").read_text()

    def fit_json(folder):
        fit = json.loads((folder / "fit.json").read_text())
        del fit["provenance"]["created"], fit["provenance"]["command_line"]
        for report in fit["incidences"] + [fit["global"]]:
            del report["elapsed_ms"]
        fit["outputs"] = [o for o in fit["outputs"] if o["path"] in same]
        return fit

    assert fit_json(tmp_path / "py") == fit_json(tmp_path / "cli")
    # The exported static material reads back as the fit's lobe sum.
    static = brtf.Material.from_rad(tmp_path / "py" / "alu-ggx.rad")
    assert static.shape == "metal ×2 lobes"
    assert static.args == pytest.approx(two_lobes.material.args, rel=1e-12)
    report = (tmp_path / "py" / "report.html").read_text()
    assert "<th>E1</th>" in report and "metal ×2 lobes" in report


def test_model_auto_records_its_candidates_as_the_cli(cli, tmp_path, alu):
    fit = brtf.fit(alu, model="auto")
    auto = fit.auto
    assert auto == fit.to_dict()["auto"]
    chosen = auto["candidates"][auto["chosen"]]
    assert fit.material.shape == chosen["model"] and fit.model == chosen["kind"]
    assert auto["reason"].startswith(chosen["model"])
    assert all(0 < c["e1_heldout"] < 1 for c in auto["candidates"][auto["first"]:])
    run_cli(cli, "fit", *alu, "--model", "auto", "--out", tmp_path / "cli", "--no-plots", "--no-export")
    want = json.loads((tmp_path / "cli" / "fit.json").read_text())["auto"]
    for c in auto["candidates"] + want["candidates"]:
        del c["elapsed_ms"]
    assert auto == want
