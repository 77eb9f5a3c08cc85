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
    read_klems,
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
from ._python import fit

__all__ = [
    "Albedo",
    "BrtfError",
    "ExportError",
    "FileError",
    "Fit",
    "FitError",
    "FormatError",
    "IncidenceFit",
    "Material",
    "Measurement",
    "MissingFileError",
    "ModelError",
    "__version__",
    "fit",
    "read",
    "read_klems",
]
