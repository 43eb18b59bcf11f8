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
