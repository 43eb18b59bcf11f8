"""Campaign: the questions a campaign asks beyond one calibration.

Which shot next (`next_shot`: expected information gain on arrays; `candidates`: a candidate's design,
its elastic-plastic split check and the ranking; `ranking_check`: the ranking's realized check on
posterior-drawn truths), which strength law (`model_comparison`: the evidence table;
`box_sensitivity`: log Z with the prior box halved and doubled; `release`: the release's arrival on
a trace), and which inputs matter (`sensitivity`: Sobol indices of the emulator, SALib). Hands on
rankings, evidence tables and their checks to the figures and the report.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "expected_information_gain": "shockcal.campaign.next_shot",
    "noise_sd": "shockcal.campaign.next_shot",
    "evidence_table": "shockcal.campaign.model_comparison",
    "emulator_sobol": "shockcal.campaign.sensitivity",
})
