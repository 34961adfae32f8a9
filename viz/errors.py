"""Exceptions of :mod:`pinarms.viz`, derived from :class:`pinarms.errors.PinarmsError`."""

from __future__ import annotations

from pinarms.errors import PinarmsError

__all__ = ["VizError", "SessionFormatError", "ViewerError"]


class VizError(PinarmsError):
    """Base of the errors raised by :mod:`pinarms.viz`."""


class SessionFormatError(VizError):
    """A session file is corrupt, truncated, incomplete, inconsistent or from a newer pinarms.

    The message names the file and the member or field that is wrong.
    """


class ViewerError(VizError):
    """The MeshCat server could not be started or talked to, or a scene could not be built."""
