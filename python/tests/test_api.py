"""The Python API itself: measurements, materials, fits, exports."""

from __future__ import annotations

import json
import threading

import numpy as np
import pytest

import brtf
from conftest import run_cli


def test_read_mountain_file(golden_paper, cli):
    m = brtf.read(golden_paper)
    info = json.loads(run_cli(cli, "info", "--json", golden_paper))
    info = info[0] if isinstance(info, list) else info
    assert m.theta_in == pytest.approx(26.8421) and m.phi_in == 0.0
    assert len(m) == 127039 == m.theta.shape[0] == m.phi.shape[0] == m.solid_angle.shape[0]
    assert m.value.shape == (127039, 1)
    assert m.quantity == "raw" and m.unit == "uA" and m.channels == "CIE-Y"
    assert m.sample_name == "Golden_glossy_paper" == m.header["sample_name"]
    assert m.header["intheta"] == "26.8421"
    assert (m.value < 0).sum() == 368  # the README's dark-current noise
    # The peak is at the mirror direction (26.99°, 175.8°).
    peak = np.argmax(m.value[:, 0])
    assert m.theta[peak] == pytest.approx(26.99, abs=0.01) and m.phi[peak] == pytest.approx(175.8, abs=0.1)
    # Voronoi cells of a full hemisphere (and a bit of the back) add up to about 2π.
    assert 5.5 < m.solid_angle.sum() < 7.0
    assert "Golden" not in repr(m) or "theta_in=26.8421" in repr(m)
    assert json.dumps(info)  # brtf info reads the same file


def test_read_mpc_file(alu):
    m = brtf.read(alu[2])
    assert (m.theta_in, m.phi_in) == (30.0, 0.0)
    assert m.quantity == "BSDF" and m.unit == "1/sr"
    assert m.header["incident angle theta [degree]"] == "30"
    # The .mpc column 8 (Voronoi cells) are the solid angles.
    first = [l.split() for l in open(alu[2]) if len(l.split()) == 8 and not l.startswith("#")][0]
    assert m.solid_angle[0] == float(first[7]) and m.value[0, 0] == float(first[6])


def test_read_klems(klems_fabric):
    k = brtf.read_klems(klems_fabric)
    both = k.measurements()
    front = k.measurements(side="front")
    back = k.measurements(side="back")
    assert len(front) == 145 and len(back) == 145 and len(both) == 290
    assert all(m.theta_in <= 90 for m in front) and all(m.theta_in > 90 for m in back)
    assert front[0].path is None and len(front[0]) == 290  # reflection + transmission patches
    with pytest.raises(brtf.FitError, match="Klems patch"):
        brtf.fit(front[0])
    # The file itself is fitted per side (test_fit_of_a_klems_side_equals_the_cli).
    with pytest.raises(brtf.ModelError, match="fitted per side"):
        brtf.fit(klems_fabric)


def test_material_construction_and_rad_round_trip():
    m = brtf.Material("metal", rgb=(0.9, 0.8, 0.7), spec=0.9, roughness=0.05)
    assert m.kind == "metal" and m.args == [0.9, 0.8, 0.7, 0.9, 0.05]
    assert m.params == {"red": 0.9, "green": 0.8, "blue": 0.7, "spec": 0.9, "rough": 0.05}
    assert repr(m) == 'Material("metal", args=[0.9, 0.8, 0.7, 0.9, 0.05])'
    again = brtf.Material.from_rad(m.to_rad("alu"))
    assert again.args == m.args and again.name == "alu"
    aniso = brtf.Material("trans2", rgb=0.5, spec=0.02, roughness=(0.1, 0.2), trans=0.5, tspec=0.4, orientation=(0, 1, 0))
    assert aniso.args == [0.5, 0.5, 0.5, 0.02, 0.1, 0.2, 0.5, 0.4] and aniso.orientation == [0.0, 1.0, 0.0]
    back = brtf.Material.from_rad(aniso.to_rad())
    assert back.args == aniso.args and back.orientation == aniso.orientation
    two = "void plastic a\n0\n0\n5 .1 .1 .1 0 0\nvoid metal b\n0\n0\n5 .5 .5 .5 .9 .1\n"
    assert brtf.Material.from_rad(two, "b").kind == "metal"


def test_eval_broadcasts_like_numpy():
    m = brtf.Material("plastic", rgb=0.5, spec=0.04, roughness=0.1)
    theta_out = np.linspace(0, 80, 5)[:, None]
    phi_out = np.array([0.0, 90.0, 180.0])[None, :]
    v = m.eval(30, 0, theta_out, phi_out)
    assert v.shape == (5, 3, 3)
    for i in range(5):
        for j in range(3):
            np.testing.assert_array_equal(v[i, j], m.eval(30.0, 0.0, theta_out[i, 0], phi_out[0, j]))
    assert m.eval(30, 0, 30, 180).shape == (3,)
    # Lists and integer arrays work; the mirror direction is the peak.
    cut = m.eval([30, 30], 0, [10, 30], [180, 180])
    assert cut.shape == (2, 3) and cut[1, 0] > cut[0, 0]
    # Grey plastic: the three channels are equal; Lambertian floor = ρ_d/π.
    assert np.all(v[..., 0] == v[..., 2])


def test_albedo_of_a_lambertian_plastic():
    m = brtf.Material("plastic", rgb=(0.2, 0.5, 0.8), spec=0.0, roughness=0.0)
    a = m.albedo(np.array([0.0, 45.0]))
    np.testing.assert_allclose(a.rho, [[0.2, 0.5, 0.8]] * 2, rtol=1e-4)
    np.testing.assert_array_equal(a.tau, 0.0)
    assert "Albedo(" in repr(a)


@pytest.fixture(scope="module")
def alu_fit(alu):
    return brtf.fit(alu, model="metal")


def test_exact_energy_holds_every_incidence_to_the_datas_energy(alu, alu_fit):
    """energy="exact" as `brtf fit --energy exact`: each incidence's model
    carries the data's ρ_dh, which the default fit misses by up to 5 %."""
    exact = brtf.fit(alu, model="metal", energy="exact")
    def worst(fit):
        return max(abs(i.adequacy["rho_model"] / i.adequacy["rho_data"] - 1) for i in fit.incidences)
    assert worst(alu_fit) > 0.03
    assert worst(exact) < 1e-6


def test_fit_objects(alu_fit):
    fit = alu_fit
    assert fit.model == "metal" and fit.name == "alu-ggx"
    assert [round(i.theta_in) for i in fit.incidences] == [0, 15, 30, 45, 60]
    inc = fit.incidences[2]
    assert set(inc.params) == {"red", "green", "blue", "spec", "rough"}
    assert inc.converged and inc.cost > 0 and inc.n_points > 1000
    assert all(v is None or v > 0 for v in inc.stderr.values())
    assert inc.adequacy["rho_data"] > 0.5 and inc.adequacy["rho_model"] > 0.5
    assert inc.material.kind == "metal" and inc.material.args == inc.material_args
    assert fit.global_fit.source == "all incidences"
    assert "IncidenceFit(theta_in=30" in repr(inc) and "Fit(name=\"alu-ggx\"" in repr(fit)
    # The table passes through the fitted incidences.
    table = fit.table([0.0, 30.0, 60.0])
    for k, theta in enumerate([0, 2, 4]):
        assert table["rough"][k] == pytest.approx(fit.incidences[theta].params["rough"], rel=1e-12)
    assert fit.material_at(30.0).args == pytest.approx(fit.incidences[2].material_args, rel=1e-12)
    d = fit.to_dict()
    assert d["name"] == "alu-ggx" and len(d["incidences"]) == 5


def test_save_load_and_export(alu_fit, tmp_path, cli):
    fit = alu_fit
    fit.save(tmp_path / "fit", plots=False)
    loaded = brtf.Fit.load(tmp_path / "fit")
    assert loaded.to_dict()["incidences"] == fit.to_dict()["incidences"]
    files = fit.export(tmp_path / "exp", at=30.0, preview=False)
    names = sorted(p.rsplit("/", 1)[1] for p in files)
    assert names == ["alu-ggx-theta.cal", "alu-ggx-theta.rad", "alu-ggx.rad"]
    static = brtf.Material.from_rad(tmp_path / "exp" / "alu-ggx.rad")
    assert static.args == pytest.approx(fit.incidences[2].material_args, rel=1e-6)


def test_klems_export_matches_brtf_export(alu_fit, tmp_path, cli):
    fit = alu_fit
    fit.save(tmp_path / "py", plots=False)
    written = fit.export(tmp_path / "py", klems="quarter")
    xml = tmp_path / "py" / "alu-ggx.xml"
    assert str(xml) in written
    run_cli(cli, "export", tmp_path / "py", "--klems", "quarter", "--out", tmp_path / "cli")
    # Klems patches read back: 41 incident patches per side in the quarter basis.
    ours = brtf.read_klems(xml).measurements(side="front")
    theirs = brtf.read_klems(tmp_path / "cli" / "alu-ggx.xml").measurements(side="front")
    assert len(ours) == len(theirs) == 41
    for a, b in zip(ours, theirs):
        np.testing.assert_array_equal(a.value, b.value)
    # Into a folder without fit.json: the fit's record is written first.
    written = fit.export(tmp_path / "fresh", klems="quarter", static_only=True, preview=False)
    assert (tmp_path / "fresh" / "fit.json").is_file() and (tmp_path / "fresh" / "alu-ggx.xml").is_file()


def test_fit_releases_the_gil(golden_paper):
    done = threading.Event()
    result = {}

    def work():
        result["fit"] = brtf.fit(golden_paper, model="metal", gray=True)
        done.set()

    thread = threading.Thread(target=work)
    thread.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        done.wait(0.001)
    thread.join()
    # The main thread kept running Python while the fit ran.
    assert ticks > 20
    assert result["fit"].incidences[0].converged


def test_material_at_follows_the_azimuth_of_an_anisotropic_klems_fit(cli, klems_fabric, tmp_path):
    """A trans2 fitted to Klems rings: `material_at(θ, φ)` gives each
    fitted incidence its own parameters, as every brtf command does; the
    rows averaged over φ_in differ from them."""
    out = tmp_path / "mecho"
    run_cli(
        cli, "fit", klems_fabric, "--model", "trans2", "--gray", "--side", "front",
        "--incidences", "theta<=20", "--no-plots", "--no-export", "--no-adequacy", "--out", out,
    )
    fit = brtf.Fit.load(out)
    differs = 0
    for inc in fit.incidences:
        at = fit.material_at(inc.theta_in, inc.phi_in)
        assert at.args == pytest.approx(inc.material_args, rel=1e-9, abs=1e-12)
        mean = fit.material_at(inc.theta_in)
        if abs(mean.args[6] - inc.material_args[6]) > 1e-3 * inc.material_args[6]:
            differs += 1
    assert differs > 10, differs


def test_fit_of_a_klems_side_equals_the_cli(cli, klems_fabric, tmp_path):
    """`brtf.fit(xml, side=...)` is `brtf fit xml --side ...`: the same
    patch-averaged fits, parameter for parameter; a side is required."""
    fit = brtf.fit(klems_fabric, model="trans", gray=True, side="back", incidences="theta<=10", adequacy=False)
    out = tmp_path / "cli"
    run_cli(
        cli, "fit", klems_fabric, "--model", "trans", "--gray", "--side", "back",
        "--incidences", "theta<=10", "--no-plots", "--no-export", "--no-adequacy", "--out", out,
    )
    want = json.loads((out / "fit.json").read_text())
    assert fit.to_dict()["recipe"]["patch_average"] == want["recipe"]["patch_average"]
    assert len(fit.incidences) == len(want["incidences"]) == 9
    for got, ref in zip(fit.incidences, want["incidences"]):
        assert got.material_args == pytest.approx(ref["material_args"], rel=1e-12, abs=1e-15)
    with pytest.raises(brtf.ModelError, match="fitted per side"):
        brtf.fit(klems_fabric, model="trans")


def test_a_fit_shows_its_3d_view_in_a_notebook(alu_fit, alu, tmp_path):
    html = alu_fit._repr_html_()
    assert html.startswith("<style>") and 'class="brtf-view"' in html
    start = html.index('class="bv-data">') + len('class="bv-data">')
    view = json.loads(html[start:html.index("</script>", start)].replace("<\\/", "</"))
    assert [i["n"] for i in view["incidences"]] == [len(brtf.read(p).theta) for p in alu]
    assert [i["fitted"] for i in view["incidences"]] == [r.n_points for r in alu_fit.incidences]
    # Two views in one notebook do not share an id.
    assert html.split('id="')[1].split('"')[0] != alu_fit._repr_html_().split('id="')[1].split('"')[0]
    # A fit folder read back shows the same samples.
    alu_fit.save(tmp_path / "fit", plots=False, export=False)
    again = brtf.Fit.load(tmp_path / "fit")._repr_html_()
    assert again.count('"n":') == html.count('"n":')
