"""Errors for bad input; each names the problem and where it is."""


class VCCError(ValueError):
    """Base class for user-facing errors of the toolkit."""


class ProgramSyntaxError(VCCError):
    """A program text or structure that is not a valid VCC program."""


class SceneError(VCCError):
    """A scene that violates the world's rules (overlap, out of bounds, too many objects)."""


class DataFileError(VCCError):
    """A data file that is corrupt, foreign or of an unknown version."""
