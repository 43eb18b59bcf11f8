"""`snakemake --logger shockcal`: one progress line on the console, the full output in a log file.

Snakemake finds a logger plugin by its package name (snakemake_logger_plugin_<name>); the handler lives in
shockcal.study.snakemake_console.
"""

from shockcal.study.snakemake_console import LogHandler, LogHandlerSettings

__all__ = ["LogHandler", "LogHandlerSettings"]
