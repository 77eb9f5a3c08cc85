"""Type stubs of python/brtf/_python.py (brtf.fit, read_klems, Klems, en14501; the rest patches the native classes)."""

from __future__ import annotations

from typing import Any, Literal, Optional, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

from ._brtf import Fit, FresnelK, Material, Measurement, Model, PathLike, Variant, _Klems

FloatArray = npt.NDArray[np.float64]
Direction = Literal[
    "Transmission Front", "Transmission Back", "Reflection Front", "Reflection Back", "tb", "tf", "rb", "rf"
]
Band = Literal["Visible", "Solar", "CIE-X", "CIE-Z", "visible", "solar", "cie-x", "cie-y", "cie-z"]

@overload
def fit(
    inputs: Union[PathLike, Measurement, Sequence[Union[PathLike, Measurement]]],
    model: Union[Model, Literal["auto"]] = "metal",
    *,
    side: Literal["both"],
    **options: Any,
) -> dict[str, Fit]:
    """A Klems BSDF XML file's sides: {"front": Fit, "back": Fit} (the sides it holds)."""
@overload
def fit(
    inputs: Union[PathLike, Measurement, Sequence[Union[PathLike, Measurement]]],
    model: Union[Model, Literal["auto"]] = "metal",
    *,
    gray: bool = False,
    residual: Literal["absolute", "relative", "log"] = "absolute",
    loss: str = "none",
    energy: Literal["free", "exact"] = "free",
    name: Optional[str] = None,
    variant: Variant = "radiance",
    fresnel_k: Optional[FresnelK] = None,
    source_omega: float = 0.0,
    orientation: Optional[Sequence[float]] = None,
    lobes: int = 1,
    floor: Optional[float] = None,
    colour: Literal["xyz", "as_recorded"] = "xyz",
    weights: Literal["solid_angle", "uniform"] = "solid_angle",
    multistart: bool = True,
    theta_cap: float = ...,
    beam_mask: float = 3.0,
    hemisphere: Optional[Literal["front", "back", "both"]] = None,
    min_value: Optional[float] = None,
    mask_holder: Union[bool, Literal["band", "auto"]] = False,
    phi_offset: Optional[Union[float, Literal["auto"]]] = None,
    beam_integral: Optional[float] = None,
    rho: Optional[tuple[float, float]] = None,
    free_scale: bool = False,
    interpolation: Literal["pchip", "linear"] = "pchip",
    adequacy: bool = True,
    side: Optional[Literal["front", "back"]] = None,
    incidences: Optional[str] = None,
    patch_samples: int = 32,
    jobs: Optional[int] = None,
) -> Fit: ...

class KlemsBasis:
    """Per patch (file order): centre theta, phi (degrees), bounds (N × 2),
    solid_angle Ω and lambda_ Λ (projected solid angle, sr; Σ Λ = π), ring."""

    name: str
    theta: FloatArray
    phi: FloatArray
    theta_bounds: FloatArray
    phi_bounds: FloatArray
    solid_angle: FloatArray
    lambda_: FloatArray
    ring: npt.NDArray[np.int_]
    def __init__(self, name: str, patches: list[dict[str, Any]]) -> None: ...
    def __len__(self) -> int: ...

class Klems:
    """A Klems BSDF XML file: matrix(...)[o, i] = BSDF (1/sr) from incident
    patch i (column) to outgoing patch o (row)."""

    basis: KlemsBasis
    header: dict[str, Any]
    notes: list[str]
    def __init__(self, data: _Klems) -> None: ...
    @property
    def source(self) -> str: ...
    @property
    def name(self) -> Optional[str]: ...
    @property
    def manufacturer(self) -> Optional[str]: ...
    @property
    def thickness(self) -> Optional[str]: ...
    @property
    def thickness_unit(self) -> Optional[str]: ...
    @property
    def device_type(self) -> Optional[str]: ...
    @property
    def fields(self) -> dict[str, str]: ...
    @property
    def blocks(self) -> list[tuple[str, str]]: ...
    @property
    def bands(self) -> list[str]: ...
    @property
    def matrices(self) -> dict[tuple[str, str], FloatArray]: ...
    def matrix(
        self,
        direction: Optional[Direction] = None,
        *,
        side: Optional[Literal["front", "back"]] = None,
        kind: Optional[Literal["reflection", "transmission"]] = None,
        band: Union[Band, str] = "Visible",
    ) -> FloatArray: ...
    def totals(
        self,
        direction: Optional[Direction] = None,
        *,
        side: Optional[Literal["front", "back"]] = None,
        kind: Optional[Literal["reflection", "transmission"]] = None,
        band: Union[Band, str] = "Visible",
    ) -> FloatArray: ...
    def info(self) -> dict[str, Any]: ...
    def measurements(self, side: Literal["front", "back", "both"] = "both") -> list[Measurement]: ...
    def xml(self) -> str: ...
    def write(self, path: PathLike) -> None: ...

def read_klems(path: PathLike) -> Klems: ...

class En14501:
    material: Material
    rad: str
    rho_nh: float
    tau_nh: float
    tau_nn: float
    def __init__(self, rad: str) -> None: ...

def en14501(*, tau_nh: float, tau_nn: float, rho_nh: float, spec: float = 0.0, name: Optional[str] = None) -> En14501: ...
