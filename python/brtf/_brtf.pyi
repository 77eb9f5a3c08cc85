"""Type stubs of the native module (crates/py)."""

from __future__ import annotations

import os
from typing import Any, Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike]
ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]

class Measurement:
    """One gonio-photometer scan: one incidence, N scattered samples."""

    @property
    def theta_in(self) -> float: ...
    @property
    def phi_in(self) -> float: ...
    @property
    def theta(self) -> FloatArray: ...
    @property
    def phi(self) -> FloatArray: ...
    @property
    def value(self) -> FloatArray:
        """N × channels (1: CIE-Y; 3: CIE X, Y, Z); NaN = not available."""
    @property
    def solid_angle(self) -> FloatArray: ...
    @property
    def quantity(self) -> Literal["BSDF", "DSF", "raw"]: ...
    @property
    def unit(self) -> str: ...
    @property
    def beam_integral(self) -> Optional[float]: ...
    @property
    def channels(self) -> Literal["CIE-Y", "CIE-XYZ"]: ...
    @property
    def format(self) -> str: ...
    @property
    def sample_name(self) -> Optional[str]: ...
    @property
    def path(self) -> Optional[str]: ...
    @property
    def header(self) -> dict[str, str]: ...
    @property
    def header_lines(self) -> list[str]: ...
    def __len__(self) -> int: ...

def read(path: PathLike) -> Measurement: ...

FresnelK = Union[Literal["classic", "pyradiance"], float]
Variant = Literal["radiance", "manual2004", "ward1992"]
Model = Literal["plastic", "metal", "trans", "plastic2", "metal2", "trans2"]

class Albedo:
    """ρ_dh, τ_dh and the delta parts, shape θ_in.shape + (3,)."""

    @property
    def rho(self) -> FloatArray: ...
    @property
    def tau(self) -> FloatArray: ...
    @property
    def rho_spike(self) -> FloatArray: ...
    @property
    def tau_spike(self) -> FloatArray: ...

class Material:
    """One Radiance primitive, or a lobe sum: `lobes` primitives of one type
    mixed with constant weights (a `mixfunc` tree), one diffuse base."""

    def __init__(
        self,
        kind: Model,
        rgb: Union[float, Sequence[float], None] = None,
        spec: float = 0.0,
        roughness: Union[float, Sequence[float], None] = None,
        trans: Optional[float] = None,
        tspec: Optional[float] = None,
        *,
        orientation: Optional[Sequence[float]] = None,
        args: Optional[Sequence[float]] = None,
        lobes: int = 1,
        oriented: bool = False,
        variant: Variant = "radiance",
        fresnel_k: Optional[FresnelK] = None,
        source_omega: float = 0.0,
        curved: bool = False,
    ) -> None: ...
    @staticmethod
    def from_rad(
        text_or_path: Union[str, os.PathLike],
        name: Optional[str] = None,
        *,
        variant: Variant = "radiance",
        fresnel_k: Optional[FresnelK] = None,
        source_omega: float = 0.0,
        curved: bool = False,
    ) -> Material: ...
    @property
    def kind(self) -> Model: ...
    @property
    def args(self) -> Optional[list[float]]:
        """The flat arguments (None for a mixture of no lobe-sum shape)."""
    @property
    def param_names(self) -> Optional[list[str]]:
        """`red green blue spec [split1 ..] rough_k.. [orient]`."""
    @property
    def params(self) -> Optional[dict[str, float]]: ...
    @property
    def shape(self) -> Optional[str]:
        """`metal`, `metal ×2 lobes`, `plastic2 (orientation fitted)`."""
    @property
    def lobes(self) -> int: ...
    @property
    def components(self) -> list[tuple[float, Material]]:
        """The primitives mixed, (weight, Material), weights summing to 1."""
    @property
    def orientation(self) -> list[float]: ...
    @property
    def name(self) -> Optional[str]: ...
    @property
    def variant(self) -> Variant: ...
    @property
    def fresnel_k(self) -> float: ...
    @property
    def source_omega(self) -> float: ...
    @property
    def curved(self) -> bool: ...
    def eval(self, theta_in: ArrayLike, phi_in: ArrayLike, theta_out: ArrayLike, phi_out: ArrayLike) -> FloatArray:
        """BSDF (1/sr, no cosine), broadcast shape + (3,) for RGB."""
    def albedo(self, theta_in: ArrayLike, phi_in: float = 0.0, tolerance: float = 1e-5) -> Albedo: ...
    def to_rad(self, name: Optional[str] = None) -> str: ...
    def to_klems(
        self,
        basis: Literal["full", "half", "quarter"] = "full",
        *,
        name: Optional[str] = None,
        samples: int = 4096,
        solar: Union[Literal["visible", "none"], str, os.PathLike, Material] = "visible",
        colour: bool = False,
        manufacturer: str = "brtf",
        thickness: float = 1.0,
        device_type: str = "Other",
        conductivity: Optional[float] = None,
        emissivity: Optional[Sequence[float]] = None,
        ir_transmittance: Optional[float] = None,
        permeability: Optional[float] = None,
    ) -> Klems:
        """The file `brtf export --klems BASIS --material` writes, as a Klems."""

class IncidenceFit:
    @property
    def theta_in(self) -> float: ...
    @property
    def phi_in(self) -> float: ...
    @property
    def source(self) -> str: ...
    @property
    def params(self) -> dict[str, float]: ...
    @property
    def stderr(self) -> dict[str, Optional[float]]: ...
    @property
    def stderr_robust(self) -> dict[str, Optional[float]]: ...
    @property
    def material_args(self) -> list[float]: ...
    @property
    def material(self) -> Optional[Material]: ...
    @property
    def scale(self) -> float: ...
    @property
    def cost(self) -> float: ...
    @property
    def rms_rel(self) -> float: ...
    @property
    def e1(self) -> Optional[float]:
        """Σ ω |model − data| / Σ ω |data|: the share of the measured light put in the wrong place."""
    @property
    def n_points(self) -> int: ...
    @property
    def termination(self) -> str: ...
    @property
    def converged(self) -> bool: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def adequacy(self) -> Optional[dict[str, Any]]: ...
    def to_dict(self) -> dict[str, Any]: ...

class Fit:
    @staticmethod
    def load(folder: PathLike) -> Fit: ...
    @property
    def name(self) -> str: ...
    @property
    def model(self) -> Model: ...
    @property
    def incidences(self) -> list[IncidenceFit]: ...
    @property
    def global_fit(self) -> Optional[IncidenceFit]: ...
    @property
    def material(self) -> Optional[Material]: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def auto(self) -> Optional[dict[str, Any]]:
        """model="auto": the candidates, `first`, `chosen` and `reason`, as fit.json's `auto`."""
    def table(self, theta_in: ArrayLike) -> dict[str, FloatArray]: ...
    def material_at(self, theta_in: float, phi_in: Optional[float] = None) -> Material: ...
    def to_dict(self) -> dict[str, Any]: ...
    def save(self, folder: PathLike, *, export: bool = True, plots: bool = True, force: bool = False) -> list[str]: ...
    def export(
        self,
        folder: PathLike,
        *,
        at: Optional[float] = None,
        name: Optional[str] = None,
        static_only: bool = False,
        preview: bool = True,
        klems: Optional[Literal["full", "half", "quarter"]] = None,
        klems_colour: bool = False,
    ) -> list[str]: ...
    def _repr_html_(self) -> str:
        """The report's 3D view (data, model, model ÷ data), shown by a notebook."""

# brtf.fit (python/brtf/_python.py, typed in _python.pyi) turns its inputs
# into the paths and passes its keyword options on; one (side, Fit) per side
# (side None for gonio files).
def fit(paths: Sequence[PathLike], model: str = "metal", **options: Any) -> list[tuple[Optional[str], Fit]]: ...

class _Klems:
    """The native half of brtf.Klems (python/brtf/_python.py)."""

    @staticmethod
    def read(path: PathLike) -> _Klems: ...
    @property
    def source(self) -> str: ...
    @property
    def notes(self) -> list[str]: ...
    def basis(self) -> tuple[str, list[dict[str, Any]]]: ...
    def header(self) -> dict[str, Any]: ...
    def info(self) -> dict[str, Any]: ...
    def blocks(self) -> list[tuple[str, str]]: ...
    def matrix(self, band: str, direction: str) -> Optional[FloatArray]: ...
    def totals(self, band: str, direction: str) -> Optional[FloatArray]: ...
    def measurements(self) -> list[Measurement]: ...
    def xml(self) -> str: ...
    def write(self, path: PathLike) -> None: ...

def _to_klems(material: Material, name: str, basis: str, samples: int, solar: Any, colour: bool,
              manufacturer: str, thickness: float, device_type: str, conductivity: Optional[float],
              emissivity: Optional[tuple[float, float]], ir_transmittance: Optional[float],
              permeability: Optional[float]) -> _Klems: ...
def en14501(tau_nh: float, tau_nn: float, rho_nh: float, spec: float, name: Optional[str]) -> str: ...

from ._python import Klems  # noqa: E402  (Material.to_klems returns one)
