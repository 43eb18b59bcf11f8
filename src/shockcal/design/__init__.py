"""Design: which hydrocode runs to make.

`tables`: the seeded Latin hypercube over the prior box (scipy.stats.qmc), user designs checked
against the box (`InputBox`), the per-shot mapping of a design row onto one shot's inputs
(`ShotMapping`), and chunk fingerprints for the fan-out; `posterior_draws`: a design of rows drawn from
a joint posterior (posterior predictions, later waves, next-shot candidates); `waves`: a sequential
study's later waves. Hands on a design table: an integer `run`
id and one column per calibration input, in the paper's Table IV units.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "InputBox": "shockcal.design.tables",
    "ShotMapping": "shockcal.design.tables",
    "latin_hypercube": "shockcal.design.tables",
    "load_design": "shockcal.design.tables",
    "write_design": "shockcal.design.tables",
})
