"""Type stubs of python/brtf/_python.py (brtf.fit; the rest patches the native classes)."""

from __future__ import annotations

from typing import Literal, Optional, Sequence, Union

from ._brtf import Fit, FresnelK, Measurement, Model, PathLike, Variant

def fit(
    inputs: Union[PathLike, Measurement, Sequence[Union[PathLike, Measurement]]],
    model: Union[Model, Literal["auto"]] = "metal",
    *,
    gray: bool = False,
    residual: Literal["absolute", "relative", "log"] = "absolute",
    loss: str = "none",
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
