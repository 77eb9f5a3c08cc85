"""Klems BSDF XML from Python: `read_klems` against `brtf info`,
`Material.to_klems` and `Klems.write` against `brtf export --klems`, the
round trip, pyWinCalc reading the written file, two-sided fits against
`brtf fit FILE.xml`, and `en14501` against `brtf fit --en14501`."""

from __future__ import annotations

import json

import numpy as np
import pytest

import brtf
from conftest import SHARED, run_cli, shared_file

SA1 = SHARED / "data" / "lbnl-frads-klems-fabrics" / "2011-SA1.xml"
TRANS = "void trans shade\n0\n0\n7 0.6 0.6 0.6 0.05 0.15 0.4 0.3\n"


@pytest.fixture(scope="module")
def sa1() -> brtf.Klems:
    return brtf.read_klems(shared_file(SA1))


def test_basis_matrices_and_header(sa1):
    b = sa1.basis
    assert b.name == "LBNL/Klems Full" and len(b) == 145
    assert abs(b.lambda_.sum() - np.pi) < 1e-3
    assert b.theta[0] == 0.0 and b.theta[-1] == 82.5 and b.phi[1:9].tolist() == [0, 45, 90, 135, 180, 225, 270, 315]
    assert b.theta_bounds.shape == (145, 2) and np.all(b.solid_angle > b.lambda_)
    assert sa1.bands == ["Visible", "Solar"] and len(sa1.blocks) == 8
    for key, m in sa1.matrices.items():
        assert m.shape == (145, 145) and m.dtype == np.float64, key
    # The openness on the diagonal of Transmission Front (docs/klems.md).
    assert sa1.matrix("Transmission Front")[0, 0] == pytest.approx(2.063833)
    assert sa1.name == "Satine 5500 5%, White Pearl" and sa1.manufacturer == "Nysan"
    assert (sa1.thickness, sa1.thickness_unit, sa1.device_type) == ("1", "Millimeter", "Other")
    assert sa1.fields["PermeabilityFactor"] == "0.049855" and sa1.fields["TIR"] == "0.10916"
    # Three ways to name a block; brtf's front (light from +z) is the file's Back.
    tf = sa1.matrix("Transmission Back")
    assert np.array_equal(sa1.matrix("tf"), tf)
    assert np.array_equal(sa1.matrix(side="front", kind="transmission"), tf)
    assert np.array_equal(sa1.matrix("rb", band="solar"), sa1.matrix(side="back", kind="reflection", band="Solar"))
    with pytest.raises(KeyError, match="CIE-X"):
        sa1.matrix("tf", band="CIE-X")
    with pytest.raises(brtf.ModelError, match="direction="):
        sa1.matrix("sideways")
    assert "LBNL/Klems Full" in repr(sa1)


def test_totals_are_brtf_infos(sa1, cli):
    """Column totals: rows are outgoing patches, columns incident ones, so
    Σ_o B[o, i] Λ_o is ρ_dh or τ_dh of incident patch i, as `brtf info`
    prints them."""
    info = json.loads(run_cli(cli, "info", "--json", SA1))[0]
    assert sa1.info()["incidences"] == info["incidences"]
    rows = [line.split() for line in run_cli(cli, "info", SA1).splitlines()]
    printed = {(r[0], int(r[1])): (float(r[4]), float(r[5])) for r in rows if len(r) == 6 and r[0] in ("front", "back")}
    assert len(printed) == 290
    for side in ("front", "back"):
        rho = sa1.totals(side=side, kind="reflection")
        tau = sa1.totals(side=side, kind="transmission")
        for i in range(145):
            assert (f"{rho[i]:.4f}", f"{tau[i]:.4f}") == tuple(f"{v:.4f}" for v in printed[side, i])
        # The same totals from the matrix and Λ (rows = outgoing patches).
        m = sa1.matrix(side=side, kind="transmission")
        np.testing.assert_allclose((m * sa1.basis.lambda_[:, None]).sum(axis=0), tau, rtol=1e-12)
    assert printed["front", 0] == (0.5600, 0.0943) and printed["back", 0] == (0.4825, 0.0959)


def test_measurements_are_the_fits_data(sa1):
    front = sa1.measurements(side="front")
    assert len(front) == 145 and len(sa1.measurements()) == 290
    m = front[0]
    assert (m.theta_in, m.phi_in, len(m)) == (0.0, 180.0, 290)
    # Σ value · cos θ · dΩ over the transmission samples is τ_dh.
    back = m.theta > 90
    tau = np.sum(m.value[back, 0] * np.abs(np.cos(np.radians(m.theta[back]))) * m.solid_angle[back])
    assert tau == pytest.approx(sa1.totals(side="front", kind="transmission")[0], rel=1e-9)


def test_material_to_klems_is_brtf_export(cli, tmp_path):
    """`Material.to_klems` computes what `brtf export --klems --material`
    writes: the same file but for its leading comment (provenance and
    time), so the same totals; close to the material's own albedo."""
    rad = tmp_path / "shade.rad"
    rad.write_text(TRANS)
    m = brtf.Material.from_rad(rad)
    k = m.to_klems("full")
    run_cli(cli, "export", "--klems", "full", "--material", rad, "--out", tmp_path / "cli")
    cli_xml = (tmp_path / "cli" / "shade.xml").read_text()
    k.write(tmp_path / "py.xml")
    ours = (tmp_path / "py.xml").read_text()
    assert ours == k.xml()
    assert ours.split("-->\n", 1)[1] == cli_xml.split("-->\n", 1)[1]
    info = json.loads(run_cli(cli, "info", "--json", tmp_path / "cli" / "shade.xml"))[0]
    assert k.info()["incidences"] == info["incidences"]
    assert k.name == "shade" and k.bands == ["Visible", "Solar"] and len(k.blocks) == 8
    albedo = m.albedo(k.basis.theta[:9])
    np.testing.assert_allclose(k.totals(side="front", kind="transmission")[:9], albedo.tau[:, 1], rtol=0.01)
    np.testing.assert_allclose(k.totals(side="back", kind="reflection")[:9], albedo.rho[:, 1], rtol=0.01)
    # The header options of `brtf export --klems`, and the bases.
    q = m.to_klems("quarter", solar="none", thickness=2.5, permeability=0.05, emissivity=(0.8, 0.7))
    assert len(q.basis) == 41 and q.bands == ["Visible"] and q.thickness == "2.5"
    assert q.fields == {"EmissivityFront": "0.8", "EmissivityBack": "0.7", "PermeabilityFactor": "0.05"}
    assert len(m.to_klems("half", samples=64).basis) == 73


def test_write_and_read_back(sa1, tmp_path):
    m = brtf.Material("trans", rgb=0.5, spec=0.04, roughness=0.15, trans=0.3, tspec=0.2)
    k = m.to_klems("quarter", name="grey")
    k.write(tmp_path / "grey.xml")
    again = brtf.read_klems(tmp_path / "grey.xml")
    assert again.blocks == k.blocks and again.header == k.header
    for key in k.blocks:
        assert np.array_equal(again.matrix(key[1], band=key[0]), k.matrix(key[1], band=key[0]))
    # A read file is written by the same writer: its 6 significant digits.
    sa1.write(tmp_path / "sa1.xml")
    back = brtf.read_klems(tmp_path / "sa1.xml")
    assert back.blocks == sa1.blocks and back.name == sa1.name
    for key, matrix in sa1.matrices.items():
        np.testing.assert_allclose(back.matrices[key], matrix, rtol=5e-6, atol=0)
    fields = sa1.fields
    del fields["AERCAcceptance"]  # no place for it in the writer: named in the comment
    assert back.fields == fields and "AERCAcceptance @" in back.xml() + sa1.xml()


def test_pywincalc_reads_the_written_file(tmp_path):
    """WINDOW's engine reads `Klems.write`'s file and computes its totals
    at normal incidence (WINDOW's front is Radiance's back)."""
    pywincalc = pytest.importorskip("pywincalc")
    m = brtf.Material("trans", rgb=0.6, spec=0.05, roughness=0.15, trans=0.4, tspec=0.3)
    k = m.to_klems()
    k.write(tmp_path / "shade.xml")
    layer = pywincalc.parse_bsdf_xml_file(str(tmp_path / "shade.xml"))
    hemisphere = pywincalc.BSDFHemisphere.create(pywincalc.BSDFBasisType.FULL)
    system = pywincalc.GlazingSystem(solid_layers=[layer], bsdf_hemisphere=hemisphere)
    results = system.optical_method_results("PHOTOPIC").system_results
    for window_side, side in (("front", "back"), ("back", "front")):
        got = getattr(results, window_side)
        tau = k.totals(side=side, kind="transmission")[0]
        rho = k.totals(side=side, kind="reflection")[0]
        assert got.transmittance.direct_hemispherical == pytest.approx(tau, rel=0.005)
        assert got.reflectance.direct_hemispherical == pytest.approx(rho, rel=0.005)


def test_fit_of_both_sides_is_brtf_fit(cli, tmp_path):
    """`brtf.fit(xml, side="both")` is `brtf fit xml` (both sides by
    default): a dict of the two sides' fits, parameter for parameter."""
    options = dict(model="trans", gray=True, incidences="theta<=10", adequacy=False)
    fits = brtf.fit(shared_file(SA1), side="both", **options)
    assert list(fits) == ["front", "back"]
    out = tmp_path / "cli"
    run_cli(
        cli, "fit", SA1, "--model", "trans", "--gray", "--incidences", "theta<=10",
        "--no-plots", "--no-export", "--no-adequacy", "--out", out,
    )
    for side, fit in fits.items():
        want = json.loads((out / side / "fit.json").read_text())
        assert len(fit.incidences) == len(want["incidences"]) == 9
        for got, ref in zip(fit.incidences, want["incidences"]):
            assert got.material_args == pytest.approx(ref["material_args"], rel=1e-12, abs=1e-15)
    one = brtf.fit(SA1, side="front", **options)
    assert one.global_fit.material_args == fits["front"].global_fit.material_args
    assert fits["front"].incidences[0].material_args != fits["back"].incidences[0].material_args


@pytest.mark.parametrize(
    "values",
    [dict(tau_nh=0.12, tau_nn=0.05, rho_nh=0.6), dict(tau_nh=0.3, tau_nn=0.0, rho_nh=0.45, spec=0.03)],
)
def test_en14501_is_brtf_fit_en14501(cli, values):
    r = brtf.en14501(**values)
    printed = run_cli(cli, "fit", "--en14501", ",".join(f"{k}={v}" for k, v in values.items()))
    # The same text but for the first line (version and command line).
    assert r.rad.splitlines()[1:] == printed.splitlines()[1:]
    assert r.material.kind == "trans" and r.material.name == "en14501"
    check = printed.splitlines()[2].split(":", 1)[1].split()
    assert check == [f"rho_nh={r.rho_nh:.4f}", f"tau_nh={r.tau_nh:.4f}", f"tau_nn={r.tau_nn:.4f}"]
    for key in ("tau_nh", "tau_nn", "rho_nh"):
        assert getattr(r, key) == pytest.approx(values[key], abs=1e-4)
    assert brtf.en14501(name="fabric", **values).material.name == "fabric"
