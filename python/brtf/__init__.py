"""brtf: fit Radiance materials to gonio-photometer measurements.

The Rust core of the ``brtf`` command, with numpy arrays in and out and
angles in degrees, as on the command line::

    import brtf
    m = brtf.read("golden_paper.txt")          # a Measurement
    fit = brtf.fit([m], model="metal", gray=True)
    fit.global_fit.params                      # {'red': ..., 'rough': ...}
    fit.save("fits/golden_paper")              # the folder `brtf fit` writes

See docs/python.md.
"""

from ._brtf import (
    Albedo,
    Fit,
    IncidenceFit,
    Material,
    Measurement,
    __version__,
    read,
)
from ._errors import (
    BrtfError,
    ExportError,
    FileError,
    FitError,
    FormatError,
    MissingFileError,
    ModelError,
)
from ._python import En14501, Klems, KlemsBasis, en14501, fit, read_klems

__all__ = [
    "Albedo",
    "BrtfError",
    "ExportError",
    "FileError",
    "En14501",
    "Fit",
    "FitError",
    "FormatError",
    "IncidenceFit",
    "Klems",
    "KlemsBasis",
    "Material",
    "Measurement",
    "MissingFileError",
    "ModelError",
    "__version__",
    "en14501",
    "fit",
    "read",
    "read_klems",
]
