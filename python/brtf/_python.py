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
    (docs/python.md). A Klems BSDF XML file is fitted per side:
    ``side="front"`` or ``"back"`` gives that side's ``Fit``, ``side="both"``
    a dict ``{"front": Fit, "back": Fit}`` of the sides the file holds."""
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
    fits = _brtf.fit(paths, model, **options)
    if options.get("side") == "both":
        return {side: f for side, f in fits}
    return fits[0][1]


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


# --- Klems BSDF XML ---------------------------------------------------------

_DIRECTIONS = {
    "tb": "Transmission Front",
    "tf": "Transmission Back",
    "rb": "Reflection Front",
    "rf": "Reflection Back",
}
_BANDS = {"visible": "Visible", "solar": "Solar", "cie-x": "CIE-X", "cie-y": "Visible", "cie-z": "CIE-Z"}


class KlemsBasis:
    """A Klems angle basis: per patch, in the file's (and the matrices')
    order, numpy arrays of the centre ``theta`` and ``phi`` (degrees), the
    bounds ``theta_bounds`` and ``phi_bounds`` (N × 2, degrees), the solid
    angle ``solid_angle`` (Ω, sr) and the projected solid angle ``lambda_``
    (Λ = ∫ cos θ dω, sr; Σ Λ = π), and ``ring``; ``name`` is e.g.
    ``"LBNL/Klems Full"``."""

    def __init__(self, name: str, patches: list):
        self.name = name
        column = lambda key: np.array([p[key] for p in patches], dtype=float)  # noqa: E731
        self.theta = column("theta_deg")
        self.phi = column("phi_deg")
        self.theta_bounds = np.array([p["theta_bounds_deg"] for p in patches], dtype=float)
        self.phi_bounds = np.array([p["phi_bounds_deg"] for p in patches], dtype=float)
        self.solid_angle = column("solid_angle_sr")
        self.lambda_ = column("projected_solid_angle_sr")
        self.ring = np.array([p["ring"] for p in patches], dtype=int)

    def __len__(self) -> int:
        return len(self.theta)

    def __repr__(self) -> str:
        return f"KlemsBasis({_text(self.name)}, patches={len(self)})"


class Klems:
    """A Klems BSDF XML file: its basis, one N × N matrix per band and
    direction, its header. Made by :func:`brtf.read_klems` or
    :meth:`Material.to_klems`; :meth:`write` writes it as ``brtf export
    --klems`` does.

    ``matrix(...)[o, i]`` is the BSDF (1/sr) for light from incident patch
    ``i`` scattered into outgoing patch ``o``: rows are outgoing patches,
    columns incident ones, as the file's ``Columns`` layout and Radiance
    hold them. Blocks are named as in the file (``"Transmission Front"``;
    WINDOW's front is Radiance's back, docs/klems.md) or by Radiance's
    components (``"tb"``, ``"tf"``, ``"rb"``, ``"rf"``), or by brtf's
    ``side`` (where the light comes from: ``"front"`` = +z = Radiance's
    front) and ``kind`` (``"reflection"`` or ``"transmission"``)."""

    def __init__(self, data):
        self._data = data
        name, patches = data.basis()
        self.basis = KlemsBasis(name, patches)
        self.header = data.header()
        self.notes = list(data.notes)

    @property
    def source(self) -> str:
        """The file read (or ``<name>.xml`` for a computed one)."""
        return self._data.source

    @property
    def name(self):
        return self.header["name"]

    @property
    def manufacturer(self):
        return self.header["manufacturer"]

    @property
    def thickness(self):
        """``Thickness`` as written (text), see ``thickness_unit``."""
        return self.header["thickness"]

    @property
    def thickness_unit(self):
        return self.header["thickness_unit"]

    @property
    def device_type(self):
        return self.header["device_type"]

    @property
    def fields(self) -> dict:
        """The other ``Material`` fields as written (WINDOW's
        ``ThermalConductivity``, ``EmissivityFront``, ``EmissivityBack``,
        ``TIR``, ``PermeabilityFactor``, ...), name → text."""
        return dict(self.header["other"])

    @property
    def blocks(self) -> list:
        """``(band, direction)`` of every matrix, in file order."""
        return self._data.blocks()

    @property
    def bands(self) -> list:
        return list(dict.fromkeys(band for band, _ in self.blocks))

    def _block(self, direction, side, kind, band):
        band = _BANDS.get(str(band).lower(), band)
        if direction is not None:
            if side is not None or kind is not None:
                raise ModelError("give direction= or side= and kind=, not both")
            return band, _DIRECTIONS.get(direction, direction)
        if side not in ("front", "back") or kind not in ("reflection", "transmission"):
            raise ModelError(
                'give direction= ("Transmission Front", "tb", ...) or side="front"|"back" '
                'with kind="reflection"|"transmission"'
            )
        # brtf's side is where the light comes from: the front (+z) is lit
        # through the file's Back blocks (docs/klems.md, "Sides").
        opposite = {"front": "Back", "back": "Front"}[side]
        return band, f"{kind.capitalize()} {opposite}"

    def matrix(self, direction=None, *, side=None, kind=None, band="Visible") -> np.ndarray:
        """One matrix, N × N: ``[o, i]`` = BSDF (1/sr) from incident patch
        ``i`` to outgoing patch ``o``. ``KeyError`` when the file has no such block."""
        key = self._block(direction, side, kind, band)
        m = self._data.matrix(*key)
        if m is None:
            raise KeyError(f"{self.source} has no {key[0]} {key[1]} block (it has {self.blocks})")
        return m

    def totals(self, direction=None, *, side=None, kind=None, band="Visible") -> np.ndarray:
        """The column totals Σ_o BSDF[o, i] Λ_o: ρ_dh or τ_dh per incident
        patch, as ``brtf info`` and Radiance's ``checkBSDF`` compute them."""
        key = self._block(direction, side, kind, band)
        t = self._data.totals(*key)
        if t is None:
            raise KeyError(f"{self.source} has no {key[0]} {key[1]} block (it has {self.blocks})")
        return t

    @property
    def matrices(self) -> dict:
        """Every matrix, ``(band, direction)`` → N × N array."""
        return {key: self._data.matrix(*key) for key in self.blocks}

    def info(self) -> dict:
        """What ``brtf info --json FILE`` gives: the header, blocks and, per
        side and incident patch, θ_in, φ_in, ρ_dh and τ_dh."""
        return self._data.info()

    def measurements(self, side="both") -> list:
        """One ``Measurement`` per incident patch lit from ``side``
        (``"front"``: light from +z, θ_in ≤ 90°; ``"back"``; ``"both"``):
        the patch averages ``brtf fit`` fits (docs/klems.md, "As measurements")."""
        if side not in ("front", "back", "both"):
            raise ModelError(f'side={side!r}: expected "front", "back" or "both"')
        # Light from the front has θ_in ≤ 90°, from the back θ_in > 90°.
        lit = {"front": lambda t: t <= 90.0, "back": lambda t: t > 90.0, "both": lambda t: True}[side]
        return [m for m in self._data.measurements() if lit(m.theta_in)]

    def xml(self) -> str:
        """The text :meth:`write` writes."""
        return self._data.xml()

    def write(self, path) -> None:
        """Writes the file as ``brtf export --klems`` does (a temporary file,
        then renamed): a computed Klems exactly as that command writes it; a
        read one with its matrices and header (the thermal fields WINDOW
        reads; other ``Material`` fields are listed in the leading comment,
        not written)."""
        self._data.write(os.fspath(path))

    def __repr__(self) -> str:
        return (
            f"Klems({_text(self.source)}, name={_text(self.name)}, basis={_text(self.basis.name)}, "
            f"blocks={len(self.blocks)}, bands={self.bands})"
        )


def read_klems(path) -> Klems:
    """Reads a Klems BSDF XML file (LBNL/WINDOW format)."""
    return Klems(_brtf._Klems.read(os.fspath(path)))


def _to_klems(
    self,
    basis="full",
    *,
    name=None,
    samples=4096,
    solar="visible",
    colour=False,
    manufacturer="brtf",
    thickness=1.0,
    device_type="Other",
    conductivity=None,
    emissivity=None,
    ir_transmittance=None,
    permeability=None,
) -> Klems:
    """The Klems BSDF XML file of this material, computed as ``brtf export
    --klems BASIS --material m.rad`` does (all four blocks; a material is
    two-sided). ``solar``: ``"visible"`` (a Solar band equal to Visible,
    said in the file), ``"none"``, a ``.rad`` file or a ``Material`` of the
    solar properties. The other keywords are that command's options."""
    name = name or self.name or "material"
    if isinstance(solar, os.PathLike):
        solar = os.fspath(solar)
    if emissivity is not None:
        emissivity = tuple(emissivity)
    data = _brtf._to_klems(
        self, name, basis, samples, solar, colour, manufacturer, thickness, device_type,
        conductivity, emissivity, ir_transmittance, permeability,
    )
    return Klems(data)


class En14501:
    """``brtf.en14501``'s result: ``material`` (the ``trans``), ``rad`` (the
    Radiance text ``brtf fit --en14501`` prints) and the material's own
    ``rho_nh``, ``tau_nh`` and ``tau_nn`` at normal incidence (brtf-model,
    the figures that command's header gives)."""

    def __init__(self, rad: str):
        self.rad = rad
        self.material = Material.from_rad(rad)
        a = self.material.albedo(0.0, tolerance=1e-8)
        self.rho_nh = float(a.rho[1] + a.rho_spike[1])
        self.tau_nh = float(a.tau[1] + a.tau_spike[1])
        self.tau_nn = float(a.tau_spike[1])

    def __repr__(self) -> str:
        return (
            f"En14501({self.material!r}, rho_nh={self.rho_nh:.4f}, tau_nh={self.tau_nh:.4f}, "
            f"tau_nn={self.tau_nn:.4f})"
        )


def en14501(*, tau_nh, tau_nn, rho_nh, spec=0.0, name=None) -> En14501:
    """A grey ``trans`` from EN 14501 datasheet values at normal incidence,
    as ``brtf fit --en14501 tau_nh=…,tau_nn=…,rho_nh=…[,spec=…]``: the
    normal-hemispherical transmittance ``tau_nh``, the normal-normal
    (direct) ``tau_nn``, the normal-hemispherical reflectance ``rho_nh``
    and its specular part ``spec``. ``name`` names the material
    (default ``en14501``)."""
    rad = _brtf.en14501(float(tau_nh), float(tau_nn), float(rho_nh), float(spec), name)
    return En14501(rad)


Material.to_klems = _to_klems
