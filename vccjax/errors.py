"""Errors for bad input; each names the problem and where it is."""


class VCCError(ValueError):
    """Base class for user-facing errors of the toolkit."""


class ProgramSyntaxError(VCCError):
    """A program text or structure that is not a valid VCC program."""


class SceneError(VCCError):
    """A scene that violates the world's rules (overlap, out of bounds, too many objects)."""


class DataFileError(VCCError):
    """A data file that is corrupt, foreign or of an unknown version."""


def _number(text: str):
    """JSON numbers as this toolkit reads them: finite, and of a sane length (JSON allows
    a 400-digit integer, which no float holds)."""
    if len(text) > 64:
        raise ValueError(f"a number of {len(text)} characters")
    value = float(text) if any(c in text for c in ".eE") else int(text)
    if value != value or value in (float("inf"), float("-inf")):
        raise ValueError(f"the number {text} is not finite")
    return value


def _constant(name: str):
    raise ValueError(f"{name} is not a number JSON allows")


def loads(text: str):
    """Strict JSON: no NaN or infinities, no numbers too long to hold; nesting too deep
    raises RecursionError (callers name the file)."""
    import json

    return json.loads(text, parse_int=_number, parse_float=_number, parse_constant=_constant)


def read_json(path, error: type[VCCError], missing: str, what: str = "JSON"):
    """Parse a JSON file strictly (`loads`), turning a missing, unreadable or malformed
    file into `error` naming the path. Only regular files are read: a pipe would block."""
    import json
    from pathlib import Path

    p = Path(path)
    if p.exists() and not p.is_file():
        raise error(f"{p}: {'a folder' if p.is_dir() else 'not a regular file'}, not {what}")
    try:
        return loads(p.read_text())
    except FileNotFoundError:
        raise error(f"{p}: {missing}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise error(f"{p}: not {what} ({e})") from None
    except (RecursionError, ValueError) as e:  # nested too deep, or a number we cannot hold
        raise error(f"{p}: not {what} we can read ({str(e)[:80] or 'nested too deep'})") from None
