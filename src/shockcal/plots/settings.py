"""How figures are written: the study config's `figures` section as a settings model (its fields' defaults,
limits and descriptions once; the config schema's entries are generated from them,
`shockcal.settings_model`). Light: reading a config loads no matplotlib."""

from __future__ import annotations

from typing import Literal

from shockcal.settings_model import SettingsModel, setting


class FigureSettings(SettingsModel):
    """The formats and raster resolution of every figure (`shockcal.plots.style.save_figure`)."""

    formats: list[Literal["png", "pdf", "svg"]] = setting(["png", "pdf"], "File formats written for every figure.")
    dpi: int = setting(150, "Resolution of the raster format (png).", unit="dots per inch", ge=50)
