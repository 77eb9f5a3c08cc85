"""The exceptions brtf raises. Each carries ``file`` and ``line`` (None
when they do not apply); ``str(err)`` is the message as ``brtf`` prints it,
``file:line: problem``."""

from __future__ import annotations

from typing import Optional


class BrtfError(Exception):
    """Base class of every brtf error."""

    def __init__(self, message: str, file: Optional[str] = None, line: Optional[int] = None):
        super().__init__(message)
        self.file = file
        self.line = line


class FormatError(BrtfError, ValueError):
    """A file is not valid: a measurement file, Radiance text or fit.json."""


class FileError(BrtfError, OSError):
    """A file or folder could not be read or written."""

    def __init__(self, message: str, file: Optional[str] = None, line: Optional[int] = None):
        BrtfError.__init__(self, message, file, line)
        self.filename = file

    def __str__(self) -> str:
        return str(self.args[0])


class MissingFileError(FileError, FileNotFoundError):
    """A file does not exist."""


class ModelError(BrtfError, ValueError):
    """A bad model name, material argument or option value."""


class FitError(BrtfError, RuntimeError):
    """A fit could not be made."""


class ExportError(BrtfError, RuntimeError):
    """Exports or plots could not be written."""
