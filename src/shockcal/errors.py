"""Exception types whose messages are meant for the user (the CLI prints them without a traceback)."""


class ShockcalError(Exception):
    """Base class: a problem the user can fix (bad config, bad table, missing file)."""


class ConfigError(ShockcalError):
    """The study configuration is invalid; the message names the key path and the reason."""


class InputError(ShockcalError):
    """An input table or record is unusable; the message names the file, row or column."""


class SamplerError(ShockcalError):
    """A sampler stopped before its target (e.g. at its likelihood-evaluation limit); the message
    gives how far it got and the setting that stopped it."""


def number(value) -> str:
    """A number as a message shows it: plain digits, ten significant at most (-5.965, 204000, 1e-07, nan),
    never a numpy repr such as np.float64(nan)."""
    return format(float(value), ".10g")


def shown(value) -> str:
    """A table cell as a message shows it: text quoted ('abc'), a number plain (`number`: nan, not
    np.float64(nan))."""
    if isinstance(value, str):
        return repr(value)
    try:
        return number(value)
    except (TypeError, ValueError):
        return str(value)
