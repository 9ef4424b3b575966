"""Errors for bad input; each names the problem and where it is."""


class VCCError(ValueError):
    """Base class for user-facing errors of the toolkit."""


class ProgramSyntaxError(VCCError):
    """A program text or structure that is not a valid VCC program."""


class SceneError(VCCError):
    """A scene that violates the world's rules (overlap, out of bounds, too many objects)."""


class DataFileError(VCCError):
    """A data file that is corrupt, foreign or of an unknown version."""


def read_json(path, error: type[VCCError], missing: str, what: str = "JSON"):
    """Parse a JSON file, turning a missing or malformed file into `error` naming the path."""
    import json
    from pathlib import Path

    p = Path(path)
    try:
        return json.loads(p.read_text())
    except FileNotFoundError:
        raise error(f"{p}: {missing}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise error(f"{p}: not {what} ({e})") from None
