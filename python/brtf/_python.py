"""The parts of the API written in Python on top of the native module:
``brtf.fit``'s inputs, ``Material.from_rad``'s file handling, dicts built
from ``to_dict()``, and the ``repr`` of every class."""

from __future__ import annotations

import json
import os

import numpy as np

from . import _brtf
from ._brtf import Albedo, Fit, IncidenceFit, Material, Measurement
from ._errors import FileError, FitError, MissingFileError, ModelError


def _num(x: float) -> str:
    """A number as brtf prints it (shortest round trip, no exponent, no ``.0``)."""
    return np.format_float_positional(x, trim="-")


def _exp(x: float, digits: int) -> str:
    """``x`` in exponent notation with ``digits`` decimals, as ``1.5e-3``."""
    mantissa, exponent = f"{x:.{digits}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _text(s: str) -> str:
    return json.dumps(s, ensure_ascii=False)


def _path(item) -> str:
    if isinstance(item, Measurement):
        if item.path is None:
            raise FitError(
                f"{item._origin}: brtf.fit fits measurement files; "
                "this Measurement has no file of its own (a Klems patch)"
            )
        return item.path
    try:
        return os.fspath(item)
    except TypeError:
        raise ModelError(f"fit: expected paths or brtf.Measurement objects, found {type(item).__name__}") from None


def fit(inputs, model="metal", **options) -> Fit:
    """Fits a Radiance model to measurement files, as ``brtf fit`` does: one
    fit per incidence, one for all, and the θ_in table. ``inputs``: a path,
    a ``Measurement`` read from a file, or a list of these. ``model``: a
    type, or ``"auto"`` (the candidates of ``brtf fit --model auto``);
    ``lobes=2`` or 3 fits a lobe sum. The options are ``brtf fit``'s
    (docs/python.md)."""
    if isinstance(inputs, (str, bytes, os.PathLike, Measurement)):
        inputs = [inputs]
    paths = [_path(item) for item in inputs]
    if not paths:
        raise FitError("no measurement files given")
    orientation = options.get("orientation")
    if orientation is not None and all(c == 0 for c in orientation):
        raise ModelError("orientation needs three numbers x, y, z, not all zero")
    if isinstance(options.get("mask_holder"), bool):
        options["mask_holder"] = "band" if options["mask_holder"] else None
    if options.get("phi_offset") is not None:
        options["phi_offset"] = str(options["phi_offset"])
    return _brtf.fit(paths, model, **options)


def _from_rad(text_or_path, name=None, *, variant="radiance", fresnel_k=None, source_omega=0.0, curved=False):
    """Reads a material from Radiance text, or from a ``.rad`` file when
    ``text_or_path`` is a path (a ``pathlib.Path``, or a one-line string
    naming an existing file). ``name`` picks one of several materials. A
    constant ``mixfunc`` tree of Ward-type primitives (a lobe sum as ``brtf
    export`` writes it) is one material."""
    if isinstance(text_or_path, str) and ("\n" in text_or_path or not os.path.isfile(text_or_path)):
        text, label = text_or_path, "<text>"
        if "\n" not in text and text.rstrip().endswith(".rad"):
            raise MissingFileError(f"{text}: no such file", text)
    else:
        path = os.fspath(text_or_path)
        label = os.fsdecode(path)
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            kind = MissingFileError if isinstance(e, FileNotFoundError) else FileError
            raise kind(f"{label}: cannot read: {e.strerror} (os error {e.errno})", label) from None
        except UnicodeDecodeError:
            raise FileError(f"{label}: cannot read: stream did not contain valid UTF-8", label) from None
    return Material._from_text(text, label, name, variant, fresnel_k, source_omega, curved)


def _material_repr(m: Material) -> str:
    if m.args is None:
        parts = ", ".join(f"({_num(w)}, {c!r})" for w, c in m.components)
        return f"<brtf.Material: a mixture of {m.lobes} primitives: {parts}>"
    text = f'Material("{m.kind}", args=[{", ".join(map(_num, m.args))}]'
    if m.lobes > 1:
        text += f", lobes={m.lobes}"
    if "orient" in m.param_names:
        text += ", oriented=True"
    elif m.kind.endswith("2"):
        text += f", orientation=({', '.join(map(_num, m.orientation))})"
    if m.variant != "radiance":
        text += f', variant="{m.variant}"'
    if m.fresnel_k != _brtf._FRESNEL_K_CLASSIC:
        text += f", fresnel_k={_num(m.fresnel_k)}"
    if m.source_omega != 0.0:
        text += f", source_omega={_num(m.source_omega)}"
    if m.curved:
        text += ", curved=True"
    return text + ")"


def _by_name(key: str, doc: str) -> property:
    return property(lambda self: {p["name"]: p[key] for p in self.to_dict()["params"]}, doc=doc)


def _incidence_repr(r: IncidenceFit) -> str:
    params = ", ".join(f"{k}={v:.6f}" for k, v in r.params.items())
    return (
        f"IncidenceFit(theta_in={_num(r.theta_in)}, {params}, cost={_exp(r.cost, 6)}, "
        f"rms_rel={r.rms_rel:.4f}, {r.termination})"
    )


def _fit_repr(f: Fit) -> str:
    g = f.global_fit
    params = ", ".join(f"{k}={v:.6f}" for k, v in g.params.items()) if g is not None else ""
    return f"Fit(name={_text(f.name)}, model={_text(f.model)}, incidences={len(f.incidences)}, global_fit=({params}))"


def _measurement_repr(m: Measurement) -> str:
    return (
        f"Measurement({_text(m._origin)}, theta_in={_num(m.theta_in)}, phi_in={_num(m.phi_in)}, "
        f"samples={len(m)}, quantity={_text(m.quantity)}, channels={_text(m.channels)})"
    )


Material.from_rad = staticmethod(_from_rad)
Material.params = property(
    lambda self: None if self.args is None else dict(zip(self.param_names, self.args)),
    doc="The arguments as a dict, name → value (None for a mixture of no lobe-sum shape).",
)
Material.__repr__ = _material_repr
IncidenceFit.params = _by_name("value", "The fitted parameters, name → value (physical units).")
IncidenceFit.stderr = _by_name("stderr", "Standard errors, name → value (None where not available).")
IncidenceFit.stderr_robust = _by_name("stderr_robust", "Robust (sandwich) standard errors, name → value.")
IncidenceFit.adequacy = property(
    lambda self: self.to_dict()["adequacy"],
    doc="The adequacy diagnostics (energy, peak, residual-kind check) as a dict, as in fit.json; None when not computed.",
)
IncidenceFit.__repr__ = _incidence_repr
Fit.__repr__ = _fit_repr
Measurement.__repr__ = _measurement_repr
Albedo.__repr__ = lambda a: f"Albedo(rho={a.rho!r}, tau={a.tau!r})"
