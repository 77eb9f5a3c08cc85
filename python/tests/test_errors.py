"""Bad input raises the right brtf exception, with the file and line and
a clear message; nothing crashes the interpreter."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import brtf


def test_missing_file(tmp_path):
    missing = tmp_path / "nope.mpc"
    with pytest.raises(brtf.MissingFileError) as e:
        brtf.read(missing)
    assert isinstance(e.value, FileNotFoundError) and isinstance(e.value, brtf.BrtfError)
    assert e.value.file == str(missing)
    assert "No such file" in str(e.value)
    with pytest.raises(brtf.MissingFileError):
        brtf.fit([missing], model="metal")
    with pytest.raises(brtf.MissingFileError):
        brtf.Material.from_rad(tmp_path / "nope.rad")
    with pytest.raises(brtf.MissingFileError):
        brtf.Fit.load(tmp_path)
    with pytest.raises(brtf.MissingFileError):
        brtf.read_klems(tmp_path / "nope.xml")


def test_malformed_measurement_names_file_and_line(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("#intheta 30\n#inphi 0\n#format: theta phi BSDF\n30 180 2.5\n10 zero 0.3\n")
    with pytest.raises(brtf.FormatError) as e:
        brtf.read(bad)
    assert isinstance(e.value, ValueError)
    assert e.value.file == str(bad) and e.value.line == 5
    assert str(e.value).startswith(f"{bad}:5: ")
    with pytest.raises(brtf.FormatError) as e:
        brtf.fit(bad, model="metal")
    assert e.value.line == 5


def test_malformed_radiance_and_klems(tmp_path):
    with pytest.raises(brtf.FormatError) as e:
        brtf.Material.from_rad("void metal m\n0\n0\n4 0.5 0.5 0.5 0.9\n")
    assert e.value.line is not None and "metal" in str(e.value)
    xml = tmp_path / "bad.xml"
    xml.write_text("<?xml version='1.0'?>\n<WindowElement>\n<Optical>\n")
    with pytest.raises(brtf.FormatError) as e:
        brtf.read_klems(xml)
    assert e.value.file == str(xml)
    (tmp_path / "fit.json").write_text("{\n  \"schema\": 1,\n oops\n")
    with pytest.raises(brtf.FormatError) as e:
        brtf.Fit.load(tmp_path)
    assert e.value.line == 3


def test_wrong_model_name_and_options(alu):
    with pytest.raises(brtf.ModelError) as e:
        brtf.fit(alu, model="metl")
    assert "metl" in str(e.value) and "plastic, metal, trans" in str(e.value)
    assert isinstance(e.value, ValueError)
    with pytest.raises(brtf.ModelError, match="is not one of plastic, metal"):
        brtf.Material("shiny", rgb=0.5)
    with pytest.raises(brtf.ModelError, match="residual"):
        brtf.fit(alu, model="metal", residual="squared")
    with pytest.raises(brtf.ModelError, match="loss"):
        brtf.fit(alu, model="metal", loss="tukey")
    with pytest.raises(brtf.ModelError, match="spec is 1.5"):
        brtf.Material("metal", rgb=0.5, spec=1.5, roughness=0.1)
    with pytest.raises(brtf.ModelError, match="trans= is needed"):
        brtf.Material("trans", rgb=0.5, spec=0.0, roughness=0.1)
    with pytest.raises(brtf.ModelError, match="source_omega=-1: out of range"):
        brtf.Material("metal", rgb=0.5, source_omega=-1)
    m = brtf.Material("metal", rgb=0.5, spec=0.5, roughness=0.1)
    with pytest.raises(brtf.ModelError, match="theta_in=90: out of range"):
        m.eval(90, 0, 30, 180)
    with pytest.raises(ValueError):  # numpy: shapes that do not broadcast
        m.eval(30, 0, np.zeros(3), np.zeros(4))
    with pytest.raises(brtf.ModelError, match="klems"):
        brtf.fit(alu, model="metal").export("/tmp/never", klems="eighth")


def test_fit_error_is_a_fit_error(tmp_path):
    # Every value zero: nothing to fit.
    flat = tmp_path / "zero.txt"
    rows = "".join(f"{t} {p} 0\n" for t in range(5, 80, 5) for p in range(0, 360, 30))
    flat.write_text("#intheta 30\n#inphi 0\n#format: theta phi BSDF\n" + rows)
    with pytest.raises(brtf.FitError) as e:
        brtf.fit(flat, model="metal")
    assert isinstance(e.value, RuntimeError)
    assert "zero" in str(e.value)


def test_bad_input_does_not_crash_the_interpreter(tmp_path):
    # Garbage of every kind, in a child interpreter: it must exit normally.
    code = """
import brtf, numpy as np, os, sys
tmp = sys.argv[1]
junk = [b"", b"\\x00\\xff" * 100, b"#intheta nan\\n", b"<?xml?><a>", b"#format: theta phi BSDF\\n1e400 0 1\\n"]
caught = 0
for i, data in enumerate(junk):
    p = os.path.join(tmp, f"j{i}.txt")
    open(p, "wb").write(data)
    for call in (lambda: brtf.read(p), lambda: brtf.read_klems(p), lambda: brtf.fit(p),
                 lambda: brtf.Material.from_rad(data.decode("latin-1") + "\\n")):
        try:
            call()
        except brtf.BrtfError:
            caught += 1
m = brtf.Material("metal", rgb=0.5, spec=0.5, roughness=0.1)
try:
    m.eval(30, 0, np.array([np.nan, np.inf, -1e300, 720.0]), 0)
except brtf.ModelError:
    caught += 1
print("caught", caught)
"""
    done = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("caught ")
    assert int(done.stdout.split()[1]) >= 16


def test_directions_out_of_range_raise():
    m = brtf.Material("plastic", rgb=0.5, spec=0.05, roughness=0.1)
    for theta_out, phi_out in [(float("nan"), 180.0), (-10.0, 180.0), (200.0, 180.0), (30.0, 1e300)]:
        with pytest.raises(brtf.ModelError, match="out of range"):
            m.eval(30.0, 0.0, [10.0, theta_out], phi_out)
    with pytest.raises(brtf.ModelError, match=r"phi_out=1e300: out of range"):
        m.eval(30.0, 0.0, 30.0, 1e300)
    assert m.eval(30.0, 0.0, [0.0, 180.0], [-360.0, 360.0]).shape == (2, 3)


def test_ctrl_c_stops_a_running_fit(klems_fabric):
    # A long fit (a Klems side, 512 directions per patch, one thread: ~28 s)
    # in a child interpreter; SIGINT while the incidences are being fitted
    # stops the solve under way and raises KeyboardInterrupt within a
    # second.
    code = """
import sys, time, brtf
print("started", flush=True)
t = time.monotonic()
try:
    brtf.fit(sys.argv[1], model="plastic2", side="front", patch_samples=512, jobs=1)
    print("finished", time.monotonic() - t)
except KeyboardInterrupt:
    print("interrupted", time.monotonic() - t)
"""
    child = subprocess.Popen([sys.executable, "-c", code, str(klems_fabric)], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "started"
    time.sleep(8.0)
    signalled = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=60)
    after = time.monotonic() - signalled
    assert out.split()[0] == "interrupted", out
    assert after < 1.0, f"{out}: {after:.2f} s after the signal"
    print(f"interrupted {after:.3f} s after SIGINT")


def test_messages_are_in_python_terms(alu, klems_fabric, tmp_path):
    """Errors name keyword arguments and Python calls, never the command
    line's flags or Rust paths."""
    m = brtf.Material("plastic", rgb=0.5, spec=0.05, roughness=0.1)
    cases = [
        (lambda: m.eval(30.0, 0.0, 200.0, 180.0), brtf.ModelError, "theta_out=200: out of range; allowed: 0 ≤ θ_out ≤ 180"),
        (lambda: m.eval(90.0, 0.0, 30.0, 180.0), brtf.ModelError, "theta_in=90: out of range"),
        (lambda: brtf.Material("metal", rgb=0.5, fresnel_k=2.0), brtf.ModelError, "fresnel_k=2: out of range"),
        (lambda: brtf.fit(alu, model="metal", theta_cap=200), brtf.ModelError, "theta_cap=200: out of range"),
        (lambda: brtf.fit(alu, model="metal", jobs=100000), brtf.FitError, "jobs=100000: out of range"),
        (lambda: brtf.fit(alu, model="auto", lobes=2), brtf.FitError, 'model="auto" chooses the lobes itself: leave out lobes='),
        (lambda: brtf.fit(alu, model="metal", incidences="theta<=10"), brtf.FitError, "incidences= selects"),
        (lambda: brtf.fit(klems_fabric, model="trans"), brtf.ModelError, 'side="front", "back" or "both"'),
        (lambda: brtf.read(klems_fabric), brtf.FormatError, "read it with brtf.read_klems"),
        (lambda: brtf.Material.from_rad("void plastic a\n0\n0\n5 .1 .1 .1 0 0\nvoid metal b\n0\n0\n5 .5 .5 .5 .9 .1\n"),
         brtf.FormatError, "choose one with name="),
        (lambda: brtf.en14501(tau_nh=0.1, tau_nn=0.2, rho_nh=0.6), brtf.ModelError, "tau_nn = 0.2 exceeds tau_nh = 0.1"),
        (lambda: brtf.en14501(tau_nh=1.5, tau_nn=0.2, rho_nh=0.6), brtf.ModelError, "tau_nh = 1.5 is outside 0-1"),
        (lambda: m.to_klems("quarter", samples=0), brtf.ExportError, "samples 0: out of range"),
        (lambda: m.to_klems("quarter", conductivity=0.0), brtf.ExportError, "conductivity=0: out of range"),
        (lambda: m.to_klems("quarter", emissivity=(0.9, 0.9), ir_transmittance=0.3), brtf.ExportError,
         "emissivity=0.9 with ir_transmittance=0.3: their sum exceeds 1"),
        (lambda: m.to_klems("eighth"), brtf.ModelError, 'basis="eighth"'),
        (lambda: brtf.read_klems(klems_fabric).measurements(side="up"), brtf.ModelError, "side='up'"),
        (lambda: brtf.fit(alu, model="metal", energy="exact", weights="uniform"), brtf.FitError,
         'energy="exact" integrates the data over their solid angles, which uniform weights (weights="uniform")'),
        (lambda: brtf.fit(alu, model="metal", energy="some"), brtf.ModelError, "energy="),
    ]
    for call, kind, wording in cases:
        with pytest.raises(kind) as e:
            call()
        message = str(e.value)
        assert wording in message, message
        assert "--" not in message and "::" not in message, message
    assert isinstance(e.value, ValueError)
    # A fit folder that is not brtf's is replaced only with force=True.
    (tmp_path / "keep.txt").write_text("mine")
    with pytest.raises(brtf.BrtfError) as e:
        brtf.fit(alu, model="metal", adequacy=False).save(tmp_path, plots=False)
    assert "force=True" in str(e.value) and "--" not in str(e.value), str(e.value)
